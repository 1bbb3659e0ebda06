// The CUDA and CPU backends build identical families: the same spectrum (bit for bit), the same
// ranks and intervals for every triangle and edge (named by their vertices, so that the test does
// not depend on the order in which each backend emits them), the same vertex intervals, the same
// master list rank by rank, the same component and hole curves, the same persistence pairs; for
// unweighted and weighted families (the same hidden points too). Skipped without a GPU; run
// on one by bench/gpu_run.sh test.
#include <algorithm>
#include <array>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "core/family/alpha_family.hpp"
#include "core/family/canonical_order.hpp"
#include "core/family/persistence.hpp"
#include "core/io/point_formats.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gtest/gtest.h"
#include "tests/support/data_files.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"
#include "tests/support/weight_generators.hpp"

namespace galpha {
namespace {

using testing::IsOk;

using Simplex = std::array<uint32_t, 3>;  // sorted vertex indices; unused slots are ~0u

Simplex EdgeKey(const AlphaFamily& f, uint32_t e) { return {f.edges()[e][0], f.edges()[e][1], ~0u}; }
Simplex TriangleKey(const AlphaFamily& f, uint32_t t) {
  Simplex s = f.triangles()[t];
  std::sort(s.begin(), s.end());
  return s;
}

// Every interval end point of the family, named by simplex vertices.
std::map<Simplex, std::array<uint32_t, 3>> Intervals(const AlphaFamily& f) {
  const AlphaRanks& r = f.ranks();
  std::map<Simplex, std::array<uint32_t, 3>> out;
  for (uint32_t t = 0; t < f.triangles().size(); ++t) out[TriangleKey(f, t)] = {r.tri_rank[t], 0, 0};
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    out[EdgeKey(f, e)] = {r.edge_rho_rank[e], r.edge_mu_low[e], r.edge_mu_high[e]};
  }
  return out;
}

// The master list of one rank as a sorted list of (kind, vertices, end point).
std::vector<std::tuple<int, Simplex, int>> MasterAt(const AlphaFamily& f, int64_t rank) {
  std::vector<std::tuple<int, Simplex, int>> out;
  for (const MasterEntry& m : f.MasterList(rank)) {
    Simplex s{m.id(), ~0u, ~0u};
    if (m.kind() == SimplexKind::kEdge) s = EdgeKey(f, m.id());
    if (m.kind() == SimplexKind::kTriangle) s = TriangleKey(f, m.id());
    out.emplace_back(static_cast<int>(m.kind()), s, static_cast<int>(m.endpoint()));
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The diagram's pairs with their simplices named by vertices.
std::vector<std::tuple<uint32_t, uint32_t, uint32_t, Simplex, Simplex>> PersistenceByVertices(const AlphaFamily& f) {
  const absl::StatusOr<PersistenceDiagram> diagram = ComputePersistence(f);
  EXPECT_THAT(diagram, IsOk());
  std::vector<std::tuple<uint32_t, uint32_t, uint32_t, Simplex, Simplex>> out;
  if (!diagram.ok()) return out;
  for (const PersistencePair& p : diagram->pairs) {
    const Simplex none{~0u, ~0u, ~0u};
    if (p.dimension == 0) {
      out.emplace_back(0, p.birth_rank, p.death_rank, Simplex{p.creator, ~0u, ~0u},
                       p.essential() ? none : EdgeKey(f, p.killer));
    } else {
      out.emplace_back(1, p.birth_rank, p.death_rank, EdgeKey(f, p.creator),
                       p.essential() ? none : TriangleKey(f, p.killer));
    }
  }
  return out;
}

/// `weights` empty: the unweighted family; else the weighted one.
void ExpectIdentical(const std::vector<Point2>& points, const std::string& where,
                     const std::vector<double>& weights = {}) {
  BuildOptions cpu_options, cuda_options;
  cpu_options.backend = Backend::kCpu;
  cuda_options.backend = Backend::kCuda;
  auto build = [&](const BuildOptions& options) {
    return weights.empty() ? BuildAlphaFamily(points, options) : BuildWeightedAlphaFamily(points, weights, options);
  };
  absl::StatusOr<AlphaFamily> cpu = build(cpu_options);
  absl::StatusOr<AlphaFamily> cuda = build(cuda_options);
  ASSERT_THAT(cpu, IsOk()) << where;
  ASSERT_THAT(cuda, IsOk()) << where;
  ASSERT_EQ(cuda->report().backend, "cuda");
  ASSERT_EQ(cpu->spectrum(), cuda->spectrum()) << where;
  ASSERT_EQ(cpu->representative(), cuda->representative()) << where;
  ASSERT_EQ(cpu->HiddenPoints(), cuda->HiddenPoints()) << where;
  ASSERT_EQ(Intervals(*cpu), Intervals(*cuda)) << where;
  ASSERT_EQ(cpu->ranks().vertex_mu_low, cuda->ranks().vertex_mu_low) << where;
  ASSERT_EQ(cpu->ranks().vertex_mu_high, cuda->ranks().vertex_mu_high) << where;
  ASSERT_EQ(cpu->ranks().vertex_tri_low, cuda->ranks().vertex_tri_low) << where;
  ASSERT_EQ(cpu->ranks().master_begin, cuda->ranks().master_begin) << where;
  for (int64_t rank = 1; rank <= cpu->max_level(); ++rank) {
    ASSERT_EQ(MasterAt(*cpu, rank), MasterAt(*cuda, rank)) << where << " rank " << rank;
  }
  for (int64_t level = 0; level <= cpu->max_level(); ++level) {
    ASSERT_EQ(cpu->Components(level), cuda->Components(level)) << where << " level " << level;
    ASSERT_EQ(cpu->SolidComponents(level), cuda->SolidComponents(level)) << where << " level " << level;
    ASSERT_EQ(cpu->RegularizedComponents(level), cuda->RegularizedComponents(level)) << where << " level " << level;
    for (ClassifyMode mode : {ClassifyMode::kGeneral, ClassifyMode::kRegularized}) {
      ASSERT_EQ(cpu->Holes(level, mode), cuda->Holes(level, mode)) << where << " level " << level;
    }
  }
  // The area curve: integer sums, so identical whatever order each backend adds in.
  ASSERT_EQ(cpu->ranks().area_units, cuda->ranks().area_units) << where;
  ASSERT_EQ(cpu->ranks().area_scale.unit_log2, cuda->ranks().area_scale.unit_log2) << where;
  ASSERT_EQ(cpu->ranks().area_scale.error_units, cuda->ranks().area_scale.error_units) << where;
  // The persistence diagram: the same classes with the same creating and killing simplices.
  ASSERT_EQ(PersistenceByVertices(*cpu), PersistenceByVertices(*cuda)) << where;
  EXPECT_EQ(cuda->report().comparisons.cpu_fallback, 0u) << where;
}

TEST(AlphaBackendIdentityTest, EveryGenerator) {
  if (!CudaBackendAvailable()) GTEST_SKIP() << "no GPU";
  for (const char* name :
       {"uniform", "gaussian", "clustered", "grid", "circle", "thin_circle", "two_lines", "parallel_lines",
        "with_duplicates", "huge_offset_1e9", "huge_offset_1e15", "tiny", "ulp_lattice", "lidar_cm"}) {
    const gen::NamedGenerator* generator = gen::FindDistribution(name);
    ASSERT_NE(generator, nullptr) << name;
    for (size_t n : {size_t{1000}, size_t{100000}}) {
      ExpectIdentical(generator->generate(n, 3), std::string(name) + " n=" + std::to_string(n));
      if (HasFatalFailure()) return;
    }
  }
}

TEST(AlphaBackendIdentityTest, WeightedFamilies) {
  if (!CudaBackendAvailable()) GTEST_SKIP() << "no GPU";
  for (const char* name : {"uniform", "gaussian", "clustered", "grid", "circle", "two_lines", "parallel_lines",
                           "with_duplicates", "huge_offset_1e9", "ulp_lattice", "lidar_cm"}) {
    const gen::NamedGenerator* generator = gen::FindDistribution(name);
    ASSERT_NE(generator, nullptr) << name;
    for (const std::string& kind : gen::WeightKinds()) {
      for (size_t n : {size_t{1000}, size_t{100000}}) {
        const std::vector<Point2> points = generator->generate(n, 5);
        ExpectIdentical(points, std::string(name) + " " + kind + " n=" + std::to_string(n),
                        gen::Weights(kind, points, 6));
        if (HasFatalFailure()) return;
      }
    }
  }
  // The molecule with its atoms' radii, and with a water probe's.
  absl::StatusOr<GeoreferencedPoints> atoms = ReadWeightedPointsFile(testdata::DataDir() + "/pdb_2xhe_radii.txt");
  ASSERT_THAT(atoms, IsOk());
  for (const double probe : {0.0, 1.4}) {
    std::vector<double> weights;
    for (const double r : atoms->weights) weights.push_back((r + probe) * (r + probe));
    ExpectIdentical(atoms->points, "2XHE probe " + std::to_string(probe), weights);
    if (HasFatalFailure()) return;
  }
}

TEST(AlphaBackendIdentityTest, RealDataSets) {
  if (!CudaBackendAvailable()) GTEST_SKIP() << "no GPU";
  for (const std::string& file : testdata::PointFiles()) {
    absl::StatusOr<std::vector<Point2>> points = ReadPointsFile(file);
    ASSERT_THAT(points, IsOk());
    ExpectIdentical(*points, file);
    if (HasFatalFailure()) return;
  }
}

}  // namespace
}  // namespace galpha
