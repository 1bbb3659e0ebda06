// The real server, started in-process on loopback ports, driven through the client library and
// raw stubs: every RPC against the local engine as the oracle, every error status of the service,
// concurrency, cancellation, deadlines, eviction, metrics over HTTP, health, reflection, TLS and
// tenants.
#include <gtest/gtest.h>
#include <grpcpp/grpcpp.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/io/point_set_handle.hpp"
#include "core/geometry/shape.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "service_test_support.hpp"
#include "tests/support/data_files.hpp"
#include "tests/support/point_generators.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using testing::ClientOf;
using testing::ScrapeMetric;
using testing::StartServer;
using testing::TestServerOptions;
using testing::WaitFor;

/// A build that takes long enough (a second or more) for a test to act while it runs.
size_t SlowBuildPoints() { return testing::TestBackend() == "cuda" ? 4000000 : 400000; }

AlphaFamily LocalFamily(const std::vector<Point2>& points) {
  BuildOptions options;
  options.backend = Backend::kCpu;
  auto family = BuildAlphaFamily(points, options);
  EXPECT_TRUE(family.ok()) << family.status();
  return *std::move(family);
}

/// The Classify stream of `request` as (kind, indices..., class) rows, and its summary.
struct ClassifyAnswer {
  v1::ClassifySummary summary;
  std::vector<std::vector<uint32_t>> rows;  // arity indices then the class byte
};

absl::StatusOr<ClassifyAnswer> ClassifyRemote(client::AlphaClient& client, const v1::ClassifyRequest& request) {
  ClassifyAnswer answer;
  absl::Status status = client.Classify(request, [&](const v1::ClassifyResponse& message) {
    if (message.has_summary()) answer.summary = message.summary();
    if (message.has_chunk()) {
      const auto& chunk = message.chunk();
      const int arity = static_cast<int>(chunk.kind());
      for (size_t i = 0; i < chunk.classes().size(); ++i) {
        std::vector<uint32_t> row;
        for (int k = 0; k < arity; ++k) row.push_back(chunk.vertex_indices(static_cast<int>(i) * arity + k));
        row.push_back(static_cast<uint8_t>(chunk.classes()[i]));
        answer.rows.push_back(row);
      }
    }
    return absl::OkStatus();
  });
  if (!status.ok()) return status;
  return answer;
}

/// The same rows from the local engine, in the service's order.
std::vector<std::vector<uint32_t>> ClassifyLocal(const AlphaFamily& family, int64_t level, ClassifyMode mode,
                                                 VertexRule rule) {
  const Classification classes = family.ClassifyAll(level, mode, rule);
  std::vector<std::vector<uint32_t>> rows;
  for (uint32_t v = 0; v < family.points().size(); ++v) {
    if (family.representative()[v] == v) rows.push_back({v, static_cast<uint32_t>(classes.vertices[v]) + 1});
  }
  std::vector<std::vector<uint32_t>> edges, triangles;
  for (uint32_t e = 0; e < family.edges().size(); ++e) {
    const auto& edge = family.edges()[e];
    edges.push_back({std::min(edge[0], edge[1]), std::max(edge[0], edge[1]), static_cast<uint32_t>(classes.edges[e]) + 1});
  }
  for (uint32_t t = 0; t < family.triangles().size(); ++t) {
    std::array<uint32_t, 3> tri = family.triangles()[t];
    std::sort(tri.begin(), tri.end());
    triangles.push_back({tri[0], tri[1], tri[2], static_cast<uint32_t>(classes.triangles[t]) + 1});
  }
  std::sort(edges.begin(), edges.end());
  std::sort(triangles.begin(), triangles.end());
  rows.insert(rows.end(), edges.begin(), edges.end());
  rows.insert(rows.end(), triangles.begin(), triangles.end());
  return rows;
}

std::vector<double> SpectrumRemote(client::AlphaClient& client, const std::string& handle, uint32_t page) {
  std::vector<double> values;
  v1::SpectrumRequest request;
  request.set_handle(handle);
  request.set_page_size(page);
  int64_t next = 1;
  while (next != 0) {
    request.set_first_rank(next);
    auto answer = client.Spectrum(request);
    EXPECT_TRUE(answer.ok()) << answer.status();
    if (!answer.ok()) break;
    values.insert(values.end(), answer->alpha_sq().begin(), answer->alpha_sq().end());
    next = answer->next_rank();
  }
  return values;
}

/// Compares everything the service answers about `points` with the local engine.
void ExpectServiceMatchesLocal(client::AlphaClient& client, const std::vector<Point2>& points, const std::string& label) {
  SCOPED_TRACE(label);
  const AlphaFamily local = LocalFamily(points);
  client::BuildCallOptions call;
  call.name = label;
  auto built = client.Build(points, call);
  ASSERT_TRUE(built.ok()) << built.status();
  EXPECT_EQ(built->handle, PointSetHandle(points));
  const v1::BuildSummary& summary = built->summary;
  EXPECT_EQ(summary.points(), points.size());
  EXPECT_EQ(summary.distinct_points(), local.num_unique());
  EXPECT_EQ(summary.duplicates(), local.num_duplicates());
  EXPECT_EQ(summary.triangles(), local.triangles().size());
  EXPECT_EQ(summary.edges(), local.edges().size());
  EXPECT_EQ(summary.spectrum_size(), local.spectrum().size());
  EXPECT_EQ(summary.backend(), testing::TestBackend());
  EXPECT_GT(summary.family_bytes(), 0u);

  EXPECT_EQ(SpectrumRemote(client, built->handle, 1000), local.spectrum());

  const int64_t k = local.max_level();
  for (const int64_t rank : {int64_t{0}, k / 3, k / 2, k}) {
    for (const auto mode : {v1::CLASSIFY_MODE_GENERAL, v1::CLASSIFY_MODE_REGULARIZED}) {
      v1::ClassifyRequest request;
      request.set_handle(built->handle);
      request.mutable_threshold()->set_rank(rank);
      request.set_mode(mode);
      request.set_vertex_rule(v1::VERTEX_RULE_CGAL);
      auto answer = ClassifyRemote(client, request);
      ASSERT_TRUE(answer.ok()) << answer.status();
      const ClassifyMode local_mode = mode == v1::CLASSIFY_MODE_GENERAL ? ClassifyMode::kGeneral : ClassifyMode::kRegularized;
      EXPECT_EQ(answer->rows, ClassifyLocal(local, rank, local_mode, VertexRule::kCgal)) << "rank " << rank;
      EXPECT_EQ(answer->summary.level(), rank);
      EXPECT_EQ(answer->summary.components(), local.Components(rank));
      EXPECT_EQ(answer->summary.solid_components(), local.SolidComponents(rank));
    }
  }

  if (k > 0) {
    v1::MasterListRequest request;
    request.set_handle(built->handle);
    request.set_first_rank(1);
    request.set_last_rank(k);
    std::vector<uint64_t> ranks;
    std::string kinds;
    absl::Status status = client.MasterList(request, [&](const v1::MasterListResponse& message) {
      ranks.insert(ranks.end(), message.ranks().begin(), message.ranks().end());
      kinds += message.kinds();
      return absl::OkStatus();
    });
    ASSERT_TRUE(status.ok()) << status;
    std::vector<uint64_t> local_ranks;
    std::string local_kinds;
    for (int64_t r = 1; r <= k; ++r) {
      for (const MasterEntry& entry : local.MasterList(r)) {
        local_ranks.push_back(static_cast<uint64_t>(r));
        local_kinds += static_cast<char>(static_cast<int>(entry.kind()) + 1);
      }
    }
    EXPECT_EQ(ranks, local_ranks);
    EXPECT_EQ(kinds, local_kinds);
  }

  v1::ComponentsRequest components;
  components.set_handle(built->handle);
  components.mutable_ranks()->set_first(0);
  components.mutable_ranks()->set_last(k);
  auto curve = client.Components(components);
  ASSERT_TRUE(curve.ok()) << curve.status();
  ASSERT_EQ(curve->components_size(), k + 1);
  for (int64_t level = 0; level <= k; ++level) {
    EXPECT_EQ(curve->components(static_cast<int>(level)), local.Components(level));
    EXPECT_EQ(curve->solid_components(static_cast<int>(level)), local.SolidComponents(level));
  }

  v1::OptimalAlphaRequest optimal;
  optimal.set_handle(built->handle);
  optimal.set_max_components(1);
  auto best = client.OptimalAlpha(optimal);
  ASSERT_TRUE(best.ok()) << best.status();
  EXPECT_EQ(best->has_regularized(), local.OptimalLevelRegularized(1).has_value());
  if (best->has_regularized()) {
    EXPECT_EQ(best->regularized().rank(), *local.OptimalLevelRegularized(1));
  }
  EXPECT_EQ(best->has_general(), local.OptimalLevelGeneral(1).has_value());
  if (best->has_general()) {
    EXPECT_EQ(best->general().rank(), *local.OptimalLevelGeneral(1));
  }

  v1::ShapeRequest shape;
  shape.set_handle(built->handle);
  shape.mutable_threshold()->set_rank(k / 2);
  shape.set_format(v1::SHAPE_FORMAT_GEOJSON);
  std::string text;
  absl::Status status = client.Shape(shape, [&](const v1::ShapeResponse& message) {
    text += message.text();
    return absl::OkStatus();
  });
  ASSERT_TRUE(status.ok()) << status;
  auto local_shape = AssembleShape(local.ComplexAt(k / 2, ClassifyMode::kGeneral));
  ASSERT_TRUE(local_shape.ok());
  EXPECT_EQ(text, ShapeToGeoJson(*local_shape, local.points()));
}

TEST(ServiceTest, EveryQueryMatchesTheLocalEngine) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  ExpectServiceMatchesLocal(*client, gen::Uniform(3000, 1), "uniform");
  ExpectServiceMatchesLocal(*client, gen::Grid(2500, 2), "grid");
  ExpectServiceMatchesLocal(*client, gen::WithDuplicates(2000, 3), "duplicates");
  ExpectServiceMatchesLocal(*client, gen::TwoLines(400, 4), "two lines");
  ExpectServiceMatchesLocal(*client, {{0.5, 0.25}}, "one point");
  ExpectServiceMatchesLocal(*client, {}, "no points");
  // A real data set, as users send them.
  const std::string file = testdata::DataDir() + "/gps_tracks_slovenia_croatia.bin";
  std::ifstream in(file, std::ios::binary);
  uint64_t n = 0;
  in.read(reinterpret_cast<char*>(&n), sizeof n);
  std::vector<Point2> gps(n);
  in.read(reinterpret_cast<char*>(gps.data()), static_cast<std::streamsize>(n * sizeof(Point2)));
  ASSERT_TRUE(in.good()) << file;
  ExpectServiceMatchesLocal(*client, gps, "gps tracks");
}

TEST(ServiceTest, DescribeReleaseAndTheCache) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  const std::vector<Point2> points = gen::Uniform(1000, 7);
  client::BuildCallOptions no_skip;
  no_skip.name = "first";
  no_skip.skip_upload_if_cached = false;
  auto first = client->Build(points, no_skip);
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_FALSE(first->cached);
  EXPECT_TRUE(first->uploaded);
  // The same points again: a cache hit, nothing recomputed (the summary is the first build's).
  auto again = client->Build(points, no_skip);
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_TRUE(again->cached);
  EXPECT_EQ(again->handle, first->handle);
  EXPECT_EQ(again->summary.SerializeAsString(), first->summary.SerializeAsString());
  // The client hashes locally and skips the upload.
  client::BuildCallOptions skip;
  skip.name = "third";
  auto skipped = client->Build(points, skip);
  ASSERT_TRUE(skipped.ok()) << skipped.status();
  EXPECT_TRUE(skipped->cached);
  EXPECT_FALSE(skipped->uploaded);
  auto described = client->Describe(first->handle);
  ASSERT_TRUE(described.ok()) << described.status();
  EXPECT_EQ(described->summary().name(), "first");
  EXPECT_EQ(server->service().cache().GetStats().entries, 1u);

  auto released = client->Release(first->handle);
  ASSERT_TRUE(released.ok());
  EXPECT_TRUE(released->released());
  EXPECT_TRUE(absl::IsNotFound(client->Describe(first->handle).status()));
  auto released_again = client->Release(first->handle);
  ASSERT_TRUE(released_again.ok());
  EXPECT_FALSE(released_again->released());
}

/// Streams `messages` as one Build call and returns its status.
absl::Status RawBuild(client::AlphaClient& client, const std::vector<v1::BuildRequest>& messages,
                      v1::BuildResponse* response = nullptr) {
  grpc::ClientContext context;
  v1::BuildResponse ignored;
  auto writer = client.stub().Build(&context, response != nullptr ? response : &ignored);
  for (const auto& message : messages) {
    if (!writer->Write(message)) break;
  }
  writer->WritesDone();
  return client::FromGrpc(writer->Finish());
}

v1::BuildRequest Header(uint64_t expected = 0) {
  v1::BuildRequest message;
  message.mutable_header()->set_expected_points(expected);
  return message;
}

v1::BuildRequest Chunk(const std::vector<double>& coordinates) {
  v1::BuildRequest message;
  message.mutable_points()->mutable_coordinates()->Add(coordinates.begin(), coordinates.end());
  return message;
}

TEST(ServiceTest, BuildStreamErrorsHaveClearStatuses) {
  ServerOptions options = TestServerOptions();
  options.service.max_points_per_build = 1000;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();

  absl::Status s = RawBuild(*client, {Header(), Chunk({0, 0, 1, 1, 2})});
  EXPECT_TRUE(absl::IsInvalidArgument(s)) << s;
  EXPECT_NE(s.message().find("odd number of doubles"), std::string::npos) << s;

  s = RawBuild(*client, {Header(), Chunk({0, 0, 1, 1}), Chunk({2, 2, 3, nan})});
  EXPECT_TRUE(absl::IsInvalidArgument(s)) << s;
  EXPECT_NE(s.message().find("point 3 has a NaN y coordinate"), std::string::npos) << s;

  s = RawBuild(*client, {Header(), Chunk({inf, 0})});
  EXPECT_NE(s.message().find("point 0 has a infinite x"), std::string::npos) << s;

  s = RawBuild(*client, {Chunk({0, 0})});
  EXPECT_TRUE(absl::IsInvalidArgument(s)) << s;
  EXPECT_NE(s.message().find("must start with a header"), std::string::npos) << s;

  s = RawBuild(*client, {Header(), Header()});
  EXPECT_NE(s.message().find("second header"), std::string::npos) << s;

  s = RawBuild(*client, {});
  EXPECT_TRUE(absl::IsInvalidArgument(s)) << s;
  EXPECT_NE(s.message().find("empty"), std::string::npos) << s;

  s = RawBuild(*client, {Header(2000)});
  EXPECT_TRUE(absl::IsResourceExhausted(s)) << s;
  std::vector<double> many(2 * 1001, 1.0);
  s = RawBuild(*client, {Header(), Chunk(many)});
  EXPECT_TRUE(absl::IsResourceExhausted(s)) << s;
  EXPECT_NE(s.message().find("1000 points"), std::string::npos) << s;

  s = RawBuild(*client, {Header(3), Chunk({0, 0, 1, 1})});
  EXPECT_TRUE(absl::IsInvalidArgument(s)) << s;
  EXPECT_NE(s.message().find("announced 3"), std::string::npos) << s;

  // Nothing of the failed builds stays in flight or in the cache.
  EXPECT_TRUE(WaitFor([&] { return server->service().in_flight_bytes() == 0; }, 5));
  EXPECT_EQ(server->service().cache().GetStats().entries, 0u);
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
  EXPECT_TRUE(absl::IsResourceExhausted(s)) << s;
  // 100000 announced points (1.6 MB) are over the bytes-in-flight limit.
  s = RawBuild(*client, {Header(100000)});
  EXPECT_TRUE(absl::IsResourceExhausted(s)) << s;
  EXPECT_NE(s.message().find("in flight"), std::string::npos) << s;
  // A build within the limits still works.
  auto ok = client->Build(gen::Uniform(1000, 5));
  EXPECT_TRUE(ok.ok()) << ok.status();
}

TEST(ServiceTest, QueryErrorsHaveClearStatuses) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  const std::string unknown = PointSetHandle(gen::Uniform(10, 99));
  absl::Status s = client->Describe(unknown).status();
  EXPECT_TRUE(absl::IsNotFound(s)) << s;
  s = client->Describe("not-a-handle").status();
  EXPECT_TRUE(absl::IsInvalidArgument(s)) << s;

  auto built = client->Build(gen::Uniform(500, 6));
  ASSERT_TRUE(built.ok()) << built.status();
  const int64_t k = static_cast<int64_t>(built->summary.spectrum_size());
  v1::ClassifyRequest classify;
  classify.set_handle(built->handle);
  s = client->Classify(classify, [](const v1::ClassifyResponse&) { return absl::OkStatus(); });
  EXPECT_TRUE(absl::IsInvalidArgument(s)) << s;
  EXPECT_NE(s.message().find("no threshold"), std::string::npos) << s;
  classify.mutable_threshold()->set_rank(k + 1);
  s = client->Classify(classify, [](const v1::ClassifyResponse&) { return absl::OkStatus(); });
  EXPECT_TRUE(absl::IsInvalidArgument(s)) << s;
  classify.mutable_threshold()->set_alpha(std::numeric_limits<double>::quiet_NaN());
  s = client->Classify(classify, [](const v1::ClassifyResponse&) { return absl::OkStatus(); });
  EXPECT_TRUE(absl::IsInvalidArgument(s)) << s;

  v1::MasterListRequest master;
  master.set_handle(built->handle);
  master.set_first_rank(0);
  s = client->MasterList(master, [](const v1::MasterListResponse&) { return absl::OkStatus(); });
  EXPECT_TRUE(absl::IsInvalidArgument(s)) << s;

  v1::SpectrumRequest spectrum;
  spectrum.set_handle(built->handle);
  spectrum.set_page_size(1u << 20);
  EXPECT_TRUE(absl::IsInvalidArgument(client->Spectrum(spectrum).status()));

  v1::ComponentsRequest components;
  components.set_handle(built->handle);
  EXPECT_TRUE(absl::IsInvalidArgument(client->Components(components).status()));

  v1::ShapeRequest shape;
  shape.set_handle(built->handle);
  shape.mutable_threshold()->set_rank(1);
  s = client->Shape(shape, [](const v1::ShapeResponse&) { return absl::OkStatus(); });
  EXPECT_TRUE(absl::IsInvalidArgument(s)) << s;

  v1::OptimalAlphaRequest optimal;
  optimal.set_handle(unknown);
  optimal.set_max_components(1);
  EXPECT_TRUE(absl::IsNotFound(client->OptimalAlpha(optimal).status()));
}

TEST(ServiceTest, ConcurrentBuildsFromSeveralClientsMatchTheLocalEngine) {
  ServerOptions options = TestServerOptions();
  options.service.build_slots = 2;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  constexpr int kClients = 6;
  std::vector<std::vector<Point2>> inputs;
  for (int i = 0; i < kClients; ++i) inputs.push_back(gen::Gaussian(4000 + 500 * (i % 3), 100 + static_cast<uint64_t>(i % 3)));
  std::vector<absl::StatusOr<client::BuildResult>> results(kClients, absl::UnknownError("not run"));
  std::vector<std::vector<double>> spectra(kClients);
  std::vector<std::thread> threads;
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
    ASSERT_TRUE(results[static_cast<size_t>(i)].ok()) << results[static_cast<size_t>(i)].status();
    EXPECT_EQ(spectra[static_cast<size_t>(i)], LocalFamily(inputs[static_cast<size_t>(i)]).spectrum()) << i;
  }
  // Three distinct inputs: three families, whatever the interleaving.
  EXPECT_EQ(server->service().cache().GetStats().entries, 3u);
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
  EXPECT_TRUE(absl::IsResourceExhausted(second.status())) << second.status();
  EXPECT_NE(second.status().message().find("queue is full"), std::string::npos);
  runner.join();
  EXPECT_TRUE(first.ok()) << first.status();
  EXPECT_EQ(ScrapeMetric(*server, "galpha_builds_rejected_total{reason=\"queue_or_memory\"}"), 1.0);
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
  EXPECT_EQ(server->service().cache().GetStats().entries, 0u);
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
    ASSERT_TRUE(first.ok()) << first.status();
    build_ms = 0;
    for (const auto& stage : first->summary.stage_times()) build_ms += 1e3 * stage.seconds();
    upload_ms = std::max(0.0, total_ms - build_ms);
    ASSERT_TRUE(unhurried->Release(first->handle).ok());
  }
  client::ClientOptions options;
  options.target = "127.0.0.1:" + std::to_string(server->port());
  options.deadline = std::chrono::milliseconds(static_cast<int64_t>(upload_ms + build_ms / 3) + 1);
  auto client = client::AlphaClient::Connect(options);
  ASSERT_TRUE(client.ok());
  auto built = (*client)->Build(points);
  EXPECT_EQ(built.status().code(), absl::StatusCode::kDeadlineExceeded) << built.status();
  // The build stops at its next phase boundary and frees what it held.
  EXPECT_TRUE(WaitFor([&] { return ScrapeMetric(*server, "galpha_builds_in_flight") == 0.0; }, 60));
  EXPECT_TRUE(WaitFor([&] { return server->service().in_flight_bytes() == 0; }, 10));
  EXPECT_EQ(server->service().cache().GetStats().entries, 0u);
}

TEST(ServiceTest, EvictionUnderASmallCacheBudget) {
  const std::vector<Point2> a = gen::Uniform(3000, 21), b = gen::Uniform(3000, 22);
  size_t one_family = 0;
  {
    auto probe = StartServer(TestServerOptions());
    ASSERT_NE(probe, nullptr);
    auto built = ClientOf(*probe)->Build(a);
    ASSERT_TRUE(built.ok());
    one_family = built->summary.family_bytes();
  }
  ServerOptions options = TestServerOptions();
  options.service.cache_bytes = one_family * 3 / 2;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  auto first = client->Build(a);
  ASSERT_TRUE(first.ok());
  auto second = client->Build(b);
  ASSERT_TRUE(second.ok());
  EXPECT_TRUE(absl::IsNotFound(client->Describe(first->handle).status()));
  EXPECT_TRUE(client->Describe(second->handle).ok());
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_evictions_total"), 1.0);
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_entries"), 1.0);
  // A family larger than the whole budget is refused, not cached half-way.
  auto huge = client->Build(gen::Uniform(20000, 23));
  EXPECT_TRUE(absl::IsResourceExhausted(huge.status())) << huge.status();
}

TEST(ServiceTest, MetricsAreScrapedOverHttp) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  auto built = client->Build(gen::Clustered(5000, 31));
  ASSERT_TRUE(built.ok());
  ASSERT_TRUE(client->Describe(built->handle).ok());
  ASSERT_FALSE(client->Describe(PointSetHandle(gen::Uniform(3, 1))).ok());
  const std::string page = testing::HttpGet(server->metrics_port(), "/metrics");
  using testing::MetricValue;
  EXPECT_EQ(MetricValue(page, "galpha_rpcs_total{code=\"OK\",method=\"Build\"}"), 1.0) << page;
  EXPECT_EQ(MetricValue(page, "galpha_rpcs_total{code=\"OK\",method=\"Describe\"}"), 1.0);
  // The client's check before uploading, and the unknown handle.
  EXPECT_EQ(MetricValue(page, "galpha_rpcs_total{code=\"NOT_FOUND\",method=\"Describe\"}"), 2.0);
  EXPECT_EQ(MetricValue(page, "galpha_build_stage_seconds_count{stage=\"insert_and_flip\"}"), 1.0);
  EXPECT_EQ(MetricValue(page, "galpha_build_seconds_count"), 1.0);
  const v1::ComparisonCounts& counts = built->summary.comparisons();
  EXPECT_EQ(MetricValue(page, "galpha_radius_comparisons_total{path=\"filter\"}"), static_cast<double>(counts.filter()));
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
  ASSERT_TRUE(built.ok());

  EXPECT_EQ(testing::HealthOf(channel, "galpha.liveness"), "SERVING");
  std::thread drain([&] { server->Drain(); });
  EXPECT_TRUE(WaitFor([&] { return testing::HealthOf(channel, "") == "NOT_SERVING"; }, 5));
  EXPECT_EQ(testing::HealthOf(channel, "galpha.v1.AlphaShapes"), "NOT_SERVING");
  EXPECT_EQ(testing::HealthOf(channel, "galpha.liveness"), "SERVING");
  // During the notice: new builds are refused, queries still answered.
  client::BuildCallOptions upload;
  upload.skip_upload_if_cached = false;
  auto refused = client->Build(gen::Uniform(100, 42), upload);
  EXPECT_TRUE(absl::IsUnavailable(refused.status())) << refused.status();
  EXPECT_TRUE(client->Describe(built->handle).ok());
  drain.join();
  EXPECT_FALSE(client->Describe(built->handle).ok());
}

/// A self-signed certificate for "localhost" made with the openssl command.
bool MakeCertificate(const std::string& dir) {
  const std::string command = "openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=localhost "
                              "-addext subjectAltName=DNS:localhost -keyout " +
                              dir + "/key.pem -out " + dir + "/cert.pem >/dev/null 2>&1";
  return std::system(command.c_str()) == 0;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(ServiceTest, TlsAndTenantScopedTokens) {
  const std::string dir = std::filesystem::temp_directory_path() / ("galpha_tls_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(MakeCertificate(dir)) << "openssl could not make a test certificate";
  ServerOptions options = TestServerOptions();
  options.tls_cert_file = dir + "/cert.pem";
  options.tls_key_file = dir + "/key.pem";
  auto tokens = TenantTokens::Parse("token-a tenant-a\ntoken-b tenant-b\n", "test");
  ASSERT_TRUE(tokens.ok());
  options.service.tokens = *tokens;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);

  auto connect = [&](const std::string& token, bool tls) {
    client::ClientOptions client_options;
    client_options.target = "localhost:" + std::to_string(server->port());
    client_options.bearer_token = token;
    if (tls) client_options.tls_root_certs_pem = ReadFile(dir + "/cert.pem");
    client_options.deadline = std::chrono::seconds(30);
    return *client::AlphaClient::Connect(client_options);
  };
  const std::vector<Point2> points = gen::Uniform(800, 51);
  auto a = connect("token-a", true);
  auto built = a->Build(points);
  ASSERT_TRUE(built.ok()) << built.status();
  EXPECT_TRUE(a->Describe(built->handle).ok());

  // Plaintext against a TLS port fails; no token or an unknown one is UNAUTHENTICATED.
  EXPECT_FALSE(connect("token-a", false)->Describe(built->handle).ok());
  EXPECT_TRUE(absl::IsUnauthenticated(connect("", true)->Describe(built->handle).status()));
  EXPECT_TRUE(absl::IsUnauthenticated(connect("token-x", true)->Describe(built->handle).status()));
  client::BuildCallOptions upload;
  upload.skip_upload_if_cached = false;
  EXPECT_TRUE(absl::IsUnauthenticated(connect("", true)->Build(points, upload).status()));

  // Another tenant cannot see tenant A's family, even with its handle; its own build is its own.
  auto b = connect("token-b", true);
  EXPECT_TRUE(absl::IsNotFound(b->Describe(built->handle).status()));
  auto b_built = b->Build(points, upload);
  ASSERT_TRUE(b_built.ok()) << b_built.status();
  EXPECT_FALSE(b_built->cached);
  EXPECT_EQ(b_built->handle, built->handle);
  auto released = b->Release(built->handle);
  ASSERT_TRUE(released.ok());
  EXPECT_TRUE(a->Describe(built->handle).ok());  // B's release dropped only B's entry
  std::filesystem::remove_all(dir);
}

/// Records the routing header of every call it gets, and answers NOT_FOUND / UNAVAILABLE.
class HeaderRecorder final : public v1::AlphaShapes::CallbackService {
 public:
  std::vector<std::string> headers() {
    std::lock_guard<std::mutex> lock(mutex_);
    return headers_;
  }
  grpc::ServerUnaryReactor* Describe(grpc::CallbackServerContext* context, const v1::DescribeRequest*,
                                     v1::DescribeResponse*) override {
    Record(context);
    auto* reactor = context->DefaultReactor();
    reactor->Finish(grpc::Status(grpc::StatusCode::NOT_FOUND, "recorder"));
    return reactor;
  }
  grpc::ServerReadReactor<v1::BuildRequest>* Build(grpc::CallbackServerContext* context,
                                                   v1::BuildResponse*) override {
    Record(context);
    class Refuse final : public grpc::ServerReadReactor<v1::BuildRequest> {
     public:
      Refuse() { Finish(grpc::Status(grpc::StatusCode::UNAVAILABLE, "recorder")); }
      void OnDone() override { delete this; }
    };
    return new Refuse();
  }

 private:
  void Record(grpc::CallbackServerContext* context) {
    const auto it = context->client_metadata().find(client::kHandleHeader);
    std::lock_guard<std::mutex> lock(mutex_);
    headers_.push_back(it == context->client_metadata().end() ? "(none)"
                                                              : std::string(it->second.data(), it->second.size()));
  }
  std::mutex mutex_;
  std::vector<std::string> headers_;
};

TEST(ServiceTest, TheClientSendsTheHandleForRouting) {
  HeaderRecorder recorder;
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
  builder.RegisterService(&recorder);
  auto server = builder.BuildAndStart();
  ASSERT_NE(server, nullptr);
  client::ClientOptions options;
  options.target = "127.0.0.1:" + std::to_string(port);
  auto client = *client::AlphaClient::Connect(options);
  const std::vector<Point2> points = gen::Uniform(1000, 61);
  // Describe (is it cached?) then the upload: both carry the handle computed before uploading.
  EXPECT_TRUE(absl::IsUnavailable(client->Build(points).status()));
  EXPECT_EQ(recorder.headers(), std::vector<std::string>(2, PointSetHandle(points)));
  server->Shutdown();
}

}  // namespace
}  // namespace galpha::server
