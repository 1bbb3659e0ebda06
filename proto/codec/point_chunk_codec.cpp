#include "proto/codec/point_chunk_codec.hpp"

#include <zstd.h>
#include <zstd_errors.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>
#include <utility>

#include "absl/strings/str_cat.h"

// Why these transforms (docs/design.md, "Wire encodings of points", has the whole table). Measured
// with zstd level 3 on 65,536-point chunks, bytes per point after compression:
//
//   data set                 | float64 none | shuffle | delta | delta2 || scaled int: shuffle | delta | delta2
//   lidar_autzen (0.01 ft)   |  6.06 |  6.02 |  5.60 |  5.62 || 2.71 | 2.08 | 1.95
//   lidar_autzen_ground      |  6.88 |  7.94 |  7.29 |  7.58 || 3.74 | 3.01 | 2.94
//   lidar_haystack_rock      |  6.71 |  8.00 |  8.19 |  8.81 || 4.23 | 3.78 | 4.04
//   gps_tracks (1e-9 deg)    | 14.28 | 10.25 |  9.94 |  9.68 || 6.03 | 5.19 | 4.99
//   autzen_ground_lonlat     | 11.98 |  8.75 |  8.44 |  8.35 ||  (not scaled integers)
//   ourairports              | 12.40 | 13.24 | 13.45 | 13.98 ||  (not scaled integers)
//   pdb_2xhe (0.001 A)       |  7.36 | 13.28 | 12.92 | 13.10 || 4.11 | 3.51 | 3.63
//   uniform [0, 1)           | 15.02 | 13.46 | 13.77 | 14.02 ||  (not scaled integers)
//
// No transform wins everywhere: whole-double repeats (LiDAR and PDB values with few decimals) are
// found by zstd's matches only in the untransformed stream; random mantissa bytes compress only
// when separated from the sign and exponent bytes (byte planes: uniform); nearby consecutive points
// share high bits that deltas of the bit patterns cancel (lon/lat); and a linear prediction wins on
// smooth tracks. XOR of consecutive bit patterns (FPC, Gorilla) measured worse than the integer
// delta on every set (it cannot borrow across a digit boundary). So the format carries the
// transform, and the encoder tries each on a sample of the chunk; scaled integers (exact decimal
// or LAS-style steps found from the data) beat every float64 form where they exist.

namespace galpha::wire {

namespace v1 = galpha::v1;

static_assert(sizeof(Point2) == 2 * sizeof(double), "points are packed x, y doubles");
static_assert(std::numeric_limits<double>::is_iec559, "the wire carries IEEE-754 binary64");

namespace {

constexpr int64_t kMaxExactInteger = int64_t{1} << 53;

// 10^k for k = 0..22: each is an exact double (5^22 < 2^53), so X / 10^k is one correctly rounded
// division, the double nearest to the decimal X * 10^-k (what strtod gives for the decimal text).
constexpr double kPowersOfTen[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                   1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
// The doubles nearest to 10^-k, as LAS writers store their scale factors.
constexpr double kTenthPowers[] = {1e-0,  1e-1,  1e-2,  1e-3,  1e-4,  1e-5,  1e-6,  1e-7,  1e-8,  1e-9,  1e-10, 1e-11,
                                   1e-12, 1e-13, 1e-14, 1e-15, 1e-16, 1e-17, 1e-18, 1e-19, 1e-20, 1e-21, 1e-22};

uint64_t Bits(double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}

const char* TypeName(v1::PointValueType type) {
  switch (type) {
    case v1::POINT_VALUE_TYPE_INT32:
      return "INT32";
    case v1::POINT_VALUE_TYPE_INT64:
      return "INT64";
    default:
      return "FLOAT64";
  }
}

size_t WordBytes(v1::PointValueType type) { return type == v1::POINT_VALUE_TYPE_INT32 ? 4 : 8; }

template <typename... Parts>
absl::Status Refuse(const ChunkPosition& at, const Parts&... parts) {
  return absl::InvalidArgumentError(
      absl::StrCat("encoded point chunk ", at.chunk_index, " (from point ", at.first_point, "): ", parts...));
}

// One axis's integer-to-double map with the proto's accessors resolved once.
struct AxisStep {
  explicit AxisStep(const v1::AxisScale& scale)
      : divide(scale.step_case() == v1::AxisScale::kDivisor),
        step(divide ? scale.divisor() : scale.scale()),
        offset(scale.offset()) {}
  // Two roundings, never one: the build compiles this module with -ffp-contract=off
  // (galpha_target_flags, tests/fuzz/run.sh), so the sum of a product is never an FMA; the unit
  // test PointChunkCodec.ScaledValueIsNeverFused fails if it were.
  double operator()(int64_t x) const {
    const double value = static_cast<double>(x);
    return divide ? offset + value / step : offset + step * value;
  }
  // The integer whose value is nearest to v (only a candidate: the caller verifies it exactly).
  std::optional<int64_t> Invert(double v) const {
    const double estimate = std::nearbyint(divide ? (v - offset) * step : (v - offset) / step);
    if (!(std::fabs(estimate) <= static_cast<double>(kMaxExactInteger))) return std::nullopt;
    return static_cast<int64_t>(estimate);
  }
  bool divide;
  double step;
  double offset;
};

template <typename Word>
Word ZigZag(Word d) {
  using Signed = std::make_signed_t<Word>;
  return static_cast<Word>(d << 1) ^ static_cast<Word>(static_cast<Signed>(d) >> (8 * sizeof(Word) - 1));
}

template <typename Word>
Word UnZigZag(Word z) {
  return static_cast<Word>(z >> 1) ^ static_cast<Word>(Word{0} - (z & 1));
}

// The prediction of an axis's next word from its two previous ones (0 before the first).
template <typename Word>
Word Predict(v1::PointTransform transform, Word previous, Word before_previous) {
  if (transform == v1::POINT_TRANSFORM_DELTA_SHUFFLE) return previous;
  if (transform == v1::POINT_TRANSFORM_DELTA2_SHUFFLE) return static_cast<Word>(2 * previous - before_previous);
  return 0;
}

bool IsPlain(v1::PointTransform transform) {
  return transform == v1::POINT_TRANSFORM_NONE || transform == v1::POINT_TRANSFORM_UNSPECIFIED;
}

// Interleaved words (x0, y0, x1, y1, ...; weighted x0, y0, w0, ...: `axes` a point) to the
// transform's bytes (the proto's PointTransform). The words first become planar (an axis at a
// time, each pass reading and writing in order), then each word's bytes go to their planes in
// one pass.
template <typename Word>
void TransformWords(const std::vector<Word>& words, size_t axes, v1::PointTransform transform,
                    std::vector<Word>* scratch, std::string* bytes) {
  const size_t count = words.size();
  const size_t n = count / axes;
  bytes->resize(count * sizeof(Word));
  auto* out = reinterpret_cast<unsigned char*>(bytes->data());
  if (IsPlain(transform)) {
    std::memcpy(out, words.data(), count * sizeof(Word));  // little-endian host (static_assert above)
    return;
  }
  std::vector<Word>& planar = *scratch;
  planar.resize(count);
  for (size_t axis = 0; axis < axes; ++axis) {
    Word previous = 0;
    Word before_previous = 0;
    Word* stored = planar.data() + axis * n;
    for (size_t i = 0; i < n; ++i) {
      const Word w = words[axes * i + axis];
      stored[i] = transform == v1::POINT_TRANSFORM_BYTE_SHUFFLE
                      ? w
                      : ZigZag<Word>(static_cast<Word>(w - Predict(transform, previous, before_previous)));
      before_previous = previous;
      previous = w;
    }
  }
  // One pass over the words, each byte to its plane: a pass per plane read every word eight times
  // (15% of the client's encoding time at 1M uniform points, with the trial encodings).
  for (size_t j = 0; j < count; ++j) {
    const Word w = planar[j];
    for (size_t b = 0; b < sizeof(Word); ++b) out[b * count + j] = static_cast<unsigned char>(w >> (8 * b));
  }
}

// The inverse of TransformWords. `planar` is scratch.
template <typename Word>
void UntransformWords(const unsigned char* bytes, size_t n, size_t axes, v1::PointTransform transform,
                      std::vector<Word>* planar, std::vector<Word>* words) {
  const size_t count = axes * n;
  words->resize(count);
  if (IsPlain(transform)) {
    std::memcpy(words->data(), bytes, count * sizeof(Word));
    return;
  }
  planar->resize(count);
  Word* stored = planar->data();
  for (size_t j = 0; j < count; ++j) stored[j] = bytes[j];
  for (size_t b = 1; b < sizeof(Word); ++b) {
    const unsigned char* plane = bytes + b * count;
    for (size_t j = 0; j < count; ++j) stored[j] |= static_cast<Word>(Word{plane[j]} << (8 * b));
  }
  Word* out = words->data();
  for (size_t axis = 0; axis < axes; ++axis) {
    const Word* in = stored + axis * n;
    if (transform == v1::POINT_TRANSFORM_BYTE_SHUFFLE) {
      for (size_t i = 0; i < n; ++i) out[axes * i + axis] = in[i];
      continue;
    }
    Word previous = 0;
    Word before_previous = 0;
    for (size_t i = 0; i < n; ++i) {
      const Word w = static_cast<Word>(UnZigZag(in[i]) + Predict(transform, previous, before_previous));
      out[axes * i + axis] = w;
      before_previous = previous;
      previous = w;
    }
  }
}

absl::Status CheckAxisScale(const v1::EncodedPointChunk& chunk, const v1::AxisScale& scale, bool present,
                            const char* name, const ChunkPosition& at) {
  if (!present) return Refuse(at, "an ", TypeName(chunk.value_type()), " chunk needs ", name);
  if (scale.step_case() == v1::AxisScale::STEP_NOT_SET) {
    return Refuse(at, name, " has neither a scale nor a divisor");
  }
  const bool divide = scale.step_case() == v1::AxisScale::kDivisor;
  const double step = divide ? scale.divisor() : scale.scale();
  if (!std::isfinite(step) || step == 0) {
    return Refuse(at, name, "'s ", divide ? "divisor" : "scale", " is ", step, ": it must be finite and nonzero");
  }
  if (!std::isfinite(scale.offset())) {
    return Refuse(at, name, "'s offset is ", scale.offset(), ": it must be finite");
  }
  return absl::OkStatus();
}

// The name of axis `axis` of a point with `axes` values, for messages.
const char* AxisName(size_t axis) {
  static constexpr const char* kNames[] = {"x", "y", "w"};
  return kNames[axis];
}

// The first of the chunk's decoded values (`axes` a point) that is not finite, as a refusal naming
// its point; OK when all are. `how`: how the values were decoded, for the message.
absl::Status CheckFinite(const double* values, size_t count, size_t axes, const ChunkPosition& at, const char* how) {
  // One branch-free pass (it vectorises); the index only when one is bad.
  bool all_finite = true;
  for (size_t i = 0; i < count; ++i) all_finite &= std::isfinite(values[i]);
  if (all_finite) return absl::OkStatus();
  size_t i = 0;
  while (std::isfinite(values[i])) ++i;
  const char* what = i % axes == 2 ? " weight" : i % axes == 0 ? " x coordinate" : " y coordinate";
  return Refuse(at, "point ", at.first_point + i / axes, " has ", std::isnan(values[i]) ? "a NaN" : "an infinite", what,
                how);
}

}  // namespace

double ScaledValue(const v1::AxisScale& scale, int64_t x) { return AxisStep(scale)(x); }

absl::Status CheckEncodedChunkShape(const v1::EncodedPointChunk& chunk, const ChunkPosition& at, bool weighted) {
  if (chunk.point_count() == 0) return Refuse(at, "it states no points (point_count 0)");
  if (chunk.point_count() > kMaxPointsPerEncodedChunk) {
    return Refuse(at, "it states ", chunk.point_count(), " points; an encoded chunk holds at most ",
                  kMaxPointsPerEncodedChunk);
  }
  if (chunk.value_type() == v1::POINT_VALUE_TYPE_UNSPECIFIED) {
    return Refuse(at, "it states no value_type (FLOAT64, INT32 or INT64)");
  }
  if (!v1::PointValueType_IsValid(chunk.value_type())) {
    return Refuse(at, "value_type ", static_cast<int>(chunk.value_type()), " is not a PointValueType");
  }
  if (!v1::PointTransform_IsValid(chunk.transform())) {
    return Refuse(at, "transform ", static_cast<int>(chunk.transform()), " is not a PointTransform");
  }
  if (!v1::PointCompression_IsValid(chunk.compression())) {
    return Refuse(at, "compression ", static_cast<int>(chunk.compression()), " is not a PointCompression");
  }
  if (!weighted && chunk.has_w_scale()) {
    return Refuse(at, "it has a w_scale, but the stream is not weighted (BuildHeader.weighted)");
  }
  if (chunk.value_type() == v1::POINT_VALUE_TYPE_FLOAT64) {
    if (chunk.has_x_scale() || chunk.has_y_scale() || chunk.has_w_scale()) {
      return Refuse(at, "a FLOAT64 chunk takes no x_scale, y_scale or w_scale");
    }
    return absl::OkStatus();
  }
  if (absl::Status s = CheckAxisScale(chunk, chunk.x_scale(), chunk.has_x_scale(), "x_scale", at); !s.ok()) return s;
  if (absl::Status s = CheckAxisScale(chunk, chunk.y_scale(), chunk.has_y_scale(), "y_scale", at); !s.ok()) return s;
  if (!weighted) return absl::OkStatus();
  return CheckAxisScale(chunk, chunk.w_scale(), chunk.has_w_scale(), "w_scale (the stream is weighted)", at);
}

// The zstd context (about 95 KB) is made at the first compressed chunk and freed with the scratch:
// a stream of raw chunks, and a finished stream waiting for its build (a BuildBatch holds one
// decoder a set), keep none.
PointChunkDecoder::PointChunkDecoder() : zstd_(nullptr, [](ZSTD_DCtx_s* context) { ZSTD_freeDCtx(context); }) {}

PointChunkDecoder::~PointChunkDecoder() = default;

void PointChunkDecoder::ReleaseScratch() {
  zstd_.reset();
  scratch_.reset();
  scratch_bytes_ = 0;
  std::vector<uint64_t>().swap(words64_);
  std::vector<uint64_t>().swap(planar64_);
  std::vector<uint32_t>().swap(words32_);
  std::vector<uint32_t>().swap(planar32_);
  std::vector<double>().swap(triples_);
}

absl::Status PointChunkDecoder::Decode(const v1::EncodedPointChunk& chunk, const ChunkPosition& at, Point2* out) {
  return DecodeValues(chunk, at, 2, &out[0].x);
}

absl::Status PointChunkDecoder::DecodeWeighted(const v1::EncodedPointChunk& chunk, const ChunkPosition& at, Point2* out,
                                               double* weights) {
  if (absl::Status s = CheckEncodedChunkShape(chunk, at, /*weighted=*/true); !s.ok()) return s;
  const size_t n = chunk.point_count();
  triples_.resize(3 * n);
  if (absl::Status s = DecodeValues(chunk, at, 3, triples_.data()); !s.ok()) return s;
  for (size_t i = 0; i < n; ++i) {
    out[i] = Point2{triples_[3 * i], triples_[3 * i + 1]};
    weights[i] = triples_[3 * i + 2];
  }
  return absl::OkStatus();
}

absl::Status PointChunkDecoder::DecodeValues(const v1::EncodedPointChunk& chunk, const ChunkPosition& at, size_t axes,
                                             double* values) {
  if (absl::Status s = CheckEncodedChunkShape(chunk, at, axes == 3); !s.ok()) return s;
  const size_t n = chunk.point_count();
  const v1::PointValueType type = chunk.value_type();
  const size_t expected = axes * n * WordBytes(type);
  const std::string& data = chunk.data();
  const unsigned char* bytes = reinterpret_cast<const unsigned char*>(data.data());
  if (chunk.compression() == v1::POINT_COMPRESSION_ZSTD) {
    const size_t frame = ZSTD_findFrameCompressedSize(data.data(), data.size());
    if (ZSTD_isError(frame)) return Refuse(at, "its data is not a zstd frame (", ZSTD_getErrorName(frame), ")");
    if (frame != data.size()) {
      return Refuse(at, "its data holds ", data.size() - frame,
                    " bytes after its zstd frame: send one frame per chunk");
    }
    const unsigned long long declared = ZSTD_getFrameContentSize(data.data(), data.size());
    if (declared != ZSTD_CONTENTSIZE_UNKNOWN && declared != ZSTD_CONTENTSIZE_ERROR && declared != expected) {
      return Refuse(at, "its zstd frame declares ", declared, " bytes; its ", n, " points of ", TypeName(type), " are ",
                    expected, " bytes");
    }
    if (scratch_bytes_ < expected) {
      scratch_.reset(new unsigned char[expected]);
      scratch_bytes_ = expected;
    }
    // The output is bounded by the stated size: a frame that would write more fails here, having
    // written at most `expected` bytes (no zip bombs).
    if (zstd_ == nullptr) {
      zstd_.reset(ZSTD_createDCtx());
      if (zstd_ == nullptr) return absl::ResourceExhaustedError("zstd: no memory for a decompression context");
    }
    const size_t decoded = ZSTD_decompressDCtx(zstd_.get(), scratch_.get(), expected, data.data(), data.size());
    if (ZSTD_isError(decoded)) {
      if (ZSTD_getErrorCode(decoded) == ZSTD_error_dstSize_tooSmall) {
        return Refuse(at, "its zstd frame decompresses to more than ", expected, " bytes, the size of its ", n,
                      " points of ", TypeName(type));
      }
      return Refuse(at, "its zstd frame is corrupt (", ZSTD_getErrorName(decoded), ")");
    }
    if (decoded != expected) {
      return Refuse(at, "its zstd frame decompresses to ", decoded, " bytes; its ", n, " points of ", TypeName(type),
                    " are ", expected, " bytes");
    }
    bytes = scratch_.get();
  } else if (data.size() != expected) {
    return Refuse(at, "its data is ", data.size(), " bytes; ", n, " uncompressed points of ", TypeName(type), " are ",
                  expected, " bytes");
  }

  const size_t count = axes * n;
  if (type == v1::POINT_VALUE_TYPE_FLOAT64) {
    UntransformWords<uint64_t>(bytes, n, axes, chunk.transform(), &planar64_, &words64_);
    std::memcpy(values, words64_.data(), count * sizeof(double));
    return CheckFinite(values, count, axes, at, "");
  }
  const AxisStep steps[3] = {AxisStep(chunk.x_scale()), AxisStep(chunk.y_scale()), AxisStep(chunk.w_scale())};
  if (type == v1::POINT_VALUE_TYPE_INT32) {
    UntransformWords<uint32_t>(bytes, n, axes, chunk.transform(), &planar32_, &words32_);
    for (size_t axis = 0; axis < axes; ++axis) {
      const AxisStep step = steps[axis];
      for (size_t i = axis; i < count; i += axes) values[i] = step(static_cast<int32_t>(words32_[i]));
    }
  } else {
    UntransformWords<uint64_t>(bytes, n, axes, chunk.transform(), &planar64_, &words64_);
    for (size_t i = 0; i < count; ++i) {
      const auto x = static_cast<int64_t>(words64_[i]);
      if (x > kMaxExactInteger || x < -kMaxExactInteger) {
        return Refuse(at, "point ", at.first_point + i / axes, "'s ", AxisName(i % axes), " integer is ", x,
                      ", over 2^53 in magnitude: no double holds it exactly");
      }
      values[i] = steps[i % axes](x);
    }
  }
  return CheckFinite(values, count, axes, at, " (decoded from its integer: offset + scale * X overflows)");
}

namespace {

// One axis of a chunk's values: every `stride`-th double from `first` (x or y of packed points,
// or a weight column with stride 1).
struct Column {
  const double* first = nullptr;
  size_t stride = 1;
  size_t size = 0;
  double operator[](size_t i) const { return first[i * stride]; }
};

Column PointAxis(absl::Span<const Point2> points, size_t axis) {
  return Column{points.empty() ? nullptr : &points[0].x + axis, 2, points.size()};
}

// X for every value of one axis under `scale`, verified bit for bit; false at the first value it
// does not reproduce.
bool AxisIntegers(const Column& column, const v1::AxisScale& scale, int64_t* smallest, int64_t* largest) {
  const AxisStep step(scale);
  int64_t low = 0;
  int64_t high = 0;
  for (size_t i = 0; i < column.size; ++i) {
    const double v = column[i];
    const std::optional<int64_t> x = step.Invert(v);
    if (!x || Bits(step(*x)) != Bits(v)) return false;
    low = std::min(low, *x);
    high = std::max(high, *x);
  }
  *smallest = low;
  *largest = high;
  return true;
}

// The smallest power-of-two step 2^-k under which every value of the axis is an integer of at
// most 53 bits; nullopt when none is. From the bits: a finite nonzero double is an odd integer
// times 2^e (its significand without the trailing zeros), so it is a multiple of 2^-k exactly when
// k >= -e. The scan stops as soon as some |v| 2^k reaches 2^54 (k only grows): no step of this kind
// can work then (AxisIntegers would refuse it), which for full-precision doubles happens within
// the first few values. (A frexp and an ldexp of every value cost 8x more: a quarter of the
// client's encoding time at 1M uniform points.)
std::optional<v1::AxisScale> PowerOfTwoScale(const Column& column) {
  constexpr uint64_t kFraction = (uint64_t{1} << 52) - 1;
  int k = 0;
  int top = std::numeric_limits<int>::min();  // the largest floor(log2 |v|) so far
  for (size_t i = 0; i < column.size; ++i) {
    const double v = column[i];
    if (!std::isfinite(v)) return std::nullopt;
    if (v == 0) continue;
    const uint64_t bits = Bits(v);
    const int biased = static_cast<int>((bits >> 52) & 0x7ff);
    // v = significand * 2^unit; subnormals have no hidden bit.
    const uint64_t significand = biased == 0 ? (bits & kFraction) : ((bits & kFraction) | (uint64_t{1} << 52));
    const int unit = biased == 0 ? -1074 : biased - 1075;
    const int lowest_bit = unit + __builtin_ctzll(significand);
    const int highest_bit = unit + 63 - __builtin_clzll(significand);
    k = std::max(k, -lowest_bit);
    top = std::max(top, highest_bit);
    if (k + top >= 54) return std::nullopt;
  }
  if (k > 1000) return std::nullopt;
  v1::AxisScale scale;
  scale.set_scale(std::ldexp(1.0, -k));
  return scale;
}

std::optional<std::pair<v1::AxisScale, bool>> FindAxisScale(const Column& column) {
  double lowest = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < column.size; ++i) lowest = std::min(lowest, column[i]);
  if (!std::isfinite(lowest)) return std::nullopt;
  std::vector<v1::AxisScale> candidates;
  for (size_t k = 0; k < std::size(kPowersOfTen); ++k) {
    v1::AxisScale scale;
    scale.set_scale(kTenthPowers[k]);
    candidates.push_back(scale);
    scale.set_divisor(kPowersOfTen[k]);
    candidates.push_back(scale);
  }
  // LAS writers pick a round offset at or below the tile's corner (lidar_haystack_rock: y is
  // 200000 + 0.01 * Y, and with no offset 0.01 * Y misses 42% of its values).
  for (size_t k = 0; k <= 9; ++k) {
    for (size_t j = 0; j <= 7; ++j) {
      v1::AxisScale scale;
      scale.set_scale(kTenthPowers[k]);
      scale.set_offset(std::floor(lowest / kPowersOfTen[j]) * kPowersOfTen[j]);
      if (scale.offset() != 0) candidates.push_back(scale);
    }
  }
  if (std::optional<v1::AxisScale> scale = PowerOfTwoScale(column)) candidates.push_back(*scale);
  for (const v1::AxisScale& scale : candidates) {
    int64_t smallest = 0;
    int64_t largest = 0;
    if (AxisIntegers(column, scale, &smallest, &largest)) {
      const bool fits32 =
          smallest >= std::numeric_limits<int32_t>::min() && largest <= std::numeric_limits<int32_t>::max();
      return std::make_pair(scale, fits32);
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<ScaledAxes> FindScaledIntegers(absl::Span<const Point2> points) { return FindScaledIntegers(points, {}); }

std::optional<ScaledAxes> FindScaledIntegers(absl::Span<const Point2> points, absl::Span<const double> weights) {
  if (points.empty()) return std::nullopt;
  auto x = FindAxisScale(PointAxis(points, 0));
  if (!x) return std::nullopt;
  auto y = FindAxisScale(PointAxis(points, 1));
  if (!y) return std::nullopt;
  ScaledAxes axes;
  axes.x = x->first;
  axes.y = y->first;
  bool fits32 = x->second && y->second;
  if (!weights.empty()) {
    auto w = FindAxisScale(Column{weights.data(), 1, weights.size()});
    if (!w) return std::nullopt;
    axes.w = w->first;
    fits32 = fits32 && w->second;
  }
  axes.value_type = fits32 ? v1::POINT_VALUE_TYPE_INT32 : v1::POINT_VALUE_TYPE_INT64;
  return axes;
}

PointChunkEncoder::PointChunkEncoder(int zstd_level)
    : level_(zstd_level), zstd_(ZSTD_createCCtx(), [](ZSTD_CCtx_s* context) { ZSTD_freeCCtx(context); }) {}

PointChunkEncoder::~PointChunkEncoder() = default;

absl::Status PointChunkEncoder::Compress(const std::string& input, std::string* output) {
  const size_t bound = ZSTD_compressBound(input.size());
  if (compressed_bytes_ < bound) {  // a buffer of its own: a string would be zero-filled on every resize
    compressed_.reset(new char[bound]);
    compressed_bytes_ = bound;
  }
  const size_t size = ZSTD_compressCCtx(zstd_.get(), compressed_.get(), bound, input.data(), input.size(), level_);
  if (ZSTD_isError(size)) return absl::InternalError(absl::StrCat("zstd: ", ZSTD_getErrorName(size)));
  output->assign(compressed_.get(), size);
  return absl::OkStatus();
}

absl::Status PointChunkEncoder::Encode(absl::Span<const Point2> points, const ChunkEncoding& encoding,
                                       v1::EncodedPointChunk* out) {
  return Encode(points, {}, encoding, out);
}

absl::Status PointChunkEncoder::Encode(absl::Span<const Point2> points, absl::Span<const double> weights,
                                       const ChunkEncoding& encoding, v1::EncodedPointChunk* out) {
  const size_t n = points.size();
  if (n == 0 || n > kMaxPointsPerEncodedChunk) {
    return absl::InvalidArgumentError(
        absl::StrCat("an encoded chunk holds 1 to ", kMaxPointsPerEncodedChunk, " points, not ", n));
  }
  const bool weighted = !weights.empty();
  if (weighted && weights.size() != n) {
    return absl::InvalidArgumentError(absl::StrCat(n, " points need ", n, " weights, not ", weights.size()));
  }
  // The values interleaved as the words are: the points themselves, or x, y, w triples.
  const size_t axes = weighted ? 3 : 2;
  const size_t count = axes * n;
  const double* values = &points[0].x;
  if (weighted) {
    triples_.resize(count);
    for (size_t i = 0; i < n; ++i) {
      triples_[3 * i] = points[i].x;
      triples_[3 * i + 1] = points[i].y;
      triples_[3 * i + 2] = weights[i];
    }
    values = triples_.data();
  }
  out->Clear();
  out->set_point_count(n);
  out->set_value_type(encoding.value_type);
  out->set_transform(encoding.transform);
  out->set_compression(encoding.compression);
  if (encoding.value_type == v1::POINT_VALUE_TYPE_FLOAT64) {
    words64_.resize(count);
    std::memcpy(words64_.data(), values, count * sizeof(double));
    TransformWords(words64_, axes, encoding.transform, &planar64_, &words_);
  } else {
    *out->mutable_x_scale() = encoding.x_scale;
    *out->mutable_y_scale() = encoding.y_scale;
    if (weighted) *out->mutable_w_scale() = encoding.w_scale;
    const AxisStep steps[3] = {AxisStep(encoding.x_scale), AxisStep(encoding.y_scale), AxisStep(encoding.w_scale)};
    const bool narrow = encoding.value_type == v1::POINT_VALUE_TYPE_INT32;
    std::vector<uint64_t>& words64 = words64_;
    std::vector<uint32_t>& words32 = words32_;
    if (narrow) {
      words32.resize(count);
    } else {
      words64.resize(count);
    }
    for (size_t i = 0; i < count; ++i) {
      const double v = values[i];
      const AxisStep& step = steps[i % axes];
      const std::optional<int64_t> x = step.Invert(v);
      if (!x || Bits(step(*x)) != Bits(v)) {
        return absl::InvalidArgumentError(absl::StrCat("point ", i / axes, "'s ", AxisName(i % axes), " (", v,
                                                       ") is not offset + scale * X for an integer X"));
      }
      if (narrow && (*x < std::numeric_limits<int32_t>::min() || *x > std::numeric_limits<int32_t>::max())) {
        return absl::InvalidArgumentError(
            absl::StrCat("point ", i / axes, "'s ", AxisName(i % axes), " integer ", *x, " does not fit INT32"));
      }
      if (narrow) {
        words32[i] = static_cast<uint32_t>(static_cast<int32_t>(*x));
      } else {
        words64[i] = static_cast<uint64_t>(*x);
      }
    }
    if (narrow) {
      TransformWords(words32, axes, encoding.transform, &planar32_, &words_);
    } else {
      TransformWords(words64, axes, encoding.transform, &planar64_, &words_);
    }
  }
  if (encoding.compression != v1::POINT_COMPRESSION_ZSTD) {
    out->set_data(words_);
    return absl::OkStatus();
  }
  return Compress(words_, out->mutable_data());
}

namespace {

// The part of a chunk its encoding is chosen on: all of it up to 16,384 points (then the choice is
// exact), else its first 8,192 points (eight trial compressions then cost one of the whole chunk).
size_t SampleSize(size_t n) { return n <= 16384 ? n : 8192; }

template <typename T>
absl::Span<const T> Sample(absl::Span<const T> values) {
  return values.subspan(0, SampleSize(values.size()));
}

}  // namespace

size_t PointChunkEncoder::BestTransform(absl::Span<const Point2> sample, absl::Span<const double> weights,
                                        ChunkEncoding* encoding) {
  size_t best_size = std::numeric_limits<size_t>::max();
  v1::PointTransform best = v1::POINT_TRANSFORM_NONE;
  for (v1::PointTransform transform : {v1::POINT_TRANSFORM_NONE, v1::POINT_TRANSFORM_BYTE_SHUFFLE,
                                       v1::POINT_TRANSFORM_DELTA_SHUFFLE, v1::POINT_TRANSFORM_DELTA2_SHUFFLE}) {
    ChunkEncoding trial = *encoding;
    trial.transform = transform;
    trial.compression = v1::POINT_COMPRESSION_ZSTD;
    v1::EncodedPointChunk chunk;
    if (!Encode(sample, weights, trial, &chunk).ok()) continue;
    if (chunk.data().size() < best_size) {
      best_size = chunk.data().size();
      best = transform;
    }
  }
  encoding->transform = best;
  return best_size;
}

v1::PointTransform PointChunkEncoder::ChooseTransform(absl::Span<const Point2> points, const ChunkEncoding& encoding) {
  return ChooseTransform(points, {}, encoding);
}

v1::PointTransform PointChunkEncoder::ChooseTransform(absl::Span<const Point2> points, absl::Span<const double> weights,
                                                      const ChunkEncoding& encoding) {
  ChunkEncoding chosen = encoding;
  const absl::Span<const Point2> sample = Sample(points);
  BestTransform(sample, weights.subspan(0, weights.empty() ? 0 : sample.size()), &chosen);
  return chosen.transform;
}

void PointChunkEncoder::EncodeSmallest(absl::Span<const Point2> points, v1::BuildRequest* out) {
  EncodeSmallest(points, {}, out).IgnoreError();  // unweighted: nothing to refuse
}

absl::Status PointChunkEncoder::EncodeSmallest(absl::Span<const Point2> points, absl::Span<const double> weights,
                                               v1::BuildRequest* out) {
  const bool weighted = !weights.empty();
  if (weighted && weights.size() != points.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat(points.size(), " points need ", points.size(), " weights, not ", weights.size()));
  }
  const size_t axes = weighted ? 3 : 2;
  const auto send_raw = [&] {
    auto* coordinates = out->mutable_points()->mutable_coordinates();
    coordinates->Clear();
    if (points.empty()) return;
    if (!weighted) {
      coordinates->Add(&points[0].x, &points[0].x + 2 * points.size());
      return;
    }
    coordinates->Reserve(static_cast<int>(3 * points.size()));
    for (size_t i = 0; i < points.size(); ++i) {
      coordinates->AddAlreadyReserved(points[i].x);
      coordinates->AddAlreadyReserved(points[i].y);
      coordinates->AddAlreadyReserved(weights[i]);
    }
  };
  if (points.empty() || points.size() > kMaxPointsPerEncodedChunk) {
    send_raw();
    return absl::OkStatus();
  }
  // Float64 and, where the data has them, scaled integers, each with its best transform on the
  // sample: integers usually win by far, but power-of-two steps of full-precision doubles (lon/lat
  // in one binade) are the same bits and can lose by a few bytes.
  const absl::Span<const Point2> sample = Sample(points);
  const absl::Span<const double> sample_weights = weights.subspan(0, weighted ? sample.size() : 0);
  ChunkEncoding encoding;
  encoding.compression = v1::POINT_COMPRESSION_ZSTD;
  const size_t float_size = BestTransform(sample, sample_weights, &encoding);
  if (std::optional<ScaledAxes> scaled = FindScaledIntegers(points, weights)) {
    ChunkEncoding integers = encoding;
    integers.value_type = scaled->value_type;
    integers.x_scale = scaled->x;
    integers.y_scale = scaled->y;
    integers.w_scale = scaled->w;
    if (BestTransform(sample, sample_weights, &integers) <= float_size) encoding = integers;
  }
  v1::EncodedPointChunk* chunk = out->mutable_encoded_points();
  const auto raw = [&] {
    send_raw();
    return absl::OkStatus();
  };
  if (!Encode(points, weights, encoding, chunk).ok()) return raw();
  const size_t uncompressed = axes * points.size() * WordBytes(encoding.value_type);
  if (chunk->data().size() >= uncompressed) {
    if (encoding.value_type == v1::POINT_VALUE_TYPE_FLOAT64) return raw();
    encoding.transform = v1::POINT_TRANSFORM_NONE;
    encoding.compression = v1::POINT_COMPRESSION_NONE;
    if (!Encode(points, weights, encoding, chunk).ok()) return raw();
  }
  // A raw chunk is 8 bytes a value plus a few of framing: the encoded one must beat that.
  if (chunk->ByteSizeLong() >= 8 * axes * points.size()) send_raw();
  return absl::OkStatus();
}

}  // namespace galpha::wire
