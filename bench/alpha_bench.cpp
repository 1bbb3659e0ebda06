// alpha_bench: the whole alpha-shape family (galpha::BuildAlphaFamily) against CGAL's Alpha_shape_2
// with exact constructions (Exact_predicates_exact_constructions_kernel, GENERAL mode) in the same
// run, over distributions x sizes (and real .bin files). Prints a markdown table with both times,
// the ratio, both memory peaks per point, the time of one classification of every simplex and
// galpha's stage times; then, for hard inputs, each row's pipeline against uniform input of the same
// size and the stage that dominates it. A plain harness, kept out of ctest.
//
//   alpha_bench [--backend=auto|cpu|cuda] [--repeat=3] [--sizes=100000,1000000]
//               [--dists=NAME,...(default: every generator)] [--seed=1] [--cgal-max=1000000]
//               [--data FILE.bin]... [--weights=KIND] [--sets=SETSxPOINTS]
//
// With --weights (a kind of tests/support/weight_generators.hpp: uniform, signed, one_huge, ...),
// every input gets those weights and both sides build the weighted family: galpha's
// BuildWeightedAlphaFamily against CGAL's Alpha_shape_2 over Regular_triangulation_2 (exact
// constructions). The same inputs are also built unweighted by galpha, and the hardness table
// prints the weighted pipeline over the unweighted one. CGAL's spectrum keeps only the values > 0:
// the spectrum check compares galpha's positive values with it.
//
// With --sets=SETSxPOINTS (e.g. 10000x1000), the families of many sets in one packed build instead
// (issue 20): for each distribution, SETS sets of POINTS points (seeds seed, seed + 1, ...) in one
// BuildAlphaFamilies call, against one BuildAlphaFamily of SETS * POINTS points of the distribution
// (the reference: at most 10x its time), one BuildAlphaFamily call a set and CGAL's
// Alpha_shape_2 a set (both timed over the first 200 sets and scaled to SETS). The sampled sets'
// packed families are checked against their own builds (every rank table).
//
// Memory: the peak resident set of the process during the call minus the resident set before it
// (Linux: VmHWM reset through /proc/self/clear_refs), so it counts everything the call allocates on
// the host: working memory, the returned family, CGAL's triangulation and intervals. On the CUDA
// backend the engine's device peak is printed too.
// GCC 12 flags a copy inside CGAL's Weighted_point_2 (a boost tuple, through Epeck's static
// filters) as maybe-uninitialized at -O3; the warning is CGAL's, not this file's.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

#include <CGAL/Alpha_shape_2.h>
#include <CGAL/Alpha_shape_face_base_2.h>
#include <CGAL/Alpha_shape_vertex_base_2.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_2.h>
#include <CGAL/Regular_triangulation_face_base_2.h>
#include <CGAL/Regular_triangulation_vertex_base_2.h>

#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "bench/bench_options.hpp"
#include "bench/sort_floor/sort_floor.hpp"
#include "core/family/alpha_family.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "tests/support/weight_generators.hpp"

namespace galpha {
namespace {

using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using Vb = CGAL::Alpha_shape_vertex_base_2<Kernel>;
using Fb = CGAL::Alpha_shape_face_base_2<Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using CgalAlphaShape = CGAL::Alpha_shape_2<CGAL::Delaunay_triangulation_2<Kernel, Tds>>;
using WeightedVb = CGAL::Alpha_shape_vertex_base_2<Kernel, CGAL::Regular_triangulation_vertex_base_2<Kernel>>;
using WeightedFb = CGAL::Alpha_shape_face_base_2<Kernel, CGAL::Regular_triangulation_face_base_2<Kernel>>;
using WeightedTds = CGAL::Triangulation_data_structure_2<WeightedVb, WeightedFb>;
using CgalWeightedAlphaShape = CGAL::Alpha_shape_2<CGAL::Regular_triangulation_2<Kernel, WeightedTds>>;

constexpr char kUsage[] =
    "usage: alpha_bench [--backend=auto|cpu|cuda] [--repeat=N] [--sizes=N,N,...] [--dists=NAME,...]\n"
    "                   [--seed=N] [--cgal-max=N] [--data FILE.bin]... [--weights=KIND]\n"
    "                   [--sets=SETSxPOINTS]\n";

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

/// A field of /proc/self/status in bytes (VmRSS, VmHWM).
size_t StatusBytes(const char* field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field, 0) == 0)
      return std::strtoull(line.c_str() + std::string(field).size() + 1, nullptr, 10) * 1024;
  }
  return 0;
}

/// Peak resident growth of `fn`, in bytes (0 where the kernel cannot reset the peak).
template <class Fn>
size_t PeakGrowth(Fn&& fn) {
  // Return memory freed by earlier runs first (so that reusing it counts again), then reset the
  // peak to the resident set as it is now.
  malloc_trim(0);
  {
    std::ofstream reset("/proc/self/clear_refs");
    reset << "5";
  }
  const size_t before = StatusBytes("VmRSS:");
  fn();
  const size_t peak = StatusBytes("VmHWM:");
  return peak > before ? peak - before : 0;
}

struct BenchResult {
  std::string name;
  size_t n = 0;
  std::string backend;
  double galpha_ms = std::numeric_limits<double>::infinity();
  double transfer_ms = 0;
  /// The engine's stages but the transfers (on CUDA: the stream's timeline between the upload and
  /// the download, by CUDA events), and the rest of the call: host work around the engine
  /// (validation, the family's assembly) and whatever no stage covers.
  double pipeline_ms = std::numeric_limits<double>::infinity();
  double host_ms = 0;
  size_t galpha_rss = 0;
  size_t galpha_engine_peak = 0;
  double classify_ms = 0;
  double floor_ms = -1;  // one backend sort of the spectrum's (key, value) pairs
  size_t spectrum = 0;
  size_t sort_pairs = 0;
  ComparisonCounts counts;
  std::vector<StageTime> stages;
  double unweighted_pipeline_ms = -1;  // with --weights: the same points built unweighted
  double cgal_ms = -1;                 // not run above --cgal-max
  size_t cgal_rss = 0;
  size_t cgal_spectrum = 0;
  std::string error;
};

bool IsTransferStage(const std::string& stage) { return stage == "upload" || stage == "download"; }

/// Host work around the engine call (BuildAlphaFamily's own stages).
bool IsHostStage(const std::string& stage) { return stage == "validate" || stage == "assemble"; }

/// The pipeline time (stages, transfers and host work apart) of a build's report.
double PipelineMilliseconds(const BuildReport& report) {
  double ms = 0;
  for (const StageTime& s : report.stage_times) {
    if (!IsTransferStage(s.stage) && !IsHostStage(s.stage)) ms += s.seconds * 1e3;
  }
  return ms;
}

BenchResult RunOne(const std::string& name, const std::vector<Point2>& points, const std::vector<double>& weights,
                   const BenchOptions& options) {
  BenchResult result;
  result.name = name;
  result.n = points.size();
  BuildOptions build;
  build.backend = options.backend;
  for (int r = 0; r < options.repeat; ++r) {
    absl::StatusOr<AlphaFamily> family = absl::InternalError("not run");
    double ms = 0;
    const size_t rss = PeakGrowth([&] {
      const auto start = std::chrono::steady_clock::now();
      family = weights.empty() ? BuildAlphaFamily(points, build) : BuildWeightedAlphaFamily(points, weights, build);
      ms = MillisecondsSince(start);
    });
    if (!family.ok()) {
      result.error = family.status().ToString();
      return result;
    }
    result.galpha_rss = std::max(result.galpha_rss, rss);
    // The pipeline and its stages are those of the run with the fastest pipeline, which need not
    // be the run with the fastest whole call: a process's first build of an input that reaches
    // the exact comparison kernels pays their first launch once (about 9 ms at 1M on an H200:
    // bench/README.md, "first launch"), and a first run whose host side happened to be quick
    // would otherwise report it.
    const double pipeline_ms = PipelineMilliseconds(family->report());
    if (pipeline_ms < result.pipeline_ms) {
      result.pipeline_ms = pipeline_ms;
      result.stages = family->report().stage_times;
    }
    if (ms < result.galpha_ms) {
      result.galpha_ms = ms;
      result.backend = family->report().backend;
      result.counts = family->report().comparisons;
      result.galpha_engine_peak = family->report().peak_memory_bytes;
      // CGAL's spectrum holds the values > 0 only (weighted thresholds can be negative).
      result.spectrum = static_cast<size_t>(
          std::count_if(family->spectrum().begin(), family->spectrum().end(), [](double v) { return v > 0; }));
      result.sort_pairs = family->triangles().size() + family->edges().size();
      result.transfer_ms = 0;
      for (const StageTime& s : family->report().stage_times) {
        if (IsTransferStage(s.stage)) result.transfer_ms += s.seconds * 1e3;
      }
      result.host_ms = ms - result.transfer_ms - pipeline_ms;
      const auto start = std::chrono::steady_clock::now();
      const Classification c =
          family->ClassifyAll(family->max_level() / 2, ClassifyMode::kGeneral, VertexRule::kReport);
      result.classify_ms = MillisecondsSince(start);
      if (c.edges.size() != family->edges().size()) result.error = "classification size mismatch";
    }
  }
  if (result.error.empty() && !result.stages.empty()) {
    // The spectrum sorts one (key, id) pair per triangle and edge: 2n + 3n pairs or so.
    auto floor = MeasureSortFloorSeconds(result.sort_pairs, options.backend);
    if (floor.ok()) result.floor_ms = *floor * 1e3;
  }
  if (!weights.empty() && result.error.empty()) {
    for (int r = 0; r < options.repeat; ++r) {
      absl::StatusOr<AlphaFamily> plain = BuildAlphaFamily(points, build);
      if (!plain.ok()) break;
      const double ms = PipelineMilliseconds(plain->report());
      if (result.unweighted_pipeline_ms < 0 || ms < result.unweighted_pipeline_ms) result.unweighted_pipeline_ms = ms;
    }
  }
  if (points.size() > options.competitor_max) return result;
  if (!weights.empty()) {
    std::vector<Kernel::Weighted_point_2> cgal_points;
    cgal_points.reserve(points.size());
    for (size_t i = 0; i < points.size(); ++i)
      cgal_points.emplace_back(Kernel::Point_2(points[i].x, points[i].y), weights[i]);
    const auto start = std::chrono::steady_clock::now();
    result.cgal_rss = PeakGrowth([&] {
      const CgalWeightedAlphaShape shape(cgal_points.begin(), cgal_points.end(), Kernel::FT(0),
                                         CgalWeightedAlphaShape::GENERAL);
      result.cgal_ms = MillisecondsSince(start);
      result.cgal_spectrum = static_cast<size_t>(std::distance(shape.alpha_begin(), shape.alpha_end()));
    });
    return result;
  }
  std::vector<Kernel::Point_2> cgal_points;
  cgal_points.reserve(points.size());
  for (const Point2& p : points) cgal_points.emplace_back(p.x, p.y);
  // CGAL takes tens of seconds at 1M points: one run is enough.
  const auto start = std::chrono::steady_clock::now();
  result.cgal_rss = PeakGrowth([&] {
    const CgalAlphaShape shape(cgal_points.begin(), cgal_points.end(), Kernel::FT(0), CgalAlphaShape::GENERAL);
    result.cgal_ms = MillisecondsSince(start);
    result.cgal_spectrum = static_cast<size_t>(std::distance(shape.alpha_begin(), shape.alpha_end()));
  });
  return result;
}

void PrintHeader() {
  std::printf(
      "| input | n | galpha backend | galpha ms (whole call) | transfers ms | pipeline ms (stages, transfers apart) | "
      "host ms | CGAL EPEC ms | CGAL / whole call | CGAL / pipeline | galpha peak RSS B/pt | "
      "engine peak B/pt | CGAL peak RSS B/pt | classify all ms | spectrum | exact cmp (filter / bounded / CPU "
      "fallback) | floor sort ms | pipeline / floor |\n"
      "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|\n");
}

void PrintRow(const BenchResult& r) {
  if (!r.error.empty()) {
    std::printf("| %s | %zu | - | error: %s ||||||||||||||\n", r.name.c_str(), r.n, r.error.c_str());
    std::fflush(stdout);
    return;
  }
  const double n = static_cast<double>(std::max<size_t>(r.n, 1));
  std::string cgal = "-", ratio = "-", pipeline_ratio = "-", cgal_mem = "-";
  if (r.cgal_ms >= 0) {
    cgal = absl::StrCat(static_cast<int64_t>(r.cgal_ms));
    char text[32];
    std::snprintf(text, sizeof text, "%.1f", r.cgal_ms / r.galpha_ms);
    ratio = text;
    std::snprintf(text, sizeof text, "%.0f", r.cgal_ms / r.pipeline_ms);
    pipeline_ratio = text;
    cgal_mem = absl::StrCat(static_cast<int64_t>(static_cast<double>(r.cgal_rss) / n));
  }
  std::string spectrum = absl::StrCat(r.spectrum);
  if (r.cgal_ms >= 0 && r.cgal_spectrum != r.spectrum)
    absl::StrAppend(&spectrum, " (CGAL ", r.cgal_spectrum, ": MISMATCH)");
  std::string floor = "-", over_floor = "-";
  if (r.floor_ms > 0) {
    char text[48];
    std::snprintf(text, sizeof text, "%.2f", r.floor_ms);
    floor = text;
    std::snprintf(text, sizeof text, "%.1f", r.pipeline_ms / r.floor_ms);
    over_floor = text;
  }
  std::printf(
      "| %s | %zu | %s | %.1f | %.1f | %.1f | %.1f | %s | %s | %s | %.0f | %.0f | %s | %.1f | %s | %llu / %llu / %llu "
      "| %s | %s |\n",
      r.name.c_str(), r.n, r.backend.c_str(), r.galpha_ms, r.transfer_ms, r.pipeline_ms, r.host_ms, cgal.c_str(),
      ratio.c_str(), pipeline_ratio.c_str(), static_cast<double>(r.galpha_rss) / n,
      static_cast<double>(r.galpha_engine_peak) / n, cgal_mem.c_str(), r.classify_ms, spectrum.c_str(),
      static_cast<unsigned long long>(r.counts.filter), static_cast<unsigned long long>(r.counts.bounded_exact),
      static_cast<unsigned long long>(r.counts.cpu_fallback), floor.c_str(), over_floor.c_str());
  std::fflush(stdout);
}

void PrintStages(const std::vector<BenchResult>& results) {
  std::printf("\n| input | n | galpha stages of the run with the best pipeline (ms) |\n|---|---:|---|\n");
  for (const BenchResult& r : results) {
    if (!r.error.empty()) continue;
    std::string stages;
    for (const StageTime& s : r.stages) {
      char ms[48];
      std::snprintf(ms, sizeof ms, "%s%s %.1f", stages.empty() ? "" : ", ", s.stage.c_str(), s.seconds * 1e3);
      stages += ms;
    }
    std::printf("| %s | %zu | %s |\n", r.name.c_str(), r.n, stages.c_str());
  }
}

/// Hard inputs against easy ones: each row's pipeline over the uniform row of the same size (when
/// there is one), over CGAL's time, and its largest stage.
void PrintHardness(const std::vector<BenchResult>& results) {
  std::printf(
      "\n| input | n | pipeline ms | pipeline / uniform's | CGAL / pipeline | dominant stage (ms) | weighted / "
      "unweighted pipeline |\n"
      "|---|---:|---:|---:|---:|---|---:|\n");
  for (const BenchResult& r : results) {
    if (!r.error.empty()) continue;
    std::string vs_uniform = "-", vs_cgal = "-", dominant = "-";
    char text[96];
    for (const BenchResult& u : results) {
      if (u.error.empty() && u.name == "uniform" && u.n == r.n && u.pipeline_ms > 0) {
        std::snprintf(text, sizeof text, "%.2fx", r.pipeline_ms / u.pipeline_ms);
        vs_uniform = text;
      }
    }
    if (r.cgal_ms >= 0 && r.pipeline_ms > 0) {
      std::snprintf(text, sizeof text, "%.0fx", r.cgal_ms / r.pipeline_ms);
      vs_cgal = text;
    }
    const StageTime* top = nullptr;
    for (const StageTime& s : r.stages) {
      if (IsTransferStage(s.stage) || IsHostStage(s.stage)) continue;
      if (top == nullptr || s.seconds > top->seconds) top = &s;
    }
    if (top != nullptr) {
      std::snprintf(text, sizeof text, "%s (%.1f)", top->stage.c_str(), top->seconds * 1e3);
      dominant = text;
    }
    std::string vs_unweighted = "-";
    if (r.unweighted_pipeline_ms > 0) {
      std::snprintf(text, sizeof text, "%.2fx (%.1f ms)", r.pipeline_ms / r.unweighted_pipeline_ms,
                    r.unweighted_pipeline_ms);
      vs_unweighted = text;
    }
    std::printf("| %s | %zu | %.1f | %s | %s | %s | %s |\n", r.name.c_str(), r.n, r.pipeline_ms, vs_uniform.c_str(),
                vs_cgal.c_str(), dominant.c_str(), vs_unweighted.c_str());
  }
}

template <class V>
bool SameVector(const V& a, const V& b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
}

/// Whether two families of one set have the same rank tables (the packed build's check; the full
/// field-by-field check is packed_families_test's).
bool SameRankTables(const AlphaFamily& a, const AlphaFamily& b) {
  const AlphaRanks& x = a.ranks();
  const AlphaRanks& y = b.ranks();
  bool same = SameVector(x.spectrum, y.spectrum) && SameVector(x.spectrum_simplex, y.spectrum_simplex) &&
              SameVector(x.tri_rank, y.tri_rank) && SameVector(x.edge_rho_rank, y.edge_rho_rank) &&
              SameVector(x.edge_mu_low, y.edge_mu_low) && SameVector(x.edge_mu_high, y.edge_mu_high) &&
              SameVector(x.vertex_mu_low, y.vertex_mu_low) && SameVector(x.vertex_tri_low, y.vertex_tri_low) &&
              SameVector(x.master_begin, y.master_begin) && SameVector(x.components, y.components) &&
              SameVector(x.holes, y.holes) && SameVector(x.area_units, y.area_units);
  for (size_t i = 0; same && i < x.master.size(); ++i) same = x.master[i].packed() == y.master[i].packed();
  return same && x.master.size() == y.master.size();
}

/// --sets: one distribution's packed families against their references (see the file comment).
/// Returns false on an engine error or a sampled set unlike its own build.
bool RunPackedFamilies(const std::string& name, size_t num_sets, size_t points_per_set, const BenchOptions& options) {
  BuildOptions build_options;
  build_options.backend = options.backend;
  std::optional<AlphaFamilies> packed;
  PackedSetsCalls calls;
  calls.packed = [&](const std::vector<Point2>& points, const std::vector<uint32_t>& set_begin, std::string* error) {
    absl::StatusOr<AlphaFamilies> built = BuildAlphaFamilies(points, set_begin, build_options);
    if (!built.ok()) *error = built.status().ToString();
    if (built.ok()) packed = *std::move(built);
    return packed.has_value();
  };
  calls.release = [&] { packed.reset(); };
  calls.whole = [&](const std::vector<Point2>& points) { return BuildAlphaFamily(points, build_options).ok(); };
  calls.alone = [&](absl::Span<const Point2> set, size_t s, bool* equal) {
    absl::StatusOr<AlphaFamily> alone = BuildAlphaFamily(set, build_options);
    if (!alone.ok()) return false;
    *equal = SameRankTables(packed->families[s], *alone);
    return true;
  };
  // CGAL's alpha shape of a set takes milliseconds to seconds: timed once.
  calls.competitor = [](absl::Span<const Point2> set) {
    std::vector<Kernel::Point_2> cgal_points;
    for (const Point2& p : set) cgal_points.emplace_back(p.x, p.y);
    const CgalAlphaShape shape(cgal_points.begin(), cgal_points.end(), Kernel::FT(0), CgalAlphaShape::GENERAL);
  };
  calls.describe = [&](PackedSetsRow* row) {
    row->backend = packed->report.backend;
    row->built_alone = packed->built_alone;
    row->stages = packed->report.stage_times;
  };
  return RunPackedSetsBench(name, num_sets, points_per_set, options, calls);
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
      !taken.ok() || (num_sets > 0 && !weight_kind.empty())) {
    std::fprintf(
        stderr, "%s\n%s",
        taken.ok() ? "--sets builds unweighted families: drop --weights" : std::string(taken.message()).c_str(),
        kUsage);
    return 2;
  }
  args = std::move(rest);
  const absl::StatusOr<BenchOptions> options = ParseBenchArgs(static_cast<int>(args.size()), args.data(), "--cgal-max");
  if (!options.ok()) {
    std::fprintf(stderr, "%s\n%s", std::string(options.status().message()).c_str(), kUsage);
    return 2;
  }
  std::printf("alpha_bench: backend %s requested (CUDA %s), galpha best of %d, CGAL once, %u host threads%s\n\n",
              BackendName(options->backend), CudaBackendAvailable() ? "available" : "unavailable", options->repeat,
              std::thread::hardware_concurrency(),
              weight_kind.empty() ? "" : absl::StrCat("; weights ", weight_kind, " (weighted families)").c_str());
  if (num_sets > 0) {
    std::printf(
        "| distribution | sets x points | backend | packed ms (BuildAlphaFamilies) | one family of all the points "
        "ms | packed / all in one | one call a set ms (200 sampled, scaled) | calls a set / packed | CGAL a set ms "
        "(same sample) | CGAL / packed | sampled sets equal their own builds |\n"
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|\n");
    bool all_equal = true;
    for (const std::string& name : options->distributions) {
      std::fprintf(stderr, "running %s, %zu sets of %zu points\n", name.c_str(), num_sets, points_per_set);
      all_equal &= RunPackedFamilies(name, num_sets, points_per_set, *options);
    }
    return all_equal ? 0 : 1;
  }
  PrintHeader();
  std::vector<BenchResult> results;
  bool failed = false;
  auto run = [&](const std::string& name, const std::vector<Point2>& points) {
    std::fprintf(stderr, "running %s n=%zu\n", name.c_str(), points.size());
    const std::vector<double> weights =
        weight_kind.empty() ? std::vector<double>{} : gen::Weights(weight_kind, points, options->seed);
    BenchResult r = RunOne(name, points, weights, *options);
    failed |= !r.error.empty() || (r.cgal_ms >= 0 && r.cgal_spectrum != r.spectrum);
    PrintRow(r);
    results.push_back(std::move(r));
  };
  if (const absl::Status read = ForEachBenchInput(*options, run); !read.ok()) {
    std::fprintf(stderr, "%s\n", read.ToString().c_str());
    return 1;
  }
  PrintStages(results);
  PrintHardness(results);
  return failed ? 1 : 0;
}

}  // namespace
}  // namespace galpha

int main(int argc, char** argv) { return galpha::Main(argc, argv); }
