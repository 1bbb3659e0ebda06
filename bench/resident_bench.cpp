// resident_bench: what a caller waits for with a resident family (gpu/alpha/resident_family.hpp:
// the rank tables stay where they were built) against the family in host memory (BuildAlphaFamily,
// today's path, measured in the same run).
//   resident_bench [--backend=auto|cpu|cuda] [--repeat=3] [--sizes=100000,1000000]
//                  [--dists=NAME,...(default: every generator)] [--seed=1] [--data FILE.bin]...
// Per input, best of --repeat: the whole in-process call (points in host memory -> family
// usable) of each form and their ratio; the host form's "download" stage and the resident one's
// "keep_resident"; ClassifyAll at the middle level from each form; the regularized shape there
// from each form (AssembleShape of the host family's complex, ResidentAlphaFamily::ShapeAt);
// ToHostFamily (the download done later, when asked); bytes per input point that each form holds
// (resident: where the tables live, and on the host), and each build's engine working-memory peak. Every answer of the
// resident family at the middle level is checked against the host family's (the bench fails on a difference).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_options.hpp"
#include "core/family/alpha_family.hpp"
#include "core/geometry/shape.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gpu/alpha/resident_family.hpp"

namespace galpha {
namespace {

constexpr char kUsage[] =
    "usage: resident_bench [--backend=auto|cpu|cuda] [--repeat=N] [--sizes=N,...] [--dists=NAME,...]\n"
    "                      [--seed=N] [--data FILE.bin]...\n";

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

double StageMs(const BuildReport& report, const char* name) {
  for (const StageTime& stage : report.stage_times) {
    if (stage.stage == name) return stage.seconds * 1e3;
  }
  return 0;
}

constexpr double kNone = std::numeric_limits<double>::infinity();

struct ResidentResult {
  std::string name;
  size_t n = 0;
  std::string backend;
  double host_call_ms = kNone, resident_call_ms = kNone;
  double download_ms = 0, keep_ms = 0;  // of the fastest calls
  double host_classify_ms = kNone, resident_classify_ms = kNone;
  // The regularized shape at the middle level: AssembleShape of the host family's complex against
  // the resident family's ShapeAt (its boundary found where the tables live).
  double host_shape_ms = kNone, resident_shape_ms = kNone;
  double to_host_ms = kNone;
  double host_bytes_per_point = 0, resident_device_per_point = 0, resident_host_per_point = 0;
  // The engine's working-memory peak (its ledger: device memory on CUDA, host memory on the CPU).
  double host_peak_per_point = 0, resident_peak_per_point = 0;
  bool same = true;
  std::string error;
};

ResidentResult RunOne(const std::string& name, const std::vector<Point2>& points, const BenchOptions& options) {
  ResidentResult r;
  r.name = name;
  r.n = points.size();
  BuildOptions build;
  build.backend = options.backend;
  for (int i = 0; i < options.repeat && r.error.empty(); ++i) {
    auto start = std::chrono::steady_clock::now();
    absl::StatusOr<AlphaFamily> host = BuildAlphaFamily(points, build);
    const double host_ms = MillisecondsSince(start);
    if (!host.ok()) {
      r.error = host.status().ToString();
      break;
    }
    if (host_ms < r.host_call_ms) {
      r.host_call_ms = host_ms;
      r.download_ms = StageMs(host->report(), "download");
    }
    r.backend = host->report().backend;
    r.host_peak_per_point =
        static_cast<double>(host->report().peak_memory_bytes) / static_cast<double>(std::max<size_t>(1, r.n));
    r.host_bytes_per_point = static_cast<double>(host->HostBytes()) / static_cast<double>(std::max<size_t>(1, r.n));

    start = std::chrono::steady_clock::now();
    absl::StatusOr<ResidentAlphaFamily> resident = BuildResidentAlphaFamily(points, build);
    const double resident_ms = MillisecondsSince(start);
    if (!resident.ok()) {
      r.error = resident.status().ToString();
      break;
    }
    if (resident_ms < r.resident_call_ms) {
      r.resident_call_ms = resident_ms;
      r.keep_ms = StageMs(resident->report(), "keep_resident");
    }
    r.resident_device_per_point =
        static_cast<double>(resident->ResidentBytes()) / static_cast<double>(std::max<size_t>(1, r.n));
    r.resident_host_per_point =
        static_cast<double>(resident->HostBytes()) / static_cast<double>(std::max<size_t>(1, r.n));
    r.resident_peak_per_point =
        static_cast<double>(resident->report().peak_memory_bytes) / static_cast<double>(std::max<size_t>(1, r.n));

    const int64_t level = host->max_level() / 2;
    start = std::chrono::steady_clock::now();
    const Classification host_classes = host->ClassifyAll(level, ClassifyMode::kGeneral, VertexRule::kReport);
    r.host_classify_ms = std::min(r.host_classify_ms, MillisecondsSince(start));
    start = std::chrono::steady_clock::now();
    const absl::StatusOr<Classification> resident_classes =
        resident->ClassifyAll(level, ClassifyMode::kGeneral, VertexRule::kReport);
    r.resident_classify_ms = std::min(r.resident_classify_ms, MillisecondsSince(start));
    if (!resident_classes.ok()) {
      r.error = resident_classes.status().ToString();
      break;
    }
    r.same &= resident_classes->vertices == host_classes.vertices && resident_classes->edges == host_classes.edges &&
              resident_classes->triangles == host_classes.triangles;
    const absl::StatusOr<TopologyAtLevel> at = resident->TopologyAt(level);
    r.same &=
        at.ok() && at->components == host->Components(level) && at->holes == host->Holes(level, ClassifyMode::kGeneral);

    start = std::chrono::steady_clock::now();
    const absl::StatusOr<ShapeGeometry> host_shape = AssembleShape(host->ComplexAt(level, ClassifyMode::kRegularized));
    r.host_shape_ms = std::min(r.host_shape_ms, MillisecondsSince(start));
    start = std::chrono::steady_clock::now();
    const absl::StatusOr<ShapeGeometry> resident_shape = resident->ShapeAt(level, ClassifyMode::kRegularized);
    r.resident_shape_ms = std::min(r.resident_shape_ms, MillisecondsSince(start));
    if (!host_shape.ok() || !resident_shape.ok()) {
      r.error = (host_shape.ok() ? resident_shape.status() : host_shape.status()).ToString();
      break;
    }
    r.same &= resident_shape->area == host_shape->area &&
              resident_shape->polygons.size() == host_shape->polygons.size() &&
              resident_shape->singular_edges == host_shape->singular_edges &&
              resident_shape->isolated_points == host_shape->isolated_points;
    for (size_t p = 0; r.same && p < host_shape->polygons.size(); ++p) {
      r.same &= resident_shape->polygons[p].outer == host_shape->polygons[p].outer &&
                resident_shape->polygons[p].holes == host_shape->polygons[p].holes;
    }

    start = std::chrono::steady_clock::now();
    const absl::StatusOr<AlphaFamily> downloaded = resident->ToHostFamily();
    r.to_host_ms = std::min(r.to_host_ms, MillisecondsSince(start));
    if (!downloaded.ok()) {
      r.error = downloaded.status().ToString();
      break;
    }
    r.same &= downloaded->max_level() == host->max_level() && downloaded->HostBytes() == host->HostBytes();
  }
  return r;
}

void PrintRow(const ResidentResult& r) {
  if (!r.error.empty()) {
    std::printf("| %s | %zu | error: %s |\n", r.name.c_str(), r.n, r.error.c_str());
    return;
  }
  std::printf(
      "| %s | %zu | %s | %.1f | %.1f | %.2fx | %.1f | %.1f | %.2f | %.2f | %.1f / %.1f | %.1f | %.0f | %.0f + %.0f | "
      "%.0f / %.0f | %s |\n",
      r.name.c_str(), r.n, r.backend.c_str(), r.host_call_ms, r.resident_call_ms, r.host_call_ms / r.resident_call_ms,
      r.download_ms, r.keep_ms, r.host_classify_ms, r.resident_classify_ms, r.host_shape_ms, r.resident_shape_ms,
      r.to_host_ms, r.host_bytes_per_point, r.resident_device_per_point, r.resident_host_per_point,
      r.host_peak_per_point, r.resident_peak_per_point, r.same ? "same" : "DIFFERENT");
  std::fflush(stdout);
}

int Main(int argc, char** argv) {
  const absl::StatusOr<BenchOptions> options = ParseBenchArgs(argc, argv, nullptr);
  if (!options.ok()) {
    std::fprintf(stderr, "%s\n%s", std::string(options.status().message()).c_str(), kUsage);
    return 2;
  }
  std::printf("resident_bench: backend %s requested (CUDA %s), best of %d, %u host threads\n\n",
              BackendName(options->backend), CudaBackendAvailable() ? "available" : "unavailable", options->repeat,
              std::thread::hardware_concurrency());
  // The first build pays for the backend's start (the CUDA context, the memory pool).
  BuildOptions warm;
  warm.backend = options->backend;
  if (!BuildAlphaFamily(std::vector<Point2>{{0, 0}, {1, 0}, {0, 1}, {1, 1}}, warm).ok()) {
    std::fprintf(stderr, "the warm-up build failed\n");
    return 1;
  }
  std::printf(
      "| input | n | backend | host family: whole call ms | resident family: whole call ms | host / resident | "
      "host's download stage ms | resident's keep stage ms | ClassifyAll from the host family ms | "
      "ClassifyAll from the resident family ms | regularized shape ms (host AssembleShape / resident ShapeAt) | "
      "ToHostFamily ms | host family B/pt | resident B/pt (tables + host) | engine peak B/pt (host / resident build) | "
      "answers |\n"
      "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
  bool failed = false;
  auto run = [&](const std::string& name, const std::vector<Point2>& points) {
    std::fprintf(stderr, "running %s n=%zu\n", name.c_str(), points.size());
    const ResidentResult r = RunOne(name, points, *options);
    failed |= !r.error.empty() || !r.same;
    PrintRow(r);
  };
  if (const absl::Status read = ForEachBenchInput(*options, run); !read.ok()) {
    std::fprintf(stderr, "%s\n", read.ToString().c_str());
    return 1;
  }
  return failed ? 1 : 0;
}

}  // namespace
}  // namespace galpha

int main(int argc, char** argv) { return galpha::Main(argc, argv); }
