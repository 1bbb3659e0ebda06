// Compact, lossless encodings of a Build stream's points (galpha.v1.EncodedPointChunk, defined in
// proto/galpha/v1/alpha_shapes.proto): the server's decoder and the client's encoder in one module,
// so that both sides read the format from one place. Free of gRPC (only the protobuf messages), so
// the fuzz target and the unit tests drive it directly.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"
#include "galpha/v1/alpha_shapes.pb.h"

struct ZSTD_CCtx_s;
struct ZSTD_DCtx_s;

namespace galpha::wire {

/// Most points one EncodedPointChunk may state (4 MiB of decoded doubles, gRPC's default message
/// size): bounds the work of one message and the decoder's scratch memory, which the in-flight
/// limits do not count (at most three buffers of that size per stream, freed when the stream ends).
inline constexpr uint64_t kMaxPointsPerEncodedChunk = uint64_t{1} << 18;

/// Where a chunk sits in its Build stream, for the messages that name it.
struct ChunkPosition {
  uint64_t chunk_index = 0;  // among the stream's point chunks, from 0
  uint64_t first_point = 0;  // index of its first point in the whole stream
};

/// InvalidArgument naming the chunk for what can be checked without decoding: point_count 0 or over
/// kMaxPointsPerEncodedChunk, an unspecified or undefined value type, transform or compression,
/// a scale on a FLOAT64 chunk, a missing, zero, NaN or infinite scale (or divisor) or a non-finite
/// offset on an integer chunk, a w_scale in an unweighted stream (`weighted` false) and a missing
/// one on a weighted integer chunk. O(1).
absl::Status CheckEncodedChunkShape(const galpha::v1::EncodedPointChunk& chunk, const ChunkPosition& at,
                                    bool weighted = false);

/// Decodes EncodedPointChunks. Holds a zstd context and a scratch buffer reused from chunk to chunk;
/// one per stream, not thread-safe.
class PointChunkDecoder {
 public:
  PointChunkDecoder();
  ~PointChunkDecoder();
  PointChunkDecoder(const PointChunkDecoder&) = delete;
  PointChunkDecoder& operator=(const PointChunkDecoder&) = delete;

  /// Decodes `chunk` into out[0, point_count). InvalidArgument naming the chunk: everything
  /// CheckEncodedChunkShape refuses, data that is not exactly one zstd frame, data whose decoded
  /// size differs from point_count's (decompression is bounded by that size: nothing more is ever
  /// written), an INT64 value over 2^53 in magnitude, a NaN or infinite coordinate (naming the
  /// point's index in the stream). On an error `out` holds unspecified values. O(point_count).
  absl::Status Decode(const galpha::v1::EncodedPointChunk& chunk, const ChunkPosition& at, Point2* out);
  /// A chunk of a weighted stream (three words a point: x, y, w): the points into out[0,
  /// point_count), their weights into weights[0, point_count). Refuses what Decode refuses, a
  /// missing w_scale on an integer chunk, and a NaN or infinite weight (naming the point).
  absl::Status DecodeWeighted(const galpha::v1::EncodedPointChunk& chunk, const ChunkPosition& at, Point2* out,
                              double* weights);

  /// Frees the scratch buffers (they grow to the largest chunk decoded) and the zstd context;
  /// decoding again makes them again.
  void ReleaseScratch();

 private:
  // The chunk's values, `axes` (2 or 3) per point interleaved, into values[0, axes * point_count).
  absl::Status DecodeValues(const galpha::v1::EncodedPointChunk& chunk, const ChunkPosition& at, size_t axes,
                            double* values);

  std::unique_ptr<ZSTD_DCtx_s, void (*)(ZSTD_DCtx_s*)> zstd_;
  std::unique_ptr<unsigned char[]> scratch_;  // decompressed data, never zero-filled first
  size_t scratch_bytes_ = 0;
  std::vector<uint64_t> words64_, planar64_;
  std::vector<uint32_t> words32_, planar32_;
  std::vector<double> triples_;  // a weighted chunk's x, y, w values before they are split
};

/// The double an integer X of an axis decodes to: `offset + scale * X` or `offset + X / divisor`,
/// two IEEE roundings, never fused (this module is built with -ffp-contract=off).
double ScaledValue(const galpha::v1::AxisScale& scale, int64_t x);

/// Per-axis scales under which every coordinate of a point set is an integer, exactly.
struct ScaledAxes {
  galpha::v1::PointValueType value_type = galpha::v1::POINT_VALUE_TYPE_INT64;  // INT32 when every X fits
  galpha::v1::AxisScale x;
  galpha::v1::AxisScale y;
  galpha::v1::AxisScale w;  // weighted sets only
};

/// Finds, per axis, the first of fl(10^-k) * X and X / 10^k (k = 0..22, offset 0: LAS with a zero
/// offset, decimal text), offset + fl(10^-k) * X (k = 0..9, offset the axis's minimum rounded
/// down to a multiple of 10^j, j = 0..7: LAS offsets) and 2^-k * X that reproduces every
/// coordinate bit for bit with |X| <= 2^53; nullopt when an axis has none (or a coordinate is -0.0, NaN or infinite).
/// Verified point by point with ScaledValue, so the server decodes exactly these doubles. O(n) per
/// candidate tried, stopping at the first coordinate that fails.
std::optional<ScaledAxes> FindScaledIntegers(absl::Span<const Point2> points);
/// The same for weighted points: a scale for their weights too (weights.size() == points.size()),
/// found as for a coordinate axis (atom radii squared from 0.01 A radii are multiples of 10^-4).
std::optional<ScaledAxes> FindScaledIntegers(absl::Span<const Point2> points, absl::Span<const double> weights);

/// How to encode one chunk.
struct ChunkEncoding {
  galpha::v1::PointValueType value_type = galpha::v1::POINT_VALUE_TYPE_FLOAT64;
  galpha::v1::AxisScale x_scale;  // integer value types only
  galpha::v1::AxisScale y_scale;
  galpha::v1::PointTransform transform = galpha::v1::POINT_TRANSFORM_NONE;
  galpha::v1::PointCompression compression = galpha::v1::POINT_COMPRESSION_NONE;
  galpha::v1::AxisScale w_scale;  // integer value types of weighted chunks only
};

/// Encodes chunks. Holds a zstd context reused from chunk to chunk; not thread-safe.
class PointChunkEncoder {
 public:
  /// `zstd_level`: zstd's compression level (1..19; 3 is zstd's default).
  explicit PointChunkEncoder(int zstd_level = 3);
  ~PointChunkEncoder();
  PointChunkEncoder(const PointChunkEncoder&) = delete;
  PointChunkEncoder& operator=(const PointChunkEncoder&) = delete;

  /// `points` (1 to kMaxPointsPerEncodedChunk) as `encoding` says. InvalidArgument when an integer
  /// encoding does not reproduce a coordinate exactly (naming it) or a value does not fit the type.
  absl::Status Encode(absl::Span<const Point2> points, const ChunkEncoding& encoding,
                      galpha::v1::EncodedPointChunk* out);
  /// Weighted points (one weight per point; empty: unweighted, as above): a chunk of a weighted
  /// stream, three words a point. InvalidArgument also for a weight the encoding does not reproduce.
  absl::Status Encode(absl::Span<const Point2> points, absl::Span<const double> weights, const ChunkEncoding& encoding,
                      galpha::v1::EncodedPointChunk* out);

  /// The smallest of the forms this module knows for `points` (float64 and, when
  /// FindScaledIntegers finds them, scaled integers; each transform tried, zstd-compressed unless
  /// that grows the data), or a raw PointChunk when nothing beats it. `out` gets `points` or
  /// `encoded_points`. The form is chosen on the whole chunk up to 16,384 points, else on its first
  /// 8,192 points (then it can miss the smallest by a little).
  void EncodeSmallest(absl::Span<const Point2> points, galpha::v1::BuildRequest* out);
  /// Weighted points (empty `weights`: as above): the smallest chunk of a weighted stream, or raw
  /// (x, y, w) triples when nothing beats their 24 bytes a point. InvalidArgument (and nothing
  /// written) for a weight count other than the points'.
  absl::Status EncodeSmallest(absl::Span<const Point2> points, absl::Span<const double> weights,
                              galpha::v1::BuildRequest* out);

  /// The best transform for `points` under `value_type` and scales, chosen as EncodeSmallest
  /// chooses it, with zstd compression.
  galpha::v1::PointTransform ChooseTransform(absl::Span<const Point2> points, const ChunkEncoding& encoding);
  /// The same for weighted points (empty `weights`: as above).
  galpha::v1::PointTransform ChooseTransform(absl::Span<const Point2> points, absl::Span<const double> weights,
                                             const ChunkEncoding& encoding);

 private:
  absl::Status Compress(const std::string& input, std::string* output);
  // Sets encoding->transform to the one that compresses `sample` (and its weights, when weighted)
  // best (zstd); that size.
  size_t BestTransform(absl::Span<const Point2> sample, absl::Span<const double> weights, ChunkEncoding* encoding);

  int level_;
  std::unique_ptr<ZSTD_CCtx_s, void (*)(ZSTD_CCtx_s*)> zstd_;
  std::string words_;  // transformed, before compression
  std::unique_ptr<char[]> compressed_;
  size_t compressed_bytes_ = 0;
  std::vector<uint64_t> words64_, planar64_;
  std::vector<uint32_t> words32_, planar32_;
  std::vector<double> triples_;  // a weighted chunk's x, y, w values, interleaved
};

}  // namespace galpha::wire
