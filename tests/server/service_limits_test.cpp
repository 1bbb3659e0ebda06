// The real server's upload limits (issue 15, item 2): an announced size reserves nothing until its
// points arrive, an idle upload is ended and its bytes freed, and one tenant can neither take the
// whole in-flight budget nor fill the build queue; each refusal is counted by its reason.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/io/point_set_handle.hpp"
#include "server/build_time_limit.hpp"
#include "server/exact_comparison_limit.hpp"
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
using ::testing::HasSubstr;
using testing::Header;
using testing::ScrapeMetric;
using testing::SlowBuildPoints;
using testing::StartServer;
using testing::TestServerOptions;
using testing::WaitFor;

std::string Rejected(const std::string& reason) { return "galpha_builds_rejected_total{reason=\"" + reason + "\"}"; }

/// A Build stream the test writes message by message and leaves open.
class OpenUpload {
 public:
  /// `token`: the bearer token to call with (the raw stub sends none of its own).
  explicit OpenUpload(client::AlphaClient& client, std::chrono::seconds deadline = std::chrono::seconds(30),
                      const std::string& token = "") {
    context_.set_deadline(std::chrono::system_clock::now() + deadline);
    if (!token.empty()) context_.AddMetadata("authorization", "Bearer " + token);
    writer_ = client.stub().Build(&context_, &response_);
  }
  bool Write(const v1::BuildRequest& message) { return writer_->Write(message); }
  /// Ends the stream (WritesDone) and returns the call's status.
  absl::Status Finish() {
    writer_->WritesDone();
    return client::FromGrpc(writer_->Finish());
  }
  /// Waits for the server's answer without ending the stream.
  absl::Status AwaitServer() { return client::FromGrpc(writer_->Finish()); }
  void Cancel() {
    context_.TryCancel();
    writer_->Finish();
  }

 private:
  grpc::ClientContext context_;
  v1::BuildResponse response_;
  std::unique_ptr<grpc::ClientWriter<v1::BuildRequest>> writer_;
};

std::vector<double> Coordinates(const std::vector<Point2>& points) {
  std::vector<double> coordinates;
  coordinates.reserve(2 * points.size());
  for (const Point2& p : points) {
    coordinates.push_back(p.x);
    coordinates.push_back(p.y);
  }
  return coordinates;
}

// Five streams that only announced 60000 points each (960 KB of a 1 MiB budget) used to reserve
// it all up front, and every later build was refused until they disconnected.
TEST(ServiceLimitsTest, AnnouncedSizesReserveNothingUntilThePointsArrive) {
  ServerOptions options = TestServerOptions();
  options.service.max_in_flight_bytes = 1 << 20;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  std::vector<std::unique_ptr<OpenUpload>> announced;
  for (int i = 0; i < 5; ++i) {
    announced.push_back(std::make_unique<OpenUpload>(*client));
    ASSERT_TRUE(announced.back()->Write(Header(60000)));
    // One point each, so that the test knows when the server has read the header.
    ASSERT_TRUE(announced.back()->Write(Chunk({static_cast<double>(i), 0.5})));
  }
  ASSERT_TRUE(WaitFor([&] { return server->service().in_flight_bytes() >= 5 * sizeof(Point2); }, 10));
  EXPECT_EQ(server->service().in_flight_bytes(), 5 * sizeof(Point2)) << "the points that arrived, not the announced";

  // A build of 60000 points (960 KB) fits next to what the announcing streams actually hold.
  auto built = client->Build(gen::Uniform(60000, 31));
  EXPECT_THAT(built, IsOk());
  EXPECT_EQ(ScrapeMetric(*server, Rejected("in_flight_bytes")), 0.0);

  // An announcement no budget could hold is still refused at the header, before any upload.
  OpenUpload too_large(*client);
  ASSERT_TRUE(too_large.Write(Header(70000)));
  EXPECT_THAT(too_large.AwaitServer(),
              StatusIs(absl::StatusCode::kResourceExhausted, HasSubstr("--max_in_flight_bytes")));
  EXPECT_EQ(ScrapeMetric(*server, Rejected("in_flight_bytes")), 1.0);

  for (auto& upload : announced) upload->Cancel();
  EXPECT_TRUE(WaitFor([&] { return server->service().in_flight_bytes() == 0; }, 10));
}

// A half-sent upload that went idle used to keep its points (and their budget) with no limit.
TEST(ServiceLimitsTest, IdleUploadIsEndedAndItsBytesFreed) {
  ServerOptions options = TestServerOptions();
  options.service.upload_idle_timeout = std::chrono::milliseconds(300);
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  EXPECT_EQ(ScrapeMetric(*server, Rejected("idle_timeout")), 0.0) << "every reason is exported from the start";
  auto client = ClientOf(*server);

  OpenUpload idle(*client, std::chrono::seconds(20));
  ASSERT_TRUE(idle.Write(Header(1000)));
  ASSERT_TRUE(idle.Write(Chunk(Coordinates(gen::Uniform(100, 32)))));
  ASSERT_TRUE(WaitFor([&] { return server->service().in_flight_bytes() == 100 * sizeof(Point2); }, 10));
  const auto start = std::chrono::steady_clock::now();
  const absl::Status ended = idle.AwaitServer();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_THAT(ended, StatusIs(absl::StatusCode::kDeadlineExceeded, HasSubstr("--upload_idle_timeout_ms")));
  EXPECT_THAT(ended.message(), HasSubstr("300 ms"));
  EXPECT_LT(seconds, 10.0) << "ended by the server's idle limit, not by the client's deadline";
  EXPECT_TRUE(WaitFor([&] { return server->service().in_flight_bytes() == 0; }, 5));
  EXPECT_EQ(ScrapeMetric(*server, Rejected("idle_timeout")), 1.0);
  EXPECT_EQ(ScrapeMetric(*server, "galpha_rpcs_total{code=\"DEADLINE_EXCEEDED\",method=\"Build\"}"), 1.0);

  // A slow upload whose messages each come within the limit is not idle, however long it takes.
  const std::vector<Point2> points = gen::Uniform(800, 33);
  OpenUpload slow(*client);
  ASSERT_TRUE(slow.Write(Header(points.size())));
  for (size_t i = 0; i < points.size(); i += 100) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    ASSERT_TRUE(slow.Write(Chunk(Coordinates(std::vector<Point2>(points.begin() + i, points.begin() + i + 100)))));
  }
  EXPECT_THAT(slow.Finish(), IsOk());

  // Nor is a build that runs (or waits in the queue) for longer than the limit: only uploads idle.
  EXPECT_THAT(client->Build(gen::Uniform(SlowBuildPoints(), 34)), IsOk());
  EXPECT_EQ(ScrapeMetric(*server, Rejected("idle_timeout")), 1.0);
}

// The build time limit (issue "No slow inputs", item 5): a multiple of the expected time for the
// size, with a floor; off at 0.
TEST(BuildTimeLimitTest, IsAMultipleOfTheExpectedTimeWithAFloor) {
  BuildTimeLimitOptions options;  // 50 x, at least 10 s
  EXPECT_DOUBLE_EQ(ExpectedBuildSeconds(1'000'000, /*cuda=*/true, 16), 0.06);
  EXPECT_DOUBLE_EQ(ExpectedBuildSeconds(1'000'000, /*cuda=*/false, 2), 7.0);
  EXPECT_DOUBLE_EQ(BuildTimeLimit(1'000'000, true, 16, options).count(), 10.0);     // the floor
  EXPECT_DOUBLE_EQ(BuildTimeLimit(100'000'000, true, 16, options).count(), 300.0);  // 50 x 6 s
  EXPECT_DOUBLE_EQ(BuildTimeLimit(1'000'000, false, 2, options).count(), 350.0);    // 50 x 7 s
  EXPECT_DOUBLE_EQ(BuildTimeLimit(1'000'000, false, 0, options).count(), 700.0);    // unknown cores: 1
  options.multiple = 0;
  EXPECT_DOUBLE_EQ(BuildTimeLimit(1'000'000, false, 2, options).count(), 0.0);  // off
}

// A build that runs past its limit stops at the engine's next phase boundary and answers
// DEADLINE_EXCEEDED naming the limit and its flags; nothing is cached, its points are freed, and
// the refusal is counted once under its reason.
TEST(ServiceLimitsTest, ABuildPastItsTimeLimitStops) {
  ServerOptions options = TestServerOptions();
  options.service.build_time.multiple = 1e-4;  // a fraction of a millisecond for these points
  options.service.build_time.floor = std::chrono::milliseconds(0);
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  EXPECT_EQ(ScrapeMetric(*server, Rejected("build_time")), 0.0) << "every reason is exported from the start";
  auto client = ClientOf(*server);
  const std::vector<Point2> points = gen::Uniform(SlowBuildPoints(), 41);
  client::BuildCallOptions call;
  call.skip_upload_if_cached = false;
  const auto built = client->Build(points, call);
  EXPECT_THAT(built.status(), StatusIs(absl::StatusCode::kDeadlineExceeded, HasSubstr("--build_time_multiple")));
  EXPECT_THAT(built.status().message(), HasSubstr("time limit"));
  EXPECT_EQ(ScrapeMetric(*server, Rejected("build_time")), 1.0);
  EXPECT_THAT(client->Describe(PointSetHandle(points)).status(), StatusIs(absl::StatusCode::kNotFound));
  EXPECT_TRUE(WaitFor([&] { return server->service().in_flight_bytes() == 0; }, 5));
}

TEST(ServiceLimitsTest, ExactComparisonLimitIsAMultipleOfThePointsWithAFloor) {
  ExactComparisonLimitOptions options;  // the defaults: 64 a point, at least 1,000,000
  EXPECT_EQ(ExactComparisonLimit(1000, options), 1'000'000u);
  EXPECT_EQ(ExactComparisonLimit(1'000'000, options), 64'000'000u);
  options.per_point = 0.5;
  options.floor = 0;
  EXPECT_EQ(ExactComparisonLimit(3, options), 2u);  // rounded up
  options.per_point = 1e300;
  EXPECT_EQ(ExactComparisonLimit(3, options), uint64_t{1} << 63);  // saturates
  options.per_point = 0;
  EXPECT_EQ(ExactComparisonLimit(1'000'000, options), 0u);  // off
}

// A build whose spectrum needs more exact comparisons than its limit stops and answers
// RESOURCE_EXHAUSTED naming the limit and its flags; nothing is cached, and the refusal is
// counted once under its reason. The same input builds under the default limit.
TEST(ServiceLimitsTest, ABuildPastItsExactComparisonLimitStops) {
  ServerOptions options = TestServerOptions();
  options.service.exact_comparisons.per_point = 0.1;  // this lattice needs about 0.36 a point
  options.service.exact_comparisons.floor = 0;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  EXPECT_EQ(ScrapeMetric(*server, Rejected("exact_comparisons")), 0.0) << "every reason is exported from the start";
  auto client = ClientOf(*server);
  const std::vector<Point2> points = gen::UlpLattice(2500, 13);
  client::BuildCallOptions call;
  call.skip_upload_if_cached = false;
  const auto built = client->Build(points, call);
  EXPECT_THAT(built.status(),
              StatusIs(absl::StatusCode::kResourceExhausted, HasSubstr("--max_exact_comparisons_per_point")));
  EXPECT_THAT(built.status().message(), HasSubstr("limit of 250 exact radius comparisons"));
  EXPECT_EQ(ScrapeMetric(*server, Rejected("exact_comparisons")), 1.0);
  EXPECT_THAT(client->Describe(PointSetHandle(points)).status(), StatusIs(absl::StatusCode::kNotFound));
  EXPECT_TRUE(WaitFor([&] { return server->service().in_flight_bytes() == 0; }, 5));

  auto lenient = StartServer(TestServerOptions());
  ASSERT_NE(lenient, nullptr);
  EXPECT_THAT(ClientOf(*lenient)->Build(points, call), IsOk());
}

ServerOptions TwoTenants() {
  ServerOptions options = TestServerOptions();
  auto tokens = TenantTokens::Parse("token-a tenant-a\ntoken-b tenant-b\n", "test");
  EXPECT_THAT(tokens, IsOk());
  if (tokens.ok()) options.service.tokens = *tokens;
  return options;
}

TEST(ServiceLimitsTest, OneTenantCannotTakeTheWholeInFlightBudget) {
  ServerOptions options = TwoTenants();
  options.service.max_in_flight_bytes = 4 << 20;
  options.service.max_tenant_in_flight_bytes = 1 << 20;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  auto a = ClientOf(*server, "token-a");
  auto b = ClientOf(*server, "token-b");

  OpenUpload holding(*a, std::chrono::seconds(30), "token-a");
  ASSERT_TRUE(holding.Write(Header(0)));
  ASSERT_TRUE(holding.Write(Chunk(Coordinates(gen::Uniform(50000, 35)))));
  ASSERT_TRUE(WaitFor([&] { return server->service().in_flight_bytes_of("tenant-a") == 50000 * sizeof(Point2); }, 10));

  // 800 KB held: 480 KB more are over tenant a's 1 MiB, though well within the server's 4 MiB.
  auto refused = a->Build(gen::Uniform(30000, 36));
  EXPECT_THAT(refused.status(),
              StatusIs(absl::StatusCode::kResourceExhausted, HasSubstr("--max_tenant_in_flight_bytes")));
  EXPECT_THAT(refused.status().message(), HasSubstr("tenant 'tenant-a'"));
  EXPECT_EQ(ScrapeMetric(*server, Rejected("tenant_in_flight_bytes")), 1.0);
  // Tenant b is not held back by a's upload.
  EXPECT_THAT(b->Build(gen::Uniform(30000, 36)), IsOk());

  holding.Cancel();
  EXPECT_TRUE(WaitFor([&] { return server->service().in_flight_bytes() == 0; }, 10));
  EXPECT_THAT(a->Build(gen::Uniform(30000, 37)), IsOk()) << "a's budget is back once its upload ended";
}

TEST(ServiceLimitsTest, OneTenantCannotFillTheBuildQueue) {
  ServerOptions options = TwoTenants();
  options.service.build_slots = 1;
  options.service.max_queued_builds = 4;
  options.service.max_tenant_queued_builds = 1;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  client::BuildCallOptions upload;
  upload.skip_upload_if_cached = false;

  absl::StatusOr<client::BuildResult> running = absl::UnknownError("not run");
  std::thread runner([&] { running = ClientOf(*server, "token-a")->Build(gen::Uniform(SlowBuildPoints(), 38)); });
  ASSERT_TRUE(WaitFor([&] { return ScrapeMetric(*server, "galpha_builds_in_flight") == 1.0; }, 60));
  absl::StatusOr<client::BuildResult> queued = absl::UnknownError("not run");
  std::thread waiter([&] { queued = ClientOf(*server, "token-a")->Build(gen::Uniform(100, 39), upload); });
  ASSERT_TRUE(WaitFor([&] { return ScrapeMetric(*server, "galpha_build_queue_length") == 1.0; }, 30));

  // Tenant a has its one build waiting: its next is refused, while the queue has room for b's.
  auto refused = ClientOf(*server, "token-a")->Build(gen::Uniform(100, 40), upload);
  EXPECT_THAT(refused.status(),
              StatusIs(absl::StatusCode::kResourceExhausted, HasSubstr("--max_tenant_queued_builds")));
  EXPECT_EQ(ScrapeMetric(*server, Rejected("tenant_queued_builds")), 1.0);
  EXPECT_EQ(ScrapeMetric(*server, Rejected("queue_full")), 0.0);
  auto other = ClientOf(*server, "token-b")->Build(gen::Uniform(100, 41), upload);
  EXPECT_THAT(other, IsOk());

  runner.join();
  waiter.join();
  EXPECT_THAT(running, IsOk());
  EXPECT_THAT(queued, IsOk());
}

}  // namespace
}  // namespace galpha::server
