// service_bench: the service under load, in one process on loopback (a real gRPC server and real
// clients over TCP): the cost of the transport against the in-process engine, the streaming rate
// of Classify, build throughput with N concurrent clients, and query latency percentiles under
// concurrent load. CGAL's Alpha_shape_2 (exact constructions) on the same points, in the same run,
// is the competitor's reference.
//
//   service_bench [--backend=auto|cpu|cuda] [--points=N] [--clients=1,2,4,8] [--repeat=R]
//                 [--query-seconds=S] [--query-clients=Q] [--build-slots=K] [--cgal-max=N]
#include <CGAL/Alpha_shape_2.h>
#include <CGAL/Alpha_shape_face_base_2.h>
#include <CGAL/Alpha_shape_vertex_base_2.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "client/galpha_client.hpp"
#include "core/io/point_set_handle.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "server/galpha_server.hpp"
#include "tests/support/point_generators.hpp"

namespace galpha {
namespace {

namespace v1 = galpha::v1;
using Clock = std::chrono::steady_clock;

struct Options {
  Backend backend = Backend::kAuto;
  size_t points = 1000000;
  std::vector<int> clients = {1, 2, 4, 8};
  int repeat = 3;
  double query_seconds = 5;
  int query_clients = 8;
  int build_slots = 0;
  size_t cgal_max = 1000000;
};

double SecondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

bool ParseOptions(int argc, char** argv, Options* options) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const size_t eq = arg.find('=');
    const std::string name = arg.substr(0, eq), value = eq == std::string::npos ? "" : arg.substr(eq + 1);
    bool ok = true;
    if (name == "--backend") {
      options->backend = value == "cpu" ? Backend::kCpu : value == "cuda" ? Backend::kCuda : Backend::kAuto;
      ok = value == "cpu" || value == "cuda" || value == "auto";
    } else if (name == "--points") {
      ok = absl::SimpleAtoi(value, &options->points);
    } else if (name == "--clients") {
      options->clients.clear();
      for (absl::string_view c : absl::StrSplit(value, ',')) {
        int count = 0;
        ok = ok && absl::SimpleAtoi(c, &count) && count > 0;
        options->clients.push_back(count);
      }
    } else if (name == "--repeat") {
      ok = absl::SimpleAtoi(value, &options->repeat) && options->repeat > 0;
    } else if (name == "--query-seconds") {
      ok = absl::SimpleAtod(value, &options->query_seconds);
    } else if (name == "--query-clients") {
      ok = absl::SimpleAtoi(value, &options->query_clients) && options->query_clients > 0;
    } else if (name == "--build-slots") {
      ok = absl::SimpleAtoi(value, &options->build_slots);
    } else if (name == "--cgal-max") {
      ok = absl::SimpleAtoi(value, &options->cgal_max);
    } else {
      ok = false;
    }
    if (!ok) {
      std::fprintf(stderr, "service_bench: bad option '%s'\n", arg.c_str());
      return false;
    }
  }
  return true;
}

double CgalSeconds(const std::vector<Point2>& points) {
  using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
  using Tds = CGAL::Triangulation_data_structure_2<CGAL::Alpha_shape_vertex_base_2<Kernel>,
                                                   CGAL::Alpha_shape_face_base_2<Kernel>>;
  using AlphaShape = CGAL::Alpha_shape_2<CGAL::Delaunay_triangulation_2<Kernel, Tds>>;
  std::vector<Kernel::Point_2> cgal_points;
  cgal_points.reserve(points.size());
  for (const Point2& p : points) cgal_points.emplace_back(p.x, p.y);
  const auto start = Clock::now();
  AlphaShape shape(cgal_points.begin(), cgal_points.end(), 0, AlphaShape::GENERAL);
  const double seconds = SecondsSince(start);
  if (shape.number_of_alphas() == 0 && points.size() > 2) std::fprintf(stderr, "CGAL built no spectrum\n");
  return seconds;
}

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<size_t>(q * static_cast<double>(values.size())))];
}

std::unique_ptr<client::AlphaClient> Client(int port) {
  client::ClientOptions options;
  options.target = "127.0.0.1:" + std::to_string(port);
  return *client::AlphaClient::Connect(options);
}

/// Releases, then uploads and builds `points`; the RPC's wall time.
double TimedBuild(client::AlphaClient& client, const std::vector<Point2>& points, v1::BuildSummary* summary) {
  if (auto released = client.Release(PointSetHandle(points)); !released.ok()) {
    std::fprintf(stderr, "release failed: %s\n", std::string(released.status().message()).c_str());
    std::exit(1);
  }
  client::BuildCallOptions call;
  call.skip_upload_if_cached = false;
  const auto start = Clock::now();
  auto built = client.Build(points, call);
  const double seconds = SecondsSince(start);
  if (!built.ok()) {
    std::fprintf(stderr, "build failed: %s\n", std::string(built.status().message()).c_str());
    std::exit(1);
  }
  if (summary != nullptr) *summary = built->summary;
  return seconds;
}

int Run(const Options& options) {
  server::ServerOptions server_options;
  server_options.listen_address = "127.0.0.1:0";
  server_options.metrics_address = "";
  server_options.service.backend = options.backend;
  server_options.service.build_slots = options.build_slots;
  server_options.service.max_queued_builds = 256;
  server_options.service.cache_bytes = size_t{64} << 30;
  server_options.service.max_in_flight_bytes = size_t{64} << 30;
  // The bench's clients are one anonymous tenant: its share must not be what limits them.
  server_options.service.max_tenant_queued_builds = 256;
  server_options.service.max_tenant_in_flight_bytes = size_t{64} << 30;
  server_options.drain_notice = std::chrono::milliseconds(0);
  auto server = server::GalphaServer::Start(server_options);
  if (!server.ok()) {
    std::fprintf(stderr, "service_bench: %s\n", std::string(server.status().message()).c_str());
    return 1;
  }
  const int port = (*server)->port();
  const std::string backend = (*server)->service().backend_name();
  std::printf("service_bench: %zu uniform points, %s backend, %zu build slots, best of %d, %u host threads\n\n",
              options.points, backend.c_str(), (*server)->service().build_slots(), options.repeat,
              std::thread::hardware_concurrency());
  auto client = Client(port);
  const std::vector<Point2> points = gen::Uniform(options.points, 1);

  // 1. One build: in-process engine, the same through gRPC, CGAL.
  double engine = 1e30, rpc = 1e30, server_engine = 1e30;
  for (int r = 0; r < options.repeat; ++r) {
    BuildOptions build;
    build.backend = options.backend;
    const auto start = Clock::now();
    auto family = BuildAlphaFamily(points, build);
    engine = std::min(engine, SecondsSince(start));
    if (!family.ok()) return 1;
    v1::BuildSummary summary;
    rpc = std::min(rpc, TimedBuild(*client, points, &summary));
    double stages = 0;
    for (const auto& s : summary.stage_times()) stages += s.seconds();
    server_engine = std::min(server_engine, stages);
  }
  const double cgal = options.points <= options.cgal_max ? CgalSeconds(points) : -1;
  std::printf("| one build of %zu points | ms | vs in-process |\n|---|---:|---:|\n", options.points);
  std::printf("| in-process BuildAlphaFamily (wall) | %.1f | 1.00 |\n", engine * 1e3);
  std::printf("| Build RPC over loopback (upload + build + answer) | %.1f | %.2f |\n", rpc * 1e3, rpc / engine);
  std::printf("| of which the server's stage times | %.1f | |\n", server_engine * 1e3);
  if (cgal >= 0) std::printf("| CGAL Alpha_shape_2 EPEC, 1 thread | %.1f | %.2f |\n", cgal * 1e3, cgal / engine);
  std::printf("\n");

  // 2. Classify streaming rate: every simplex at the middle rank.
  const std::string handle = PointSetHandle(points);
  v1::SpectrumRequest size_request;
  size_request.set_handle(handle);
  size_request.set_page_size(1);
  const int64_t k = client->Spectrum(size_request)->spectrum_size();
  v1::ClassifyRequest classify;
  classify.set_handle(handle);
  classify.mutable_threshold()->set_rank(k / 2);
  double classify_seconds = 1e30;
  size_t bytes = 0, simplices = 0;
  for (int r = 0; r < options.repeat; ++r) {
    bytes = simplices = 0;
    const auto start = Clock::now();
    absl::Status status = client->Classify(classify, [&](const v1::ClassifyResponse& message) {
      bytes += message.ByteSizeLong();
      simplices += message.chunk().classes().size();
      return absl::OkStatus();
    });
    classify_seconds = std::min(classify_seconds, SecondsSince(start));
    if (!status.ok()) return 1;
  }
  std::printf("| Classify, all simplices at rank K/2 | value |\n|---|---:|\n");
  std::printf("| simplices | %zu |\n| bytes on the wire (messages) | %zu |\n| ms | %.1f |\n| GB/s | %.2f |\n\n",
              simplices, bytes, classify_seconds * 1e3, static_cast<double>(bytes) / classify_seconds / 1e9);

  // 3. Concurrent builds of distinct point sets.
  std::printf(
      "| concurrent clients | builds | wall s | builds/s | throughput vs 1 client |\n|---:|---:|---:|---:|---:|\n");
  double single_rate = 0;
  for (const int c : options.clients) {
    std::vector<std::vector<Point2>> inputs;
    inputs.reserve(static_cast<size_t>(c));
    for (int i = 0; i < c; ++i) inputs.push_back(gen::Uniform(options.points, 1000 + static_cast<uint64_t>(i)));
    // Connected before the clock starts (each client has a connection of its own); best of the
    // repeats, the families released between them.
    std::vector<std::unique_ptr<client::AlphaClient>> clients;
    clients.reserve(static_cast<size_t>(c));
    for (int i = 0; i < c; ++i) clients.push_back(Client(port));
    double wall = std::numeric_limits<double>::infinity();
    for (int r = 0; r < options.repeat; ++r) {
      std::vector<std::thread> threads;
      threads.reserve(static_cast<size_t>(c));
      const auto start = Clock::now();
      for (int i = 0; i < c; ++i) {
        threads.emplace_back(
            [&, i] { TimedBuild(*clients[static_cast<size_t>(i)], inputs[static_cast<size_t>(i)], nullptr); });
      }
      for (auto& t : threads) t.join();
      wall = std::min(wall, SecondsSince(start));
      for (const auto& input : inputs) client->Release(PointSetHandle(input)).IgnoreError();
    }
    const double rate = c / wall;
    if (single_rate == 0) single_rate = rate;
    std::printf("| %d | %d | %.3f | %.2f | %.2fx |\n", c, c, wall, rate, rate / single_rate);
  }
  std::printf("\n");

  // 4. Query latency under concurrent load.
  std::map<std::string, std::vector<double>> latencies;
  std::mutex mutex;
  std::atomic<bool> stop{false};
  std::vector<std::thread> threads;
  threads.reserve(static_cast<size_t>(options.query_clients));
  for (int q = 0; q < options.query_clients; ++q) {
    threads.emplace_back([&, q] {
      auto own = Client(port);
      std::map<std::string, std::vector<double>> mine;
      uint64_t i = static_cast<uint64_t>(q);
      while (!stop) {
        const int64_t rank = static_cast<int64_t>((i * 7919) % static_cast<uint64_t>(k + 1));
        auto start = Clock::now();
        (void)own->Describe(handle);
        mine["Describe"].push_back(SecondsSince(start));
        v1::SpectrumRequest page;
        page.set_handle(handle);
        page.set_first_rank(std::max<int64_t>(1, rank));
        page.set_page_size(1000);
        start = Clock::now();
        (void)own->Spectrum(page);
        mine["Spectrum (1000 values)"].push_back(SecondsSince(start));
        v1::ComponentsRequest components;
        components.set_handle(handle);
        components.mutable_threshold()->set_rank(rank);
        start = Clock::now();
        (void)own->Components(components);
        mine["Components"].push_back(SecondsSince(start));
        v1::ClassifyRequest summary;
        summary.set_handle(handle);
        summary.mutable_threshold()->set_rank(rank);
        summary.set_summary_only(true);
        start = Clock::now();
        (void)own->Classify(summary, [](const v1::ClassifyResponse&) { return absl::OkStatus(); });
        mine["Classify summary (counts at a rank)"].push_back(SecondsSince(start));
        ++i;
      }
      std::lock_guard<std::mutex> lock(mutex);
      for (auto& [name, values] : mine) latencies[name].insert(latencies[name].end(), values.begin(), values.end());
    });
  }
  std::this_thread::sleep_for(std::chrono::duration<double>(options.query_seconds));
  stop = true;
  for (auto& t : threads) t.join();
  std::printf("| query (%d clients, %.0f s) | calls | p50 ms | p90 ms | p99 ms |\n|---|---:|---:|---:|---:|\n",
              options.query_clients, options.query_seconds);
  for (const auto& [name, values] : latencies) {
    std::printf("| %s | %zu | %.3f | %.3f | %.3f |\n", name.c_str(), values.size(), Percentile(values, 0.5) * 1e3,
                Percentile(values, 0.9) * 1e3, Percentile(values, 0.99) * 1e3);
  }
  (*server)->Drain();
  return 0;
}

}  // namespace
}  // namespace galpha

int main(int argc, char** argv) {
  galpha::Options options;
  if (!galpha::ParseOptions(argc, argv, &options)) return 2;
  return galpha::Run(options);
}
