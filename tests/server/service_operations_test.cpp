// The real server as operators see it: eviction under a small cache budget, the metrics page over
// HTTP, health, reflection and the drain.
#include <gmock/gmock.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "core/io/point_set_handle.hpp"
#include "gpu/system/device_streams.hpp"
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
using ::testing::HasSubstr;
using ::testing::Not;
using testing::ScrapeMetric;
using testing::StartServer;
using testing::TestBackend;
using testing::TestServerOptions;
using testing::WaitFor;

/// The largest `family_bytes` a server charges for the families of `sets` (0 when a build fails,
/// with a test failure).
size_t LargestFamilyBytes(const std::vector<std::vector<Point2>>& sets) {
  auto probe = StartServer(TestServerOptions());
  if (probe == nullptr) return 0;
  size_t largest = 0;
  for (const std::vector<Point2>& points : sets) {
    auto built = ClientOf(*probe)->Build(points);
    if (!built.ok()) {
      ADD_FAILURE() << built.status();
      return 0;
    }
    largest = std::max<size_t>(largest, built->summary.family_bytes());
  }
  return largest;
}

TEST(ServiceTest, EvictionUnderASmallCacheBudget) {
  const std::vector<Point2> a = gen::Uniform(3000, 21), b = gen::Uniform(3000, 22);
  const size_t one_family = LargestFamilyBytes({a});
  ASSERT_GT(one_family, 0u);
  ServerOptions options = TestServerOptions();
  options.service.cache_bytes = one_family * 3 / 2;
  options.service.compact_cache_bytes = 0;  // no compact tier: a family pushed out is gone
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  auto first = client->Build(a);
  ASSERT_THAT(first, IsOk());
  auto second = client->Build(b);
  ASSERT_THAT(second, IsOk());
  EXPECT_THAT(client->Describe(first->handle).status(), StatusIs(absl::StatusCode::kNotFound));
  EXPECT_THAT(client->Describe(second->handle), IsOk());
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_evictions_total{tier=\"resident\"}"), 1.0);
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_entries{tier=\"resident\"}"), 1.0);
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_demotions_total"), 0.0);
  // A family larger than the whole budget is refused, not cached half-way.
  auto huge = client->Build(gen::Uniform(20000, 23));
  EXPECT_THAT(huge.status(), StatusIs(absl::StatusCode::kResourceExhausted));
}

/// The device's used memory in bytes (0 without a GPU).
size_t DeviceBytesInUse() {
  const absl::StatusOr<DeviceMemory> memory = QueryDeviceMemory();
  return memory.ok() ? memory->used_bytes() : 0;
}

// On a GPU, the memory CUDA's pool keeps after builds goes back to the device once the server has
// been idle for --device_idle_release_ms: after a 1M-point build and its release, the device's
// used memory returns to what it was before the build (without the release it would stay at the
// build's high-water mark, hundreds of megabytes up).
TEST(ServiceTest, IdleDeviceMemoryGoesBackToTheDevice) {
  if (TestBackend() != "cuda") GTEST_SKIP() << "needs the CUDA backend (GALPHA_SERVICE_BACKEND=cuda)";
  ServerOptions options = TestServerOptions();
  options.service.device_idle_release = std::chrono::milliseconds(1000);
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  // A first build loads the engine's kernels and creates its pools: the baseline is taken after
  // it has been released and the idle release has run.
  const std::vector<Point2> warm = gen::Uniform(100000, 61);
  ASSERT_THAT(client->Build(warm), IsOk());
  ASSERT_THAT(client->Release(PointSetHandle(warm)), IsOk());
  std::this_thread::sleep_for(std::chrono::milliseconds(3000));
  const size_t baseline = DeviceBytesInUse();
  const std::vector<Point2> points = gen::Uniform(1000000, 62);
  ASSERT_THAT(client->Build(points), IsOk());
  const size_t built = DeviceBytesInUse();  // before the idle release can run (1 s)
  ASSERT_GT(built, baseline + (size_t{100} << 20)) << "the premise: the build left its pool memory on the device";
  ASSERT_THAT(client->Release(PointSetHandle(points)), IsOk());
  size_t now = 0;
  EXPECT_TRUE(WaitFor([&] { return (now = DeviceBytesInUse()) <= baseline + (size_t{64} << 20); }, 10))
      << "used " << now / 1000000 << " MB of device memory, " << baseline / 1000000 << " MB before the build and "
      << built / 1000000 << " MB after it";
}

/// Every message of a Classify stream, serialized: two answers are the same when these are.
absl::StatusOr<std::vector<std::string>> ClassifyMessages(client::AlphaClient& client, const std::string& handle,
                                                          uint32_t rank) {
  v1::ClassifyRequest request;
  request.set_handle(handle);
  request.mutable_threshold()->set_rank(rank);
  std::vector<std::string> messages;
  absl::Status status = client.Classify(request, [&](const v1::ClassifyResponse& message) {
    messages.push_back(message.SerializeAsString());
    return absl::OkStatus();
  });
  if (!status.ok()) return status;
  return messages;
}

TEST(ServiceTest, DemotedFamiliesAreRebuiltWhenQueried) {
  const std::vector<Point2> a = gen::Clustered(3000, 24), b = gen::Uniform(3000, 25);
  const size_t one_family = LargestFamilyBytes({a, b});
  ASSERT_GT(one_family, 0u);
  ServerOptions options = TestServerOptions();
  options.service.cache_bytes = one_family * 3 / 2;  // one family resident at a time
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  // Classify in one call: the parts of a split answer are calls of their own, each a cache lookup,
  // and how many of them find the family still demoted depends on their timing.
  client::ClientOptions one_call;
  one_call.target = "127.0.0.1:" + std::to_string(server->port());
  one_call.classify_parts = 1;
  auto connected = client::AlphaClient::Connect(one_call);
  ASSERT_THAT(connected, IsOk());
  const std::unique_ptr<client::AlphaClient> client = *std::move(connected);
  auto first = client->Build(a);
  ASSERT_THAT(first, IsOk());
  const auto before = ClassifyMessages(*client, first->handle, 40);
  ASSERT_THAT(before, IsOk());
  ASSERT_GT(before->size(), 2u);
  const std::vector<double> spectrum_before = testing::SpectrumRemote(*client, first->handle, 500);

  auto second = client->Build(b);
  ASSERT_THAT(second, IsOk());
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_demotions_total"), 1.0);
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_entries{tier=\"resident\"}"), 1.0);
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_entries{tier=\"compact\"}"), 1.0);
  // The compact entry is the points: 16 bytes each, next to hundreds for the family.
  const double compact_bytes = ScrapeMetric(*server, "galpha_cache_bytes{tier=\"compact\"}");
  EXPECT_GE(compact_bytes, 16.0 * static_cast<double>(a.size()));
  EXPECT_LE(compact_bytes, 64.0 * static_cast<double>(a.size()));

  // A query of the demoted family answers as before: it is rebuilt, transparently.
  const auto after = ClassifyMessages(*client, first->handle, 40);
  ASSERT_THAT(after, IsOk());
  EXPECT_EQ(*after, *before) << "the rebuilt family answers byte for byte as the first build";
  EXPECT_EQ(testing::SpectrumRemote(*client, first->handle, 500), spectrum_before);
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_promotions_total"), 1.0);
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_demotions_total"), 2.0) << "b made room";
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_hits_total{tier=\"compact\"}"), 1.0);
  EXPECT_EQ(ScrapeMetric(*server, "galpha_build_seconds_count"), 3.0) << "two uploads and one rebuild";

  // The client's check before an upload (a Describe) promotes a demoted family: no upload.
  auto again = client->Build(b);
  ASSERT_THAT(again, IsOk());
  EXPECT_EQ(again->handle, second->handle);
  EXPECT_TRUE(again->cached);
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_promotions_total"), 2.0);
  EXPECT_EQ(ScrapeMetric(*server, "galpha_build_seconds_count"), 4.0);

  // An upload of demoted points (no check first) is built as uploaded and takes the entry's place.
  std::vector<double> coordinates;
  for (const Point2& p : a) coordinates.insert(coordinates.end(), {p.x, p.y});
  v1::BuildResponse uploaded;
  ASSERT_THAT(testing::RawBuild(*client, {testing::Header(a.size()), testing::Chunk(coordinates)}, &uploaded), IsOk());
  EXPECT_EQ(uploaded.handle(), first->handle);
  EXPECT_FALSE(uploaded.cached());
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_promotions_total"), 3.0);
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_entries{tier=\"compact\"}"), 1.0) << "b, demoted again";

  // Release reaches the compact tier too.
  auto released = client->Release(second->handle);
  ASSERT_THAT(released, IsOk());
  EXPECT_TRUE(released->released());
  EXPECT_THAT(client->Describe(second->handle).status(), StatusIs(absl::StatusCode::kNotFound));
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_entries{tier=\"compact\"}"), 0.0);
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
  EXPECT_EQ(MetricValue(page, "galpha_cache_entries{tier=\"resident\"}"), 1.0);
  EXPECT_EQ(MetricValue(page, "galpha_cache_bytes{tier=\"resident\"}"),
            static_cast<double>(built->summary.family_bytes()));
  EXPECT_EQ(MetricValue(page, "galpha_cache_hits_total{tier=\"resident\"}"), 1.0);
  EXPECT_EQ(MetricValue(page, "galpha_cache_misses_total"), 3.0);  // skip check, build, unknown handle
  // The slot is handed back just after the response is sent: the gauge settles to 0 right after.
  EXPECT_TRUE(testing::WaitFor([&] { return testing::ScrapeMetric(*server, "galpha_builds_in_flight") == 0.0; }, 5.0));
  EXPECT_EQ(MetricValue(page, "galpha_build_queue_length"), 0.0);
  EXPECT_EQ(MetricValue(page, "galpha_backend_info{backend=\"" + testing::TestBackend() + "\"}"), 1.0);
  EXPECT_EQ(MetricValue(page, "galpha_warm_up_seconds"), 0.0);  // TestServerOptions: no warm-up
}

TEST(ServiceTest, WarmUpRunsAtStartAndIsNotACallersBuild) {
  ServerOptions options = TestServerOptions();
  options.warm_up = true;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  EXPECT_GT(server->warm_up_seconds(), 0.0);
  const std::string page = testing::HttpGet(server->metrics_port(), "/metrics");
  using testing::MetricValue;
  EXPECT_NEAR(MetricValue(page, "galpha_warm_up_seconds"), server->warm_up_seconds(), 1e-6 * server->warm_up_seconds())
      << page;
  // Not a caller's build: nothing cached, no build counted.
  EXPECT_EQ(MetricValue(page, "galpha_cache_entries{tier=\"resident\"}"), 0.0);
  EXPECT_EQ(MetricValue(page, "galpha_build_seconds_count"), 0.0);
  // Its slot is handed back just after the warm-up's result is: the gauge settles to 0 right after.
  EXPECT_TRUE(testing::WaitFor([&] { return testing::ScrapeMetric(*server, "galpha_builds_in_flight") == 0.0; }, 5.0));
  auto client = ClientOf(*server);
  auto built = client->Build(gen::Uniform(2000, 43));
  ASSERT_THAT(built, IsOk());
  EXPECT_FALSE(built->cached);
}

TEST(ServiceTest, AFailedWarmUpStopsTheStartWithItsReason) {
  ServerOptions options = TestServerOptions();
  options.warm_up = true;
  options.service.build_memory_bytes = 1 << 20;  // below the warm-up lattice's 13 MB
  auto server = GalphaServer::Start(options);
  ASSERT_FALSE(server.ok());
  EXPECT_EQ(server.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(server.status().message(), HasSubstr("the warm-up build failed (--warm_up=false skips it)"));
  EXPECT_THAT(server.status().message(), HasSubstr("--build_memory_bytes"));
}

TEST(ServiceTest, UnreadableTlsFilesStopTheStartWithTheirName) {
  ServerOptions options = TestServerOptions();
  options.tls_cert_file = "/nonexistent/galpha-cert.pem";
  options.tls_key_file = "/nonexistent/galpha-key.pem";
  auto server = GalphaServer::Start(options);
  ASSERT_FALSE(server.ok());
  EXPECT_THAT(server.status().message(), HasSubstr("galpha-cert.pem"));
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
