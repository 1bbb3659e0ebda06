// topology_bench: the topology of the whole family (Betti curves of both complexes and the H0/H1
// persistence diagram) against GUDHI's exact alpha-complex persistence, measured in the same run.
//   topology_bench [--backend=auto|cpu|cuda] [--repeat=3] [--sizes=100000,1000000]
//                  [--dists=NAME,...(default: every generator)] [--seed=1] [--gudhi-max=1000000]
//                  [--data FILE.bin]...
// Per input: the family build (the engine's stages, the Betti curves among them: the "components"
// stage computes the component and hole curves of both complexes in one pass), the persistence
// diagram from the built family by the engine on the build's backend (gpu/alpha/
// persistence_engine.hpp: upload, canonical orders, the two forests' elder rule, the sorted pairs;
// checked pair for pair against the host's), the same computed inside a build (BuildOptions::
// persistence: the family's arrays where they lie, the stages persistence_*; its components stage
// also finds the diagram's primal forest, so its time is shown beside the plain build's), the host's diagram (the
// canonical orders, which the service computes once per cached family, then radix sorts by rank and two union-finds),
// and GUDHI's AlphaComplex (exact) + persistent cohomology over Z/2Z on the same points, with both diagrams' numbers of
// intervals of positive length (they may differ by a few where GUDHI's doubles reorder near-ties:
// tests/gpu/alpha/persistence_gudhi_test.cpp compares the diagrams themselves).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_options.hpp"
#include "core/family/alpha_family.hpp"
#include "core/family/canonical_order.hpp"
#include "core/family/persistence.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gpu/alpha/persistence_engine.hpp"
#include "tests/support/gudhi_persistence_oracle.hpp"

namespace galpha {
namespace {

constexpr char kUsage[] =
    "usage: topology_bench [--backend=auto|cpu|cuda] [--repeat=N] [--sizes=N,...] [--dists=NAME,...]\n"
    "                      [--seed=N] [--gudhi-max=N] [--data FILE.bin]...\n";

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

struct TopologyResult {
  std::string name;
  size_t n = 0;
  std::string backend;
  double build_ms = std::numeric_limits<double>::infinity();        // the whole BuildAlphaFamily call
  double curves_ms = 0;                                             // its "components" stage
  double orders_ms = std::numeric_limits<double>::infinity();       // the canonical orders (cached by the service)
  double persistence_ms = std::numeric_limits<double>::infinity();  // the diagram from them
  double engine_ms = std::numeric_limits<double>::infinity();       // the engine's diagram, whole call
  PersistenceReport engine_report;                                  // of its fastest run
  bool engine_same = true;                                          // pair for pair the host's
  double build_with_ms = std::numeric_limits<double>::infinity();   // BuildOptions::persistence
  std::vector<StageTime> in_build_stages;                           // its persistence_* stages
  double curves_with_ms = 0;                                        // its "components" stage
  size_t intervals[2] = {0, 0};                                     // of positive length (as doubles), both dimensions
  double gudhi_ms = -1;                                             // not run above --gudhi-max
  size_t gudhi_intervals[2] = {0, 0};
  std::string error;
};

bool SameDiagram(const PersistenceDiagram& a, const PersistenceDiagram& b) { return a.pairs == b.pairs; }

TopologyResult RunOne(const std::string& name, const std::vector<Point2>& points, const BenchOptions& options) {
  TopologyResult result;
  result.name = name;
  result.n = points.size();
  BuildOptions build;
  build.backend = options.backend;
  for (int r = 0; r < options.repeat; ++r) {
    auto start = std::chrono::steady_clock::now();
    absl::StatusOr<AlphaFamily> family = BuildAlphaFamily(points, build);
    const double build_ms = MillisecondsSince(start);
    if (!family.ok()) {
      result.error = family.status().ToString();
      return result;
    }
    if (build_ms < result.build_ms) {
      result.build_ms = build_ms;
      result.backend = family->report().backend;
      for (const StageTime& s : family->report().stage_times) {
        if (s.stage == "components") result.curves_ms = s.seconds * 1e3;
      }
    }
    start = std::chrono::steady_clock::now();
    const CanonicalOrders orders = ComputeCanonicalOrders(*family);
    result.orders_ms = std::min(result.orders_ms, MillisecondsSince(start));
    start = std::chrono::steady_clock::now();
    absl::StatusOr<PersistenceDiagram> diagram = ComputePersistence(*family, orders.edge_order, orders.triangle_order);
    const double persistence_ms = MillisecondsSince(start);
    if (!diagram.ok()) {
      result.error = diagram.status().ToString();
      return result;
    }
    result.persistence_ms = std::min(result.persistence_ms, persistence_ms);
    PersistenceOptions engine_options;
    engine_options.backend = options.backend;
    PersistenceReport report;
    start = std::chrono::steady_clock::now();
    absl::StatusOr<PersistenceDiagram> engine = ComputePersistenceOnBackend(*family, engine_options, &report);
    const double engine_ms = MillisecondsSince(start);
    if (!engine.ok()) {
      result.error = engine.status().ToString();
      return result;
    }
    if (engine_ms < result.engine_ms) {
      result.engine_ms = engine_ms;
      result.engine_report = std::move(report);
    }
    result.engine_same &= SameDiagram(*engine, *diagram);
    // The diagram computed in the build, from the family's arrays where they lie.
    BuildOptions with = build;
    with.persistence = true;
    start = std::chrono::steady_clock::now();
    absl::StatusOr<AlphaFamily> built_with = BuildAlphaFamily(points, with);
    const double build_with_ms = MillisecondsSince(start);
    if (!built_with.ok()) {
      result.error = built_with.status().ToString();
      return result;
    }
    result.engine_same &= built_with->persistence() != nullptr && SameDiagram(*built_with->persistence(), *diagram);
    if (build_with_ms < result.build_with_ms) {
      result.build_with_ms = build_with_ms;
      result.in_build_stages.clear();
      for (const StageTime& s : built_with->report().stage_times) {
        if (s.stage.rfind("persistence_", 0) == 0) result.in_build_stages.push_back(s);
        if (s.stage == "components") result.curves_with_ms = s.seconds * 1e3;
      }
    }
    for (int d = 0; d < 2; ++d) {
      result.intervals[d] = 0;
      for (size_t i = diagram->dimension_begin[d]; i < diagram->dimension_begin[d + 1]; ++i) {
        const PersistencePair& p = diagram->pairs[i];
        result.intervals[d] += RankValue(*family, p.death_rank) > RankValue(*family, p.birth_rank);
      }
    }
  }
  if (points.size() <= options.competitor_max) {
    // GUDHI takes seconds at 1M points: one run.
    const auto start = std::chrono::steady_clock::now();
    const testing::GudhiDiagram gudhi = testing::GudhiAlphaPersistence(points);
    result.gudhi_ms = MillisecondsSince(start);
    for (int d = 0; d < 2; ++d) result.gudhi_intervals[d] = gudhi.intervals[d].size();
  }
  return result;
}

void PrintRow(const TopologyResult& r) {
  if (!r.error.empty()) {
    std::printf("| %s | %zu | error: %s |\n", r.name.c_str(), r.n, r.error.c_str());
    return;
  }
  std::string gudhi = "-", ratio = "-", gudhi_counts = "-";
  char text[64];
  if (r.gudhi_ms >= 0) {
    std::snprintf(text, sizeof text, "%.1f", r.gudhi_ms);
    gudhi = text;
    double in_build_ms = 0;
    for (const StageTime& stage : r.in_build_stages) in_build_ms += stage.seconds * 1e3;
    std::snprintf(text, sizeof text, "%.0fx", r.gudhi_ms / (r.curves_with_ms + in_build_ms));
    ratio = text;
    std::snprintf(text, sizeof text, "%zu / %zu", r.gudhi_intervals[0], r.gudhi_intervals[1]);
    gudhi_counts = text;
  }
  std::string stages;
  for (const StageTime& stage : r.engine_report.stage_times) {
    std::snprintf(text, sizeof text, "%s%s %.2f", stages.empty() ? "" : ", ", stage.stage.c_str(), stage.seconds * 1e3);
    stages += text;
  }
  for (int d = 0; d < 2; ++d) {
    const ForestPairing& f = r.engine_report.forests[d];
    std::snprintf(text, sizeof text, "; H%d: %u rounds, %u of %u edges on the host", d, f.rounds, f.host_finished_edges,
                  f.forest_edges);
    stages += text;
  }
  double in_build_ms = 0;
  std::string in_build;
  for (const StageTime& stage : r.in_build_stages) {
    in_build_ms += stage.seconds * 1e3;
    std::snprintf(text, sizeof text, "%s%s %.2f", in_build.empty() ? "" : ", ", stage.stage.c_str() + 12,
                  stage.seconds * 1e3);
    in_build += text;
  }
  std::printf(
      "| %s | %zu | %s | %.1f | %.2f | %.1f | %.2f | %.2f (%s) | %.2f | %.2f (%s)%s | %.1f | %.1f | %.2fx | %zu / %zu "
      "| "
      "%s | %s | %s |\n",
      r.name.c_str(), r.n, r.backend.c_str(), r.build_ms, r.curves_ms, r.build_with_ms, r.curves_with_ms, in_build_ms,
      in_build.c_str(), r.curves_with_ms + in_build_ms, r.engine_ms, stages.c_str(),
      r.engine_same ? "" : " DIFFERENT from the host's", r.orders_ms, r.persistence_ms,
      (r.orders_ms + r.persistence_ms) / r.engine_ms, r.intervals[0], r.intervals[1], gudhi_counts.c_str(),
      gudhi.c_str(), ratio.c_str());
  std::fflush(stdout);
}

int Main(int argc, char** argv) {
  const absl::StatusOr<BenchOptions> options = ParseBenchArgs(argc, argv, "--gudhi-max");
  if (!options.ok()) {
    std::fprintf(stderr, "%s\n%s", std::string(options.status().message()).c_str(), kUsage);
    return 2;
  }
  std::printf("topology_bench: backend %s requested (CUDA %s), galpha best of %d, GUDHI once, %u host threads\n\n",
              BackendName(options->backend), CudaBackendAvailable() ? "available" : "unavailable", options->repeat,
              std::thread::hardware_concurrency());
  std::printf(
      "| input | n | backend | family build ms | Betti curves ms (components stage) | build with the diagram ms | "
      "its components stage ms (curves and the primal forest) | the diagram's stages in that build ms | "
      "curves + diagram in that build ms | engine diagram of a built family ms (stages) | "
      "host: canonical orders ms | host: diagram ms | host / engine | H0 / H1 intervals | GUDHI's H0 / H1 intervals | "
      "GUDHI exact ms | GUDHI / (curves + diagram in the build) |\n"
      "|---|---:|---|---:|---:|---:|---:|---|---:|---|---:|---:|---:|---:|---:|---:|---:|\n");
  bool failed = false;
  auto run = [&](const std::string& name, const std::vector<Point2>& points) {
    std::fprintf(stderr, "running %s n=%zu\n", name.c_str(), points.size());
    const TopologyResult r = RunOne(name, points, *options);
    failed |= !r.error.empty() || !r.engine_same;
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
