// The Build stream decoder against the protocol (proto/galpha/v1/alpha_shapes.proto, BuildRequest):
// the order of header and chunks, every limit as the messages arrive, NaN and infinity named by
// their index in the whole stream, the points decoded bit for bit and the handle independent of
// how the points are split into chunks; and the server-wide bytes in flight, held and given back.
#include "server/build_stream.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/types/span.h"
#include "core/io/point_set_handle.hpp"
#include "gtest/gtest.h"
#include "proto/codec/point_chunk_codec.hpp"
#include "server/build_refusal.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

using galpha::testing::IsOk;
using galpha::testing::StatusIs;

namespace v1 = galpha::v1;

v1::BuildRequest Header(uint64_t expected_points, const std::string& name = "test") {
  v1::BuildRequest message;
  message.mutable_header()->set_name(name);
  message.mutable_header()->set_expected_points(expected_points);
  return message;
}

v1::BuildRequest Chunk(const std::vector<double>& coordinates) {
  v1::BuildRequest message;
  message.mutable_points()->mutable_coordinates()->Add(coordinates.begin(), coordinates.end());
  return message;
}

v1::BuildRequest Chunk(absl::Span<const Point2> points) {
  v1::BuildRequest message;
  auto* coordinates = message.mutable_points()->mutable_coordinates();
  for (const Point2& p : points) {
    coordinates->Add(p.x);
    coordinates->Add(p.y);
  }
  return message;
}

// A chunk that is present but holds no coordinates (the oneof case is set).
v1::BuildRequest EmptyChunk() {
  v1::BuildRequest message;
  message.mutable_points();
  return message;
}

uint64_t Bits(double value) {
  uint64_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  return bits;
}

// Whether `decoded` holds exactly `points` and `weights` (none for an unweighted stream), bit for
// bit; the first difference otherwise.
::testing::AssertionResult DecodedBitForBit(const DecodedBuild& decoded, const std::vector<Point2>& points,
                                            const std::vector<double>& weights = {}) {
  if (decoded.points.size() != points.size() || decoded.weights.size() != weights.size()) {
    return ::testing::AssertionFailure() << decoded.points.size() << " points and " << decoded.weights.size()
                                         << " weights decoded, not " << points.size() << " and " << weights.size();
  }
  for (size_t i = 0; i < points.size(); ++i) {
    if (Bits(decoded.points[i].x) != Bits(points[i].x) || Bits(decoded.points[i].y) != Bits(points[i].y) ||
        (!weights.empty() && Bits(decoded.weights[i]) != Bits(weights[i]))) {
      return ::testing::AssertionFailure() << "point " << i << " differs";
    }
  }
  return ::testing::AssertionSuccess();
}

TEST(BuildStreamDecoderTest, DecodesHeaderAndChunks) {
  const std::vector<Point2> points = gen::Uniform(10, 1);
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(decoder.Add(Header(10, "ten points")), IsOk());
  ASSERT_THAT(decoder.Add(Chunk(absl::MakeConstSpan(points).subspan(0, 4))), IsOk());
  EXPECT_EQ(decoder.points_received(), 4u);
  ASSERT_THAT(decoder.Add(Chunk(absl::MakeConstSpan(points).subspan(4))), IsOk());
  EXPECT_EQ(decoder.points_received(), 10u);
  absl::StatusOr<DecodedBuild*> decoded = decoder.Finish();
  ASSERT_THAT(decoded, IsOk());
  EXPECT_EQ((*decoded)->header.name(), "ten points");
  EXPECT_EQ((*decoded)->header.expected_points(), 10u);
  EXPECT_EQ((*decoded)->points, points);
  EXPECT_EQ((*decoded)->handle, PointSetHandle(points));
  EXPECT_TRUE(IsWellFormedHandle((*decoded)->handle));
}

TEST(BuildStreamDecoderTest, HeaderMustComeFirst) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  const absl::Status status = decoder.Add(Chunk(std::vector<double>{1.0, 2.0}));
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(status.message().find("header"), absl::string_view::npos) << status;
  EXPECT_EQ(decoder.points_received(), 0u);
}

TEST(BuildStreamDecoderTest, EmptyChunkBeforeHeaderIsRefused) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  EXPECT_THAT(decoder.Add(EmptyChunk()), StatusIs(absl::StatusCode::kInvalidArgument));
}

TEST(BuildStreamDecoderTest, SecondHeaderIsRefused) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(decoder.Add(Header(0)), IsOk());
  ASSERT_THAT(decoder.Add(Chunk(std::vector<double>{1.0, 2.0})), IsOk());
  const absl::Status status = decoder.Add(Header(0));
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(status.message().find("second header"), absl::string_view::npos) << status;
}

TEST(BuildStreamDecoderTest, OddNumberOfDoublesIsRefused) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(decoder.Add(Header(0)), IsOk());
  ASSERT_THAT(decoder.Add(Chunk(std::vector<double>{1.0, 2.0})), IsOk());
  const absl::Status status = decoder.Add(Chunk(std::vector<double>{3.0, 4.0, 5.0}));
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(status.message().find("odd"), absl::string_view::npos) << status;
  EXPECT_EQ(decoder.points_received(), 1u) << "a refused chunk adds nothing";
}

// Whether `message` names point `index` exactly ("point 7 ", not "point 70").
bool NamesPoint(absl::string_view message, uint64_t index) {
  return message.find(absl::StrCat("point ", index, " ")) != absl::string_view::npos;
}

TEST(BuildStreamDecoderTest, NanNamesTheGlobalPointIndex) {
  // The NaN is the y of the 5th point (index 4) of the second chunk; the first chunk holds 3
  // points, so the point's index in the stream is 3 + 4 = 7.
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(decoder.Add(Header(0)), IsOk());
  ASSERT_THAT(decoder.Add(Chunk(gen::Uniform(3, 2))), IsOk());
  std::vector<Point2> second = gen::Uniform(6, 3);
  second[4].y = std::numeric_limits<double>::quiet_NaN();
  const absl::Status status = decoder.Add(Chunk(second));
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_TRUE(NamesPoint(status.message(), 7)) << status;
  EXPECT_NE(status.message().find("NaN"), absl::string_view::npos) << status;
  EXPECT_NE(status.message().find(" y "), absl::string_view::npos) << status;
  EXPECT_EQ(decoder.points_received(), 3u) << "a refused chunk adds nothing";
}

TEST(BuildStreamDecoderTest, InfinityNamesTheGlobalPointIndex) {
  for (const double bad : {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()}) {
    SCOPED_TRACE(bad);
    BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
    ASSERT_THAT(decoder.Add(Header(20)), IsOk());
    ASSERT_THAT(decoder.Add(Chunk(gen::Uniform(5, 4))), IsOk());
    ASSERT_THAT(decoder.Add(Chunk(gen::Uniform(2, 5))), IsOk());
    std::vector<Point2> third = gen::Uniform(4, 6);
    third[0].x = bad;  // index 5 + 2 + 0 = 7
    const absl::Status status = decoder.Add(Chunk(third));
    EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_TRUE(NamesPoint(status.message(), 7)) << status;
    EXPECT_NE(status.message().find("infinite"), absl::string_view::npos) << status;
    EXPECT_NE(status.message().find(" x "), absl::string_view::npos) << status;
  }
}

TEST(BuildStreamDecoderTest, NanInTheFirstPoint) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(decoder.Add(Header(0)), IsOk());
  const absl::Status status =
      decoder.Add(Chunk(std::vector<double>{std::numeric_limits<double>::quiet_NaN(), 0.0, 1.0, 1.0}));
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_TRUE(NamesPoint(status.message(), 0)) << status;
}

TEST(BuildStreamDecoderTest, MessageWithNeitherHeaderNorPointsIsRefused) {
  {
    BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
    EXPECT_THAT(decoder.Add(v1::BuildRequest()), StatusIs(absl::StatusCode::kInvalidArgument));
  }
  {
    BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
    ASSERT_THAT(decoder.Add(Header(0)), IsOk());
    const absl::Status status = decoder.Add(v1::BuildRequest());
    EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_NE(status.message().find("neither"), absl::string_view::npos) << status;
  }
}

TEST(BuildStreamDecoderTest, AnUnreadableCrsIsRefusedAtTheHeader) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  v1::BuildRequest header = Header(0);
  header.mutable_header()->set_crs("no such crs");
  // With PROJ: not understood; without: this build reads no CRS. Either way before any point.
  EXPECT_THAT(decoder.Add(header),
              StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("the header's crs")));
}

TEST(BuildStreamDecoderTest, AnnouncedCountOverTheLimitIsRefusedAtTheHeader) {
  BuildStreamLimits limits;
  limits.max_points = 100;
  BuildStreamDecoder decoder(limits, nullptr);
  const absl::Status status = decoder.Add(Header(101));
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kResourceExhausted));
  EXPECT_NE(status.message().find("100"), absl::string_view::npos) << status;

  BuildStreamDecoder at_limit(limits, nullptr);
  EXPECT_THAT(at_limit.Add(Header(100)), IsOk());
}

TEST(BuildStreamDecoderTest, NameLongerThanTheLimitIsRefusedByName) {
  BuildStreamDecoder at_limit(BuildStreamLimits{}, nullptr);
  EXPECT_THAT(at_limit.Add(Header(0, std::string(kMaxBuildNameBytes, 'n'))), IsOk());
  BuildStreamDecoder over(BuildStreamLimits{}, nullptr);
  EXPECT_THAT(over.Add(Header(0, std::string(kMaxBuildNameBytes + 1, 'n'))),
              StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("name is 257 bytes long; a name is "
                                                                                "at most 256 bytes")));
}

TEST(BuildStreamDecoderTest, UnannouncedCountOverTheLimitIsRefusedAtTheChunk) {
  BuildStreamLimits limits;
  limits.max_points = 5;
  BuildStreamDecoder decoder(limits, nullptr);
  ASSERT_THAT(decoder.Add(Header(0)), IsOk());
  ASSERT_THAT(decoder.Add(Chunk(gen::Uniform(3, 7))), IsOk());
  ASSERT_THAT(decoder.Add(Chunk(gen::Uniform(2, 8))), IsOk()) << "exactly the limit is allowed";
  const absl::Status status = decoder.Add(Chunk(gen::Uniform(1, 9)));
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kResourceExhausted));
  EXPECT_EQ(decoder.points_received(), 5u);
}

TEST(BuildStreamDecoderTest, FewerPointsThanAnnouncedIsRefusedAtFinish) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(decoder.Add(Header(10)), IsOk());
  ASSERT_THAT(decoder.Add(Chunk(gen::Uniform(9, 10))), IsOk());
  const absl::StatusOr<DecodedBuild*> decoded = decoder.Finish();
  EXPECT_THAT(decoded.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(decoded.status().message().find("9"), absl::string_view::npos) << decoded.status();
}

TEST(BuildStreamDecoderTest, MorePointsThanAnnouncedIsRefusedAtTheChunk) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(decoder.Add(Header(10)), IsOk());
  ASSERT_THAT(decoder.Add(Chunk(gen::Uniform(8, 11))), IsOk());
  const absl::Status status = decoder.Add(Chunk(gen::Uniform(3, 12)));
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_EQ(decoder.points_received(), 8u);
}

TEST(BuildStreamDecoderTest, EmptyStreamIsRefused) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  const absl::StatusOr<DecodedBuild*> decoded = decoder.Finish();
  EXPECT_THAT(decoded.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(decoded.status().message().find("empty"), absl::string_view::npos) << decoded.status();
}

TEST(BuildStreamDecoderTest, HeaderWithZeroPointsIsAnEmptyPointSet) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(decoder.Add(Header(0)), IsOk());
  const absl::StatusOr<DecodedBuild*> decoded = decoder.Finish();
  ASSERT_THAT(decoded, IsOk());
  EXPECT_TRUE((*decoded)->points.empty());
  EXPECT_EQ((*decoded)->handle, PointSetHandle({}));
}

TEST(BuildStreamDecoderTest, NothingIsAcceptedAfterFinish) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(decoder.Add(Header(0)), IsOk());
  ASSERT_THAT(decoder.Finish(), IsOk());
  EXPECT_THAT(decoder.Add(Chunk(std::vector<double>{1.0, 2.0})), StatusIs(absl::StatusCode::kFailedPrecondition));
  EXPECT_THAT(decoder.Finish().status(), StatusIs(absl::StatusCode::kFailedPrecondition));
}

// Decodes `points` split at `cuts` (ascending point counts; a repeated cut is an empty chunk).
absl::StatusOr<std::string> DecodeSplit(const std::vector<Point2>& points, const std::vector<size_t>& cuts,
                                        bool announce, std::vector<Point2>* decoded_points) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  if (absl::Status s = decoder.Add(Header(announce ? points.size() : 0)); !s.ok()) return s;
  size_t begin = 0;
  std::vector<size_t> ends = cuts;
  ends.push_back(points.size());
  for (const size_t end : ends) {
    const v1::BuildRequest chunk =
        end == begin ? EmptyChunk() : Chunk(absl::MakeConstSpan(points).subspan(begin, end - begin));
    if (absl::Status s = decoder.Add(chunk); !s.ok()) return s;
    begin = end;
  }
  absl::StatusOr<DecodedBuild*> decoded = decoder.Finish();
  if (!decoded.ok()) return decoded.status();
  decoded_points->assign((*decoded)->points.begin(), (*decoded)->points.end());
  return (*decoded)->handle;
}

TEST(BuildStreamDecoderTest, HandleDoesNotDependOnTheSplit) {
  const std::vector<Point2> points = gen::WithDuplicates(100, 13);
  const std::string expected = PointSetHandle(points);
  const std::vector<std::vector<size_t>> splits = {
      {},                           // one chunk
      {0},                          // an empty chunk first
      {50},                         // halves
      {1, 2, 3, 99},                // single points at both ends
      {10, 10, 10, 40, 100},        // empty chunks in the middle and at the end
      {0, 0, 33, 66, 66, 100, 100}  // empty chunks everywhere
  };
  for (const bool announce : {false, true}) {
    for (const std::vector<size_t>& cuts : splits) {
      SCOPED_TRACE(absl::StrCat("announce ", announce, ", cuts ", cuts.size(), " first ", cuts.empty() ? 0 : cuts[0]));
      std::vector<Point2> decoded_points;
      const absl::StatusOr<std::string> handle = DecodeSplit(points, cuts, announce, &decoded_points);
      ASSERT_THAT(handle, IsOk());
      EXPECT_EQ(*handle, expected);
      EXPECT_EQ(decoded_points, points);
    }
  }
  // One point per chunk.
  std::vector<size_t> every;
  for (size_t i = 1; i < points.size(); ++i) every.push_back(i);
  std::vector<Point2> decoded_points;
  const absl::StatusOr<std::string> handle = DecodeSplit(points, every, true, &decoded_points);
  ASSERT_THAT(handle, IsOk());
  EXPECT_EQ(*handle, expected);
}

TEST(BuildStreamDecoderTest, DifferentPointsGiveDifferentHandles) {
  std::vector<Point2> points = gen::Uniform(20, 14);
  std::vector<Point2> decoded_points;
  const absl::StatusOr<std::string> a = DecodeSplit(points, {}, false, &decoded_points);
  std::swap(points[0], points[1]);  // order matters: answers name points by index
  const absl::StatusOr<std::string> b = DecodeSplit(points, {}, false, &decoded_points);
  ASSERT_THAT(a, IsOk());
  ASSERT_THAT(b, IsOk());
  EXPECT_NE(*a, *b);
}

TEST(BuildStreamDecoderTest, PointsAreDecodedBitForBit) {
  const std::vector<double> coordinates = {-0.0,
                                           0.0,
                                           std::numeric_limits<double>::denorm_min(),
                                           -std::numeric_limits<double>::denorm_min(),
                                           1e300,
                                           -1e300,
                                           std::numeric_limits<double>::max(),
                                           std::numeric_limits<double>::lowest(),
                                           std::numeric_limits<double>::min() / 3.0,  // subnormal
                                           0.1,
                                           1.0 / 3.0,
                                           -12345.678901234567};
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(decoder.Add(Header(coordinates.size() / 2)), IsOk());
  ASSERT_THAT(decoder.Add(Chunk(std::vector<double>(coordinates.begin(), coordinates.begin() + 4))), IsOk());
  ASSERT_THAT(decoder.Add(Chunk(std::vector<double>(coordinates.begin() + 4, coordinates.end()))), IsOk());
  const absl::StatusOr<DecodedBuild*> decoded = decoder.Finish();
  ASSERT_THAT(decoded, IsOk());
  const HostVector<Point2>& points = (*decoded)->points;
  ASSERT_EQ(points.size() * 2, coordinates.size());
  for (size_t i = 0; i < points.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(Bits(points[i].x), Bits(coordinates[2 * i]));
    EXPECT_EQ(Bits(points[i].y), Bits(coordinates[2 * i + 1]));
  }
  EXPECT_TRUE(std::signbit(points[0].x)) << "-0.0 keeps its sign";
  EXPECT_EQ((*decoded)->handle, PointSetHandle(points));
  // -0.0 and 0.0 are equal doubles but different inputs: their handles differ.
  std::vector<Point2> positive_zero(points.begin(), points.end());
  positive_zero[0].x = 0.0;
  EXPECT_NE(PointSetHandle(positive_zero), (*decoded)->handle);
}

// ---- InFlightBytes --------------------------------------------------------------------------------

TEST(InFlightBytesTest, ReservesUpToTheLimit) {
  InFlightBytes in_flight(100);
  EXPECT_EQ(in_flight.limit(), 100u);
  EXPECT_THAT(in_flight.Reserve("", 60), IsOk());
  const absl::Status refused = in_flight.Reserve("", 41);
  EXPECT_THAT(refused, StatusIs(absl::StatusCode::kResourceExhausted, ::testing::HasSubstr("--max_in_flight_bytes")));
  EXPECT_EQ(RefusalLabelOf(refused), "in_flight_bytes");
  EXPECT_EQ(in_flight.held(), 60u) << "a refused reservation holds nothing";
  EXPECT_THAT(in_flight.Reserve("", 40), IsOk());
  EXPECT_EQ(in_flight.held(), 100u);
  in_flight.Release("", 100);
  EXPECT_EQ(in_flight.held(), 0u);
}

TEST(InFlightBytesTest, ZeroLimitAdmitsEverything) {
  InFlightBytes in_flight(0);
  EXPECT_THAT(in_flight.Reserve("", size_t{1} << 40), IsOk());
  EXPECT_THAT(in_flight.Reserve("", size_t{1} << 40), IsOk());
  EXPECT_EQ(in_flight.held(), size_t{2} << 40);
}

TEST(InFlightBytesTest, EachTenantHasItsOwnLimitWithinTheServers) {
  InFlightBytes in_flight(/*limit=*/100, /*tenant_limit=*/60);
  EXPECT_THAT(in_flight.Reserve("a", 60), IsOk());
  const absl::Status refused = in_flight.Reserve("a", 1);
  EXPECT_THAT(refused, StatusIs(absl::StatusCode::kResourceExhausted, ::testing::HasSubstr("tenant 'a' holds 60")));
  EXPECT_THAT(refused.message(), ::testing::HasSubstr("--max_tenant_in_flight_bytes"));
  EXPECT_EQ(RefusalLabelOf(refused), "tenant_in_flight_bytes");
  EXPECT_THAT(in_flight.Reserve("b", 40), IsOk()) << "another tenant is not held back by a's bytes";
  EXPECT_EQ(RefusalLabelOf(in_flight.Reserve("b", 1)), "in_flight_bytes") << "the server's limit still holds";
  EXPECT_EQ(in_flight.held_by("a"), 60u);
  EXPECT_EQ(in_flight.held_by("b"), 40u);
  in_flight.Release("a", 60);
  EXPECT_EQ(in_flight.held_by("a"), 0u);
  EXPECT_EQ(in_flight.held(), 40u);

  // Without authentication every caller is one tenant, "".
  InFlightBytes anonymous(/*limit=*/0, /*tenant_limit=*/10);
  EXPECT_THAT(anonymous.Reserve("", 11).message(), ::testing::HasSubstr("the anonymous tenant"));
}

TEST(InFlightBytesTest, AnnouncedSizeReservesNothingUntilThePointsArrive) {
  InFlightBytes in_flight(100 * sizeof(Point2));
  auto first = std::make_unique<BuildStreamDecoder>(BuildStreamLimits{}, &in_flight);
  ASSERT_THAT(first->Add(Header(60)), IsOk());
  EXPECT_EQ(in_flight.held(), 0u) << "a header alone holds nothing";

  // A second announcement that fits the limit on its own is accepted whatever the first holds.
  BuildStreamDecoder second(BuildStreamLimits{}, &in_flight);
  ASSERT_THAT(second.Add(Header(60)), IsOk());
  EXPECT_EQ(in_flight.held(), 0u);

  const std::vector<Point2> points = gen::Uniform(60, 15);
  ASSERT_THAT(first->Add(Chunk(absl::MakeConstSpan(points).subspan(0, 20))), IsOk());
  EXPECT_EQ(in_flight.held(), 20 * sizeof(Point2)) << "the bytes that arrived";
  ASSERT_THAT(first->Add(Chunk(absl::MakeConstSpan(points).subspan(20))), IsOk());
  EXPECT_EQ(in_flight.held(), 60 * sizeof(Point2));
  const absl::StatusOr<DecodedBuild*> decoded = first->Finish();
  ASSERT_THAT(decoded, IsOk());
  EXPECT_EQ((*decoded)->handle, PointSetHandle(points));
  EXPECT_EQ(in_flight.held(), 60 * sizeof(Point2)) << "Finish keeps the reservation";

  // The second stream's points do not fit next to the first's: refused at the chunk.
  const absl::Status refused = second.Add(Chunk(gen::Uniform(60, 16)));
  EXPECT_THAT(refused, StatusIs(absl::StatusCode::kResourceExhausted));
  EXPECT_EQ(in_flight.held(), 60 * sizeof(Point2));

  first->ReleasePoints();
  EXPECT_EQ(in_flight.held(), 0u);
  EXPECT_TRUE((*decoded)->points.empty());
  first.reset();
  EXPECT_EQ(in_flight.held(), 0u) << "the destructor does not release twice";
}

TEST(InFlightBytesTest, AnnouncementNoLimitCouldHoldIsRefusedAtTheHeader) {
  InFlightBytes in_flight(/*limit=*/100 * sizeof(Point2), /*tenant_limit=*/50 * sizeof(Point2));
  BuildStreamDecoder server_wide(BuildStreamLimits{}, &in_flight, "a");
  const absl::Status over_server = server_wide.Add(Header(101));
  EXPECT_THAT(over_server,
              StatusIs(absl::StatusCode::kResourceExhausted, ::testing::HasSubstr("--max_in_flight_bytes")));
  EXPECT_EQ(RefusalLabelOf(over_server), "in_flight_bytes");
  BuildStreamDecoder tenant(BuildStreamLimits{}, &in_flight, "a");
  const absl::Status over_tenant = tenant.Add(Header(51));
  EXPECT_THAT(over_tenant,
              StatusIs(absl::StatusCode::kResourceExhausted, ::testing::HasSubstr("--max_tenant_in_flight_bytes")));
  EXPECT_EQ(RefusalLabelOf(over_tenant), "tenant_in_flight_bytes");
  BuildStreamDecoder fits(BuildStreamLimits{}, &in_flight, "a");
  EXPECT_THAT(fits.Add(Header(50)), IsOk());
  BuildStreamDecoder huge(BuildStreamLimits{std::numeric_limits<uint64_t>::max()}, &in_flight, "a");
  EXPECT_THAT(huge.Add(Header(std::numeric_limits<uint64_t>::max() / 2)),
              StatusIs(absl::StatusCode::kResourceExhausted))
      << "the announced bytes do not wrap around";
  EXPECT_EQ(in_flight.held(), 0u);
}

TEST(InFlightBytesTest, DestructorFreesTheBytes) {
  InFlightBytes in_flight(100 * sizeof(Point2));
  {
    BuildStreamDecoder first(BuildStreamLimits{}, &in_flight);
    ASSERT_THAT(first.Add(Header(70)), IsOk());
    ASSERT_THAT(first.Add(Chunk(gen::Uniform(70, 16))), IsOk());
    ASSERT_THAT(first.Finish(), IsOk());
    BuildStreamDecoder second(BuildStreamLimits{}, &in_flight);
    ASSERT_THAT(second.Add(Header(70)), IsOk());
    EXPECT_THAT(second.Add(Chunk(gen::Uniform(70, 17))), StatusIs(absl::StatusCode::kResourceExhausted));
    EXPECT_EQ(in_flight.held(), 70 * sizeof(Point2));
  }
  EXPECT_EQ(in_flight.held(), 0u);
  BuildStreamDecoder third(BuildStreamLimits{}, &in_flight);
  ASSERT_THAT(third.Add(Header(70)), IsOk());
  EXPECT_THAT(third.Add(Chunk(gen::Uniform(70, 18))), IsOk());
}

TEST(InFlightBytesTest, UnannouncedChunksReserveAsTheyArrive) {
  InFlightBytes in_flight(100 * sizeof(Point2));
  BuildStreamDecoder first(BuildStreamLimits{}, &in_flight);
  ASSERT_THAT(first.Add(Header(0)), IsOk());
  EXPECT_EQ(in_flight.held(), 0u);
  ASSERT_THAT(first.Add(Chunk(gen::Uniform(30, 17))), IsOk());
  EXPECT_EQ(in_flight.held(), 30 * sizeof(Point2));
  ASSERT_THAT(first.Add(Chunk(gen::Uniform(30, 18))), IsOk());
  EXPECT_EQ(in_flight.held(), 60 * sizeof(Point2));

  BuildStreamDecoder second(BuildStreamLimits{}, &in_flight);
  ASSERT_THAT(second.Add(Header(0)), IsOk());
  ASSERT_THAT(second.Add(Chunk(gen::Uniform(40, 19))), IsOk()) << "exactly the limit";
  const absl::Status refused = second.Add(Chunk(gen::Uniform(1, 20)));
  EXPECT_THAT(refused, StatusIs(absl::StatusCode::kResourceExhausted));
  EXPECT_EQ(in_flight.held(), 100 * sizeof(Point2));

  first.ReleasePoints();
  EXPECT_EQ(in_flight.held(), 40 * sizeof(Point2));
  EXPECT_THAT(second.Add(Chunk(gen::Uniform(1, 20))), IsOk()) << "the released bytes are available again";
  EXPECT_EQ(second.points_received(), 41u);
  second.ReleasePoints();
  EXPECT_EQ(in_flight.held(), 0u);
}

// ---- Encoded chunks (EncodedPointChunk) -------------------------------------------------------------

// `points` as float64 bit patterns, delta-transformed and zstd-compressed.
v1::BuildRequest EncodedChunk(absl::Span<const Point2> points) {
  wire::PointChunkEncoder encoder;
  wire::ChunkEncoding encoding;
  encoding.transform = v1::POINT_TRANSFORM_DELTA_SHUFFLE;
  encoding.compression = v1::POINT_COMPRESSION_ZSTD;
  v1::BuildRequest message;
  EXPECT_THAT(encoder.Encode(points, encoding, message.mutable_encoded_points()), IsOk());
  return message;
}

// A chunk that states `points` points but whose data is no zstd frame: refused only when decoded.
v1::BuildRequest UndecodableChunk(uint64_t points) {
  v1::BuildRequest message;
  message.mutable_encoded_points()->set_point_count(points);
  message.mutable_encoded_points()->set_value_type(v1::POINT_VALUE_TYPE_FLOAT64);
  message.mutable_encoded_points()->set_compression(v1::POINT_COMPRESSION_ZSTD);
  message.mutable_encoded_points()->set_data("not zstd");
  return message;
}

TEST(BuildStreamDecoderTest, EncodedAndRawChunksMixToTheSamePointsAndHandle) {
  const std::vector<Point2> points = gen::Uniform(300, 40);
  const auto all = absl::MakeConstSpan(points);
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(decoder.Add(Header(300)), IsOk());
  ASSERT_THAT(decoder.Add(EncodedChunk(all.subspan(0, 100))), IsOk());
  ASSERT_THAT(decoder.Add(Chunk(all.subspan(100, 100))), IsOk());
  ASSERT_THAT(decoder.Add(EncodedChunk(all.subspan(200))), IsOk());
  absl::StatusOr<DecodedBuild*> decoded = decoder.Finish();
  ASSERT_THAT(decoded, IsOk());
  ASSERT_TRUE(DecodedBitForBit(**decoded, points));
  EXPECT_EQ((*decoded)->handle, PointSetHandle(points));
}

TEST(BuildStreamDecoderTest, EncodedChunkCountsItsDecodedPointsAgainstTheLimitBeforeDecoding) {
  BuildStreamLimits limits;
  limits.max_points = 100;
  BuildStreamDecoder decoder(limits, nullptr);
  ASSERT_THAT(decoder.Add(Header(0)), IsOk());
  ASSERT_THAT(decoder.Add(EncodedChunk(gen::Uniform(60, 41))), IsOk());
  // 41 more would pass 100: refused for the limit, not for its undecodable data (never decoded).
  const absl::Status status = decoder.Add(UndecodableChunk(41));
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kResourceExhausted));
  EXPECT_EQ(RefusalLabelOf(status), "points_per_build") << status;
  EXPECT_EQ(decoder.points_received(), 60u);
}

TEST(BuildStreamDecoderTest, EncodedChunkBeyondTheAnnouncedCountIsRefused) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(decoder.Add(Header(50)), IsOk());
  const absl::Status status = decoder.Add(EncodedChunk(gen::Uniform(51, 42)));
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("the 50 its header")));
}

TEST(InFlightBytesTest, EncodedChunksReserveTheirDecodedBytes) {
  // 1,000 points on a grid compress to a few hundred bytes but decode to 16,000: the reservation
  // is for the decoded bytes.
  std::vector<Point2> grid;
  grid.reserve(1000);
  for (int row = 0; row < 25; ++row) {
    for (int column = 0; column < 40; ++column) grid.push_back({static_cast<double>(column), static_cast<double>(row)});
  }
  const v1::BuildRequest chunk = EncodedChunk(grid);
  ASSERT_LT(chunk.ByteSizeLong(), 2000u);
  {
    InFlightBytes in_flight(20000);
    BuildStreamDecoder decoder(BuildStreamLimits{}, &in_flight);
    ASSERT_THAT(decoder.Add(Header(0)), IsOk());
    ASSERT_THAT(decoder.Add(chunk), IsOk());
    EXPECT_EQ(in_flight.held(), 1000 * sizeof(Point2));
    const absl::Status status = decoder.Add(chunk);
    EXPECT_THAT(status, StatusIs(absl::StatusCode::kResourceExhausted));
    EXPECT_EQ(RefusalLabelOf(status), "in_flight_bytes") << status;
    EXPECT_EQ(in_flight.held(), 1000 * sizeof(Point2));
  }
  // A chunk refused while decoding holds nothing afterwards.
  InFlightBytes in_flight(0);
  BuildStreamDecoder decoder(BuildStreamLimits{}, &in_flight);
  ASSERT_THAT(decoder.Add(Header(0)), IsOk());
  ASSERT_THAT(decoder.Add(chunk), IsOk());
  EXPECT_THAT(decoder.Add(UndecodableChunk(10)), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_EQ(in_flight.held(), 1000 * sizeof(Point2));
  EXPECT_EQ(decoder.points_received(), 1000u);
}

TEST(BuildStreamDecoderTest, MalformedEncodedChunkIsNamedByItsIndexAndFirstPoint) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(decoder.Add(Header(0)), IsOk());
  ASSERT_THAT(decoder.Add(Chunk(gen::Uniform(7, 43))), IsOk());
  ASSERT_THAT(decoder.Add(EncodedChunk(gen::Uniform(5, 44))), IsOk());
  const absl::Status status = decoder.Add(UndecodableChunk(3));
  EXPECT_THAT(status,
              StatusIs(absl::StatusCode::kInvalidArgument,
                       ::testing::HasSubstr("encoded point chunk 2 (from point 12): its data is not a zstd frame")));
  EXPECT_EQ(decoder.points_received(), 12u) << "a refused chunk adds nothing";
}

TEST(BuildStreamDecoderTest, EncodedChunkBeforeTheHeaderIsRefused) {
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
  EXPECT_THAT(decoder.Add(EncodedChunk(gen::Uniform(3, 45))),
              StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("must start with a header")));
}

// ---- Weighted streams (BuildHeader.weighted) ------------------------------------------------

v1::BuildRequest WeightedHeader(uint64_t expected_points) {
  v1::BuildRequest message = Header(expected_points);
  message.mutable_header()->set_weighted(true);
  return message;
}

// Raw (x, y, w) triples.
v1::BuildRequest WeightedChunk(absl::Span<const Point2> points, absl::Span<const double> weights) {
  v1::BuildRequest message;
  auto* coordinates = message.mutable_points()->mutable_coordinates();
  for (size_t i = 0; i < points.size(); ++i) {
    coordinates->Add(points[i].x);
    coordinates->Add(points[i].y);
    coordinates->Add(weights[i]);
  }
  return message;
}

// Weights with negative values, zeros and a subnormal: every bit pattern must survive.
std::vector<double> AwkwardWeights(size_t n) {
  std::vector<double> weights(n);
  for (size_t i = 0; i < n; ++i) weights[i] = i % 5 == 0 ? -0.25 * static_cast<double>(i) : 1.0 / (1.0 + i);
  weights[1] = 0.0;
  weights[2] = std::numeric_limits<double>::denorm_min();
  return weights;
}

TEST(BuildStreamDecoderTest, WeightedTriplesRawAndEncodedDecodeToThePointsTheirWeightsAndTheirHandle) {
  const std::vector<Point2> points = gen::Uniform(300, 46);
  const std::vector<double> weights = AwkwardWeights(points.size());
  const auto all = absl::MakeConstSpan(points);
  const auto all_weights = absl::MakeConstSpan(weights);
  wire::PointChunkEncoder encoder;
  v1::BuildRequest encoded;
  ASSERT_THAT(encoder.EncodeSmallest(all.subspan(100, 200), all_weights.subspan(100, 200), &encoded), IsOk());
  ASSERT_TRUE(encoded.has_encoded_points()) << "200 points compress";
  InFlightBytes in_flight(0);
  BuildStreamDecoder decoder(BuildStreamLimits{}, &in_flight);
  ASSERT_THAT(decoder.Add(WeightedHeader(300)), IsOk());
  ASSERT_THAT(decoder.Add(WeightedChunk(all.subspan(0, 100), all_weights.subspan(0, 100))), IsOk());
  ASSERT_THAT(decoder.Add(encoded), IsOk());
  EXPECT_EQ(in_flight.held(), 300 * (sizeof(Point2) + sizeof(double))) << "24 bytes a weighted point";
  absl::StatusOr<DecodedBuild*> decoded = decoder.Finish();
  ASSERT_THAT(decoded, IsOk());
  ASSERT_TRUE(DecodedBitForBit(**decoded, points, weights));
  EXPECT_EQ((*decoded)->handle, WeightedPointSetHandle(points, weights));
  EXPECT_NE((*decoded)->handle, PointSetHandle(points)) << "the handle covers the weights";
  // A weighted stream of no points is the empty set, unweighted: one handle for every empty set.
  BuildStreamDecoder empty(BuildStreamLimits{}, nullptr);
  ASSERT_THAT(empty.Add(WeightedHeader(0)), IsOk());
  absl::StatusOr<DecodedBuild*> none = empty.Finish();
  ASSERT_THAT(none, IsOk());
  EXPECT_EQ((*none)->handle, PointSetHandle(std::vector<Point2>{}));
}

// Chunks decoded on a pool land where they belong: many small encoded chunks, some raw ones between
// them, with no announced count (so the vectors move several times while chunks are decoding)
// and with one (allocated at the first chunk), points bit for bit and the handle as for the
// points themselves; weighted streams too.
TEST(BuildStreamDecoderTest, ChunksDecodedOnAPoolGiveThePointsBitForBit) {
  ChunkCodecPool pool(4);
  const std::vector<Point2> points = gen::Uniform(20000, 47);
  const std::vector<double> weights = AwkwardWeights(points.size());
  const auto all = absl::MakeConstSpan(points);
  const auto all_weights = absl::MakeConstSpan(weights);
  for (const bool weighted : {false, true}) {
    for (const uint64_t announced : {uint64_t{0}, uint64_t{points.size()}}) {
      SCOPED_TRACE(absl::StrCat(weighted ? "weighted" : "unweighted", ", announced ", announced));
      InFlightBytes in_flight(0);
      BuildStreamDecoder decoder(BuildStreamLimits{}, &in_flight, "", &pool);
      ASSERT_THAT(decoder.Add(weighted ? WeightedHeader(announced) : Header(announced)), IsOk());
      wire::PointChunkEncoder encoder;
      size_t encoded_chunks = 0;
      for (size_t first = 0, size = 37; first < points.size(); first += size, size = size * 3 / 2 + 1) {
        const size_t count = std::min(size, points.size() - first);
        const auto part = all.subspan(first, count);
        const auto part_weights = weighted ? all_weights.subspan(first, count) : absl::Span<const double>();
        v1::BuildRequest message;
        if ((first / size) % 3 == 2) {  // every third chunk raw
          message = weighted ? WeightedChunk(part, part_weights) : Chunk(part);
        } else {
          ASSERT_THAT(encoder.EncodeSmallest(part, part_weights, &message), IsOk());
          encoded_chunks += message.has_encoded_points() ? 1 : 0;
        }
        ASSERT_THAT(decoder.Add(std::move(message)), IsOk()) << "chunk from point " << first;
      }
      ASSERT_GE(encoded_chunks, 5u);
      absl::StatusOr<DecodedBuild*> decoded = decoder.Finish();
      ASSERT_THAT(decoded, IsOk());
      ASSERT_TRUE(DecodedBitForBit(**decoded, points, weighted ? weights : std::vector<double>{}));
      EXPECT_EQ((*decoded)->handle, weighted ? WeightedPointSetHandle(points, weights) : PointSetHandle(points));
      EXPECT_EQ(in_flight.held(), points.size() * (weighted ? 24u : 16u));
    }
  }
}

// A chunk that only its decoding refuses, on a pool: the stream is refused by a later message or by
// Finish, always with the error of the earliest such chunk (the one the decoder without a pool
// names), whatever order the pool's threads finish in.
// Holds a pool's threads until opened, so that every chunk of a stream is queued before any is
// decoded. Opens when it goes out of scope (an ASSERT may leave early), and only then returns
// once every held thread has let go of it.
class PoolGate {
 public:
  PoolGate(ChunkCodecPool* pool, size_t threads) : held_(threads) {
    for (size_t i = 0; i < threads; ++i) {
      pool->Submit([this](ChunkCodecs&) {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return open_; });
        --held_;
        changed_.notify_all();
      });
    }
  }
  ~PoolGate() {
    Open();
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return held_ == 0; });
  }
  void Open() {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = true;
    changed_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  bool open_ = false;
  size_t held_;
};

TEST(BuildStreamDecoderTest, ChunksThatFailOnAPoolRefuseTheStreamWithTheEarliestError) {
  constexpr size_t kThreads = 4;
  ChunkCodecPool pool(kThreads);
  const std::vector<Point2> points = gen::Uniform(1000, 48);
  const auto all = absl::MakeConstSpan(points);
  const std::string expected = "encoded point chunk 3 (from point 300): its data is not a zstd frame";
  const auto chunk = [&](size_t i) {
    return i == 3 || i == 5 ? UndecodableChunk(100) : EncodedChunk(all.subspan(100 * i, 100));
  };
  for (int round = 0; round < 20; ++round) {
    // As it comes: chunk 3 usually fails before a later message, which is then refused.
    BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr, "", &pool);
    ASSERT_THAT(decoder.Add(Header(0)), IsOk());
    absl::Status refused;
    for (size_t i = 0; i < 10 && refused.ok(); ++i) refused = decoder.Add(chunk(i));
    if (refused.ok()) refused = decoder.Finish().status();
    ASSERT_THAT(refused, StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr(expected)))
        << "round " << round;
  }
  for (int round = 0; round < 20; ++round) {
    // Every chunk queued before any decodes (the pool's threads held at a gate): both bad chunks
    // fail, in either order, and Finish answers with the first one's error. A raw chunk of 1,000
    // points first, so that the vectors move before the first encoded chunk and never while the
    // gate holds the decodes (a move waits for them).
    // The decoder first: it is destroyed last, once the gate has let the decodes it waits for run.
    BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr, "", &pool);
    PoolGate gate(&pool, kThreads);
    ASSERT_THAT(decoder.Add(Header(0)), IsOk());
    ASSERT_THAT(decoder.Add(Chunk(all)), IsOk());
    for (size_t i = 0; i < 8; ++i) ASSERT_THAT(decoder.Add(chunk(i)), IsOk()) << "nothing decoded yet";
    gate.Open();
    EXPECT_THAT(decoder.Finish().status(),
                StatusIs(absl::StatusCode::kInvalidArgument,
                         ::testing::HasSubstr("encoded point chunk 4 (from point 1300): its data is not a zstd frame")))
        << "round " << round;
  }
}

// A refusal found at once (a malformed chunk's shape) while an earlier chunk is still decoding and
// about to fail: the answer is the earlier chunk's error, as without a pool.
TEST(BuildStreamDecoderTest, AnEarlierChunkStillDecodingIsTheAnswerToALaterRefusal) {
  constexpr size_t kThreads = 2;
  ChunkCodecPool pool(kThreads);
  const std::vector<Point2> points = gen::Uniform(1000, 49);
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr, "", &pool);
  PoolGate gate(&pool, kThreads);
  ASSERT_THAT(decoder.Add(Header(0)), IsOk());
  ASSERT_THAT(decoder.Add(Chunk(points)), IsOk());
  ASSERT_THAT(decoder.Add(UndecodableChunk(100)), IsOk()) << "queued behind the gate";
  std::thread opener([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    gate.Open();
  });
  v1::BuildRequest shapeless;
  shapeless.mutable_encoded_points()->set_point_count(0);  // refused before any decoding
  EXPECT_THAT(decoder.Add(std::move(shapeless)),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       ::testing::HasSubstr("encoded point chunk 1 (from point 1000): its data is not a zstd frame")));
  opener.join();
}

// Back-pressure: a stream has at most two chunks per pool thread waiting or decoding; the next Add
// waits for one to finish.
TEST(BuildStreamDecoderTest, AStreamQueuesAtMostTwoChunksPerPoolThread) {
  constexpr size_t kThreads = 2;
  ChunkCodecPool pool(kThreads);
  const std::vector<Point2> points = gen::Uniform(1200, 50);
  const auto all = absl::MakeConstSpan(points);
  BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr, "", &pool);
  ASSERT_THAT(decoder.Add(Header(1200)), IsOk());  // announced: the vectors never move (no waits)
  std::atomic<size_t> accepted{0};
  {
    PoolGate gate(&pool, kThreads);
    std::thread sender([&] {
      for (size_t i = 0; i < 12; ++i) {
        if (decoder.Add(EncodedChunk(all.subspan(100 * i, 100))).ok()) ++accepted;
      }
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    EXPECT_EQ(accepted.load(), 2 * kThreads) << "chunks accepted while none could decode";
    gate.Open();
    sender.join();
  }
  EXPECT_EQ(accepted.load(), 12u);
  absl::StatusOr<DecodedBuild*> decoded = decoder.Finish();
  ASSERT_THAT(decoded, IsOk());
  EXPECT_EQ((*decoded)->handle, PointSetHandle(points));
}

TEST(BuildStreamDecoderTest, WeightedStreamRefusalsNameThePointAndTheWeight) {
  {
    BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
    ASSERT_THAT(decoder.Add(WeightedHeader(0)), IsOk());
    EXPECT_THAT(
        decoder.Add(Chunk(std::vector<double>{0, 0, 1, 1})),
        StatusIs(absl::StatusCode::kInvalidArgument,
                 ::testing::HasSubstr("4 doubles, not a multiple of 3, after point 0: the header is weighted")));
  }
  {
    BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
    ASSERT_THAT(decoder.Add(WeightedHeader(0)), IsOk());
    ASSERT_THAT(decoder.Add(Chunk(std::vector<double>{0, 0, 1, 1, 0, 2})), IsOk());
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THAT(decoder.Add(Chunk(std::vector<double>{3, 3, 0.5, 4, 4, nan})),
                StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("point 3 has a NaN weight")));
    const std::vector<Point2> two = {{5, 5}, {6, 6}};
    const std::vector<double> infinite = {1.0, -std::numeric_limits<double>::infinity()};
    wire::PointChunkEncoder encoder;
    wire::ChunkEncoding float64;
    v1::BuildRequest encoded;
    ASSERT_THAT(encoder.Encode(two, infinite, float64, encoded.mutable_encoded_points()), IsOk());
    EXPECT_THAT(decoder.Add(encoded), StatusIs(absl::StatusCode::kInvalidArgument,
                                               ::testing::HasSubstr("(from point 2): point 3 has an infinite weight")));
    EXPECT_EQ(decoder.points_received(), 2u) << "refused chunks add nothing";
  }
  {
    // An unweighted stream takes no weight scale, and a weighted integer chunk needs one.
    const std::vector<Point2> two = {{1, 2}, {3, 4}};
    const std::vector<double> weights = {0.5, 0.25};
    wire::PointChunkEncoder encoder;
    wire::ChunkEncoding integers;
    integers.value_type = v1::POINT_VALUE_TYPE_INT32;
    integers.x_scale.set_scale(1.0);
    integers.y_scale.set_scale(1.0);
    integers.w_scale.set_scale(0.25);
    v1::BuildRequest weighted_chunk;
    ASSERT_THAT(encoder.Encode(two, weights, integers, weighted_chunk.mutable_encoded_points()), IsOk());
    BuildStreamDecoder unweighted(BuildStreamLimits{}, nullptr);
    ASSERT_THAT(unweighted.Add(Header(0)), IsOk());
    EXPECT_THAT(unweighted.Add(weighted_chunk),
                StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("the stream is not weighted")));
    v1::BuildRequest no_scale = weighted_chunk;
    no_scale.mutable_encoded_points()->clear_w_scale();
    BuildStreamDecoder weighted(BuildStreamLimits{}, nullptr);
    ASSERT_THAT(weighted.Add(WeightedHeader(0)), IsOk());
    EXPECT_THAT(weighted.Add(no_scale), StatusIs(absl::StatusCode::kInvalidArgument,
                                                 ::testing::HasSubstr("needs w_scale (the stream is weighted)")));
    ASSERT_THAT(weighted.Add(weighted_chunk), IsOk());
    absl::StatusOr<DecodedBuild*> decoded = weighted.Finish();
    ASSERT_THAT(decoded, IsOk());
    EXPECT_EQ((*decoded)->weights[1], 0.25);
  }
#ifdef GALPHA_WITH_PROJ
  {
    BuildStreamDecoder decoder(BuildStreamLimits{}, nullptr);
    v1::BuildRequest header = WeightedHeader(0);
    header.mutable_header()->set_crs("EPSG:4326");
    EXPECT_THAT(decoder.Add(header),
                StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("weights need planar coordinates")));
  }
#endif
}

}  // namespace
}  // namespace galpha::server
