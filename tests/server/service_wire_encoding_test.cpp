// The point encodings against the real server (proto EncodedPointChunk, client PointEncoding):
// every encoding of the same data set is the same family under the same handle (a second upload in
// another encoding is a cache hit), each encoding built from scratch answers Classify exactly as
// raw doubles do, and the automatic choice sends the fewest bytes.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/point_io.hpp"
#include "core/io/point_set_handle.hpp"
#include "tests/server/service_test_support.hpp"
#include "tests/support/data_files.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using client::PointEncoding;
using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using testing::ClientOf;
using testing::StartServer;
using testing::TestServerOptions;

const char* EncodingName(PointEncoding encoding) {
  switch (encoding) {
    case PointEncoding::kAuto:
      return "auto";
    case PointEncoding::kRaw:
      return "raw";
    case PointEncoding::kFloat64Compressed:
      return "float64+zstd";
    case PointEncoding::kScaledIntegers:
      return "scaled integers";
    case PointEncoding::kScaledIntegersCompressed:
      return "scaled integers+zstd";
  }
  return "?";
}

// Every Classify message of `request`, as the client hands them over, serialized: equal strings are
// equal answers. `wire_bytes`: what crossed the wire.
std::vector<std::string> ClassifyBytes(client::AlphaClient& client, const v1::ClassifyRequest& request,
                                       uint64_t* wire_bytes = nullptr) {
  std::vector<std::string> messages;
  const absl::Status status = client.Classify(
      request,
      [&](const v1::ClassifyResponse& message) {
        EXPECT_FALSE(message.has_encoded_chunk()) << "the client decodes encoded chunks";
        messages.push_back(message.SerializeAsString());
        return absl::OkStatus();
      },
      wire_bytes);
  EXPECT_THAT(status, IsOk());
  return messages;
}

// Every Classify message at `rank`, raw.
std::vector<std::string> ClassifyBytes(client::AlphaClient& client, const std::string& handle, int64_t rank) {
  v1::ClassifyRequest request;
  request.set_handle(handle);
  request.mutable_threshold()->set_rank(rank);
  return ClassifyBytes(client, request);
}

TEST(ServiceWireEncodingTest, EveryEncodingIsTheSameFamilyUnderTheSameHandle) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  struct DataSet {
    std::string name;
    absl::StatusOr<std::vector<Point2>> points;
    bool scaled;  // whether the points are exact scaled integers
  };
  const auto data_file = [](const std::string& name) {
    return ReadPointsBin(testdata::DataDir() + "/" + name + ".bin");
  };
  // LAS steps (0.01 ft); 9-digit decimals (X / 10^9); degrees in one binade (power-of-two steps);
  // full-precision random doubles (no step reproduces them).
  for (const DataSet& data :
       std::vector<DataSet>{{"lidar_autzen_ground", data_file("lidar_autzen_ground"), true},
                            {"gps_tracks_slovenia_croatia", data_file("gps_tracks_slovenia_croatia"), true},
                            {"lidar_autzen_ground_lonlat", data_file("lidar_autzen_ground_lonlat"), true},
                            {"uniform", gen::Uniform(20000, 3), false}}) {
    SCOPED_TRACE(data.name);
    const absl::StatusOr<std::vector<Point2>>& points = data.points;
    ASSERT_THAT(points.status(), IsOk());
    client::BuildCallOptions options;
    options.skip_upload_if_cached = false;  // upload every time: the server decodes each encoding
    options.encoding = PointEncoding::kRaw;
    absl::StatusOr<client::BuildResult> raw = client->Build(*points, options);
    ASSERT_THAT(raw.status(), IsOk());
    EXPECT_FALSE(raw->cached);
    EXPECT_EQ(raw->handle, PointSetHandle(*points));
    const int64_t rank = static_cast<int64_t>(raw->summary.spectrum_size() / 2);
    const std::vector<std::string> reference = ClassifyBytes(*client, raw->handle, rank);
    ASSERT_GT(reference.size(), 1u);

    uint64_t smallest = raw->upload_bytes;
    uint64_t automatic = 0;
    for (PointEncoding encoding : {PointEncoding::kAuto, PointEncoding::kFloat64Compressed,
                                   PointEncoding::kScaledIntegers, PointEncoding::kScaledIntegersCompressed}) {
      SCOPED_TRACE(EncodingName(encoding));
      options.encoding = encoding;
      const bool refused = !data.scaled && (encoding == PointEncoding::kScaledIntegers ||
                                            encoding == PointEncoding::kScaledIntegersCompressed);
      // A second upload of the same points in another encoding: the same handle, a cache hit.
      absl::StatusOr<client::BuildResult> again = client->Build(*points, options);
      if (refused) {
        EXPECT_THAT(again.status(), StatusIs(absl::StatusCode::kInvalidArgument));
        continue;
      }
      ASSERT_THAT(again.status(), IsOk());
      EXPECT_EQ(again->handle, raw->handle);
      EXPECT_TRUE(again->cached);
      EXPECT_TRUE(again->uploaded);
      // Uncompressed INT64 is as large as raw doubles; everything else is smaller.
      if (encoding != PointEncoding::kScaledIntegers) {
        EXPECT_LT(again->upload_bytes, raw->upload_bytes);
      }
      if (encoding == PointEncoding::kAuto) automatic = again->upload_bytes;
      smallest = std::min(smallest, again->upload_bytes);
      std::printf("%-30s %-22s %8.2f bytes/point\n", data.name.c_str(), EncodingName(encoding),
                  static_cast<double>(again->upload_bytes) / static_cast<double>(points->size()));

      // Built from this encoding alone: the same answers, byte for byte.
      ASSERT_THAT(client->Release(raw->handle).status(), IsOk());
      absl::StatusOr<client::BuildResult> fresh = client->Build(*points, options);
      ASSERT_THAT(fresh.status(), IsOk());
      EXPECT_FALSE(fresh->cached);
      EXPECT_EQ(fresh->handle, raw->handle);
      EXPECT_EQ(fresh->summary.spectrum_size(), raw->summary.spectrum_size());
      EXPECT_EQ(ClassifyBytes(*client, fresh->handle, rank), reference);
    }
    // Exact up to 16,384 points a chunk; on a sample of larger chunks it may miss by a little.
    EXPECT_LE(static_cast<double>(automatic), 1.01 * static_cast<double>(smallest))
        << "the automatic choice sends the fewest bytes";
  }
}

// The compact Classify answers (ClassifyRequest.simplex_encoding): in every request shape, DELTA
// and DELTA_ZSTD answers reach the client's callback as exactly the raw answer's messages, in fewer
// bytes on the wire; an encoding the enum does not define is refused.
TEST(ServiceWireEncodingTest, EveryAnswerEncodingIsTheRawAnswerInFewerBytes) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  const auto autzen = ReadPointsBin(testdata::DataDir() + "/lidar_autzen_ground.bin");
  ASSERT_THAT(autzen.status(), IsOk());
  // The file in its scan order; shuffled uniform points with more than one chunk of edges and of
  // triangles (131,072 simplices a chunk).
  for (const std::vector<Point2>& points : {*autzen, gen::Uniform(60000, 5)}) {
    absl::StatusOr<client::BuildResult> built = client->Build(points);
    ASSERT_THAT(built.status(), IsOk());
    const int64_t k = static_cast<int64_t>(built->summary.spectrum_size());
    for (int64_t rank : {int64_t{0}, k / 2, k}) {
      for (v1::ClassifyMode mode : {v1::CLASSIFY_MODE_GENERAL, v1::CLASSIFY_MODE_REGULARIZED}) {
        for (bool non_exterior_only : {false, true}) {
          SCOPED_TRACE(::testing::Message() << points.size() << " points, rank " << rank << " of " << k << ", mode "
                                            << mode << (non_exterior_only ? ", non-exterior only" : ""));
          v1::ClassifyRequest request;
          request.set_handle(built->handle);
          request.mutable_threshold()->set_rank(rank);
          request.set_mode(mode);
          request.set_non_exterior_only(non_exterior_only);
          request.set_simplex_encoding(v1::SIMPLEX_ENCODING_RAW);
          uint64_t raw_bytes = 0;
          const std::vector<std::string> raw = ClassifyBytes(*client, request, &raw_bytes);
          ASSERT_GE(raw.size(), 1u);
          for (v1::SimplexEncoding encoding : {v1::SIMPLEX_ENCODING_DELTA, v1::SIMPLEX_ENCODING_DELTA_ZSTD}) {
            request.set_simplex_encoding(encoding);
            uint64_t bytes = 0;
            EXPECT_EQ(ClassifyBytes(*client, request, &bytes), raw) << "encoding " << encoding;
            if (raw.size() > 1) {
              EXPECT_LT(bytes, raw_bytes) << "encoding " << encoding;
            }
            if (rank == k / 2 && mode == v1::CLASSIFY_MODE_GENERAL && !non_exterior_only) {
              std::printf("%zu points, Classify at rank K/2: raw %llu bytes, %s %llu (%.2fx)\n", points.size(),
                          static_cast<unsigned long long>(raw_bytes),
                          encoding == v1::SIMPLEX_ENCODING_DELTA ? "DELTA" : "DELTA_ZSTD",
                          static_cast<unsigned long long>(bytes),
                          static_cast<double>(bytes) / static_cast<double>(raw_bytes));
            }
          }
        }
      }
    }
    // A caller that stops after the summary and one chunk gets its own error back, and the
    // connection answers the next call in full.
    v1::ClassifyRequest stopping;
    stopping.set_handle(built->handle);
    stopping.mutable_threshold()->set_rank(k / 2);
    stopping.set_simplex_encoding(v1::SIMPLEX_ENCODING_DELTA_ZSTD);
    int seen = 0;
    EXPECT_THAT(client->Classify(stopping,
                                 [&](const v1::ClassifyResponse&) {
                                   return ++seen == 2 ? absl::AbortedError("enough") : absl::OkStatus();
                                 }),
                StatusIs(absl::StatusCode::kAborted, "enough"));
    EXPECT_EQ(seen, 2);
    stopping.set_mode(v1::CLASSIFY_MODE_GENERAL);
    EXPECT_FALSE(ClassifyBytes(*client, stopping).empty());

    v1::ClassifyRequest undefined;
    undefined.set_handle(built->handle);
    undefined.mutable_threshold()->set_rank(1);
    undefined.set_simplex_encoding(static_cast<v1::SimplexEncoding>(7));
    EXPECT_THAT(client->Classify(undefined, [](const v1::ClassifyResponse&) { return absl::OkStatus(); }),
                StatusIs(absl::StatusCode::kInvalidArgument));
  }
}

// More chunks than the client encodes at once (8 threads): they arrive in order, the progress
// callback counts up to every point, and the server's handle is the local one.
TEST(ServiceWireEncodingTest, ManyChunksEncodedInParallelArriveInOrder) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  // 11 chunks of 65,536 points, the last one short; integers on a 1/8 grid (scaled integers).
  std::vector<Point2> points = gen::Uniform(10 * client::kPointsPerChunk + 1234, 11);
  for (Point2& p : points) p = {std::round(p.x * 8000) / 8, std::round(p.y * 8000) / 8};
  client::BuildCallOptions options;
  options.skip_upload_if_cached = false;
  std::vector<uint64_t> progress;
  options.progress = [&](uint64_t sent) { progress.push_back(sent); };
  absl::StatusOr<client::BuildResult> built = client->Build(points, options);
  ASSERT_THAT(built.status(), IsOk());
  EXPECT_EQ(built->handle, PointSetHandle(points));
  EXPECT_EQ(built->summary.points(), points.size());
  ASSERT_EQ(progress.size(), 11u);
  for (size_t i = 0; i + 1 < progress.size(); ++i) EXPECT_EQ(progress[i], (i + 1) * client::kPointsPerChunk);
  EXPECT_EQ(progress.back(), points.size());
  EXPECT_LT(built->upload_bytes, 6 * points.size()) << "scaled integers, not raw doubles";
}

TEST(ServiceWireEncodingTest, MalformedEncodedChunkIsInvalidArgumentNamingTheChunk) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  grpc::ClientContext context;
  client->PrepareContext(&context);
  v1::BuildResponse response;
  auto writer = client->stub().Build(&context, &response);
  v1::BuildRequest message;
  message.mutable_header()->set_expected_points(10);
  ASSERT_TRUE(writer->Write(message));
  v1::EncodedPointChunk* chunk = message.mutable_encoded_points();
  chunk->set_point_count(10);
  chunk->set_value_type(v1::POINT_VALUE_TYPE_INT32);
  chunk->mutable_x_scale()->set_scale(0.01);
  chunk->mutable_y_scale()->set_scale(0);
  chunk->set_data(std::string(80, '\0'));
  writer->Write(message);
  writer->WritesDone();
  const grpc::Status status = writer->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("encoded point chunk 0 (from point 0): y_scale's scale is 0"),
            std::string::npos)
      << status.error_message();
}

}  // namespace
}  // namespace galpha::server
