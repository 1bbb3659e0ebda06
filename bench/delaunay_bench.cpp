// delaunay_bench: galpha::Triangulate against CGAL's Delaunay_triangulation_2 in the same run, over
// distributions x sizes (and real .bin files), printed as markdown tables with the ratio and
// galpha's per-stage times. A plain harness, kept out of ctest.
//
//   delaunay_bench [--backend=auto|cpu|cuda] [--repeat=3] [--sizes=100000,1000000]
//                  [--dists=uniform,gaussian,clustered,grid] [--seed=1] [--data FILE.bin]...
//                  [--weights=KIND]
//
// With --weights (a kind of tests/support/weight_generators.hpp: uniform, signed, one_huge,
// many_hidden, ...), the regular triangulation: galpha::TriangulateWeighted against CGAL's
// Regular_triangulation_2, with the hidden points counted.
//
// With --sets=SETSxPOINTS (e.g. 10000x1000), the packed build of many sets instead (issue 20):
// for each distribution, SETS sets of POINTS points (generated with seeds seed, seed + 1, ...) in
// one TriangulateSets call, against one Triangulate of SETS * POINTS points of the distribution
// (the reference: a batch should take under 10x that), Triangulate called once a set and
// CGAL a set (both timed over the first 200 sets and scaled to SETS). The sampled sets' packed
// triangulations must equal their own builds, triangle for triangle, or the run fails.
//
// With --data and no --dists/--sizes, only the files run. Times are the best of --repeat runs;
// point generation and conversion are not timed.
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_2.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "bench/bench_options.hpp"
#include "core/io/point_io.hpp"
#include "gpu/triangulation/delaunay.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/weight_generators.hpp"

namespace galpha {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalDelaunay = CGAL::Delaunay_triangulation_2<Kernel>;
using CgalRegular = CGAL::Regular_triangulation_2<Kernel>;

// One input to time: a generated distribution at a size, or a file.
struct BenchInput {
  std::string name;
  std::vector<Point2> points;
  std::vector<double> weights;  // empty: unweighted
};

struct BenchResult {
  std::string name;
  size_t n = 0;
  Backend backend = Backend::kCpu;
  double galpha_ms = 0;          // the whole call, transfers included
  double galpha_compute_ms = 0;  // the same run without the upload and download stages
  size_t galpha_peak_bytes = 0;  // working memory peak on the backend
  double cgal_ms = 0;
  size_t galpha_triangles = 0;
  size_t cgal_triangles = 0;
  size_t galpha_hidden = 0;  // weighted only
  size_t cgal_hidden = 0;
  std::vector<StageTime> stages;  // of galpha's best run
  std::string error;              // galpha's failure, if any: the row says so, the run goes on
};

constexpr char kUsage[] =
    "usage: delaunay_bench [--backend=auto|cpu|cuda] [--repeat=N] [--sizes=N,N,...]\n"
    "                      [--dists=NAME,NAME,...] [--seed=N] [--data FILE.bin]... [--weights=KIND]\n"
    "                      [--sets=SETSxPOINTS]\n";

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// Host-device copies: on the CUDA backend these are PCIe transfers, reported apart from compute.
bool IsTransferStage(const std::string& stage) { return stage == "upload" || stage == "download"; }

BenchResult RunOne(const BenchInput& input, const BenchOptions& options) {
  BenchResult result;
  result.name = input.name;
  result.n = input.points.size();
  result.galpha_ms = std::numeric_limits<double>::infinity();
  result.cgal_ms = std::numeric_limits<double>::infinity();
  TriangulateOptions triangulate_options;
  triangulate_options.backend = options.backend;
  for (int r = 0; r < options.repeat; ++r) {
    const auto start = std::chrono::steady_clock::now();
    absl::StatusOr<Triangulation> t = input.weights.empty()
                                          ? Triangulate(input.points, triangulate_options)
                                          : TriangulateWeighted(input.points, input.weights, triangulate_options);
    const double ms = MillisecondsSince(start);
    if (!t.ok()) {
      result.error = t.status().ToString();
      return result;
    }
    if (ms < result.galpha_ms) {
      result.galpha_ms = ms;
      result.backend = t->backend;
      result.galpha_triangles = t->triangles.size();
      result.galpha_hidden = t->hidden.size();
      result.stages = t->stage_times;
      result.galpha_peak_bytes = t->peak_memory_bytes;
      result.galpha_compute_ms = 0;
      for (const StageTime& stage : t->stage_times) {
        if (!IsTransferStage(stage.stage)) result.galpha_compute_ms += stage.seconds * 1e3;
      }
    }
  }

  if (!input.weights.empty()) {
    std::vector<Kernel::Weighted_point_2> cgal_points;
    cgal_points.reserve(input.points.size());
    for (size_t i = 0; i < input.points.size(); ++i) {
      cgal_points.emplace_back(Kernel::Point_2(input.points[i].x, input.points[i].y), input.weights[i]);
    }
    for (int r = 0; r < options.repeat; ++r) {
      const auto start = std::chrono::steady_clock::now();
      const CgalRegular rt(cgal_points.begin(), cgal_points.end());
      result.cgal_ms = std::min(result.cgal_ms, MillisecondsSince(start));
      result.cgal_triangles = rt.dimension() == 2 ? rt.number_of_faces() : 0;
      result.cgal_hidden = rt.number_of_hidden_vertices();
    }
    return result;
  }
  std::vector<Kernel::Point_2> cgal_points;
  cgal_points.reserve(input.points.size());
  for (const Point2& p : input.points) cgal_points.emplace_back(p.x, p.y);
  for (int r = 0; r < options.repeat; ++r) {
    const auto start = std::chrono::steady_clock::now();
    // Range insertion spatially sorts first: CGAL's fast path.
    const CgalDelaunay dt(cgal_points.begin(), cgal_points.end());
    result.cgal_ms = std::min(result.cgal_ms, MillisecondsSince(start));
    result.cgal_triangles = dt.dimension() == 2 ? dt.number_of_faces() : 0;
  }
  return result;
}

/// --sets: one distribution's packed build against its references (see the file comment). Returns
/// false on an engine error or a sampled set unlike its own build.
bool RunPackedSets(const std::string& name, size_t num_sets, size_t points_per_set, const BenchOptions& options) {
  TriangulateOptions triangulate_options;
  triangulate_options.backend = options.backend;
  std::optional<TriangulatedSets> packed;
  PackedSetsCalls calls;
  calls.packed = [&](const std::vector<Point2>& points, const std::vector<uint32_t>& set_begin, std::string* error) {
    absl::StatusOr<TriangulatedSets> built = TriangulateSets(points, set_begin, triangulate_options);
    if (!built.ok()) *error = built.status().ToString();
    if (built.ok()) packed = *std::move(built);
    return packed.has_value();
  };
  calls.release = [&] { packed.reset(); };
  calls.whole = [&](const std::vector<Point2>& points) { return Triangulate(points, triangulate_options).ok(); };
  calls.alone = [&](absl::Span<const Point2> set, size_t s, bool* equal) {
    absl::StatusOr<Triangulation> alone = Triangulate(set, triangulate_options);
    if (!alone.ok()) return false;
    *equal = alone->triangles == packed->sets[s].triangles && alone->edges == packed->sets[s].edges;
    return true;
  };
  calls.competitor = [](absl::Span<const Point2> set) {
    std::vector<Kernel::Point_2> cgal_points;
    for (const Point2& p : set) cgal_points.emplace_back(p.x, p.y);
    const CgalDelaunay dt(cgal_points.begin(), cgal_points.end());
  };
  calls.competitor_repeat = options.repeat;
  calls.describe = [&](PackedSetsRow* row) {
    row->backend = BackendName(packed->backend);
    row->built_alone = packed->built_alone;
    row->stages = packed->stage_times;
  };
  return RunPackedSetsBench(name, num_sets, points_per_set, options, calls);
}

void PrintHeader() {
  std::printf(
      "| distribution | n | galpha backend | galpha ms (no transfers) | transfers+host copies ms | CGAL ms | "
      "CGAL/galpha (no transfers) | CGAL/galpha (whole call) | peak bytes/point | triangles | hidden (CGAL's) |\n"
      "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
}

// One row as soon as its input is measured (flushed), so that a run cut short keeps its rows.
void PrintRow(const BenchResult& r) {
  if (!r.error.empty()) {
    std::printf("| %s | %zu | - | error: %s | | | | | | | |\n", r.name.c_str(), r.n, r.error.c_str());
  } else {
    const std::string triangles = r.galpha_triangles == r.cgal_triangles
                                      ? absl::StrCat(r.galpha_triangles)
                                      : absl::StrCat(r.galpha_triangles, " (CGAL ", r.cgal_triangles, ": MISMATCH)");
    // CGAL counts a point hidden only once per position and weight; ours lists every copy.
    const std::string hidden = r.cgal_hidden == 0 && r.galpha_hidden == 0
                                   ? std::string("-")
                                   : absl::StrCat(r.galpha_hidden, " (", r.cgal_hidden, ")");
    std::printf("| %s | %zu | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f | %s | %s |\n", r.name.c_str(), r.n,
                BackendName(r.backend), r.galpha_compute_ms, r.galpha_ms - r.galpha_compute_ms, r.cgal_ms,
                r.cgal_ms / r.galpha_compute_ms, r.cgal_ms / r.galpha_ms,
                static_cast<double>(r.galpha_peak_bytes) / static_cast<double>(std::max<size_t>(r.n, 1)),
                triangles.c_str(), hidden.c_str());
  }
  std::fflush(stdout);
}

void PrintStageTable(const std::vector<BenchResult>& results) {
  std::printf("\n| distribution | n | galpha stages, best run (ms) |\n|---|---:|---|\n");
  for (const BenchResult& r : results) {
    if (!r.error.empty()) continue;
    std::printf("| %s | %zu | %s |\n", r.name.c_str(), r.n, StageSummary(r.stages).c_str());
  }
}

int Main(int argc, char** argv) {
  // --weights is this benchmark's own; the shared parser gets the rest.
  std::string weight_kind;
  std::vector<char*> args;
  if (const absl::Status taken = TakeWeightsOption(argc, argv, &weight_kind, &args); !taken.ok()) {
    std::fprintf(stderr, "%s\n%s", std::string(taken.message()).c_str(), kUsage);
    return 2;
  }
  size_t num_sets = 0, points_per_set = 0;
  std::vector<char*> rest;
  if (const absl::Status taken =
          TakeSetsOption(static_cast<int>(args.size()), args.data(), &num_sets, &points_per_set, &rest);
      !taken.ok()) {
    std::fprintf(stderr, "%s\n%s", std::string(taken.message()).c_str(), kUsage);
    return 2;
  }
  args = std::move(rest);
  const absl::StatusOr<BenchOptions> options = ParseBenchArgs(static_cast<int>(args.size()), args.data(), nullptr);
  if (!options.ok()) {
    std::fprintf(stderr, "%s\n%s", std::string(options.status().message()).c_str(), kUsage);
    return 2;
  }
  std::printf("delaunay_bench: backend %s requested (CUDA %s), best of %d, %u host threads%s\n\n",
              BackendName(options->backend), CudaBackendAvailable() ? "available" : "unavailable", options->repeat,
              std::thread::hardware_concurrency(),
              weight_kind.empty() ? "" : absl::StrCat("; weights ", weight_kind, " (regular triangulations)").c_str());

  if (num_sets > 0) {
    std::printf(
        "| distribution | sets x points | backend | packed ms (TriangulateSets) | one set of all the points ms | "
        "packed / all in one | one call a set ms (200 sampled, scaled) | calls a set / packed | CGAL a set ms "
        "(same sample) | CGAL / packed | sampled sets equal their own builds |\n"
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|\n");
    bool all_equal = true;
    for (const std::string& name : options->distributions) {
      std::fprintf(stderr, "running %s, %zu sets of %zu points\n", name.c_str(), num_sets, points_per_set);
      all_equal &= RunPackedSets(name, num_sets, points_per_set, *options);
    }
    return all_equal ? 0 : 1;
  }
  PrintHeader();
  std::vector<BenchResult> results;
  bool failed = false;
  auto run = [&](BenchInput input) {
    if (!weight_kind.empty()) input.weights = gen::Weights(weight_kind, input.points, options->seed);
    std::fprintf(stderr, "running %s n=%zu\n", input.name.c_str(), input.points.size());
    BenchResult result = RunOne(input, *options);
    failed |= !result.error.empty() || result.galpha_triangles != result.cgal_triangles;
    PrintRow(result);
    results.push_back(std::move(result));
  };
  for (const std::string& name : options->distributions) {
    for (size_t n : options->sizes) {
      run({name, gen::FindDistribution(name)->generate(n, options->seed), {}});
    }
  }
  for (const std::string& file : options->data_files) {
    absl::StatusOr<std::vector<Point2>> points = ReadPointsBin(file);
    if (!points.ok()) {
      std::fprintf(stderr, "%s\n", points.status().ToString().c_str());
      return 1;
    }
    const size_t slash = file.find_last_of('/');
    run({slash == std::string::npos ? file : file.substr(slash + 1), *std::move(points), {}});
  }
  PrintStageTable(results);
  // An engine error, or a triangle count unlike CGAL's for the same point set, fails the run.
  return failed ? 1 : 0;
}

}  // namespace
}  // namespace galpha

int main(int argc, char** argv) { return galpha::Main(argc, argv); }
