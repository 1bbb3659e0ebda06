#include "proto/codec/simplex_chunk_codec.hpp"

#include <zstd.h>
#include <zstd_errors.h>

#include <algorithm>
#include <cstring>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"

// Why this layout (measured on 1M-point families, 6.0M simplices at rank K/2, 58.0 MB raw; the
// numbers are in docs/design.md, "Compact Classify answers"):
// - Classes take 2 bits: four classes exist, and a byte each was 10% of the raw answer.
// - Indices are differences from the simplex before, in lexicographic order, because the answer is
//   sorted that way: a vertex chunk is a run of zeros, and an edge (a, b) after (a, b') costs
//   b - b' - 1 rather than b. Varints then spend bytes by magnitude, so input in a spatial order
//   (LiDAR strips, sorted grids) costs about one byte an index and random order about three.
// - zstd is optional: over loopback and fast links the server's cores, not the link, are the limit,
//   and the varints alone are about half the raw bytes.

namespace galpha::wire {

namespace v1 = galpha::v1;

namespace {

constexpr size_t kMaxVarintBytes = 5;

size_t ClassBytes(size_t count) { return (count + 3) / 4; }

// The most bytes a chunk's sections can take: every varint at its longest.
size_t SectionBound(size_t count, int arity) {
  return ClassBytes(count) + count * static_cast<size_t>(arity) * kMaxVarintBytes;
}

inline char* PutVarint(uint32_t value, char* out) {
  while (value >= 0x80) {
    *out++ = static_cast<char>(value | 0x80);
    value >>= 7;
  }
  *out++ = static_cast<char>(value);
  return out;
}

template <typename... Args>
absl::Status Refuse(uint64_t chunk_index, const Args&... args) {
  return absl::InvalidArgumentError(absl::StrCat("encoded simplex chunk ", chunk_index, ": ", args...));
}

// Writes the two sections of `count` simplices into `out` (at least SectionBound bytes); returns
// the bytes written, or an error for input the format cannot state.
absl::StatusOr<size_t> WriteSections(int arity, const uint32_t* indices, const char* classes, size_t count, char* out) {
  char* p = out;
  for (size_t i = 0; i < count; i += 4) {
    unsigned packed = 0;
    const size_t end = std::min(count, i + 4);
    for (size_t j = i; j < end; ++j) {
      const unsigned c = static_cast<unsigned char>(classes[j]) - 1u;
      if (c > 3) {
        return absl::InvalidArgumentError(absl::StrCat("simplex ", j, " has class byte ",
                                                       static_cast<int>(static_cast<unsigned char>(classes[j])),
                                                       "; a SimplexClass is 1..4"));
      }
      packed |= c << (2 * (j - i));
    }
    *p++ = static_cast<char>(packed);
  }
  const size_t a = static_cast<size_t>(arity);
  for (size_t i = 0; i < count; ++i) {
    const uint32_t* u = indices + i * a;
    const uint32_t* prev = i > 0 ? u - a : nullptr;
    bool same = prev != nullptr;  // u[0..k-1] == prev[0..k-1]
    for (size_t k = 0; k < a; ++k) {
      int64_t value;
      if (same) {
        value = int64_t{u[k]} - int64_t{prev[k]} - (k + 1 == a ? 1 : 0);
        same = u[k] == prev[k];
      } else if (k == 0) {
        value = u[0];
      } else {
        value = int64_t{u[k]} - int64_t{u[k - 1]} - 1;
      }
      if (value < 0) {
        return absl::InvalidArgumentError(
            absl::StrCat("simplex ", i, " is not strictly ascending within itself and after the simplex before it"));
      }
      p = PutVarint(static_cast<uint32_t>(value), p);
    }
  }
  return static_cast<size_t>(p - out);
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
  const size_t bound = SectionBound(count, arity);
  std::string* target = encoding == v1::SIMPLEX_ENCODING_DELTA ? out->mutable_data() : &plain_;
  target->resize(bound);
  const absl::StatusOr<size_t> written = WriteSections(arity, indices.data(), classes.data(), count, target->data());
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

SimplexChunkDecoder::SimplexChunkDecoder()
    : zstd_(ZSTD_createDCtx(), [](ZSTD_DCtx_s* context) { ZSTD_freeDCtx(context); }) {}

SimplexChunkDecoder::~SimplexChunkDecoder() = default;

absl::Status SimplexChunkDecoder::Decode(const v1::EncodedSimplexChunk& chunk, uint64_t chunk_index,
                                         v1::SimplexChunk* out) {
  const int arity = SimplexArity(chunk.kind());
  if (arity == 0) return Refuse(chunk_index, "its kind ", static_cast<int>(chunk.kind()), " is not a simplex kind");
  const v1::SimplexEncoding encoding = chunk.encoding();
  if (encoding != v1::SIMPLEX_ENCODING_DELTA && encoding != v1::SIMPLEX_ENCODING_DELTA_ZSTD) {
    return Refuse(chunk_index, "its encoding ", static_cast<int>(encoding), " is not DELTA (2) or DELTA_ZSTD (3)");
  }
  const size_t count = chunk.simplex_count();
  if (count == 0 || count > kMaxSimplicesPerEncodedChunk) {
    return Refuse(chunk_index, "it states ", count, " simplices; a chunk holds 1 to ", kMaxSimplicesPerEncodedChunk);
  }
  const size_t bound = SectionBound(count, arity);
  const std::string& data = chunk.data();
  const unsigned char* sections = reinterpret_cast<const unsigned char*>(data.data());
  size_t size = data.size();
  if (encoding == v1::SIMPLEX_ENCODING_DELTA_ZSTD) {
    const size_t frame = ZSTD_findFrameCompressedSize(data.data(), data.size());
    if (ZSTD_isError(frame))
      return Refuse(chunk_index, "its data is not a zstd frame (", ZSTD_getErrorName(frame), ")");
    if (frame != data.size()) {
      return Refuse(chunk_index, "it has ", data.size() - frame, " bytes after its zstd frame");
    }
    if (scratch_bytes_ < bound) {
      scratch_.reset(new unsigned char[bound]);  // not zero-filled: decompression writes it
      scratch_bytes_ = bound;
    }
    // Bounded by what `count` simplices can take: a frame that says or holds more fails here.
    size = ZSTD_decompressDCtx(zstd_.get(), scratch_.get(), bound, data.data(), data.size());
    if (ZSTD_isError(size)) {
      if (ZSTD_getErrorCode(size) == ZSTD_error_dstSize_tooSmall) {
        return Refuse(chunk_index, "its zstd frame decompresses to more than the ", bound, " bytes ", count,
                      " simplices can take");
      }
      return Refuse(chunk_index, "its zstd frame is corrupt (", ZSTD_getErrorName(size), ")");
    }
    sections = scratch_.get();
  } else if (size > bound) {
    return Refuse(chunk_index, "its ", size, " bytes are more than the ", bound, " bytes ", count,
                  " simplices can take");
  }

  const size_t class_bytes = ClassBytes(count);
  if (size < class_bytes) {
    return Refuse(chunk_index, "its ", size, " bytes end before its ", class_bytes, " bytes of classes");
  }
  const unsigned tail = static_cast<unsigned>(count % 4);
  if (tail != 0 && (sections[class_bytes - 1] >> (2 * tail)) != 0) {
    return Refuse(chunk_index, "the unused bits of its last class byte are not 0");
  }
  out->Clear();
  out->set_kind(chunk.kind());
  std::string* classes = out->mutable_classes();
  classes->resize(count);
  char* c = classes->data();
  for (size_t i = 0; i < count; ++i) {
    c[i] = static_cast<char>(((sections[i / 4] >> (2 * (i % 4))) & 3u) + 1u);
  }

  const size_t a = static_cast<size_t>(arity);
  auto* indices = out->mutable_vertex_indices();
  indices->Resize(static_cast<int>(count * a), 0);
  uint32_t* u = indices->mutable_data();
  const unsigned char* p = sections + class_bytes;
  const unsigned char* end = sections + size;
  for (size_t i = 0; i < count; ++i) {
    uint32_t* cur = u + i * a;
    const uint32_t* prev = i > 0 ? cur - a : nullptr;
    bool same = prev != nullptr;
    for (size_t k = 0; k < a; ++k) {
      uint64_t value = 0;
      for (int shift = 0;; shift += 7) {
        if (p == end) return Refuse(chunk_index, "its varints end inside simplex ", i, " (truncated)");
        if (shift == 7 * static_cast<int>(kMaxVarintBytes)) {
          return Refuse(chunk_index, "simplex ", i, " has a varint longer than ", kMaxVarintBytes, " bytes");
        }
        const unsigned byte = *p++;
        value |= static_cast<uint64_t>(byte & 0x7Fu) << shift;
        if ((byte & 0x80u) == 0) break;
      }
      uint64_t index;
      if (same) {
        index = uint64_t{prev[k]} + value + (k + 1 == a ? 1 : 0);
        same = value == 0;
      } else if (k == 0) {
        index = value;
      } else {
        index = uint64_t{cur[k - 1]} + value + 1;
      }
      if (index > UINT32_MAX) return Refuse(chunk_index, "simplex ", i, " has an index over 2^32 - 1");
      cur[k] = static_cast<uint32_t>(index);
    }
  }
  if (p != end) return Refuse(chunk_index, "it has ", end - p, " bytes after its ", count, " simplices");
  return absl::OkStatus();
}

}  // namespace galpha::wire
