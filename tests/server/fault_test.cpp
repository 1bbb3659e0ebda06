// Faults against the real galpha_server process on the CPU backend (issue: deployment and
// operations): SIGTERM during a build, clients that vanish mid-upload, a burst of builds over the
// queue limit, malformed and oversized messages, a slow reader of a large Classify stream. After
// each, the server is still up and answering, and its resident memory is back near its baseline.
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <signal.h>  // NOLINT(modernize-deprecated-headers): POSIX kill and signal numbers

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "client/galpha_client.hpp"
#include "core/io/point_set_handle.hpp"
#include "service_test_support.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/server_process.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using galpha::testing::ServerProcess;
using galpha::testing::SpawnShell;
using galpha::testing::StatusIs;
using galpha::testing::WaitChild;
using ::testing::Not;
using testing::WaitFor;

std::unique_ptr<client::AlphaClient> ClientOf(const ServerProcess& server) {
  client::ClientOptions options;
  options.target = server.address();
  options.deadline = std::chrono::seconds(120);
  return *client::AlphaClient::Connect(options);
}

double Metric(const ServerProcess& server, const std::string& series) {
  return testing::MetricValue(testing::HttpGet(server.metrics_port(), "/metrics"), series);
}

client::BuildCallOptions Upload() {
  client::BuildCallOptions call;
  call.skip_upload_if_cached = false;
  return call;
}

/// Resident memory once the server is idle again: nothing in flight, nothing cached (the caller
/// released its handles). glibc returns freed memory lazily: allow a little slack.
void ExpectBackToBaseline(const ServerProcess& server, size_t baseline) {
  ASSERT_TRUE(WaitFor([&] { return Metric(server, "galpha_builds_in_flight") == 0.0; }, 60));
  ASSERT_TRUE(WaitFor([&] { return Metric(server, "galpha_cache_entries{tier=\"resident\"}") == 0.0; }, 10))
      << "the server's metrics:\n"
      << testing::HttpGet(server.metrics_port(), "/metrics") << "\nits log:\n"
      << server.log();
  const size_t slack = std::max<size_t>(64u << 20, baseline / 2);
  size_t now = 0;
  // Connections and their buffers go away a little after their calls end.
  EXPECT_TRUE(WaitFor([&] { return (now = server.ResidentBytes()) <= baseline + slack; }, 20))
      << "resident " << now << " bytes, baseline " << baseline << " bytes";
  std::printf("fault_test: resident %.1f MB after the faults, baseline %.1f MB\n", static_cast<double>(now) / 1e6,
              static_cast<double>(baseline) / 1e6);
}

/// Measures the server's baseline after one build, one streamed Classify and a release, so that
/// what gRPC and the allocator keep for reuse after such calls (threads, slice pools, arenas) is
/// in the baseline, not counted as a leak.
size_t WarmBaseline(const ServerProcess& server) {
  auto client = ClientOf(server);
  const auto points = gen::Uniform(300000, 77);
  auto built = client->Build(points, Upload());
  EXPECT_THAT(built, IsOk());
  v1::ClassifyRequest classify;
  classify.set_handle(PointSetHandle(points));
  classify.mutable_threshold()->set_rank(1);
  EXPECT_THAT(client->Classify(classify, [](const v1::ClassifyResponse&) { return absl::OkStatus(); }), IsOk());
  EXPECT_THAT(client->Release(PointSetHandle(points)), IsOk());
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  return server.ResidentBytes();
}

TEST(FaultTest, SigtermDuringABuildFinishesItAndRefusesNewWork) {
  ServerProcess server(GALPHA_SERVER, "--drain_notice_ms 1500 --drain_grace_ms 60000 --build_slots 1");
  ASSERT_GT(server.port(), 0) << server.log();
  absl::StatusOr<client::BuildResult> running = absl::UnknownError("not run");
  std::thread builder([&] { running = ClientOf(server)->Build(gen::Uniform(400000, 1), Upload()); });
  ASSERT_TRUE(WaitFor([&] { return Metric(server, "galpha_builds_in_flight") == 1.0; }, 60));
  const auto start = std::chrono::steady_clock::now();
  kill(server.pid(), SIGTERM);

  auto other = ClientOf(server);
  EXPECT_TRUE(WaitFor([&] { return testing::HealthOf(other->channel(), "") == "NOT_SERVING"; }, 1.0));
  const auto refused = other->Build(gen::Uniform(100, 2), Upload());
  EXPECT_THAT(refused.status(), StatusIs(absl::StatusCode::kUnavailable));
  builder.join();
  EXPECT_THAT(running, IsOk()) << "the build running at SIGTERM must finish";
  const int status = server.Signal(0, 90);
  EXPECT_EQ(status, 0) << server.log();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 1.5 + 60 + 5) << "the process must exit within notice + grace";
}

TEST(FaultTest, SigtermWithAShortGraceCancelsTheBuildCleanly) {
  ServerProcess server(GALPHA_SERVER, "--drain_notice_ms 0 --drain_grace_ms 200 --build_slots 1");
  ASSERT_GT(server.port(), 0) << server.log();
  absl::StatusOr<client::BuildResult> running = absl::UnknownError("not run");
  std::thread builder([&] { running = ClientOf(server)->Build(gen::Uniform(600000, 3), Upload()); });
  ASSERT_TRUE(WaitFor([&] { return Metric(server, "galpha_builds_in_flight") == 1.0; }, 60));
  const auto start = std::chrono::steady_clock::now();
  const int status = server.Signal(SIGTERM, 60);
  builder.join();
  EXPECT_EQ(status, 0) << server.log();
  EXPECT_THAT(running, Not(IsOk())) << "a build cut by the grace period fails; it does not hang";
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The build stops at its next phase boundary, so the exit may pass the grace by one phase.
  EXPECT_LT(seconds, 30.0) << server.log();
}

TEST(FaultTest, VanishingClientsBurstsAndBadMessagesLeaveTheServerUp) {
  ServerProcess server(GALPHA_SERVER,
                       "--drain_notice_ms 0 --build_slots 1 --max_queued_builds 2 "
                       "--max_message_bytes 2097152");
  ASSERT_GT(server.port(), 0) << server.log();
  const size_t baseline = WarmBaseline(server);
  ASSERT_GT(baseline, 0u);

  // Clients that die mid-upload: their uploads are dropped and their reservations freed.
  std::vector<pid_t> vanishing;
  vanishing.reserve(4);
  for (int i = 0; i < 4; ++i) {
    vanishing.push_back(
        SpawnShell(std::string(GALPHA_FAULT_CLIENT) + " vanish " + server.address() + " 1000000 >/dev/null"));
  }
  for (pid_t pid : vanishing) EXPECT_EQ(WaitChild(pid, 60), 0);

  // A burst over the queue limit: one runs, two wait, the rest are refused at once.
  constexpr int kBurst = 8;
  std::vector<absl::StatusOr<client::BuildResult>> results(kBurst, absl::UnknownError("not run"));
  std::vector<std::vector<Point2>> inputs;
  inputs.reserve(kBurst);
  for (int i = 0; i < kBurst; ++i) inputs.push_back(gen::Uniform(150000, 100 + static_cast<uint64_t>(i)));
  std::vector<std::thread> threads;
  threads.reserve(kBurst);
  for (int i = 0; i < kBurst; ++i) {
    threads.emplace_back([&, i] {
      results[static_cast<size_t>(i)] = ClientOf(server)->Build(inputs[static_cast<size_t>(i)], Upload());
    });
  }
  for (auto& t : threads) t.join();
  int ok = 0, exhausted = 0;
  for (const auto& r : results) {
    ok += r.ok() ? 1 : 0;
    exhausted += absl::IsResourceExhausted(r.status()) ? 1 : 0;
  }
  EXPECT_EQ(ok + exhausted, kBurst);
  EXPECT_GE(ok, 3);
  EXPECT_GE(exhausted, 1);
  EXPECT_EQ(Metric(server, "galpha_builds_rejected_total{reason=\"queue_full\"}"), static_cast<double>(exhausted));

  // Malformed bytes where a request belongs, and a message over the limit.
  auto client = ClientOf(server);
  grpc::GenericStub generic(client->channel());
  grpc::ClientContext context;
  grpc::Slice garbage(std::string("\xff\xff\xff\xff\x0f garbage"));
  grpc::ByteBuffer request(&garbage, 1), response;
  std::mutex mutex;
  std::condition_variable done;
  bool finished = false;
  grpc::Status garbage_status;
  generic.UnaryCall(&context, "/galpha.v1.AlphaShapes/Describe", grpc::StubOptions(), &request, &response,
                    [&](const grpc::Status& s) {
                      std::lock_guard<std::mutex> lock(mutex);
                      garbage_status = s;
                      finished = true;
                      done.notify_all();
                    });
  {
    std::unique_lock<std::mutex> lock(mutex);
    ASSERT_TRUE(done.wait_for(lock, std::chrono::seconds(30), [&] { return finished; }));
  }
  EXPECT_FALSE(garbage_status.ok());  // a grpc::Status
  // gRPC reports the refused message's failed read and the call's cancellation in either order:
  // repeated, a server that takes the failed read for the stream's end builds and caches the empty
  // set about every other time (ExpectBackToBaseline then finds a resident entry).
  for (int rep = 0; rep < 50; ++rep) {
    grpc::ClientContext big_context;
    v1::BuildResponse big_response;
    auto writer = client->stub().Build(&big_context, &big_response);
    v1::BuildRequest header;
    header.mutable_header();
    writer->Write(header);
    v1::BuildRequest big;
    big.mutable_points()->mutable_coordinates()->Resize(400000, 0.5);  // 3.2 MB > 2 MiB
    writer->Write(big);
    writer->WritesDone();
    EXPECT_EQ(writer->Finish().error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  }

  // Still serving, and back to the baseline once everything is released.
  EXPECT_EQ(testing::HealthOf(client->channel(), "galpha.v1.AlphaShapes"), "SERVING");
  for (const auto& input : inputs) ASSERT_THAT(client->Release(PointSetHandle(input)), IsOk());
  ExpectBackToBaseline(server, baseline);
}

TEST(FaultTest, ASlowReaderDoesNotHoldUpOthers) {
  ServerProcess server(GALPHA_SERVER, "--drain_notice_ms 0");
  ASSERT_GT(server.port(), 0) << server.log();
  const size_t baseline = WarmBaseline(server);
  auto client = ClientOf(server);
  const auto points = gen::Uniform(300000, 9);
  auto built = client->Build(points, Upload());
  ASSERT_THAT(built, IsOk());

  // About 15 messages of ~1 MB, read one per 300 ms: the stream lasts seconds, and the server
  // holds one message for it at a time.
  const std::string log = std::filesystem::temp_directory_path() / ("slow_reader_" + std::to_string(getpid()));
  const pid_t reader = SpawnShell(std::string(GALPHA_FAULT_CLIENT) + " slow-classify " + server.address() + " " +
                                  built->handle + " 300 >" + log);
  ASSERT_TRUE(WaitFor([&] { return std::filesystem::exists(log) && std::filesystem::file_size(log) > 0; }, 30));
  for (int i = 0; i < 20; ++i) {
    const auto start = std::chrono::steady_clock::now();
    ASSERT_THAT(client->Describe(built->handle), IsOk());
    v1::ComponentsRequest components;
    components.set_handle(built->handle);
    components.mutable_threshold()->set_rank(i);
    ASSERT_THAT(client->Components(components), IsOk());
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  }
  EXPECT_TRUE(std::filesystem::exists(log));
  // A reader that is killed mid-stream leaves nothing behind.
  kill(reader, SIGKILL);
  WaitChild(reader, 10);
  std::filesystem::remove(log);
  ASSERT_THAT(client->Release(built->handle), IsOk());
  EXPECT_EQ(testing::HealthOf(client->channel(), "galpha.v1.AlphaShapes"), "SERVING");
  ExpectBackToBaseline(server, baseline);
}

// The upload limits as the process's flags set them: a stalled client's upload is ended after
// --upload_idle_timeout_ms (it used to hold its points until it disconnected), and a header
// announcing more than --max_tenant_in_flight_bytes is refused before the upload.
TEST(FaultTest, UploadLimitsFollowTheirFlags) {
  ServerProcess server(GALPHA_SERVER,
                       "--drain_notice_ms 0 --upload_idle_timeout_ms 300 --max_tenant_in_flight_bytes 1048576");
  ASSERT_GT(server.port(), 0) << server.log();
  EXPECT_EQ(Metric(server, "galpha_builds_rejected_total{reason=\"idle_timeout\"}"), 0.0);
  auto client = ClientOf(server);

  grpc::ClientContext stalled;
  stalled.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(20));
  v1::BuildResponse response;
  auto writer = client->stub().Build(&stalled, &response);
  v1::BuildRequest header;
  header.mutable_header()->set_expected_points(1000);
  ASSERT_TRUE(writer->Write(header));
  v1::BuildRequest chunk;
  for (const Point2& p : gen::Uniform(500, 60)) {
    chunk.mutable_points()->add_coordinates(p.x);
    chunk.mutable_points()->add_coordinates(p.y);
  }
  ASSERT_TRUE(writer->Write(chunk));
  // The client sends nothing more and never ends the stream: the server does.
  const grpc::Status ended = writer->Finish();
  EXPECT_EQ(ended.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << ended.error_message();
  EXPECT_NE(ended.error_message().find("--upload_idle_timeout_ms"), std::string::npos) << ended.error_message();
  EXPECT_NE(ended.error_message().find("300 ms"), std::string::npos) << ended.error_message();
  EXPECT_EQ(Metric(server, "galpha_builds_rejected_total{reason=\"idle_timeout\"}"), 1.0);

  grpc::ClientContext announcing;
  auto too_large = client->stub().Build(&announcing, &response);
  header.mutable_header()->set_expected_points(70000);  // 1.12 MB
  too_large->Write(header);
  const grpc::Status refused = too_large->Finish();
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << refused.error_message();
  EXPECT_NE(refused.error_message().find("--max_tenant_in_flight_bytes"), std::string::npos) << refused.error_message();
  EXPECT_EQ(Metric(server, "galpha_builds_rejected_total{reason=\"tenant_in_flight_bytes\"}"), 1.0);

  EXPECT_THAT(client->Build(gen::Uniform(1000, 61), Upload()), IsOk()) << "the server is still up";
  EXPECT_EQ(server.Signal(SIGTERM, 30), 0) << server.log();
}

}  // namespace
}  // namespace galpha::server
