// The real server as operators see it: eviction under a small cache budget, the metrics page over
// HTTP, health, reflection and the drain.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>
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
using testing::ClientOf;
using ::testing::Not;
using testing::ScrapeMetric;
using testing::StartServer;
using testing::TestServerOptions;
using testing::WaitFor;

TEST(ServiceTest, EvictionUnderASmallCacheBudget) {
  const std::vector<Point2> a = gen::Uniform(3000, 21), b = gen::Uniform(3000, 22);
  size_t one_family = 0;
  {
    auto probe = StartServer(TestServerOptions());
    ASSERT_NE(probe, nullptr);
    auto built = ClientOf(*probe)->Build(a);
    ASSERT_THAT(built, IsOk());
    one_family = built->summary.family_bytes();
  }
  ServerOptions options = TestServerOptions();
  options.service.cache_bytes = one_family * 3 / 2;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  auto first = client->Build(a);
  ASSERT_THAT(first, IsOk());
  auto second = client->Build(b);
  ASSERT_THAT(second, IsOk());
  EXPECT_THAT(client->Describe(first->handle).status(), StatusIs(absl::StatusCode::kNotFound));
  EXPECT_THAT(client->Describe(second->handle), IsOk());
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_evictions_total"), 1.0);
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_entries"), 1.0);
  // A family larger than the whole budget is refused, not cached half-way.
  auto huge = client->Build(gen::Uniform(20000, 23));
  EXPECT_THAT(huge.status(), StatusIs(absl::StatusCode::kResourceExhausted));
}

TEST(ServiceTest, MetricsAreScrapedOverHttp) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  auto built = client->Build(gen::Clustered(5000, 31));
  ASSERT_THAT(built, IsOk());
  ASSERT_THAT(client->Describe(built->handle), IsOk());
  ASSERT_THAT(client->Describe(PointSetHandle(gen::Uniform(3, 1))), Not(IsOk()));
  const std::string page = testing::HttpGet(server->metrics_port(), "/metrics");
  using testing::MetricValue;
  EXPECT_EQ(MetricValue(page, "galpha_rpcs_total{code=\"OK\",method=\"Build\"}"), 1.0) << page;
  EXPECT_EQ(MetricValue(page, "galpha_rpcs_total{code=\"OK\",method=\"Describe\"}"), 1.0);
  // The client's check before uploading, and the unknown handle.
  EXPECT_EQ(MetricValue(page, "galpha_rpcs_total{code=\"NOT_FOUND\",method=\"Describe\"}"), 2.0);
  EXPECT_EQ(MetricValue(page, "galpha_build_stage_seconds_count{stage=\"insert_and_flip\"}"), 1.0);
  EXPECT_EQ(MetricValue(page, "galpha_build_seconds_count"), 1.0);
  const v1::ComparisonCounts& counts = built->summary.comparisons();
  EXPECT_EQ(MetricValue(page, "galpha_radius_comparisons_total{path=\"filter\"}"),
            static_cast<double>(counts.filter()));
  EXPECT_GT(counts.filter(), 0u);
  EXPECT_EQ(MetricValue(page, "galpha_radius_comparisons_total{path=\"device_exact\"}"),
            static_cast<double>(counts.device_exact()));
  EXPECT_EQ(MetricValue(page, "galpha_radius_comparisons_total{path=\"cpu_fallback\"}"),
            static_cast<double>(counts.cpu_fallback()));
  EXPECT_EQ(MetricValue(page, "galpha_cache_entries"), 1.0);
  EXPECT_EQ(MetricValue(page, "galpha_cache_bytes"), static_cast<double>(built->summary.family_bytes()));
  EXPECT_EQ(MetricValue(page, "galpha_cache_hits_total"), 1.0);
  EXPECT_EQ(MetricValue(page, "galpha_cache_misses_total"), 3.0);  // skip check, build, unknown handle
  // The slot is handed back just after the response is sent: the gauge settles to 0 right after.
  EXPECT_TRUE(testing::WaitFor([&] { return testing::ScrapeMetric(*server, "galpha_builds_in_flight") == 0.0; }, 5.0));
  EXPECT_EQ(MetricValue(page, "galpha_build_queue_length"), 0.0);
  EXPECT_EQ(MetricValue(page, "galpha_backend_info{backend=\"" + testing::TestBackend() + "\"}"), 1.0);
}

TEST(ServiceTest, HealthReflectionAndDrain) {
  ServerOptions options = TestServerOptions();
  options.drain_notice = std::chrono::milliseconds(1500);
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  const auto channel = client->channel();
  EXPECT_EQ(testing::HealthOf(channel, ""), "SERVING");
  EXPECT_EQ(testing::HealthOf(channel, "galpha.v1.AlphaShapes"), "SERVING");
  const std::vector<std::string> services = testing::ReflectedServices(channel);
  EXPECT_NE(std::find(services.begin(), services.end(), "galpha.v1.AlphaShapes"), services.end());
  EXPECT_NE(std::find(services.begin(), services.end(), "grpc.health.v1.Health"), services.end());
  auto built = client->Build(gen::Uniform(500, 41));
  ASSERT_THAT(built, IsOk());

  EXPECT_EQ(testing::HealthOf(channel, "galpha.liveness"), "SERVING");
  std::thread drain([&] { server->Drain(); });
  EXPECT_TRUE(WaitFor([&] { return testing::HealthOf(channel, "") == "NOT_SERVING"; }, 5));
  EXPECT_EQ(testing::HealthOf(channel, "galpha.v1.AlphaShapes"), "NOT_SERVING");
  EXPECT_EQ(testing::HealthOf(channel, "galpha.liveness"), "SERVING");
  // During the notice: new builds are refused, queries still answered.
  client::BuildCallOptions upload;
  upload.skip_upload_if_cached = false;
  auto refused = client->Build(gen::Uniform(100, 42), upload);
  EXPECT_THAT(refused.status(), StatusIs(absl::StatusCode::kUnavailable));
  EXPECT_THAT(client->Describe(built->handle), IsOk());
  drain.join();
  EXPECT_THAT(client->Describe(built->handle), Not(IsOk()));
}

}  // namespace
}  // namespace galpha::server
