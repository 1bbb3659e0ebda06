// The alpha family against CGAL's Alpha_shape_2 with exact constructions (tests/support's oracle):
// the spectrum (same length, same exact values in the same order, nearest doubles), and at every
// spectrum value and between consecutive values (sampled on big inputs) the class of every edge by
// its vertex indices, vertex classes under CGAL's rule, the number of interior triangles and of
// solid components. Where exactly co-circular points let two valid triangulations differ, only
// what is invariant is compared: edges present in both, vertices, counts.
#include <gmpxx.h>

#include <algorithm>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/exact/radius_rational.hpp"
#include "core/family/alpha_family.hpp"
#include "core/io/point_formats.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gtest/gtest.h"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/cgal_alpha_oracle.hpp"
#include "tests/support/data_files.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::CgalAlphaOracle;
using testing::IsOk;
using testing::OracleClass;

OracleClass ToOracle(SimplexClass c) {
  switch (c) {
    case SimplexClass::kExterior:
      return OracleClass::kExterior;
    case SimplexClass::kSingular:
      return OracleClass::kSingular;
    case SimplexClass::kRegular:
      return OracleClass::kRegular;
    case SimplexClass::kInterior:
      return OracleClass::kInterior;
  }
  return OracleClass::kExterior;
}

// The exact threshold of a rank, recomputed from the simplex the family names for it.
mpq_class ExactThreshold(const AlphaFamily& f, int64_t rank) {
  const uint32_t id = f.ranks().spectrum_simplex[static_cast<size_t>(rank - 1)];
  const uint32_t num_tri = static_cast<uint32_t>(f.triangles().size());
  Point2 p[3];
  int n = 2;
  if (id < num_tri) {
    for (int k = 0; k < 3; ++k) p[k] = f.points()[f.triangles()[id][k]];
    n = 3;
  } else {
    p[0] = f.points()[f.edges()[id - num_tri][0]];
    p[1] = f.points()[f.edges()[id - num_tri][1]];
  }
  return *RadiusSqRational(p, n);
}

void CompareAtLevel(const AlphaFamily& f, const CgalAlphaOracle& oracle, int64_t level, const mpq_class& alpha_sq,
                    const std::string& where) {
  const CgalAlphaOracle::Classes expected = oracle.Classify(alpha_sq);
  const Classification got = f.ClassifyAll(level, ClassifyMode::kGeneral, VertexRule::kCgal);
  size_t common = 0;
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    const auto it = expected.edges.find({f.edges()[e][0], f.edges()[e][1]});
    if (it == expected.edges.end()) continue;  // a co-circular diagonal CGAL chose differently
    ++common;
    ASSERT_EQ(ToOracle(got.edges[e]), it->second)
        << where << " level " << level << " edge " << f.edges()[e][0] << "-" << f.edges()[e][1];
  }
  // A grid's squares each have a diagonal either triangulation may choose: a third of its edges.
  EXPECT_GE(common, f.edges().size() * 3 / 5) << where;
  for (const auto& [v, cls] : expected.vertices) {
    ASSERT_EQ(ToOracle(got.vertices[v]), cls) << where << " level " << level << " vertex " << v;
  }
  const size_t interior =
      static_cast<size_t>(std::count(got.triangles.begin(), got.triangles.end(), SimplexClass::kInterior));
  if (oracle.dimension() == 2) {
    EXPECT_EQ(interior, expected.interior_triangles) << where << " level " << level;
    EXPECT_EQ(f.SolidComponents(level), expected.solid_components) << where << " level " << level;
  }
}

void CompareWithCgal(const std::vector<Point2>& points, const std::string& where, Backend backend, int max_levels) {
  BuildOptions options;
  options.backend = backend;
  absl::StatusOr<AlphaFamily> built = BuildAlphaFamily(points, options);
  ASSERT_THAT(built, IsOk()) << where;
  const AlphaFamily& f = *built;
  const CgalAlphaOracle oracle(points);

  // The spectrum: same length, same exact values, nearest doubles.
  const std::vector<mpq_class>& spectrum = oracle.spectrum();
  if (oracle.dimension() == 2) {
    ASSERT_EQ(f.max_level(), static_cast<int64_t>(spectrum.size())) << where;
    for (int64_t r = 1; r <= f.max_level(); ++r) {
      ASSERT_EQ(ExactThreshold(f, r), spectrum[static_cast<size_t>(r - 1)]) << where << " rank " << r;
      ASSERT_EQ(f.spectrum()[static_cast<size_t>(r - 1)], NearestDouble(spectrum[static_cast<size_t>(r - 1)]))
          << where << " rank " << r;
    }
  }
  EXPECT_EQ(f.report().comparisons.cpu_fallback, 0u) << where;

  // Levels: at every (sampled) spectrum value, and strictly between neighbours.
  const int64_t k = f.max_level();
  const int64_t step = std::max<int64_t>(1, k / max_levels);
  for (int64_t level = 0; level <= k; level += (level == 0 ? 1 : step)) {
    const mpq_class at = level == 0 ? mpq_class(0) : ExactThreshold(f, level);
    CompareAtLevel(f, oracle, level, at, where);
    if (::testing::Test::HasFatalFailure()) return;
    if (level < k) {
      const mpq_class next = ExactThreshold(f, level + 1);
      const double between = NearestDouble((at + next) / 2);
      if (mpq_class(between) > at && mpq_class(between) < next) {
        absl::StatusOr<int64_t> resolved = f.LevelForAlphaSq(between);
        ASSERT_THAT(resolved, IsOk());
        ASSERT_EQ(*resolved, level) << where << " alpha_sq " << between;
        CompareAtLevel(f, oracle, level, mpq_class(between), where + " (between)");
        if (::testing::Test::HasFatalFailure()) return;
      }
    }
    if (level > 0) {
      // The published double resolves to the level whose exact interval holds it (the level
      // itself when the double is exact; tiny inputs round many thresholds to one double).
      const double published = f.spectrum()[static_cast<size_t>(level - 1)];
      absl::StatusOr<int64_t> resolved = f.LevelForAlphaSq(published);
      ASSERT_THAT(resolved, IsOk());
      if (*resolved > 0) {
        ASSERT_LE(ExactThreshold(f, *resolved), mpq_class(published)) << where;
      }
      if (*resolved < k) {
        ASSERT_GT(ExactThreshold(f, *resolved + 1), mpq_class(published)) << where;
      }
      if (mpq_class(published) == at) {
        ASSERT_EQ(*resolved, level) << where;
      }
    }
  }

  // Where every point is on a triangle: CGAL's find_alpha_solid.
  const std::optional<mpq_class> solid = oracle.AlphaSolid();
  ASSERT_EQ(f.SolidLevel().has_value(), solid.has_value()) << where;
  if (solid && *f.SolidLevel() > 0) {
    EXPECT_EQ(ExactThreshold(f, *f.SolidLevel()), *solid) << where;
  }
}

struct Case {
  std::string name;
  std::vector<Point2> points;
};

std::vector<Case> GeneratedCases() {
  using namespace gen;
  return {
      {"uniform", Uniform(1500, 1)},
      {"gaussian", Gaussian(1500, 2)},
      {"clustered", Clustered(1500, 3)},
      {"grid", Grid(900, 4)},
      {"circle", Circle(400, 5)},
      {"thin_circle", ThinCircle(400, 6)},
      {"two_lines", TwoLines(300, 7)},
      {"parallel_lines", ParallelLines(300, 8)},
      {"duplicates", WithDuplicates(1000, 9)},
      {"offset_1e9", HugeOffset(1000, 10, 1e9)},
      {"offset_1e15", HugeOffset(1000, 11, 1e15)},
      {"tiny", Tiny(1000, 12)},
      {"ulp_lattice", UlpLattice(2500, 13)},  // runs longer than one thread sorts: refined keys
      {"lidar_cm", LidarCentimetres(2000, 14)},
      {"three_points", {{0, 0}, {4, 0}, {2, 3}}},
      {"square", {{0, 0}, {1, 0}, {1, 1}, {0, 1}}},
  };
}

using AlphaCgalTest = testing::BackendTest;

TEST_P(AlphaCgalTest, Generators) {
  for (const Case& c : GeneratedCases()) {
    SCOPED_TRACE(c.name);
    CompareWithCgal(c.points, c.name, GetParam(), 40);
    if (HasFatalFailure()) return;
  }
}

TEST_P(AlphaCgalTest, RealDataSets) {
  const std::vector<std::string> files = testdata::PointFiles();
  ASSERT_FALSE(files.empty());
  for (const std::string& file : files) {
    absl::StatusOr<std::vector<Point2>> points = ReadPointsFile(file);
    ASSERT_THAT(points, IsOk());
    SCOPED_TRACE(file);
    CompareWithCgal(*points, file, GetParam(), points->size() > 50000 ? 4 : 12);
    if (HasFatalFailure()) return;
  }
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(AlphaCgalTest);

}  // namespace
}  // namespace galpha
