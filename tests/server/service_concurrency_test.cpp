// The real server under concurrent use: builds from several clients at once, a full build queue,
// a client cancelling mid-upload, a deadline expiring during a build.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

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
using testing::LocalFamily;
using testing::ScrapeMetric;
using testing::SlowBuildPoints;
using testing::SpectrumRemote;
using testing::StartServer;
using testing::TestServerOptions;
using testing::WaitFor;

TEST(ServiceTest, ConcurrentBuildsFromSeveralClientsMatchTheLocalEngine) {
  ServerOptions options = TestServerOptions();
  options.service.build_slots = 2;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  constexpr int kClients = 6;
  std::vector<std::vector<Point2>> inputs;
  inputs.reserve(kClients);
  for (int i = 0; i < kClients; ++i)
    inputs.push_back(gen::Gaussian(4000 + 500 * (i % 3), 100 + static_cast<uint64_t>(i % 3)));
  std::vector<absl::StatusOr<client::BuildResult>> results(kClients, absl::UnknownError("not run"));
  std::vector<std::vector<double>> spectra(kClients);
  std::vector<std::thread> threads;
  threads.reserve(kClients);
  for (int i = 0; i < kClients; ++i) {
    threads.emplace_back([&, i] {
      auto client = ClientOf(*server);
      client::BuildCallOptions call;
      call.skip_upload_if_cached = false;  // every client uploads, even of equal point sets
      results[static_cast<size_t>(i)] = client->Build(inputs[static_cast<size_t>(i)], call);
      if (results[static_cast<size_t>(i)].ok()) {
        spectra[static_cast<size_t>(i)] = SpectrumRemote(*client, results[static_cast<size_t>(i)]->handle, 65536);
      }
    });
  }
  for (auto& thread : threads) thread.join();
  for (int i = 0; i < kClients; ++i) {
    ASSERT_THAT(results[static_cast<size_t>(i)], IsOk());
    EXPECT_EQ(spectra[static_cast<size_t>(i)], LocalFamily(inputs[static_cast<size_t>(i)]).spectrum()) << i;
  }
  // Three distinct inputs: three families, whatever the interleaving.
  EXPECT_EQ(server->service().cache().GetStats().resident.entries, 3u);
}

TEST(ServiceTest, FullQueueAnswersResourceExhausted) {
  ServerOptions options = TestServerOptions();
  options.service.build_slots = 1;
  options.service.max_queued_builds = 0;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  const std::vector<Point2> large = gen::Uniform(SlowBuildPoints(), 11);
  absl::StatusOr<client::BuildResult> first = absl::UnknownError("not run");
  std::thread runner([&] { first = ClientOf(*server)->Build(large); });
  ASSERT_TRUE(WaitFor([&] { return ScrapeMetric(*server, "galpha_builds_in_flight") == 1.0; }, 60));
  auto second = ClientOf(*server)->Build(gen::Uniform(100, 12));
  EXPECT_THAT(second.status(), StatusIs(absl::StatusCode::kResourceExhausted));
  EXPECT_NE(second.status().message().find("queue is full"), std::string::npos);
  runner.join();
  EXPECT_THAT(first, IsOk());
  EXPECT_EQ(ScrapeMetric(*server, "galpha_builds_rejected_total{reason=\"queue_full\"}"), 1.0);
}

TEST(ServiceTest, CancellationMidStreamFreesTheUpload) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  grpc::ClientContext context;
  v1::BuildResponse response;
  auto writer = client->stub().Build(&context, &response);
  ASSERT_TRUE(writer->Write(Header(1000000)));
  std::vector<double> chunk(2 * 10000, 0.25);
  for (size_t i = 0; i < chunk.size(); ++i) chunk[i] = static_cast<double>(i);
  ASSERT_TRUE(writer->Write(Chunk(chunk)));
  ASSERT_TRUE(WaitFor([&] { return server->service().in_flight_bytes() > 0; }, 10));
  context.TryCancel();
  EXPECT_EQ(writer->Finish().error_code(), grpc::StatusCode::CANCELLED);
  EXPECT_TRUE(WaitFor([&] { return server->service().in_flight_bytes() == 0; }, 10));
  EXPECT_EQ(server->service().cache().GetStats().resident.entries, 0u);
}

TEST(ServiceTest, DeadlineStopsARunningBuild) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  const std::vector<Point2> points = gen::Uniform(SlowBuildPoints() * 3 / 2, 13);
  // Unhurried builds (the second one warm) say how long the upload and the build take on this
  // machine; the deadline then falls a third of the way into the engine's work (a fixed deadline
  // expired in the upload or after the build, as machines and the engine got faster).
  double upload_ms = 0, build_ms = 0;
  for (int warm = 0; warm < 2; ++warm) {
    auto unhurried = ClientOf(*server);
    const auto start = std::chrono::steady_clock::now();
    auto first = unhurried->Build(points);
    const double total_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ASSERT_THAT(first, IsOk());
    build_ms = 0;
    for (const auto& stage : first->summary.stage_times()) build_ms += 1e3 * stage.seconds();
    upload_ms = std::max(0.0, total_ms - build_ms);
    ASSERT_THAT(unhurried->Release(first->handle), IsOk());
  }
  client::ClientOptions options;
  options.target = "127.0.0.1:" + std::to_string(server->port());
  options.deadline = std::chrono::milliseconds(static_cast<int64_t>(upload_ms + build_ms / 3) + 1);
  auto client = client::AlphaClient::Connect(options);
  ASSERT_THAT(client, IsOk());
  auto built = (*client)->Build(points);
  EXPECT_THAT(built.status(), StatusIs(absl::StatusCode::kDeadlineExceeded));
  // The build stops at its next phase boundary and frees what it held.
  EXPECT_TRUE(WaitFor([&] { return ScrapeMetric(*server, "galpha_builds_in_flight") == 0.0; }, 60));
  EXPECT_TRUE(WaitFor([&] { return server->service().in_flight_bytes() == 0; }, 10));
  EXPECT_EQ(server->service().cache().GetStats().resident.entries, 0u);
}

}  // namespace
}  // namespace galpha::server
