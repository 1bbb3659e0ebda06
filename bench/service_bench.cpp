// service_bench: the service under load, in one process on loopback (a real gRPC server and real
// clients over TCP): the cost of the transport against the in-process engine, the streaming rate
// of Classify, build throughput with N concurrent clients, query latency percentiles under
// concurrent load, and the first query of a family demoted to the cache's compact tier (its rebuild). CGAL's
// Alpha_shape_2 (exact constructions) on the same points, in the same run, is the competitor's reference. With --links
// naming tc rates (root only), the build and Classify are also measured over a veth pair between two network namespaces
// shaped to each rate.
//
//   service_bench [--backend=auto|cpu|cuda] [--points=N] [--clients=1,2,4,8] [--repeat=R]
//                 [--query-seconds=S] [--query-clients=Q] [--build-slots=K] [--cgal-max=N]
//                 [--links=loopback,1gbit,10gbit] [--device-cache-bytes=N] [--classify-parts=1,2,4,8]
// --classify-parts lists the part counts (ClientOptions::classify_parts) the parts table reads the
// uniform set's Classify in; the other tables read it in one call.
// --device-cache-bytes gives the server a device budget for resident families (CUDA builds keep
// their tables on the GPU and answer from there: server/README.md, "Cache"); 0 (the default):
// CUDA families are downloaded into host memory, as the CPU backend's are.
// --batch=SETSxPOINTS (e.g. 10000x1000) runs only the batch scenario of issue 20: the sets in one
// BuildBatch call (packed into one build, and one set a host core), against one Build a set and
// one Build of all their points (RunBatch).
// --stress=SETSxPOINTS (e.g. 8x20000000) runs only the stress scenario of issue 16: SETS clients
// build SETS distinct point sets at once, then each queries every family (Describe and a Classify
// summary; a family the cache pushed out is rebuilt by the query), then every family is released;
// it prints the failures, the cache's movements, the device memory before, at the peak and after
// the release (the server gives its pool's memory back after --device_idle_release_ms of idleness).
#include <CGAL/Alpha_shape_2.h>
#include <CGAL/Alpha_shape_face_base_2.h>
#include <CGAL/Alpha_shape_vertex_base_2.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <fcntl.h>
#include <grpcpp/grpcpp.h>
#include <sched.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "client/galpha_client.hpp"
#include "core/io/point_io.hpp"
#include "core/io/point_set_handle.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gpu/system/device_streams.hpp"
#include "server/galpha_server.hpp"
#include "tests/support/data_files.hpp"
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
  /// "loopback" and tc rates ("1gbit", "10gbit", "100mbit"): the links Build and Classify cross.
  std::vector<std::string> links = {"loopback"};
  /// The part counts the parts table reads the uniform set's Classify in (ClientOptions::classify_parts).
  std::vector<uint32_t> classify_parts = {1, 2, 4, 8};
  size_t device_cache_bytes = 0;
  /// --stress: how many sets of how many points (0: no stress run).
  size_t stress_sets = 0;
  size_t stress_points = 0;
  /// --batch: how many sets of how many points go up in one BuildBatch call (0: no batch run).
  size_t batch_sets = 0;
  size_t batch_points = 0;
};

/// A tc rate "<digits><kbit|mbit|gbit>" in bits per second; 0 when it is not one.
double RateBits(const std::string& rate) {
  const size_t unit = rate.find_first_not_of("0123456789");
  double value = 0;
  if (unit == 0 || unit == std::string::npos || !absl::SimpleAtod(rate.substr(0, unit), &value)) return 0;
  const std::string suffix = rate.substr(unit);
  const double scale = suffix == "kbit" ? 1e3 : suffix == "mbit" ? 1e6 : suffix == "gbit" ? 1e9 : 0;
  return value * scale;
}

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
    } else if (name == "--device-cache-bytes") {
      ok = absl::SimpleAtoi(value, &options->device_cache_bytes);
    } else if (name == "--stress") {
      const std::vector<std::string> parts = absl::StrSplit(value, 'x');
      ok = parts.size() == 2 && absl::SimpleAtoi(parts[0], &options->stress_sets) &&
           absl::SimpleAtoi(parts[1], &options->stress_points) && options->stress_sets > 0 &&
           options->stress_points > 0;
    } else if (name == "--batch") {
      const std::vector<std::string> parts = absl::StrSplit(value, 'x');
      ok = parts.size() == 2 && absl::SimpleAtoi(parts[0], &options->batch_sets) &&
           absl::SimpleAtoi(parts[1], &options->batch_points) && options->batch_sets > 0 && options->batch_points > 0;
    } else if (name == "--classify-parts") {
      options->classify_parts.clear();
      for (const absl::string_view part : absl::StrSplit(value, ',')) {
        uint32_t count = 0;
        ok = ok && absl::SimpleAtoi(part, &count) && count >= 1 && count <= client::kMaxClassifyParts;
        options->classify_parts.push_back(count);
      }
    } else if (name == "--links") {
      options->links = absl::StrSplit(value, ',');
      for (const std::string& link : options->links) ok = ok && (link == "loopback" || RateBits(link) > 0);
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

server::ServerOptions BenchServerOptions(const Options& options, const std::string& listen_address) {
  server::ServerOptions server_options;
  server_options.listen_address = listen_address;
  server_options.metrics_address = "";
  server_options.service.backend = options.backend;
  server_options.service.build_slots = options.build_slots;
  server_options.service.max_queued_builds = 256;
  server_options.service.cache_bytes = size_t{64} << 30;
  server_options.service.device_cache_bytes = options.device_cache_bytes;
  server_options.service.max_in_flight_bytes = size_t{64} << 30;
  // The bench's clients are one anonymous tenant: its share must not be what limits them.
  server_options.service.max_tenant_queued_builds = 256;
  server_options.service.max_tenant_in_flight_bytes = size_t{64} << 30;
  server_options.drain_notice = std::chrono::milliseconds(0);
  return server_options;
}

/// Runs a command (no shell) and waits; true when it exits 0. posix_spawn rather than fork, so
/// that gRPC's threads and fork handlers are not involved; `quiet` sends its output to /dev/null.
bool RunCommand(const std::vector<std::string>& args, bool quiet = false) {
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (quiet) {
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  }
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return false;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

/// Two network namespaces joined by a veth pair, shaped with tc: this process moves to a new
/// namespace (the client's side, 10.77.0.1) and a forked child serves from another (10.77.0.2).
/// Both namespaces are anonymous, so they vanish with their last process: no exit path (an error,
/// a signal, SIGKILL) leaves one behind. Create() must run before the process starts a thread.
class VethLink {
 public:
  static constexpr const char* kClientAddress = "10.77.0.1";
  static constexpr const char* kServerAddress = "10.77.0.2";

  /// Why shaped links cannot be measured here (not root, `ip`/`tc`/`nsenter` missing), or "".
  static std::string Unavailable() {
    if (geteuid() != 0) return "shaped links need root (network namespaces, veth, tc)";
    for (const char* tool : {"ip", "tc", "nsenter"}) {
      if (!RunCommand({tool, "-V"}, true) && !RunCommand({tool, "--version"}, true)) {
        return absl::StrCat("shaped links need `", tool, "`, which is not on PATH");
      }
    }
    return "";
  }

  static absl::StatusOr<std::unique_ptr<VethLink>> Create(const server::ServerOptions& server_options) {
    if (unshare(CLONE_NEWNET) != 0) return absl::InternalError(absl::StrCat("unshare: ", std::strerror(errno)));
    // The in-process loopback server lives in the new namespace too: its loopback must be up.
    if (!RunCommand({"ip", "link", "set", "lo", "up"})) return absl::InternalError("ip link set lo up failed");
    std::unique_ptr<VethLink> link(new VethLink);
    int up[2], down[2];
    if (pipe(up) != 0 || pipe(down) != 0) return absl::InternalError("pipe failed");
    std::fflush(stdout);
    link->child_ = fork();
    if (link->child_ < 0) return absl::InternalError(absl::StrCat("fork: ", std::strerror(errno)));
    if (link->child_ == 0) {
      close(up[0]);
      close(down[1]);
      _exit(ServeInChild(server_options, up[1], down[0]));
    }
    close(up[1]);
    close(down[0]);
    link->to_child_ = down[1];
    link->from_child_ = up[0];
    char ready = 0;
    if (read(link->from_child_, &ready, 1) != 1) return absl::InternalError("the server's child did not start");
    const std::string pid = std::to_string(link->child_);
    const bool configured =
        RunCommand({"ip", "link", "add", "galpha-c", "type", "veth", "peer", "name", "galpha-s", "netns", pid}) &&
        RunCommand({"ip", "addr", "add", absl::StrCat(kClientAddress, "/24"), "dev", "galpha-c"}) &&
        RunCommand({"ip", "link", "set", "galpha-c", "up"}) &&
        RunCommand(link->InChild({"ip", "link", "set", "lo", "up"})) &&
        RunCommand(link->InChild({"ip", "addr", "add", absl::StrCat(kServerAddress, "/24"), "dev", "galpha-s"})) &&
        RunCommand(link->InChild({"ip", "link", "set", "galpha-s", "up"}));
    if (!configured) return absl::InternalError("configuring the veth pair failed (see ip's message above)");
    // Some kernels (this build machine's) lack sch_netem: then the rate is shaped, the RTT is not.
    link->netem_ = RunCommand({"tc", "qdisc", "add", "dev", "galpha-c", "root", "netem", "delay", "500us"}, true);
    if (link->netem_) RunCommand({"tc", "qdisc", "del", "dev", "galpha-c", "root"}, true);
    if (write(link->to_child_, "g", 1) != 1 ||
        read(link->from_child_, &link->port_, sizeof link->port_) != static_cast<ssize_t>(sizeof link->port_) ||
        link->port_ <= 0) {
      return absl::InternalError("the server in the other namespace did not start");
    }
    return link;
  }

  VethLink(const VethLink&) = delete;
  VethLink& operator=(const VethLink&) = delete;

  /// Closing the pipe tells the child to drain and exit.
  ~VethLink() {
    if (to_child_ >= 0) close(to_child_);
    if (from_child_ >= 0) close(from_child_);
    if (child_ > 0) waitpid(child_, nullptr, 0);
  }

  /// Shapes both directions to `rate` with tbf (a burst of 1 ms at the rate, at least 64 KiB), under
  /// a netem delay of 0.5 ms each way (1 ms RTT) where the kernel has netem.
  absl::Status Shape(const std::string& rate) {
    const auto burst = static_cast<uint64_t>(std::max(65536.0, RateBits(rate) / 8 / 1000));
    for (const bool server_side : {false, true}) {
      const std::string dev = server_side ? "galpha-s" : "galpha-c";
      auto tc = [&](std::vector<std::string> args, bool quiet = false) {
        args.insert(args.begin(), "tc");
        return RunCommand(server_side ? InChild(args) : args, quiet);
      };
      tc({"qdisc", "del", "dev", dev, "root"}, true);  // the previous link's shaping, if any
      const std::string burst_bytes = std::to_string(burst);
      const bool shaped =
          netem_
              ? tc({"qdisc", "add", "dev", dev, "root", "handle", "1:", "netem", "delay", "500us", "limit",
                    "100000"}) &&
                    tc({"qdisc", "add", "dev", dev, "parent", "1:1", "handle", "10:", "tbf", "rate", rate, "burst",
                        burst_bytes, "latency", "50ms"})
              : tc({"qdisc", "add", "dev", dev, "root", "tbf", "rate", rate, "burst", burst_bytes, "latency", "50ms"});
      if (!shaped) return absl::InternalError(absl::StrCat("tc could not shape ", dev, " to ", rate));
    }
    return absl::OkStatus();
  }

  bool rtt_emulated() const { return netem_; }
  std::string target() const { return absl::StrCat(kServerAddress, ":", port_); }

 private:
  VethLink() = default;

  /// The command, run in the child's namespace.
  std::vector<std::string> InChild(std::vector<std::string> args) const {
    args.insert(args.begin(), {"nsenter", absl::StrCat("--net=/proc/", child_, "/ns/net")});
    return args;
  }

  /// The child: a namespace of its own, then (once the parent has joined it to the veth pair) a
  /// server on kServerAddress until the parent closes the pipe or dies.
  static int ServeInChild(server::ServerOptions options, int up, int down) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (unshare(CLONE_NEWNET) != 0 || write(up, "r", 1) != 1) return 1;
    char go = 0;
    if (read(down, &go, 1) != 1) return 1;
    options.listen_address = absl::StrCat(kServerAddress, ":0");
    auto server = server::GalphaServer::Start(options);
    const int port = server.ok() ? (*server)->port() : -1;
    if (!server.ok())
      std::fprintf(stderr, "service_bench (server side): %s\n", std::string(server.status().message()).c_str());
    if (write(up, &port, sizeof port) != static_cast<ssize_t>(sizeof port) || !server.ok()) return 1;
    while (read(down, &go, 1) > 0) {}
    (*server)->Drain();
    return 0;
  }

  pid_t child_ = -1;
  int to_child_ = -1, from_child_ = -1;
  int port_ = 0;
  bool netem_ = false;
};

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

/// A client whose Classify answers come in `classify_parts` calls (1: one call, so that the first
/// tables compare with earlier runs; the parts table sets its own).
std::unique_ptr<client::AlphaClient> Client(const std::string& target, uint32_t classify_parts = 1) {
  client::ClientOptions options;
  options.target = target;
  options.classify_parts = classify_parts;
  return *client::AlphaClient::Connect(options);
}

std::unique_ptr<client::AlphaClient> Client(int port, uint32_t classify_parts = 1) {
  return Client("127.0.0.1:" + std::to_string(port), classify_parts);
}

/// Releases, then uploads and builds `points`; the RPC's wall time.
double TimedBuild(client::AlphaClient& client, const std::vector<Point2>& points, client::BuildResult* result) {
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
  if (result != nullptr) *result = *built;
  return seconds;
}

/// The answer encodings Classify is measured in (ClassifyRequest.simplex_encoding).
constexpr std::array<v1::SimplexEncoding, 3> kAnswerEncodings = {v1::SIMPLEX_ENCODING_RAW, v1::SIMPLEX_ENCODING_DELTA,
                                                                 v1::SIMPLEX_ENCODING_DELTA_ZSTD};
const char* AnswerEncodingName(v1::SimplexEncoding encoding) {
  return encoding == v1::SIMPLEX_ENCODING_RAW ? "raw" : encoding == v1::SIMPLEX_ENCODING_DELTA ? "delta" : "zstd";
}

/// One Classify of every simplex at rank K/2 in one answer encoding (best of the repeats):
/// `wire_bytes` as they crossed the link, `answer_bytes` the raw messages the client decoded them to.
struct ClassifyMeasure {
  double seconds = 1e30;
  double first_message_seconds = 0;  // of the fastest repeat: the server's classification before the stream
  uint64_t wire_bytes = 0, answer_bytes = 0, simplices = 0;
};

/// One build and one Classify of every simplex at rank K/2 per answer encoding, over one link
/// (best of `repeat`).
struct LinkMeasure {
  double build_seconds = 1e30, server_stage_seconds = 1e30;
  uint64_t bytes_up = 0;
  int64_t spectrum_size = 0;
  std::array<ClassifyMeasure, kAnswerEncodings.size()> classify;
};

std::array<ClassifyMeasure, kAnswerEncodings.size()> MeasureClassify(client::AlphaClient& client,
                                                                     const std::string& handle, int64_t rank,
                                                                     int repeat) {
  std::array<ClassifyMeasure, kAnswerEncodings.size()> measured;
  for (size_t e = 0; e < kAnswerEncodings.size(); ++e) {
    v1::ClassifyRequest classify;
    classify.set_handle(handle);
    classify.mutable_threshold()->set_rank(rank);
    classify.set_simplex_encoding(kAnswerEncodings[e]);
    ClassifyMeasure& m = measured[e];
    for (int r = 0; r < repeat; ++r) {
      m.answer_bytes = m.simplices = 0;
      double first_message = -1;
      const auto start = Clock::now();
      absl::Status status = client.Classify(
          classify,
          [&](const v1::ClassifyResponse& message) {
            if (first_message < 0) first_message = SecondsSince(start);
            m.answer_bytes += message.ByteSizeLong();
            m.simplices += message.chunk().classes().size();
            return absl::OkStatus();
          },
          &m.wire_bytes);
      const double seconds = SecondsSince(start);
      if (seconds < m.seconds) {
        m.seconds = seconds;
        m.first_message_seconds = first_message;
      }
      if (!status.ok()) {
        std::fprintf(stderr, "classify failed: %s\n", std::string(status.message()).c_str());
        std::exit(1);
      }
    }
  }
  return measured;
}

LinkMeasure MeasureLink(client::AlphaClient& client, const std::vector<Point2>& points, int repeat) {
  LinkMeasure m;
  for (int r = 0; r < repeat; ++r) {
    client::BuildResult built;
    m.build_seconds = std::min(m.build_seconds, TimedBuild(client, points, &built));
    m.bytes_up = built.upload_bytes;
    double stages = 0;
    for (const auto& s : built.summary.stage_times()) stages += s.seconds();
    m.server_stage_seconds = std::min(m.server_stage_seconds, stages);
  }
  const std::string handle = PointSetHandle(points);
  v1::SpectrumRequest size_request;
  size_request.set_handle(handle);
  size_request.set_page_size(1);
  m.spectrum_size = client.Spectrum(size_request)->spectrum_size();
  m.classify = MeasureClassify(client, handle, m.spectrum_size / 2, repeat);
  return m;
}

double Megabytes(uint64_t bytes) { return static_cast<double>(bytes) / 1e6; }

/// 5. The compact tier: a server whose resident tier holds one family, two families queried in
/// turn, so that every Describe finds its family demoted and rebuilds it (a promotion), against a
/// Describe of a resident family and against the client's alternative when the family is gone
/// (`upload_seconds`: a Build RPC over loopback, measured above).
int MeasurePromotion(const Options& options, const std::vector<Point2>& points, double upload_seconds) {
  const std::vector<Point2> other = gen::Uniform(options.points, 2);
  server::ServerOptions server_options = BenchServerOptions(options, "127.0.0.1:0");
  {
    // Room for one family of either set (their sizes differ by a few percent), in the form the
    // server caches it.
    BuildOptions build;
    build.backend = options.backend;
    const bool on_cpu =
        options.backend == Backend::kCpu || (options.backend == Backend::kAuto && !CudaBackendAvailable());
    const bool resident = options.device_cache_bytes > 0 && !on_cpu;
    auto cached = server::BuildCachedFamily(points, {}, /*weighted=*/false, build, resident, nullptr);
    if (!cached.ok()) return 1;
    server_options.service.cache_bytes = (*cached)->bytes() * 5 / 4;
    if (options.device_cache_bytes > 0) server_options.service.device_cache_bytes = (*cached)->device_bytes() * 5 / 4;
  }
  auto server = server::GalphaServer::Start(server_options);
  if (!server.ok()) {
    std::fprintf(stderr, "service_bench: %s\n", std::string(server.status().message()).c_str());
    return 1;
  }
  auto client = Client((*server)->port());
  const std::string first = PointSetHandle(points), second = PointSetHandle(other);
  if (!client->Build(points).ok() || !client->Build(other).ok()) return 1;  // `points` demoted
  double resident = std::numeric_limits<double>::infinity();
  std::vector<double> promotions;
  for (int r = 0; r < options.repeat; ++r) {
    for (const std::string* handle : {&first, &second}) {
      auto start = Clock::now();
      if (!client->Describe(*handle).ok()) return 1;  // a promotion: the other one is demoted
      promotions.push_back(SecondsSince(start));
      start = Clock::now();
      if (!client->Describe(*handle).ok()) return 1;  // resident now
      resident = std::min(resident, SecondsSince(start));
    }
  }
  const server::FamilyCache::Stats stats = (*server)->service().cache().GetStats();
  const double promoted = *std::min_element(promotions.begin(), promotions.end());
  std::printf(
      "\n| a family of %zu points, when the first query after a while finds it... | Describe ms (best of %zu) | "
      "vs resident | bytes a point held for it |\n|---|---:|---:|---:|\n",
      options.points, promotions.size());
  std::printf("| resident (whole) | %.2f | 1 | %.0f |\n", resident * 1e3,
              static_cast<double>(stats.resident.bytes) / static_cast<double>(options.points));
  std::printf("| in the compact tier (its points): rebuilt on a slot, promoted | %.1f | %.0f | %.0f |\n",
              promoted * 1e3, promoted / resident,
              static_cast<double>(stats.compact.bytes) / static_cast<double>(options.points));
  std::printf("| evicted: the client uploads it again (Build RPC over loopback, above) | %.1f | %.0f | 0 |\n",
              upload_seconds * 1e3, upload_seconds / resident);
  std::printf("\npromotions %llu, demotions %llu (cache statistics)\n",
              static_cast<unsigned long long>(stats.promotions), static_cast<unsigned long long>(stats.demotions));
  (*server)->Drain();
  return 0;
}

/// Used device memory in bytes, 0 without a GPU.
size_t DeviceBytesInUse() {
  const absl::StatusOr<DeviceMemory> memory = QueryDeviceMemory();
  return memory.ok() ? memory->used_bytes() : 0;
}

int RunStress(const Options& options) {
  const size_t sets = options.stress_sets, n = options.stress_points;
  auto server = server::GalphaServer::Start(BenchServerOptions(options, "127.0.0.1:0"));
  if (!server.ok()) {
    std::fprintf(stderr, "service_bench: %s\n", std::string(server.status().message()).c_str());
    return 1;
  }
  const int port = (*server)->port();
  // The baseline: after a first build (kernels loaded, pools created) is released and the server's
  // idle release (2 s) has run.
  {
    auto client = Client(port);
    const std::vector<Point2> warm = gen::Uniform(100000, 99);
    if (!client->Build(warm).ok() || !client->Release(PointSetHandle(warm)).ok()) {
      std::fprintf(stderr, "service_bench: the warm-up build failed\n");
      (*server)->Drain();
      return 1;
    }
  }
  std::this_thread::sleep_for(std::chrono::seconds(4));
  const size_t baseline = DeviceBytesInUse();
  std::vector<std::vector<Point2>> points(sets);
  {
    std::vector<std::thread> makers;
    for (size_t i = 0; i < sets; ++i) makers.emplace_back([&, i] { points[i] = gen::Uniform(n, 1000 + i); });
    for (std::thread& maker : makers) maker.join();
  }
  std::vector<std::string> handles(sets);
  for (size_t i = 0; i < sets; ++i) handles[i] = PointSetHandle(points[i]);
  std::atomic<size_t> peak{baseline};
  std::atomic<bool> sampling{true};
  std::thread sampler([&] {
    while (sampling) {
      size_t now = DeviceBytesInUse(), seen = peak.load();
      while (now > seen && !peak.compare_exchange_weak(seen, now)) {}
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
  std::mutex mutex;
  std::vector<std::string> failures;
  const auto fail = [&](const std::string& what, const absl::Status& status) {
    std::lock_guard<std::mutex> lock(mutex);
    failures.push_back(absl::StrCat(what, ": ", status.ToString()));
  };
  std::vector<double> build_seconds(sets), query_seconds(sets);
  const auto start = Clock::now();
  {
    std::vector<std::thread> clients;
    for (size_t i = 0; i < sets; ++i) {
      clients.emplace_back([&, i] {
        auto client = Client(port);
        auto begin = Clock::now();
        const absl::StatusOr<client::BuildResult> built = client->Build(points[i]);
        build_seconds[i] = SecondsSince(begin);
        if (!built.ok()) fail(absl::StrCat("build ", i), built.status());
      });
    }
    for (std::thread& c : clients) c.join();
  }
  const double builds_wall = SecondsSince(start);
  {
    std::vector<std::thread> clients;
    for (size_t i = 0; i < sets; ++i) {
      clients.emplace_back([&, i] {
        auto client = Client(port);
        const auto begin = Clock::now();
        for (size_t k = 0; k < sets; ++k) {
          const size_t j = (i + k) % sets;
          auto described = client->Describe(handles[j]);
          if (!described.ok()) {
            fail(absl::StrCat("client ", i, " Describe of set ", j), described.status());
            continue;
          }
          v1::ClassifyRequest request;
          request.set_handle(handles[j]);
          request.set_summary_only(true);
          request.mutable_threshold()->set_rank(
              std::max<int64_t>(1, static_cast<int64_t>(described->summary().spectrum_size() / 2)));
          absl::Status classified =
              client->Classify(request, [](const v1::ClassifyResponse&) { return absl::OkStatus(); });
          if (!classified.ok()) fail(absl::StrCat("client ", i, " Classify of set ", j), classified);
        }
        query_seconds[i] = SecondsSince(begin);
      });
    }
    for (std::thread& c : clients) c.join();
  }
  const double total_wall = SecondsSince(start);
  const server::FamilyCache::Stats stats = (*server)->service().cache().GetStats();
  {
    auto client = Client(port);
    for (size_t i = 0; i < sets; ++i) {
      auto released = client->Release(handles[i]);
      if (!released.ok() && !absl::IsNotFound(released.status())) fail(absl::StrCat("release ", i), released.status());
    }
  }
  const auto released_at = Clock::now();
  size_t after = DeviceBytesInUse();
  while (after > baseline + (size_t{64} << 20) && SecondsSince(released_at) < 30) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    after = DeviceBytesInUse();
  }
  const double back_after = SecondsSince(released_at);
  sampling = false;
  sampler.join();
  const auto mb = [](size_t bytes) { return static_cast<double>(bytes) / 1e6; };
  std::printf(
      "service_bench --stress: %zu clients, %zu distinct sets of %zu points at once, %s backend, %zu build "
      "slots, host cache %.1f GB, device cache %.1f GB\n\n",
      sets, sets, n, (*server)->service().backend_name().c_str(), (*server)->service().build_slots(),
      static_cast<double>(BenchServerOptions(options, "").service.cache_bytes) / 1e9,
      static_cast<double>(options.device_cache_bytes) / 1e9);
  std::printf("| what | value |\n|---|---:|\n");
  std::printf("| failures (builds, queries, releases) | %zu |\n", failures.size());
  std::printf("| builds, wall s (all %zu at once) | %.2f |\n", sets, builds_wall);
  std::printf("| one build's RPC s, fastest / slowest | %.2f / %.2f |\n",
              *std::min_element(build_seconds.begin(), build_seconds.end()),
              *std::max_element(build_seconds.begin(), build_seconds.end()));
  std::printf(
      "| queries (Describe + Classify summary of every family, by every client), wall s | %.2f (slowest "
      "client %.2f) |\n",
      total_wall - builds_wall, *std::max_element(query_seconds.begin(), query_seconds.end()));
  std::printf("| cache: resident entries, demotions, promotions, evictions (both tiers) | %zu, %llu, %llu, %llu |\n",
              stats.resident.entries, static_cast<unsigned long long>(stats.demotions),
              static_cast<unsigned long long>(stats.promotions),
              static_cast<unsigned long long>(stats.resident.evictions + stats.compact.evictions));
  std::printf("| device memory used MB: baseline / peak / after the releases | %.0f / %.0f / %.0f |\n", mb(baseline),
              mb(peak.load()), mb(after));
  const bool back = after <= baseline + (size_t{64} << 20);
  const std::string back_text = back ? absl::StrCat(std::round(back_after * 10) / 10) : "not within 30 s";
  std::printf("| back within 64 MB of the baseline after the releases, s | %s |\n", back_text.c_str());
  for (const std::string& f : failures) std::printf("failure: %s\n", f.c_str());
  (*server)->Drain();
  return failures.empty() && back ? 0 : 1;
}

/// --batch: SETS sets of POINTS uniform points each (each in its own unit square, seeds apart) as
/// one BuildBatch call (its small sets packed into one build, and again built one a host core),
/// against the same sets as SETS Build calls one after the other (what a client did before
/// BuildBatch) and against one Build of all their points together (issue 20's reference: a batch
/// should take under 10x that). Each after a fresh server start, so that
/// nothing is cached; best of --repeat.
int RunBatch(const Options& options) {
  const size_t sets = options.batch_sets, n = options.batch_points;
  std::vector<std::vector<Point2>> points;
  std::vector<Point2> all;
  points.reserve(sets);
  all.reserve(sets * n);
  for (size_t i = 0; i < sets; ++i) {
    points.push_back(gen::Uniform(n, 5000 + i));
    for (Point2 p : points.back())
      all.push_back({p.x + static_cast<double>(i % 1000) * 2.0, p.y + static_cast<double>(i / 1000 * 2)});
  }
  std::vector<client::BatchSet> batch;
  for (size_t i = 0; i < sets; ++i) batch.push_back({absl::StrCat("set-", i), points[i], {}});
  double batch_s = 1e300, unpacked_s = 1e300, single_s = 1e300, whole_s = 1e300;
  std::string backend;
  for (int r = 0; r < options.repeat; ++r) {
    // 0: BuildBatch, its small sets packed into one build; 1: the same, one set a host core;
    // 2: one Build a set; 3: one Build of all the points.
    for (int which = 0; which < 4; ++which) {
      server::ServerOptions server_options = BenchServerOptions(options, "127.0.0.1:0");
      server_options.service.batch_packing = which == 1 ? server::BatchPacking::kOff : server::BatchPacking::kOn;
      auto server = server::GalphaServer::Start(server_options);
      if (!server.ok()) {
        std::fprintf(stderr, "service_bench: %s\n", std::string(server.status().message()).c_str());
        return 1;
      }
      backend = (*server)->service().backend_name();
      auto client = Client((*server)->port());
      const auto start = Clock::now();
      absl::Status status;
      if (which <= 1) {
        auto answers = client->BuildBatch(batch);
        status = answers.status();
        if (answers.ok()) {
          for (const auto& answer : *answers) {
            if (!answer.ok()) status = answer.status();
          }
        }
        double& best = which == 0 ? batch_s : unpacked_s;
        if (status.ok()) best = std::min(best, SecondsSince(start));
      } else if (which == 2) {
        client::BuildCallOptions call;
        call.skip_upload_if_cached = false;
        for (size_t i = 0; i < sets && status.ok(); ++i) status = client->Build(points[i], call).status();
        if (status.ok()) single_s = std::min(single_s, SecondsSince(start));
      } else {
        client::BuildCallOptions call;
        call.skip_upload_if_cached = false;
        status = client->Build(all, call).status();
        if (status.ok()) whole_s = std::min(whole_s, SecondsSince(start));
      }
      (*server)->Drain();
      if (!status.ok()) {
        std::fprintf(stderr, "service_bench --batch: %s\n", std::string(status.message()).c_str());
        return 1;
      }
    }
  }
  std::printf("service_bench --batch: %zu sets of %zu uniform points, %s backend, loopback, best of %d\n", sets, n,
              backend.c_str(), options.repeat);
  std::printf("| call | ms | ms a set | / one Build of all points |\n|---|---:|---:|---:|\n");
  const auto row = [&](const char* what, double seconds) {
    std::printf("| %s | %.1f | %.3f | %.2f |\n", what, seconds * 1e3, seconds * 1e3 / static_cast<double>(sets),
                seconds / whole_s);
  };
  row("BuildBatch, one call, sets packed into one build (--batch_packing=on)", batch_s);
  row("BuildBatch, one call, one set a host core (--batch_packing=off)", unpacked_s);
  row("Build, one call a set", single_s);
  row("Build of all the points as one set", whole_s);
  std::printf("ratio BuildBatch (packed) / one Build a set: %.2f; packed / one set a host core: %.2f\n",
              batch_s / single_s, batch_s / unpacked_s);
  return 0;
}

int Run(const Options& options) {
  if (options.stress_sets > 0) return RunStress(options);
  if (options.batch_sets > 0) return RunBatch(options);
  // Shaped links first: the namespaces must exist before this process starts any thread.
  std::vector<std::string> links;
  std::unique_ptr<VethLink> veth;
  const bool wants_shaped = std::any_of(options.links.begin(), options.links.end(),
                                        [](const std::string& link) { return link != "loopback"; });
  if (wants_shaped) {
    std::string why = VethLink::Unavailable();
    if (why.empty()) {
      auto created = VethLink::Create(BenchServerOptions(options, ""));
      if (created.ok()) {
        veth = *std::move(created);
      } else {
        why = std::string(created.status().message());
      }
    }
    if (!why.empty()) std::fprintf(stderr, "service_bench: %s; measuring loopback only\n", why.c_str());
  }
  for (const std::string& link : options.links) {
    if (link == "loopback" || veth != nullptr) links.push_back(link);
  }
  if (std::find(links.begin(), links.end(), "loopback") == links.end()) links.insert(links.begin(), "loopback");

  auto server = server::GalphaServer::Start(BenchServerOptions(options, "127.0.0.1:0"));
  if (!server.ok()) {
    std::fprintf(stderr, "service_bench: %s\n", std::string(server.status().message()).c_str());
    return 1;
  }
  const int port = (*server)->port();
  const std::string backend = (*server)->service().backend_name();
  std::printf(
      "service_bench: %zu uniform points, %s backend, %zu build slots, best of %d, %u host threads, device cache %zu "
      "bytes (%s)\n\n",
      options.points, backend.c_str(), (*server)->service().build_slots(), options.repeat,
      std::thread::hardware_concurrency(), options.device_cache_bytes,
      backend == "cuda" && options.device_cache_bytes > 0 ? "families resident on the GPU" : "families in host memory");
  auto client = Client(port);
  const std::vector<Point2> points = gen::Uniform(options.points, 1);

  // 1. One build: in-process engine, the same through gRPC over each link, CGAL.
  double engine = 1e30;
  for (int r = 0; r < options.repeat; ++r) {
    BuildOptions build;
    build.backend = options.backend;
    const auto start = Clock::now();
    auto family = BuildAlphaFamily(points, build);
    engine = std::min(engine, SecondsSince(start));
    if (!family.ok()) return 1;
  }
  std::map<std::string, LinkMeasure> measured;
  for (const std::string& link : links) {
    if (link == "loopback") {
      measured[link] = MeasureLink(*client, points, options.repeat);
      continue;
    }
    if (absl::Status shaped = veth->Shape(link); !shaped.ok()) {
      std::fprintf(stderr, "service_bench: %s\n", std::string(shaped.message()).c_str());
      return 1;
    }
    measured[link] = MeasureLink(*Client(veth->target()), points, options.repeat);
  }
  const double cgal = options.points <= options.cgal_max ? CgalSeconds(points) : -1;
  std::printf(
      "| one build of %zu points; Classify of every simplex at rank K/2 | bytes up | bytes down | build ms | build vs "
      "in-process | Classify ms |\n|---|---:|---:|---:|---:|---:|\n",
      options.points);
  std::printf("| in-process BuildAlphaFamily (wall) | | | %.1f | 1.00 | |\n", engine * 1e3);
  for (const std::string& link : links) {
    const LinkMeasure& m = measured[link];
    const std::string name =
        link == "loopback" ? "Build RPC over loopback (upload + build + answer)"
                           : absl::StrCat("Build RPC over a veth pair, tbf ", link, " both ways, ",
                                          veth->rtt_emulated() ? "netem 1 ms RTT" : "RTT not emulated (no netem)");
    std::printf("| %s | %.2f MB | %.2f MB | %.1f | %.2f | %.1f |\n", name.c_str(), Megabytes(m.bytes_up),
                Megabytes(m.classify[0].wire_bytes), m.build_seconds * 1e3, m.build_seconds / engine,
                m.classify[0].seconds * 1e3);
    if (link == "loopback") {
      std::printf("| of which the server's stage times | | | %.1f | | |\n", m.server_stage_seconds * 1e3);
    }
  }
  if (cgal >= 0) std::printf("| CGAL Alpha_shape_2 EPEC, 1 thread | | | %.1f | %.2f | |\n", cgal * 1e3, cgal / engine);
  std::printf("\n");

  // 2. Classify of every simplex at the middle rank, per answer encoding and link: the uniform
  // set above (shuffled input order: the encodings' worst case), LiDAR-like points quantized to
  // centimetres (also in random order) and the real lidar_autzen file in its own (scan) order.
  const LinkMeasure& loopback = measured["loopback"];
  const std::string handle = PointSetHandle(points);
  const int64_t k = loopback.spectrum_size;
  struct ClassifySet {
    std::string name;
    std::vector<Point2> points;
  };
  std::vector<ClassifySet> classify_sets;
  classify_sets.push_back(
      {absl::StrCat("lidar_cm ", options.points, " (random order)"), gen::LidarCentimetres(options.points, 1)});
  if (auto autzen = ReadPointsBin(testdata::DataDir() + "/lidar_autzen.bin"); autzen.ok()) {
    classify_sets.push_back({absl::StrCat("lidar_autzen ", autzen->size(), " (file order)"), *std::move(autzen)});
  } else {
    std::fprintf(stderr, "service_bench: no lidar_autzen (%s); set GALPHA_DATA_DIR\n",
                 std::string(autzen.status().message()).c_str());
  }
  std::printf(
      "| Classify of every simplex at rank K/2 | link | answer encoding | simplices | MB on the wire | ms | of which "
      "before the summary | vs raw | wire GB/s | answer GB/s (raw bytes / ms) "
      "|\n|---|---|---|---:|---:|---:|---:|---:|---:"
      "|---:|\n");
  const auto print_classify = [&](const std::string& set, const std::string& link,
                                  const std::array<ClassifyMeasure, kAnswerEncodings.size()>& m) {
    for (size_t e = 0; e < kAnswerEncodings.size(); ++e) {
      std::printf("| %s | %s | %s | %zu | %.2f | %.1f | %.1f | %.2f | %.2f | %.2f |\n", set.c_str(), link.c_str(),
                  AnswerEncodingName(kAnswerEncodings[e]), static_cast<size_t>(m[e].simplices),
                  Megabytes(m[e].wire_bytes), m[e].seconds * 1e3, m[e].first_message_seconds * 1e3,
                  m[e].seconds / m[0].seconds, static_cast<double>(m[e].wire_bytes) / m[e].seconds / 1e9,
                  static_cast<double>(m[e].answer_bytes) / m[e].seconds / 1e9);
    }
  };
  for (const std::string& link : links) {
    print_classify(absl::StrCat("uniform ", options.points), link, measured[link].classify);
  }
  // The same answer read in P parts at once (ClassifyRequest.part_count), each on a connection of
  // its own, merged back in order by the client library.
  std::vector<std::pair<std::string, std::array<ClassifyMeasure, kAnswerEncodings.size()>>> by_parts;
  for (const uint32_t parts : options.classify_parts) {
    by_parts.emplace_back(absl::StrCat(parts), MeasureClassify(*Client(port, parts), handle, k / 2, options.repeat));
  }
  for (const ClassifySet& set : classify_sets) {
    for (const std::string& link : links) {
      if (link != "loopback") {
        if (absl::Status shaped = veth->Shape(link); !shaped.ok()) {
          std::fprintf(stderr, "service_bench: %s\n", std::string(shaped.message()).c_str());
          return 1;
        }
      }
      const auto link_client = link == "loopback" ? Client(port) : Client(veth->target());
      client::BuildResult built;
      TimedBuild(*link_client, set.points, &built);
      const int64_t set_rank = static_cast<int64_t>(built.summary.spectrum_size() / 2);
      print_classify(set.name, link, MeasureClassify(*link_client, built.handle, set_rank, options.repeat));
      link_client->Release(built.handle).IgnoreError();
    }
  }
  std::printf("\n");
  std::printf(
      "| Classify of every simplex of uniform %zu at rank K/2, loopback, in parts | parts | answer encoding | ms | of "
      "which before the summary | vs one call | answer GB/s (raw bytes / ms) |\n|---|---:|---|---:|---:|---:|---:|\n",
      options.points);
  for (const auto& [parts, m] : by_parts) {
    for (size_t e = 0; e < kAnswerEncodings.size(); ++e) {
      const double one_call = loopback.classify[e].seconds;  // the first table's one call
      std::printf("| | %s | %s | %.1f | %.1f | %.2f | %.2f |\n", parts.c_str(), AnswerEncodingName(kAnswerEncodings[e]),
                  m[e].seconds * 1e3, m[e].first_message_seconds * 1e3, m[e].seconds / one_call,
                  static_cast<double>(m[e].answer_bytes) / m[e].seconds / 1e9);
    }
  }
  std::printf("\n");

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
  return MeasurePromotion(options, points, loopback.build_seconds);
}

}  // namespace
}  // namespace galpha

int main(int argc, char** argv) {
  galpha::Options options;
  if (!galpha::ParseOptions(argc, argv, &options)) return 2;
  return galpha::Run(options);
}
