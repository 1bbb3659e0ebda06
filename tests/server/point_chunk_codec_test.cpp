// The compact point encodings (proto/codec/point_chunk_codec.hpp, EncodedPointChunk in
// proto/galpha/v1/alpha_shapes.proto): every value type, transform and compression decodes bit for
// bit to the points it encoded, through the server's Build stream decoder with the same handle as
// raw doubles; the scales found from the data reproduce every coordinate; reconstruction is never
// fused; malformed chunks are refused naming the chunk; and the bytes per point on the wire for
// every data set of data/ and for uniform random doubles (printed, and held to the targets).
#include "proto/codec/point_chunk_codec.hpp"

#include <zstd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/types/span.h"
#include "core/io/point_io.hpp"
#include "core/io/point_set_handle.hpp"
#include "gtest/gtest.h"
#include "server/build_stream.hpp"
#include "tests/support/data_files.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::wire {
namespace {

using galpha::testing::IsOk;
using galpha::testing::StatusIs;

namespace v1 = galpha::v1;

uint64_t Bits(double value) {
  uint64_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  return bits;
}

void ExpectBitIdentical(absl::Span<const Point2> got, absl::Span<const Point2> want) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    ASSERT_EQ(Bits(got[i].x), Bits(want[i].x)) << "point " << i;
    ASSERT_EQ(Bits(got[i].y), Bits(want[i].y)) << "point " << i;
  }
}

std::string DataFile(const std::string& name) { return testdata::DataDir() + "/" + name + ".bin"; }

std::vector<Point2> ReadData(const std::string& name) {
  absl::StatusOr<std::vector<Point2>> points = ReadPointsBin(DataFile(name));
  EXPECT_THAT(points.status(), IsOk());
  return points.ok() ? *points : std::vector<Point2>{};
}

// Doubles that stress bit patterns: signed zeros, subnormals, the extremes, huge offsets.
std::vector<Point2> AwkwardDoubles() {
  const double denorm = std::numeric_limits<double>::denorm_min();
  const double big = std::numeric_limits<double>::max();
  return {{-0.0, 0.0}, {denorm, -denorm}, {big, -big},     {1e-300, 3e-310}, {2.23e6, 252070.78},
          {0.1, 0.3},  {-1.5, 1.5},       {1e15 + 1, 7.0}, {-0.0, -0.0},     {5e-324, 1.0}};
}

const v1::PointTransform kTransforms[] = {v1::POINT_TRANSFORM_UNSPECIFIED, v1::POINT_TRANSFORM_NONE,
                                          v1::POINT_TRANSFORM_BYTE_SHUFFLE, v1::POINT_TRANSFORM_DELTA_SHUFFLE,
                                          v1::POINT_TRANSFORM_DELTA2_SHUFFLE};
const v1::PointCompression kCompressions[] = {v1::POINT_COMPRESSION_UNSPECIFIED, v1::POINT_COMPRESSION_NONE,
                                              v1::POINT_COMPRESSION_ZSTD};

// The points of `chunks` through the server's Build stream decoder (a header, then the chunks).
absl::StatusOr<std::vector<Point2>> ThroughTheServer(const std::vector<v1::BuildRequest>& chunks, std::string* handle) {
  server::BuildStreamDecoder decoder(server::BuildStreamLimits{}, nullptr);
  v1::BuildRequest header;
  header.mutable_header()->set_name("codec");
  if (absl::Status s = decoder.Add(header); !s.ok()) return s;
  for (const v1::BuildRequest& chunk : chunks) {
    if (absl::Status s = decoder.Add(chunk); !s.ok()) return s;
  }
  absl::StatusOr<server::DecodedBuild*> decoded = decoder.Finish();
  if (!decoded.ok()) return decoded.status();
  *handle = (*decoded)->handle;
  return std::vector<Point2>((*decoded)->points.begin(), (*decoded)->points.end());
}

TEST(PointChunkCodec, Float64RoundTripsBitForBitInEveryForm) {
  const std::vector<std::pair<std::string, std::vector<Point2>>> sets = {
      {"uniform", gen::Uniform(5000, 1)},
      {"gaussian", gen::Gaussian(3000, 2)},
      {"awkward", AwkwardDoubles()},
      {"lidar_autzen_ground_lonlat", ReadData("lidar_autzen_ground_lonlat")},
      {"one point", {{3.25, -7.5}}}};
  PointChunkEncoder encoder;
  PointChunkDecoder decoder;
  for (const auto& [name, points] : sets) {
    for (v1::PointTransform transform : kTransforms) {
      for (v1::PointCompression compression : kCompressions) {
        SCOPED_TRACE(absl::StrCat(name, ", transform ", transform, ", compression ", compression));
        ChunkEncoding encoding;
        encoding.transform = transform;
        encoding.compression = compression;
        v1::EncodedPointChunk chunk;
        ASSERT_THAT(encoder.Encode(points, encoding, &chunk), IsOk());
        std::vector<Point2> decoded(points.size());
        ASSERT_THAT(decoder.Decode(chunk, ChunkPosition{}, decoded.data()), IsOk());
        ExpectBitIdentical(decoded, points);
      }
    }
  }
}

TEST(PointChunkCodec, ScaledIntegersFoundFromTheDataRoundTripInEveryForm) {
  struct Case {
    std::string name;
    std::vector<Point2> points;
  };
  std::vector<Case> cases = {{"lidar_autzen", ReadData("lidar_autzen")},
                             {"gps_tracks_slovenia_croatia", ReadData("gps_tracks_slovenia_croatia")},
                             {"pdb_2xhe_proj", ReadData("pdb_2xhe_proj")},
                             {"lidar_haystack_rock", ReadData("lidar_haystack_rock")},
                             {"integer grid", {{-3, 4}, {100000, -2}, {0, 0}, {7, 7}}},
                             {"binary fractions", {{0.5, 0.25}, {-0.125, 1024.75}, {3, 1.0 / 1024}}}};
  PointChunkEncoder encoder;
  PointChunkDecoder decoder;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::optional<ScaledAxes> scaled = FindScaledIntegers(c.points);
    ASSERT_TRUE(scaled.has_value());
    for (v1::PointValueType type : {v1::POINT_VALUE_TYPE_INT64, v1::POINT_VALUE_TYPE_INT32}) {
      if (type == v1::POINT_VALUE_TYPE_INT32 && scaled->value_type != type) continue;
      for (v1::PointTransform transform : kTransforms) {
        for (v1::PointCompression compression : kCompressions) {
          SCOPED_TRACE(absl::StrCat("type ", type, ", transform ", transform, ", compression ", compression));
          ChunkEncoding encoding{type, scaled->x, scaled->y, transform, compression, {}};
          v1::EncodedPointChunk chunk;
          ASSERT_THAT(encoder.Encode(c.points, encoding, &chunk), IsOk());
          std::vector<Point2> decoded(c.points.size());
          ASSERT_THAT(decoder.Decode(chunk, ChunkPosition{}, decoded.data()), IsOk());
          ExpectBitIdentical(decoded, c.points);
        }
      }
    }
  }
}

TEST(PointChunkCodec, FindsTheScalesTheDataWasWrittenWith) {
  // LAS: autzen stores 0.01 ft steps, reproduced by the multiplication LAS readers do.
  const std::optional<ScaledAxes> autzen = FindScaledIntegers(ReadData("lidar_autzen"));
  ASSERT_TRUE(autzen.has_value());
  EXPECT_EQ(autzen->x.scale(), 0.01);
  EXPECT_EQ(autzen->value_type, v1::POINT_VALUE_TYPE_INT32);
  // Decimal text with 9 digits: only X / 10^9 reproduces every value (10^-9 * X does not).
  const std::optional<ScaledAxes> gps = FindScaledIntegers(ReadData("gps_tracks_slovenia_croatia"));
  ASSERT_TRUE(gps.has_value());
  EXPECT_EQ(gps->x.step_case(), v1::AxisScale::kDivisor);
  EXPECT_EQ(gps->x.divisor(), 1e9);
  EXPECT_EQ(gps->value_type, v1::POINT_VALUE_TYPE_INT64);
  // LAS with an offset: haystack rock's y is 200000 + 0.01 * Y (0.01 * Y alone misses 42%).
  const std::optional<ScaledAxes> haystack = FindScaledIntegers(ReadData("lidar_haystack_rock"));
  ASSERT_TRUE(haystack.has_value());
  EXPECT_EQ(haystack->y.scale(), 0.01);
  EXPECT_EQ(haystack->y.offset(), 200000.0);
  // 0.1 * 3 is 0.30000000000000004: 0.3 is X / 10, not 0.1 * X.
  const std::optional<ScaledAxes> tenths = FindScaledIntegers(std::vector<Point2>{{0.3, 0.7}, {0.1, 0.2}});
  ASSERT_TRUE(tenths.has_value());
  EXPECT_EQ(tenths->x.divisor(), 10.0);
  // Not scaled integers: a -0.0 (no X gives it), a NaN, full-precision random doubles of
  // different binades beyond 2^53 steps.
  EXPECT_FALSE(FindScaledIntegers(std::vector<Point2>{{1, 2}, {-0.0, 3}}).has_value());
  EXPECT_FALSE(FindScaledIntegers(std::vector<Point2>{{1, std::numeric_limits<double>::quiet_NaN()}}).has_value());
  EXPECT_FALSE(FindScaledIntegers(std::vector<Point2>{{1e300, 1}, {1e-300, 1}}).has_value());
}

// The power-of-two step (read from the doubles' bits): the finest one the values need, accepted
// up to integers of exactly 2^53 and refused one binade above; binary fractions finer than any
// decimal step tried (10^-22) take it.
TEST(PointChunkCodec, PowerOfTwoStepIsTheFinestTheValuesNeedWithin53Bits) {
  const double fine = std::ldexp(3.0, -30);  // 30 binary digits: no decimal step up to 10^-22 gives it
  const std::optional<ScaledAxes> binary =
      FindScaledIntegers(std::vector<Point2>{{fine, 0}, {5, 1}, {-std::ldexp(7.0, -12), 2}});
  ASSERT_TRUE(binary.has_value());
  EXPECT_EQ(binary->x.scale(), std::ldexp(1.0, -30));
  EXPECT_EQ(binary->value_type, v1::POINT_VALUE_TYPE_INT64);
  // 2^43 on a step of 2^-10 is the integer 2^53: the largest accepted.
  const std::optional<ScaledAxes> widest =
      FindScaledIntegers(std::vector<Point2>{{std::ldexp(1.0, -10), 0}, {std::ldexp(1.0, 43), 1}});
  ASSERT_TRUE(widest.has_value());
  EXPECT_EQ(widest->x.scale(), std::ldexp(1.0, -10));
  // 2^44 would be 2^54: no step of either kind works.
  EXPECT_FALSE(
      FindScaledIntegers(std::vector<Point2>{{std::ldexp(1.0, -10), 0}, {std::ldexp(1.0, 44), 1}}).has_value());
  // Subnormals need steps below 2^-1000: refused.
  EXPECT_FALSE(
      FindScaledIntegers(std::vector<Point2>{{std::ldexp(3.0, -1074), 0}, {std::ldexp(1.0, -1070), 1}}).has_value());
  // Every form round-trips bit for bit.
  PointChunkEncoder encoder;
  PointChunkDecoder decoder;
  const std::vector<Point2> points = {{fine, 0}, {5, 1}, {-std::ldexp(7.0, -12), 2}};
  ChunkEncoding encoding{binary->value_type,         binary->x, binary->y, v1::POINT_TRANSFORM_DELTA_SHUFFLE,
                         v1::POINT_COMPRESSION_ZSTD, {}};
  v1::EncodedPointChunk chunk;
  ASSERT_THAT(encoder.Encode(points, encoding, &chunk), IsOk());
  std::vector<Point2> decoded(points.size());
  ASSERT_THAT(decoder.Decode(chunk, ChunkPosition{}, decoded.data()), IsOk());
  ExpectBitIdentical(decoded, points);
}

TEST(PointChunkCodec, ScaledValueIsNeverFused) {
  // With scale 0.1, X = 3 and offset -0.3 the unfused result (two roundings) and an FMA (one)
  // differ: the product rounds to 0.30000000000000004 first. The server must give the former.
  v1::AxisScale scale;
  scale.set_scale(0.1);
  scale.set_offset(-0.3);
  volatile double product = 0.1 * 3.0;  // volatile: rounded and stored, never fused with the sum
  const double unfused = product + -0.3;
  ASSERT_NE(Bits(unfused), Bits(std::fma(0.1, 3.0, -0.3))) << "the chosen values must tell the two apart";
  EXPECT_EQ(Bits(ScaledValue(scale, 3)), Bits(unfused));
  EXPECT_EQ(unfused, 5.551115123125783e-17);
}

// Byte planes of `words` as the proto defines them: byte b of word j at b * words.size() + j.
std::string BytePlanes(const std::vector<uint64_t>& words) {
  std::string bytes(8 * words.size(), '\0');
  for (size_t b = 0; b < 8; ++b) {
    for (size_t j = 0; j < words.size(); ++j) bytes[b * words.size() + j] = static_cast<char>(words[j] >> (8 * b));
  }
  return bytes;
}

TEST(PointChunkCodec, DecodesTheLayoutTheProtoDocuments) {
  // Chunks written by hand from alpha_shapes.proto's words, not by the encoder (other clients
  // implement the format from that text). The points: x integers 10, 12, 9 at scale 0.5; y
  // integers -4, -4, 100 at scale 0.25 with offset 100.
  const std::vector<Point2> want = {{5, 99}, {6, 99}, {4.5, 125}};
  v1::EncodedPointChunk chunk;
  chunk.set_point_count(3);
  chunk.set_value_type(v1::POINT_VALUE_TYPE_INT64);
  chunk.mutable_x_scale()->set_scale(0.5);
  chunk.mutable_y_scale()->set_scale(0.25);
  chunk.mutable_y_scale()->set_offset(100);
  PointChunkDecoder decoder;
  std::vector<Point2> got(3);
  // Deltas, planar: x 10, 2, -3; y -4, 0, 104; zigzag: 20, 4, 5; 7, 0, 208.
  chunk.set_transform(v1::POINT_TRANSFORM_DELTA_SHUFFLE);
  chunk.set_data(BytePlanes({20, 4, 5, 7, 0, 208}));
  ASSERT_THAT(decoder.Decode(chunk, ChunkPosition{}, got.data()), IsOk());
  ExpectBitIdentical(got, want);
  // The same, zstd-compressed.
  chunk.set_compression(v1::POINT_COMPRESSION_ZSTD);
  std::string frame(ZSTD_compressBound(chunk.data().size()), '\0');
  frame.resize(ZSTD_compress(frame.data(), frame.size(), chunk.data().data(), chunk.data().size(), 3));
  chunk.set_data(frame);
  ASSERT_THAT(decoder.Decode(chunk, ChunkPosition{}, got.data()), IsOk());
  ExpectBitIdentical(got, want);
  // Linear prediction 2 w[i-1] - w[i-2]: x 10 - 0, 12 - 20, 9 - 14 = 10, -8, -5; y -4, -4 + 8, 100 + 4
  // = -4, 4, 104; zigzag: 20, 15, 9; 7, 8, 208.
  chunk.set_compression(v1::POINT_COMPRESSION_NONE);
  chunk.set_transform(v1::POINT_TRANSFORM_DELTA2_SHUFFLE);
  chunk.set_data(BytePlanes({20, 15, 9, 7, 8, 208}));
  ASSERT_THAT(decoder.Decode(chunk, ChunkPosition{}, got.data()), IsOk());
  ExpectBitIdentical(got, want);
  // INT32, interleaved little-endian words.
  chunk.set_value_type(v1::POINT_VALUE_TYPE_INT32);
  chunk.set_transform(v1::POINT_TRANSFORM_NONE);
  const int32_t words[] = {10, -4, 12, -4, 9, 100};
  chunk.set_data(std::string(reinterpret_cast<const char*>(words), sizeof words));
  ASSERT_THAT(decoder.Decode(chunk, ChunkPosition{}, got.data()), IsOk());
  ExpectBitIdentical(got, want);
  // FLOAT64 bit patterns in byte planes, planar (all x, then all y).
  v1::EncodedPointChunk doubles;
  doubles.set_point_count(3);
  doubles.set_value_type(v1::POINT_VALUE_TYPE_FLOAT64);
  doubles.set_transform(v1::POINT_TRANSFORM_BYTE_SHUFFLE);
  doubles.set_data(BytePlanes({Bits(5), Bits(6), Bits(4.5), Bits(99), Bits(99), Bits(125)}));
  ASSERT_THAT(decoder.Decode(doubles, ChunkPosition{}, got.data()), IsOk());
  ExpectBitIdentical(got, want);
}

// Weighted streams (BuildHeader.weighted): the weight is a third axis, written from the proto's
// text by hand (x integers 10, 12 at scale 0.5; y -4, 100 at scale 0.25, offset 100; w 3, -7 at
// divisor 4), then encoded and decoded in every form with atom-like weights (squared radii of
// 0.01 A steps: X / 10^4) and awkward float64 ones.
TEST(PointChunkCodec, WeightedChunksCarryTheWeightAsAThirdAxis) {
  v1::EncodedPointChunk chunk;
  chunk.set_point_count(2);
  chunk.set_value_type(v1::POINT_VALUE_TYPE_INT64);
  chunk.mutable_x_scale()->set_scale(0.5);
  chunk.mutable_y_scale()->set_scale(0.25);
  chunk.mutable_y_scale()->set_offset(100);
  chunk.mutable_w_scale()->set_divisor(4);
  chunk.set_transform(v1::POINT_TRANSFORM_BYTE_SHUFFLE);
  // Planar: x 10, 12; y -4, 100; w 3, -7 (two's complement), in byte planes.
  chunk.set_data(BytePlanes({10, 12, static_cast<uint64_t>(-4), 100, 3, static_cast<uint64_t>(-7)}));
  PointChunkDecoder decoder;
  std::vector<Point2> points(2);
  std::vector<double> weights(2);
  ASSERT_THAT(decoder.DecodeWeighted(chunk, ChunkPosition{}, points.data(), weights.data()), IsOk());
  ExpectBitIdentical(points, {{5, 99}, {6, 125}});
  EXPECT_EQ(weights, (std::vector<double>{0.75, -1.75}));
  // Read as an unweighted chunk it is refused (a w_scale; and the data holds three words a point).
  EXPECT_THAT(decoder.Decode(chunk, ChunkPosition{}, points.data()),
              StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("the stream is not weighted")));
  chunk.clear_w_scale();
  EXPECT_THAT(decoder.DecodeWeighted(chunk, ChunkPosition{}, points.data(), weights.data()),
              StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("needs w_scale")));

  std::vector<Point2> atoms;
  std::vector<double> squared_radii;
  for (int i = 0; i < 5000; ++i) {
    atoms.push_back({static_cast<double>(i * 37 % 9973) / 1000, static_cast<double>(i * 91 % 9967) / 1000});
    const int radius = 120 + i % 81;  // 1.20 to 2.00 A
    squared_radii.push_back(static_cast<double>(radius * radius) / 10000);
  }
  const std::optional<ScaledAxes> scaled = FindScaledIntegers(atoms, squared_radii);
  ASSERT_TRUE(scaled.has_value());
  EXPECT_EQ(scaled->value_type, v1::POINT_VALUE_TYPE_INT32);
  EXPECT_EQ(ScaledValue(scaled->w, 14400), 1.44);
  std::vector<double> awkward(atoms.size());
  for (size_t i = 0; i < awkward.size(); ++i) awkward[i] = (i % 3 == 0 ? -1.0 : 1.0) * std::ldexp(1.0 + i, -1070);
  awkward[1] = -0.0;
  PointChunkEncoder encoder;
  for (v1::PointValueType type :
       {v1::POINT_VALUE_TYPE_FLOAT64, v1::POINT_VALUE_TYPE_INT32, v1::POINT_VALUE_TYPE_INT64}) {
    for (v1::PointTransform transform : kTransforms) {
      for (v1::PointCompression compression : {v1::POINT_COMPRESSION_NONE, v1::POINT_COMPRESSION_ZSTD}) {
        SCOPED_TRACE(absl::StrCat("type ", type, ", transform ", transform, ", compression ", compression));
        const bool floats = type == v1::POINT_VALUE_TYPE_FLOAT64;
        ChunkEncoding encoding{type, {}, {}, transform, compression, {}};
        if (!floats) {
          encoding.x_scale = scaled->x;
          encoding.y_scale = scaled->y;
          encoding.w_scale = scaled->w;
        }
        for (const std::vector<double>* w : {&squared_radii, &awkward}) {
          if (!floats && w == &awkward) continue;
          v1::EncodedPointChunk encoded;
          ASSERT_THAT(encoder.Encode(atoms, *w, encoding, &encoded), IsOk());
          EXPECT_EQ(encoded.has_w_scale(), !floats);
          std::vector<Point2> got(atoms.size());
          std::vector<double> got_weights(atoms.size());
          ASSERT_THAT(decoder.DecodeWeighted(encoded, ChunkPosition{}, got.data(), got_weights.data()), IsOk());
          ExpectBitIdentical(got, atoms);
          for (size_t i = 0; i < atoms.size(); ++i) ASSERT_EQ(Bits(got_weights[i]), Bits((*w)[i])) << i;
        }
      }
    }
  }
  // The smallest form of a weighted chunk is scaled integers here, well under raw triples.
  v1::BuildRequest smallest;
  ASSERT_THAT(encoder.EncodeSmallest(atoms, squared_radii, &smallest), IsOk());
  EXPECT_THAT(encoder.EncodeSmallest(atoms, absl::MakeConstSpan(squared_radii).subspan(1), &smallest),
              StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("5000 points need 5000 weights")));
  ASSERT_TRUE(smallest.has_encoded_points());
  EXPECT_LT(smallest.ByteSizeLong(), 8 * atoms.size());
}

TEST(PointChunkCodec, EveryEncodingOfTheSamePointsHasTheSameHandleAsRaw) {
  const std::vector<Point2> points = ReadData("lidar_autzen");
  const std::string raw_handle = PointSetHandle(points);
  const std::optional<ScaledAxes> scaled = FindScaledIntegers(points);
  ASSERT_TRUE(scaled.has_value());
  std::vector<ChunkEncoding> encodings = {
      {v1::POINT_VALUE_TYPE_FLOAT64, {}, {}, v1::POINT_TRANSFORM_DELTA_SHUFFLE, v1::POINT_COMPRESSION_ZSTD, {}},
      {v1::POINT_VALUE_TYPE_INT32, scaled->x, scaled->y, v1::POINT_TRANSFORM_NONE, v1::POINT_COMPRESSION_NONE, {}},
      {v1::POINT_VALUE_TYPE_INT64,
       scaled->x,
       scaled->y,
       v1::POINT_TRANSFORM_DELTA2_SHUFFLE,
       v1::POINT_COMPRESSION_ZSTD,
       {}}};
  PointChunkEncoder encoder;
  for (size_t e = 0; e < encodings.size(); ++e) {
    SCOPED_TRACE(e);
    // Chunks of 40,000 points, the last one raw: encodings mix freely within a stream.
    std::vector<v1::BuildRequest> chunks;
    for (size_t begin = 0; begin < points.size(); begin += 40000) {
      const auto part = absl::MakeConstSpan(points).subspan(begin, 40000);
      v1::BuildRequest message;
      if (begin + 40000 >= points.size()) {
        message.mutable_points()->mutable_coordinates()->Add(&part[0].x, &part[0].x + 2 * part.size());
      } else {
        ASSERT_THAT(encoder.Encode(part, encodings[e], message.mutable_encoded_points()), IsOk());
      }
      chunks.push_back(message);
    }
    std::string handle;
    absl::StatusOr<std::vector<Point2>> decoded = ThroughTheServer(chunks, &handle);
    ASSERT_THAT(decoded.status(), IsOk());
    ExpectBitIdentical(*decoded, points);
    EXPECT_EQ(handle, raw_handle);
  }
}

TEST(PointChunkCodec, IntegerEncodingOfPointsItCannotReproduceIsRefused) {
  PointChunkEncoder encoder;
  ChunkEncoding encoding;
  encoding.value_type = v1::POINT_VALUE_TYPE_INT32;
  encoding.x_scale.set_scale(0.1);
  encoding.y_scale.set_scale(0.1);
  v1::EncodedPointChunk chunk;
  const absl::Status status = encoder.Encode(std::vector<Point2>{{0.1, 0.2}, {0.3, 0.4}}, encoding, &chunk);
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(status.message().find("point 1's x (0.3)"), std::string::npos) << status;
}

// ---- Malformed chunks -----------------------------------------------------------------------------

v1::EncodedPointChunk ValidIntegerChunk() {
  PointChunkEncoder encoder;
  ChunkEncoding encoding;
  encoding.value_type = v1::POINT_VALUE_TYPE_INT64;
  encoding.x_scale.set_scale(0.5);
  encoding.y_scale.set_divisor(100);
  encoding.transform = v1::POINT_TRANSFORM_DELTA_SHUFFLE;
  encoding.compression = v1::POINT_COMPRESSION_ZSTD;
  v1::EncodedPointChunk chunk;
  EXPECT_THAT(encoder.Encode(std::vector<Point2>{{1.5, 0.25}, {-2, 7.01}, {3, 3}}, encoding, &chunk), IsOk());
  return chunk;
}

std::string Compressed(const std::string& input, bool with_content_size) {
  ZSTD_CCtx* context = ZSTD_createCCtx();
  ZSTD_CCtx_setParameter(context, ZSTD_c_contentSizeFlag, with_content_size ? 1 : 0);
  std::string output(ZSTD_compressBound(input.size()), '\0');
  // The streaming API leaves the size out when asked (a single-shot call would record it).
  ZSTD_inBuffer in{input.data(), input.size(), 0};
  ZSTD_outBuffer out{output.data(), output.size(), 0};
  const size_t left = ZSTD_compressStream2(context, &out, &in, ZSTD_e_end);
  EXPECT_EQ(left, 0u);
  ZSTD_freeCCtx(context);
  output.resize(out.pos);
  return output;
}

TEST(PointChunkCodec, MalformedChunksAreRefusedNamingTheChunk) {
  struct Case {
    std::string name;
    std::function<void(v1::EncodedPointChunk*)> damage;
    std::string says;
  };
  const std::vector<Case> cases = {
      {"no points", [](auto* c) { c->set_point_count(0); }, "states no points"},
      {"too many points", [](auto* c) { c->set_point_count(kMaxPointsPerEncodedChunk + 1); }, "at most 262144"},
      {"no value type", [](auto* c) { c->set_value_type(v1::POINT_VALUE_TYPE_UNSPECIFIED); }, "no value_type"},
      {"undefined value type", [](auto* c) { c->set_value_type(static_cast<v1::PointValueType>(9)); },
       "value_type 9 is not"},
      {"undefined transform", [](auto* c) { c->set_transform(static_cast<v1::PointTransform>(17)); },
       "transform 17 is not"},
      {"undefined compression", [](auto* c) { c->set_compression(static_cast<v1::PointCompression>(5)); },
       "compression 5 is not"},
      {"float64 with a scale", [](auto* c) { c->set_value_type(v1::POINT_VALUE_TYPE_FLOAT64); }, "takes no x_scale"},
      {"integers without y_scale", [](auto* c) { c->clear_y_scale(); }, "needs y_scale"},
      {"a scale without a step", [](auto* c) { c->mutable_x_scale()->clear_step(); }, "neither a scale nor"},
      {"zero scale", [](auto* c) { c->mutable_x_scale()->set_scale(0); }, "x_scale's scale is 0"},
      {"NaN scale", [](auto* c) { c->mutable_x_scale()->set_scale(std::nan("")); }, "x_scale's scale is nan"},
      {"infinite divisor", [](auto* c) { c->mutable_y_scale()->set_divisor(std::numeric_limits<double>::infinity()); },
       "y_scale's divisor is inf"},
      {"NaN offset", [](auto* c) { c->mutable_y_scale()->set_offset(std::nan("")); }, "offset is nan"},
      {"not a zstd frame", [](auto* c) { c->set_data("definitely not zstd"); }, "not a zstd frame"},
      {"bytes after the frame", [](auto* c) { c->mutable_data()->append("tail"); }, "4 bytes after its zstd frame"},
      {"a frame declaring another size", [](auto* c) { c->set_data(Compressed(std::string(40, 'a'), true)); },
       "declares 40 bytes"},
      {"a frame without a size that is too short",
       [](auto* c) { c->set_data(Compressed(std::string(40, 'a'), false)); }, "decompresses to 40 bytes"},
      {"a frame without a size that is too long", [](auto* c) { c->set_data(Compressed(std::string(49, 'a'), false)); },
       "decompresses to more than 48"},
      {"uncompressed data of the wrong size",
       [](auto* c) {
         c->set_compression(v1::POINT_COMPRESSION_NONE);
         c->set_data(std::string(47, '\0'));
       },
       "its data is 47 bytes; 3 uncompressed points of INT64 are 48"},
      {"an integer over 2^53",
       [](auto* c) {
         c->set_compression(v1::POINT_COMPRESSION_NONE);
         c->set_transform(v1::POINT_TRANSFORM_NONE);
         std::string data(48, '\0');
         const int64_t huge = (int64_t{1} << 53) + 1;
         std::memcpy(&data[24], &huge, 8);  // point 1's y
         c->set_data(data);
       },
       "point 1001's y integer is 9007199254740993"},
      {"integers that decode to infinity", [](auto* c) { c->mutable_x_scale()->set_scale(1e308); },
       "point 1000 has an infinite x coordinate"},
  };
  PointChunkDecoder decoder;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    v1::EncodedPointChunk chunk = ValidIntegerChunk();
    std::vector<Point2> out(3);
    ASSERT_THAT(decoder.Decode(chunk, ChunkPosition{4, 1000}, out.data()), IsOk());
    c.damage(&chunk);
    const absl::Status status = decoder.Decode(chunk, ChunkPosition{4, 1000}, out.data());
    EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_NE(status.message().find("encoded point chunk 4 (from point 1000)"), std::string::npos) << status;
    EXPECT_NE(status.message().find(c.says), std::string::npos) << status;
  }
}

TEST(PointChunkCodec, Float64NanIsNamedByItsIndexInTheStream) {
  std::vector<Point2> points = gen::Uniform(100, 5);
  points[37].y = -std::numeric_limits<double>::infinity();
  PointChunkEncoder encoder;
  ChunkEncoding encoding;
  encoding.transform = v1::POINT_TRANSFORM_DELTA_SHUFFLE;
  encoding.compression = v1::POINT_COMPRESSION_ZSTD;
  v1::EncodedPointChunk chunk;
  ASSERT_THAT(encoder.Encode(points, encoding, &chunk), IsOk());
  PointChunkDecoder decoder;
  std::vector<Point2> out(points.size());
  const absl::Status status = decoder.Decode(chunk, ChunkPosition{2, 500}, out.data());
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(status.message().find("point 537 has an infinite y coordinate"), std::string::npos) << status;
}

TEST(PointChunkCodec, ZipBombIsRefusedWithoutDecompressingIt) {
  // 64 MiB of zeros compress to a few kilobytes; the chunk states one point (16 bytes). Without a
  // recorded size the decoder may only learn the truth by decompressing: it stops at 16 bytes.
  const std::string bomb = Compressed(std::string(size_t{64} << 20, '\0'), false);
  ASSERT_LT(bomb.size(), 64u << 10);
  v1::EncodedPointChunk chunk;
  chunk.set_point_count(1);
  chunk.set_value_type(v1::POINT_VALUE_TYPE_FLOAT64);
  chunk.set_compression(v1::POINT_COMPRESSION_ZSTD);
  chunk.set_data(bomb);
  PointChunkDecoder decoder;
  Point2 out;
  const absl::Status status = decoder.Decode(chunk, ChunkPosition{}, &out);
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(status.message().find("decompresses to more than 16 bytes"), std::string::npos) << status;
}

// ---- Bytes on the wire -----------------------------------------------------------------------------

// The Build stream's point messages when the encoder picks the smallest form per 65,536-point
// chunk (as the client library sends them): bytes per point, and the seconds to encode and to
// decode them; the stream round-trips through the server's decoder to the same points and handle.
struct WireMeasure {
  double bytes_per_point = 0;
  double encode_seconds = 0;
  double decode_seconds = 0;
};

WireMeasure MeasureWire(const std::vector<Point2>& points, int level) {
  using Clock = std::chrono::steady_clock;
  PointChunkEncoder encoder(level);
  std::vector<v1::BuildRequest> chunks;
  size_t bytes = 0;
  const auto start = Clock::now();
  for (size_t begin = 0; begin < points.size(); begin += 65536) {
    v1::BuildRequest message;
    encoder.EncodeSmallest(absl::MakeConstSpan(points).subspan(begin, 65536), &message);
    bytes += message.ByteSizeLong();
    chunks.push_back(std::move(message));
  }
  const auto encoded = Clock::now();
  // Decoding alone (the codec's work, into memory already touched); the stream decoder's growth
  // and the handle's hash are the same for every encoding.
  std::vector<Point2> out(points.size());
  PointChunkDecoder decoder;
  size_t first = 0;
  const auto decoding = Clock::now();
  for (const v1::BuildRequest& message : chunks) {
    if (message.has_encoded_points()) {
      EXPECT_THAT(decoder.Decode(message.encoded_points(), ChunkPosition{0, first}, &out[first]), IsOk());
      first += message.encoded_points().point_count();
    } else {
      std::memcpy(&out[first], message.points().coordinates().data(), 8 * message.points().coordinates_size());
      first += message.points().coordinates_size() / 2;
    }
  }
  const auto end = Clock::now();
  ExpectBitIdentical(out, points);
  std::string handle;
  absl::StatusOr<std::vector<Point2>> decoded = ThroughTheServer(chunks, &handle);
  EXPECT_THAT(decoded.status(), IsOk());
  if (decoded.ok()) ExpectBitIdentical(*decoded, points);
  EXPECT_EQ(handle, PointSetHandle(points));
  return {static_cast<double>(bytes) / static_cast<double>(points.size()),
          std::chrono::duration<double>(encoded - start).count(),
          std::chrono::duration<double>(end - decoding).count()};
}

TEST(PointChunkCodec, BytesPerPointOnTheWire) {
  struct Row {
    std::string name;
    std::vector<Point2> points;
    double at_most;  // the target, or what is achievable (docs/design.md, "Wire encodings of points")
  };
  std::vector<Row> rows;
  for (const std::string& path : testdata::PointFiles()) {
    const std::string name = path.substr(path.rfind('/') + 1, path.size() - path.rfind('/') - 5);
    double at_most = 16.01;  // never worse than raw doubles and their framing
    if (name == "lidar_autzen") at_most = 4.0;
    if (name == "gps_tracks_slovenia_croatia") at_most = 5.2;  // entropy-bound miss of the 4-byte target
    rows.push_back({name, ReadData(name), at_most});
  }
  // 13.25 bytes is the entropy of two 53-bit random doubles: 12 is impossible (docs/design.md).
  rows.push_back({"uniform random doubles (1M)", gen::Uniform(1'000'000, 7), 13.7});
  std::printf("%-30s %9s %10s %10s %12s %12s\n", "data set", "points", "B/pt zstd3", "B/pt zstd19", "encode MB/s",
              "decode MB/s");
  for (const Row& row : rows) {
    SCOPED_TRACE(row.name);
    const WireMeasure fast = MeasureWire(row.points, 3);
    const WireMeasure small = row.points.size() <= 200'000 ? MeasureWire(row.points, 19) : fast;
    // Rates in megabytes of decoded points (16 bytes each) per second, at the default level.
    const double megabytes = 16e-6 * static_cast<double>(row.points.size());
    std::printf("%-30s %9zu %10.2f %10.2f %12.0f %12.0f\n", row.name.c_str(), row.points.size(), fast.bytes_per_point,
                small.bytes_per_point, megabytes / fast.encode_seconds, megabytes / fast.decode_seconds);
    EXPECT_LE(fast.bytes_per_point, row.at_most);
  }
}

// The atoms of PDB 2XHE with their squared van der Waals radii (data/pdb_2xhe_radii.txt) as a
// weighted Build stream: the smallest encoding (printed; the Python encoder gave 4.79 bytes a
// point, docs/design.md) decodes through the server to the same points, weights and handle.
TEST(PointChunkCodec, WeightedMoleculeOnTheWire) {
  std::ifstream in(testdata::DataDir() + "/pdb_2xhe_radii.txt");
  ASSERT_TRUE(in.good());
  std::vector<Point2> atoms;
  std::vector<double> weights;
  std::string line;
  while (std::getline(in, line)) {
    double x = 0, y = 0, r = 0;
    if (line.empty() || line[0] == '#' || std::sscanf(line.c_str(), "%lf %lf %lf", &x, &y, &r) != 3) continue;
    atoms.push_back({x, y});
    weights.push_back(r * r);
  }
  ASSERT_EQ(atoms.size(), 6267u);
  PointChunkEncoder encoder;
  v1::BuildRequest chunk;
  ASSERT_THAT(encoder.EncodeSmallest(atoms, weights, &chunk), IsOk());
  ASSERT_TRUE(chunk.has_encoded_points());
  const double bytes_per_point = static_cast<double>(chunk.ByteSizeLong()) / static_cast<double>(atoms.size());
  std::printf("pdb_2xhe with squared van der Waals radii: %.2f bytes a point (raw triples: 24)\n", bytes_per_point);
  EXPECT_LE(bytes_per_point, 6.0);
  server::BuildStreamDecoder decoder(server::BuildStreamLimits{}, nullptr);
  v1::BuildRequest header;
  header.mutable_header()->set_weighted(true);
  ASSERT_THAT(decoder.Add(header), IsOk());
  ASSERT_THAT(decoder.Add(chunk), IsOk());
  absl::StatusOr<server::DecodedBuild*> decoded = decoder.Finish();
  ASSERT_THAT(decoded, IsOk());
  ExpectBitIdentical(absl::MakeConstSpan((*decoded)->points.data(), (*decoded)->points.size()), atoms);
  for (size_t i = 0; i < atoms.size(); ++i) ASSERT_EQ(Bits((*decoded)->weights[i]), Bits(weights[i])) << i;
  EXPECT_EQ((*decoded)->handle, WeightedPointSetHandle(atoms, weights));
}

}  // namespace
}  // namespace galpha::wire
