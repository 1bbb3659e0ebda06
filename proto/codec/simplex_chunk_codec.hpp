// Compact, lossless Classify answers (galpha.v1.EncodedSimplexChunk, defined in
// proto/galpha/v1/alpha_shapes.proto): the server's encoder and the client's decoder in one module,
// so that both sides read the format from one place (the chunk's data section itself is
// simplex_sections). Free of gRPC (only the protobuf messages), so the fuzz target
// (tests/fuzz/simplex_chunk_fuzzer.cpp) and the unit tests drive it directly.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/types/span.h"
#include "galpha/v1/alpha_shapes.pb.h"
#include "proto/sections/simplex_sections.hpp"

struct ZSTD_CCtx_s;

namespace galpha::wire {

/// Vertex indices a simplex of `kind` has (1, 2, 3); 0 for a kind the format does not define.
int SimplexArity(galpha::v1::SimplexKind kind);

/// Encodes simplex chunks. Holds a zstd context and a scratch buffer reused from chunk to chunk;
/// not thread-safe.
class SimplexChunkEncoder {
 public:
  /// `zstd_level`: zstd's compression level for DELTA_ZSTD (1 is the fastest).
  explicit SimplexChunkEncoder(int zstd_level = 1);
  ~SimplexChunkEncoder();
  SimplexChunkEncoder(const SimplexChunkEncoder&) = delete;
  SimplexChunkEncoder& operator=(const SimplexChunkEncoder&) = delete;

  /// The simplices of `kind` whose indices are `indices` (arity a simplex) and whose classes are
  /// `classes` (one SimplexClass number, 1..4, a simplex), as `encoding` (DELTA or DELTA_ZSTD).
  /// InvalidArgument for an unknown kind or encoding, counts that disagree, 0 or more than
  /// kMaxSimplicesPerEncodedChunk simplices, a class byte outside 1..4, and simplices that are not
  /// strictly ascending within themselves and across the chunk (the format cannot state them).
  absl::Status Encode(galpha::v1::SimplexKind kind, absl::Span<const uint32_t> indices, std::string_view classes,
                      galpha::v1::SimplexEncoding encoding, galpha::v1::EncodedSimplexChunk* out);
  /// The same from a raw chunk.
  absl::Status Encode(const galpha::v1::SimplexChunk& chunk, galpha::v1::SimplexEncoding encoding,
                      galpha::v1::EncodedSimplexChunk* out);

  /// Frees the scratch buffer (it grows to the largest DELTA_ZSTD chunk encoded).
  void ReleaseScratch() { std::string().swap(plain_); }

 private:
  int level_;
  std::unique_ptr<ZSTD_CCtx_s, void (*)(ZSTD_CCtx_s*)> zstd_;
  std::string plain_;  // the uncompressed sections, for DELTA_ZSTD
};

/// Decodes EncodedSimplexChunks. Holds a zstd context and a scratch buffer reused from chunk to
/// chunk; one per stream, not thread-safe.
class SimplexChunkDecoder {
 public:
  /// `chunk` as the SimplexChunk it encodes (`out` is overwritten). InvalidArgument naming the
  /// chunk (`chunk_index`: its place among the answer's chunks, from 0) for everything the proto
  /// says a client refuses. Decompression never writes more than the count allows. O(count).
  absl::Status Decode(const galpha::v1::EncodedSimplexChunk& chunk, uint64_t chunk_index,
                      galpha::v1::SimplexChunk* out);

 private:
  SimplexSectionReader reader_;
};

}  // namespace galpha::wire
