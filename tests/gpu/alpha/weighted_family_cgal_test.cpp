// The weighted alpha family (BuildWeightedAlphaFamily) against CGAL's weighted Alpha_shape_2 over
// Regular_triangulation_2 with exact constructions (tests/support/cgal_weighted_alpha_oracle.hpp),
// on every distribution with every kind of weights (tests/support/weight_generators.hpp), small
// random sets, and the molecular data set with element radii (data/pdb_2xhe_radii.txt): the same hidden points; where
// the two regular triangulations are the same (they differ only where an exact power tie falls to a term of the tie
// rule beyond the first: core/exact/power.hpp), the same thresholds exactly (our spectrum is every distinct threshold,
// negative ones included), the nearest doubles, and at sampled levels and between them the class of every edge and
// vertex (CGAL's vertex rule) and the number of interior triangles; where they differ, the classes of the edges both
// have.
#include <gmpxx.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/exact/radius_rational.hpp"
#include "core/exact/weighted_radius_rational.hpp"
#include "core/family/alpha_family.hpp"
#include "core/io/point_formats.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gtest/gtest.h"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/cgal_weighted_alpha_oracle.hpp"
#include "tests/support/data_files.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"
#include "tests/support/weight_generators.hpp"

namespace galpha {
namespace {

using testing::CgalWeightedAlphaOracle;
using testing::IsOk;
using testing::OracleClass;

OracleClass ToOracle(SimplexClass c) { return static_cast<OracleClass>(static_cast<int>(c)); }

// The exact threshold of a rank, recomputed from the simplex the family names for it.
mpq_class ExactThreshold(const AlphaFamily& f, int64_t rank) {
  const uint32_t id = f.ranks().spectrum_simplex[static_cast<size_t>(rank - 1)];
  const uint32_t num_tri = static_cast<uint32_t>(f.triangles().size());
  Point2 p[3];
  double w[3];
  int n = 2;
  if (id < num_tri) {
    n = 3;
    for (int k = 0; k < 3; ++k) {
      p[k] = f.points()[f.triangles()[id][k]];
      w[k] = f.weights()[f.triangles()[id][k]];
    }
  } else {
    for (int k = 0; k < 2; ++k) {
      p[k] = f.points()[f.edges()[id - num_tri][k]];
      w[k] = f.weights()[f.edges()[id - num_tri][k]];
    }
  }
  return *SimplexRadiusSqRational(p, w, n);
}

std::vector<std::pair<uint32_t, uint32_t>> SortedEdges(const AlphaFamily& f) {
  std::vector<std::pair<uint32_t, uint32_t>> out;
  for (const auto& e : f.edges()) out.emplace_back(std::min(e[0], e[1]), std::max(e[0], e[1]));
  std::sort(out.begin(), out.end());
  return out;
}

/// Classes at `level` (alpha_sq exactly `alpha_sq`) against CGAL's; every edge CGAL has too.
void CompareAtLevel(const AlphaFamily& f, const CgalWeightedAlphaOracle& oracle, int64_t level,
                    const mpq_class& alpha_sq, bool same_triangulation, const std::string& where) {
  const CgalWeightedAlphaOracle::Classes expected = oracle.Classify(alpha_sq);
  const Classification got = f.ClassifyAll(level, ClassifyMode::kGeneral, VertexRule::kCgal);
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    const auto it =
        expected.edges.find({std::min(f.edges()[e][0], f.edges()[e][1]), std::max(f.edges()[e][0], f.edges()[e][1])});
    if (it == expected.edges.end()) continue;
    ASSERT_EQ(ToOracle(got.edges[e]), it->second)
        << where << " level " << level << " edge " << f.edges()[e][0] << "-" << f.edges()[e][1];
  }
  if (!same_triangulation) return;  // a vertex's class reads its faces, which may differ there
  for (const auto& [v, cls] : expected.vertices) {
    ASSERT_EQ(ToOracle(got.vertices[v]), cls) << where << " level " << level << " vertex " << v;
  }
  for (const uint32_t v : oracle.hidden()) {
    ASSERT_EQ(got.vertices[v], SimplexClass::kExterior) << where << " hidden vertex " << v;
  }
  const auto interior =
      static_cast<size_t>(std::count(got.triangles.begin(), got.triangles.end(), SimplexClass::kInterior));
  EXPECT_EQ(interior, expected.interior_triangles) << where << " level " << level;
  // The component curve against a union-find over the complex CGAL classified (its vertices
  // joined by its edges that are not EXTERIOR): hidden points are in no component.
  std::map<uint32_t, uint32_t> parent;
  for (const auto& [v, cls] : expected.vertices) {
    if (cls != OracleClass::kExterior) parent[v] = v;
  }
  auto find = [&](uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  size_t components = parent.size();
  for (const auto& [edge, cls] : expected.edges) {
    if (cls == OracleClass::kExterior) continue;
    const uint32_t a = find(edge.first), b = find(edge.second);
    if (a != b) {
      parent[a] = b;
      --components;
    }
  }
  EXPECT_EQ(f.Components(level), components) << where << " level " << level;
}

/// Returns whether the two triangulations were the same (full comparison made).
bool CompareWithCgal(const std::vector<Point2>& points, const std::vector<double>& weights, const std::string& where,
                     Backend backend, int max_levels) {
  BuildOptions options;
  options.backend = backend;
  absl::StatusOr<AlphaFamily> built = BuildWeightedAlphaFamily(points, weights, options);
  EXPECT_THAT(built, IsOk()) << where;
  if (!built.ok()) return false;
  const AlphaFamily& f = *built;
  const CgalWeightedAlphaOracle oracle(points, weights);
  EXPECT_EQ(f.report().comparisons.cpu_fallback, 0u) << where;

  // Hidden points: CGAL reports first occurrences of each (point, weight).
  std::vector<uint32_t> ours;
  for (const uint32_t v : f.HiddenPoints()) {
    if (f.representative()[v] == v) ours.push_back(v);
  }
  std::vector<std::pair<uint32_t, uint32_t>> cgal_edges;
  for (const auto& [edge, cls] : oracle.Classify(0).edges) cgal_edges.push_back(edge);
  const bool same = SortedEdges(f) == cgal_edges && ours == oracle.hidden();
  if (oracle.dimension() == 2 && same) {
    const std::vector<mpq_class>& thresholds = oracle.thresholds();
    EXPECT_EQ(f.max_level(), static_cast<int64_t>(thresholds.size())) << where;
    if (f.max_level() != static_cast<int64_t>(thresholds.size())) return same;
    for (int64_t r = 1; r <= f.max_level(); ++r) {
      const mpq_class& exact = thresholds[static_cast<size_t>(r - 1)];
      EXPECT_EQ(ExactThreshold(f, r), exact) << where << " rank " << r;
      EXPECT_EQ(f.spectrum()[static_cast<size_t>(r - 1)], NearestDouble(exact)) << where << " rank " << r;
      if (::testing::Test::HasFailure()) return same;
    }
  }
  if (oracle.dimension() != 2) return same;
  const int64_t k = f.max_level();
  const int64_t step = std::max<int64_t>(1, k / max_levels);
  for (int64_t level = 0; level <= k; level += (level == 0 ? 1 : step)) {
    mpq_class at = level == 0 ? mpq_class(f.min_alpha_sq()) : ExactThreshold(f, level);
    if (level == 0 && k > 0 && !(at < ExactThreshold(f, 1))) continue;  // level 0 is empty
    CompareAtLevel(f, oracle, level, at, same, where);
    if (::testing::Test::HasFatalFailure()) return same;
    if (level < k) {
      const mpq_class next = ExactThreshold(f, level + 1);
      const double between = NearestDouble((at + next) / 2);
      if (mpq_class(between) > at && mpq_class(between) < next) {
        absl::StatusOr<int64_t> resolved = f.LevelForAlphaSq(between);
        EXPECT_THAT(resolved, IsOk());
        EXPECT_EQ(*resolved, level) << where << " alpha_sq " << between;
        CompareAtLevel(f, oracle, level, mpq_class(between), same, where + " (between)");
        if (::testing::Test::HasFatalFailure()) return same;
      }
    }
  }
  return same;
}

using WeightedCgalTest = testing::BackendTest;

TEST_P(WeightedCgalTest, EveryDistributionWithEveryKindOfWeights) {
  int compared = 0, same = 0;
  for (const gen::NamedGenerator& generator : gen::AllDistributions()) {
    for (const std::string& kind : gen::WeightKinds()) {
      const std::vector<Point2> points = generator.generate(600, /*seed=*/3);
      const std::string where = absl::StrCat(generator.name, " ", kind);
      SCOPED_TRACE(where);
      same += CompareWithCgal(points, gen::Weights(kind, points, /*seed=*/4), where, GetParam(), 24) ? 1 : 0;
      ++compared;
      if (HasFatalFailure()) return;
    }
  }
  // Different triangulations only on power ties beyond the tie rule's first term: a few sets.
  std::printf("%d of %d weighted sets compared in full\n", same, compared);
  EXPECT_GE(same, compared * 3 / 4) << same << " of " << compared << " sets compared in full";
}

TEST_P(WeightedCgalTest, ManySmallRandomSets) {
  for (uint64_t seed = 0; seed < 120; ++seed) {
    const size_t n = 3 + seed % 23;
    const std::vector<Point2> points = seed % 2 == 0 ? gen::Uniform(n, seed) : gen::Grid(n, seed);
    const std::string kind = gen::WeightKinds()[seed % gen::WeightKinds().size()];
    const std::string where = absl::StrCat("seed ", seed, " n=", n, " ", kind);
    SCOPED_TRACE(where);
    CompareWithCgal(points, gen::Weights(kind, points, seed), where, GetParam(), 1000);
    if (HasFatalFailure()) return;
  }
}

TEST_P(WeightedCgalTest, MoleculeWithElementRadii) {
  // data/pdb_2xhe_radii.txt: the atoms of pdb_2xhe_proj.bin with their elements' van der Waals
  // radii; weights r^2 (the atoms) and (r + 1.4)^2 (the solvent-accessible disks of a water probe).
  absl::StatusOr<GeoreferencedPoints> atoms = ReadWeightedPointsFile(testdata::DataDir() + "/pdb_2xhe_radii.txt");
  ASSERT_THAT(atoms, IsOk());
  ASSERT_EQ(atoms->points.size(), 6267u);
  for (const double probe : {0.0, 1.4}) {
    std::vector<double> weights;
    for (const double r : atoms->weights) weights.push_back((r + probe) * (r + probe));
    const std::string where = absl::StrCat("2XHE, probe ", probe);
    SCOPED_TRACE(where);
    EXPECT_TRUE(CompareWithCgal(atoms->points, weights, where, GetParam(), 30)) << "triangulations differ";
    if (HasFatalFailure()) return;
  }
}

TEST_P(WeightedCgalTest, KnownShape) {
  // Three unit disks at the corners of a triangle of side 2 and a heavy disk in the middle that
  // hides nothing but overlaps them: negative thresholds come first.
  const std::vector<Point2> points = {{0, 0}, {2, 0}, {1, 1.75}, {1, 0.6}};
  const std::vector<double> weights = {1, 1, 1, 0.5};
  CompareWithCgal(points, weights, "known shape", GetParam(), 1000);
  absl::StatusOr<AlphaFamily> f = BuildWeightedAlphaFamily(points, weights);
  ASSERT_THAT(f, IsOk());
  EXPECT_TRUE(f->weighted());
  EXPECT_EQ(f->min_alpha_sq(), -1.0);
  EXPECT_LT(f->spectrum().front(), 0.0);  // the edges between overlapping disks
  // Below min_alpha_sq nothing is in; at it the points are.
  EXPECT_EQ(*f->LevelForAlphaSq(-1.5), -1);
  EXPECT_EQ(f->ClassifyVertex(0, -1, ClassifyMode::kGeneral, VertexRule::kCgal), SimplexClass::kExterior);
}

TEST_P(WeightedCgalTest, ZeroWeightsGiveTheUnweightedFamily) {
  const std::vector<Point2> points = gen::Uniform(2000, 9);
  BuildOptions options;
  options.backend = GetParam();
  absl::StatusOr<AlphaFamily> plain = BuildAlphaFamily(points, options);
  absl::StatusOr<AlphaFamily> zero = BuildWeightedAlphaFamily(points, std::vector<double>(points.size(), 0.0), options);
  ASSERT_THAT(plain, IsOk());
  ASSERT_THAT(zero, IsOk());
  ASSERT_EQ(plain->max_level(), zero->max_level());
  EXPECT_TRUE(std::equal(plain->spectrum().begin(), plain->spectrum().end(), zero->spectrum().begin()));
  EXPECT_EQ(SortedEdges(*plain), SortedEdges(*zero));
  EXPECT_EQ(zero->min_alpha_sq(), 0.0);
  EXPECT_TRUE(zero->HiddenPoints().empty());
}

TEST_P(WeightedCgalTest, BadWeightsAreErrors) {
  const std::vector<Point2> points = {{0, 0}, {1, 0}, {0, 1}};
  absl::StatusOr<AlphaFamily> short_weights = BuildWeightedAlphaFamily(points, std::vector<double>{1, 2});
  EXPECT_EQ(short_weights.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(short_weights.status().message().find("2 weights for 3 points"), std::string::npos)
      << short_weights.status();
  absl::StatusOr<AlphaFamily> nan = BuildWeightedAlphaFamily(points, std::vector<double>{1, NAN, 2});
  EXPECT_EQ(nan.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(nan.status().message().find("weight 1 is not finite"), std::string::npos) << nan.status();
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(WeightedCgalTest);

}  // namespace
}  // namespace galpha
