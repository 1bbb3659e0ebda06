#include "proto/sections/simplex_sections.hpp"

#include <zstd.h>
#include <zstd_errors.h>

#include <algorithm>
#include <array>
#include <cstring>

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

namespace {

constexpr size_t kMaxVarintBytes = 5;

size_t ClassBytes(size_t count) { return (count + 3) / 4; }

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

// The classes section: four 2-bit classes a byte, unpacked through a table of four class bytes
// per packed byte.
void UnpackClasses(const unsigned char* packed, size_t count, char* out) {
  static const std::array<std::array<char, 4>, 256> kTable = [] {
    std::array<std::array<char, 4>, 256> table{};
    for (unsigned byte = 0; byte < 256; ++byte) {
      for (unsigned j = 0; j < 4; ++j) table[byte][j] = static_cast<char>(((byte >> (2 * j)) & 3u) + 1u);
    }
    return table;
  }();
  const size_t whole = count / 4;
  for (size_t i = 0; i < whole; ++i) std::memcpy(out + 4 * i, kTable[packed[i]].data(), 4);
  for (size_t i = 4 * whole; i < count; ++i) out[i] = kTable[packed[i / 4]][i % 4];
}

// Why the indices section failed, and at which simplex.
struct IndexFailure {
  enum Kind { kNone, kTruncated, kOverlong, kOverflow } kind = kNone;
  size_t simplex = 0;
};

// One varint at *p with no bound check (the caller knows that kMaxVarintBytes bytes are there);
// false for a longer one.
inline bool ReadVarintUnchecked(const unsigned char** p, uint64_t* value) {
  const unsigned char* q = *p;
  uint64_t v = q[0];
  if (v < 0x80) {
    *p = q + 1;
    *value = v;
    return true;
  }
  v &= 0x7F;
  for (int i = 1; i < static_cast<int>(kMaxVarintBytes); ++i) {
    const uint64_t byte = q[i];
    v |= (byte & 0x7F) << (7 * i);
    if (byte < 0x80) {
      *p = q + i + 1;
      *value = v;
      return true;
    }
  }
  return false;
}

// One varint at *p, checked against `end`.
inline IndexFailure::Kind ReadVarintChecked(const unsigned char** p, const unsigned char* end, uint64_t* value) {
  uint64_t v = 0;
  for (int shift = 0;; shift += 7) {
    if (*p == end) return IndexFailure::kTruncated;
    if (shift == 7 * static_cast<int>(kMaxVarintBytes)) return IndexFailure::kOverlong;
    const unsigned byte = *(*p)++;
    v |= static_cast<uint64_t>(byte & 0x7Fu) << shift;
    if ((byte & 0x80u) == 0) break;
  }
  *value = v;
  return IndexFailure::kNone;
}

// The indices of `count` simplices of A vertices from the varints at *p (proto: EncodedSimplexChunk),
// into out[0, A * count). Simplices whose varints are surely all there (A * kMaxVarintBytes bytes
// left) are read without bound checks; the prefix rule is written as selects, not branches.
template <int A>
IndexFailure DecodeIndices(const unsigned char** cursor, const unsigned char* end, size_t count, uint32_t* out) {
  const unsigned char* p = *cursor;
  for (size_t i = 0; i < count; ++i) {
    std::array<uint64_t, A> v;
    if (end - p >= static_cast<std::ptrdiff_t>(A * kMaxVarintBytes)) {
      for (int k = 0; k < A; ++k) {
        if (!ReadVarintUnchecked(&p, &v[static_cast<size_t>(k)])) return {IndexFailure::kOverlong, i};
      }
    } else {
      for (int k = 0; k < A; ++k) {
        const IndexFailure::Kind read = ReadVarintChecked(&p, end, &v[static_cast<size_t>(k)]);
        if (read != IndexFailure::kNone) return {read, i};
      }
    }
    uint32_t* u = out + i * A;
    std::array<uint64_t, A> index;
    if (i == 0) {
      // The chunk's first simplex: from nothing, each index after the one before it.
      index[0] = v[0];
      for (int k = 1; k < A; ++k) index[k] = index[k - 1] + v[k] + 1;
    } else {
      const uint32_t* prev = u - A;
      bool same = true;  // u[0..k-1] == prev[0..k-1]
      for (int k = 0; k < A; ++k) {
        const uint64_t last = k + 1 == A ? 1 : 0;
        const uint64_t from_prev = uint64_t{prev[k]} + v[k] + last;
        const uint64_t from_before = k == 0 ? 0 : index[k > 0 ? k - 1 : 0] + v[k] + 1;
        index[k] = same ? from_prev : from_before;
        same = same && v[k] == 0;
      }
    }
    uint64_t high = 0;
    for (int k = 0; k < A; ++k) {
      high |= index[k] >> 32;
      u[k] = static_cast<uint32_t>(index[k]);
    }
    if (high != 0) return {IndexFailure::kOverflow, i};
  }
  *cursor = p;
  return {};
}

}  // namespace

size_t SimplexSectionBound(size_t count, int arity) {
  return ClassBytes(count) + count * static_cast<size_t>(arity) * kMaxVarintBytes;
}

absl::StatusOr<size_t> WriteSimplexSections(int arity, const uint32_t* indices, const char* classes, size_t count,
                                            char* out) {
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

SimplexSectionReader::SimplexSectionReader()
    : zstd_(ZSTD_createDCtx(), [](ZSTD_DCtx_s* context) { ZSTD_freeDCtx(context); }) {}

SimplexSectionReader::~SimplexSectionReader() = default;

absl::Status SimplexSectionReader::Read(int arity, size_t count, bool zstd, std::string_view data, uint64_t chunk_index,
                                        uint32_t* indices, char* classes) {
  if (arity < 1 || arity > 3) return Refuse(chunk_index, "its simplices have ", arity, " vertices, not 1 to 3");
  if (count == 0 || count > kMaxSimplicesPerEncodedChunk) {
    return Refuse(chunk_index, "it states ", count, " simplices; a chunk holds 1 to ", kMaxSimplicesPerEncodedChunk);
  }
  const size_t bound = SimplexSectionBound(count, arity);
  const unsigned char* sections = reinterpret_cast<const unsigned char*>(data.data());
  size_t size = data.size();
  if (zstd) {
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
  UnpackClasses(sections, count, classes);
  const unsigned char* p = sections + class_bytes;
  const unsigned char* end = sections + size;
  const IndexFailure failure = arity == 1   ? DecodeIndices<1>(&p, end, count, indices)
                               : arity == 2 ? DecodeIndices<2>(&p, end, count, indices)
                                            : DecodeIndices<3>(&p, end, count, indices);
  switch (failure.kind) {
    case IndexFailure::kNone:
      break;
    case IndexFailure::kTruncated:
      return Refuse(chunk_index, "its varints end inside simplex ", failure.simplex, " (truncated)");
    case IndexFailure::kOverlong:
      return Refuse(chunk_index, "simplex ", failure.simplex, " has a varint longer than ", kMaxVarintBytes, " bytes");
    case IndexFailure::kOverflow:
      return Refuse(chunk_index, "simplex ", failure.simplex, " has an index over 2^32 - 1");
  }
  if (p != end) return Refuse(chunk_index, "it has ", end - p, " bytes after its ", count, " simplices");
  return absl::OkStatus();
}

}  // namespace galpha::wire
