#include "proto/codec/simplex_chunk_codec.hpp"

#include <zstd.h>

#include <cstddef>

#include "absl/strings/str_cat.h"

namespace galpha::wire {

namespace v1 = galpha::v1;

namespace {

template <typename... Args>
absl::Status Refuse(uint64_t chunk_index, const Args&... args) {
  return absl::InvalidArgumentError(absl::StrCat("encoded simplex chunk ", chunk_index, ": ", args...));
}

}  // namespace

int SimplexArity(v1::SimplexKind kind) {
  switch (kind) {
    case v1::SIMPLEX_KIND_VERTEX:
      return 1;
    case v1::SIMPLEX_KIND_EDGE:
      return 2;
    case v1::SIMPLEX_KIND_TRIANGLE:
      return 3;
    default:
      return 0;
  }
}

// ---- Encoder ----------------------------------------------------------------------------------------

SimplexChunkEncoder::SimplexChunkEncoder(int zstd_level)
    : level_(zstd_level), zstd_(ZSTD_createCCtx(), [](ZSTD_CCtx_s* context) { ZSTD_freeCCtx(context); }) {}

SimplexChunkEncoder::~SimplexChunkEncoder() = default;

absl::Status SimplexChunkEncoder::Encode(v1::SimplexKind kind, absl::Span<const uint32_t> indices,
                                         std::string_view classes, v1::SimplexEncoding encoding,
                                         v1::EncodedSimplexChunk* out) {
  const int arity = SimplexArity(kind);
  if (arity == 0)
    return absl::InvalidArgumentError(absl::StrCat("simplex kind ", static_cast<int>(kind), " is unknown"));
  if (encoding != v1::SIMPLEX_ENCODING_DELTA && encoding != v1::SIMPLEX_ENCODING_DELTA_ZSTD) {
    return absl::InvalidArgumentError(
        absl::StrCat("simplex encoding ", static_cast<int>(encoding), " is not DELTA (2) or DELTA_ZSTD (3)"));
  }
  const size_t count = classes.size();
  if (indices.size() != count * static_cast<size_t>(arity)) {
    return absl::InvalidArgumentError(
        absl::StrCat(indices.size(), " indices for ", count, " simplices of ", arity, " vertices"));
  }
  if (count == 0 || count > kMaxSimplicesPerEncodedChunk) {
    return absl::InvalidArgumentError(
        absl::StrCat(count, " simplices; an encoded chunk holds 1 to ", kMaxSimplicesPerEncodedChunk));
  }
  out->Clear();
  out->set_kind(kind);
  out->set_simplex_count(static_cast<uint32_t>(count));
  out->set_encoding(encoding);
  const size_t bound = SimplexSectionBound(count, arity);
  std::string* target = encoding == v1::SIMPLEX_ENCODING_DELTA ? out->mutable_data() : &plain_;
  target->resize(bound);
  const absl::StatusOr<size_t> written =
      WriteSimplexSections(arity, indices.data(), classes.data(), count, target->data());
  if (!written.ok()) {
    out->Clear();
    return written.status();
  }
  target->resize(*written);
  if (encoding == v1::SIMPLEX_ENCODING_DELTA) return absl::OkStatus();
  std::string* data = out->mutable_data();
  data->resize(ZSTD_compressBound(plain_.size()));
  const size_t size = ZSTD_compressCCtx(zstd_.get(), data->data(), data->size(), plain_.data(), plain_.size(), level_);
  if (ZSTD_isError(size)) {
    out->Clear();
    return absl::InternalError(absl::StrCat("zstd: ", ZSTD_getErrorName(size)));
  }
  data->resize(size);
  return absl::OkStatus();
}

absl::Status SimplexChunkEncoder::Encode(const v1::SimplexChunk& chunk, v1::SimplexEncoding encoding,
                                         v1::EncodedSimplexChunk* out) {
  return Encode(chunk.kind(), absl::MakeConstSpan(chunk.vertex_indices().data(), chunk.vertex_indices().size()),
                chunk.classes(), encoding, out);
}

// ---- Decoder ----------------------------------------------------------------------------------------

absl::Status SimplexChunkDecoder::Decode(const v1::EncodedSimplexChunk& chunk, uint64_t chunk_index,
                                         v1::SimplexChunk* out) {
  const int arity = SimplexArity(chunk.kind());
  if (arity == 0) return Refuse(chunk_index, "its kind ", static_cast<int>(chunk.kind()), " is not a simplex kind");
  const v1::SimplexEncoding encoding = chunk.encoding();
  if (encoding != v1::SIMPLEX_ENCODING_DELTA && encoding != v1::SIMPLEX_ENCODING_DELTA_ZSTD) {
    return Refuse(chunk_index, "its encoding ", static_cast<int>(encoding), " is not DELTA (2) or DELTA_ZSTD (3)");
  }
  const size_t count = chunk.simplex_count();
  // Checked before the outputs are sized (the reader checks it again).
  if (count == 0 || count > kMaxSimplicesPerEncodedChunk) {
    return Refuse(chunk_index, "it states ", count, " simplices; a chunk holds 1 to ", kMaxSimplicesPerEncodedChunk);
  }
  out->Clear();
  out->set_kind(chunk.kind());
  std::string* classes = out->mutable_classes();
  classes->resize(count);
  auto* indices = out->mutable_vertex_indices();
  indices->Resize(static_cast<int>(count * static_cast<size_t>(arity)), 0);
  absl::Status read = reader_.Read(arity, count, encoding == v1::SIMPLEX_ENCODING_DELTA_ZSTD, chunk.data(), chunk_index,
                                   indices->mutable_data(), classes->data());
  if (!read.ok()) out->Clear();
  return read;
}

}  // namespace galpha::wire
