// The real server's error statuses: malformed Build streams, message and in-flight limits, and
// queries with bad handles, thresholds or requests.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/io/point_set_handle.hpp"
#include "tests/server/service_test_calls.hpp"
#include "tests/server/service_test_support.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using testing::Chunk;
using testing::ClientOf;
using testing::Header;
using testing::RawBuild;
using testing::StartServer;
using testing::TestServerOptions;
using testing::WaitFor;

TEST(ServiceTest, BuildStreamErrorsHaveClearStatuses) {
  ServerOptions options = TestServerOptions();
  options.service.max_points_per_build = 1000;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();

  absl::Status s = RawBuild(*client, {Header(), Chunk({0, 0, 1, 1, 2})});
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(s.message().find("odd number of doubles"), std::string::npos) << s;

  s = RawBuild(*client, {Header(), Chunk({0, 0, 1, 1}), Chunk({2, 2, 3, nan})});
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(s.message().find("point 3 has a NaN y coordinate"), std::string::npos) << s;

  s = RawBuild(*client, {Header(), Chunk({inf, 0})});
  EXPECT_NE(s.message().find("point 0 has a infinite x"), std::string::npos) << s;

  s = RawBuild(*client, {Chunk({0, 0})});
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(s.message().find("must start with a header"), std::string::npos) << s;

  s = RawBuild(*client, {Header(), Header()});
  EXPECT_NE(s.message().find("second header"), std::string::npos) << s;

  s = RawBuild(*client, {});
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(s.message().find("empty"), std::string::npos) << s;

  s = RawBuild(*client, {Header(2000)});
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kResourceExhausted));
  std::vector<double> many(2 * 1001, 1.0);
  s = RawBuild(*client, {Header(), Chunk(many)});
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kResourceExhausted));
  EXPECT_NE(s.message().find("1000 points"), std::string::npos) << s;

  s = RawBuild(*client, {Header(3), Chunk({0, 0, 1, 1})});
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(s.message().find("announced 3"), std::string::npos) << s;

  // Nothing of the failed builds stays in flight or in the cache.
  EXPECT_TRUE(WaitFor([&] { return server->service().in_flight_bytes() == 0; }, 5));
  EXPECT_EQ(server->service().cache().GetStats().resident.entries, 0u);
}

TEST(ServiceTest, MessageAndInFlightLimits) {
  ServerOptions options = TestServerOptions();
  options.max_receive_message_bytes = 1 << 20;
  options.service.max_in_flight_bytes = 1 << 20;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  // A 1.6 MB chunk is over the message limit.
  std::vector<double> big(200000, 0.5);
  absl::Status s = RawBuild(*client, {Header(), Chunk(big)});
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kResourceExhausted));
  // 100000 announced points (1.6 MB) are over the bytes-in-flight limit.
  s = RawBuild(*client, {Header(100000)});
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kResourceExhausted));
  EXPECT_NE(s.message().find("in flight"), std::string::npos) << s;
  // A build within the limits still works.
  auto ok = client->Build(gen::Uniform(1000, 5));
  EXPECT_THAT(ok, IsOk());
}

TEST(ServiceTest, QueryErrorsHaveClearStatuses) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  const std::string unknown = PointSetHandle(gen::Uniform(10, 99));
  absl::Status s = client->Describe(unknown).status();
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kNotFound));
  s = client->Describe("not-a-handle").status();
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kInvalidArgument));

  auto built = client->Build(gen::Uniform(500, 6));
  ASSERT_THAT(built, IsOk());
  const int64_t k = static_cast<int64_t>(built->summary.spectrum_size());
  v1::ClassifyRequest classify;
  classify.set_handle(built->handle);
  s = client->Classify(classify, [](const v1::ClassifyResponse&) { return absl::OkStatus(); });
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(s.message().find("no threshold"), std::string::npos) << s;
  classify.mutable_threshold()->set_rank(k + 1);
  s = client->Classify(classify, [](const v1::ClassifyResponse&) { return absl::OkStatus(); });
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kInvalidArgument));
  classify.mutable_threshold()->set_alpha(std::numeric_limits<double>::quiet_NaN());
  s = client->Classify(classify, [](const v1::ClassifyResponse&) { return absl::OkStatus(); });
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kInvalidArgument));

  v1::MasterListRequest master;
  master.set_handle(built->handle);
  master.set_first_rank(0);
  s = client->MasterList(master, [](const v1::MasterListResponse&) { return absl::OkStatus(); });
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kInvalidArgument));

  v1::SpectrumRequest spectrum;
  spectrum.set_handle(built->handle);
  spectrum.set_page_size(1u << 20);
  EXPECT_THAT(client->Spectrum(spectrum).status(), StatusIs(absl::StatusCode::kInvalidArgument));

  v1::ComponentsRequest components;
  components.set_handle(built->handle);
  EXPECT_THAT(client->Components(components).status(), StatusIs(absl::StatusCode::kInvalidArgument));

  v1::ShapeRequest shape;
  shape.set_handle(built->handle);
  shape.mutable_threshold()->set_rank(1);
  s = client->Shape(shape, [](const v1::ShapeResponse&) { return absl::OkStatus(); });
  EXPECT_THAT(s, StatusIs(absl::StatusCode::kInvalidArgument));

  v1::OptimalAlphaRequest optimal;
  optimal.set_handle(unknown);
  optimal.set_max_components(1);
  EXPECT_THAT(client->OptimalAlpha(optimal).status(), StatusIs(absl::StatusCode::kNotFound));
}

}  // namespace
}  // namespace galpha::server
