// The data of an EncodedSimplexChunk (proto/galpha/v1/alpha_shapes.proto: 2-bit classes, then the
// indices as lexicographic varint differences, optionally one zstd frame), written and read
// without the protobuf message around it. simplex_chunk_codec wraps it for the server and the C++
// client; the Python package's compiled module reads it directly (python/engine/), so that it
// links no protobuf of its own beside the interpreter's.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

struct ZSTD_DCtx_s;

namespace galpha::wire {

/// Most simplices one EncodedSimplexChunk may state: bounds the decoder's work and memory for one
/// message (13 MiB of decoded triangles). The server sends 131,072 a chunk.
inline constexpr uint32_t kMaxSimplicesPerEncodedChunk = uint32_t{1} << 20;

/// The most bytes the sections of `count` simplices of `arity` vertices can take (every varint at
/// its longest): what a writer must provide and what a reader accepts.
size_t SimplexSectionBound(size_t count, int arity);

/// Writes the sections of `count` simplices (`indices`: arity a simplex; `classes`: one
/// SimplexClass number, 1..4, a simplex) into `out` (SimplexSectionBound bytes); returns the bytes
/// written. InvalidArgument for a class byte outside 1..4 and for simplices that are not strictly
/// ascending within themselves and across the chunk (the format cannot state them).
absl::StatusOr<size_t> WriteSimplexSections(int arity, const uint32_t* indices, const char* classes, size_t count,
                                            char* out);

/// Reads sections. Holds a zstd context and a scratch buffer reused from chunk to chunk; one per
/// stream, not thread-safe.
class SimplexSectionReader {
 public:
  SimplexSectionReader();
  ~SimplexSectionReader();
  SimplexSectionReader(const SimplexSectionReader&) = delete;
  SimplexSectionReader& operator=(const SimplexSectionReader&) = delete;

  /// The `count` simplices of `arity` (1, 2 or 3) vertices that `data` holds (`zstd`: as one zstd
  /// frame), into `indices` (arity * count) and `classes` (count SimplexClass numbers).
  /// InvalidArgument naming the chunk (`chunk_index`: its place among the answer's chunks, from 0)
  /// for a count of 0 or over kMaxSimplicesPerEncodedChunk and for every malformed section the
  /// proto lists; the outputs are then unspecified. Decompression never writes more than
  /// SimplexSectionBound bytes. O(count).
  absl::Status Read(int arity, size_t count, bool zstd, std::string_view data, uint64_t chunk_index, uint32_t* indices,
                    char* classes);

 private:
  std::unique_ptr<ZSTD_DCtx_s, void (*)(ZSTD_DCtx_s*)> zstd_;
  std::unique_ptr<unsigned char[]> scratch_;  // decompressed sections, never zero-filled first
  size_t scratch_bytes_ = 0;
};

}  // namespace galpha::wire
