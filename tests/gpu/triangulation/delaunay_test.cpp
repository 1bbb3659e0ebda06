// Triangulate() on every backend this build and machine have, over every hard distribution, the
// real data sets and the degenerate inputs; each result must pass the exact CheckTriangulation.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <limits>
#include <ostream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/io/point_io.hpp"
#include "gpu/triangulation/delaunay.hpp"
#include "gpu/triangulation/triangulation_checks.hpp"
#include "gtest/gtest.h"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/data_files.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"
#include "tests/support/triangulation_sets.hpp"

namespace galpha {

// Test parameters print as "cpu"/"cuda" (found by argument-dependent lookup).
static void PrintTo(Backend backend, std::ostream* os) { *os << BackendName(backend); }

namespace {

using testing::CanonicalTriangles;
using testing::IsOk;
using testing::SortedEdges;
using testing::StatusIs;

using Edge = std::array<uint32_t, 2>;
using Tri = std::array<uint32_t, 3>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Empty when the sorted lists `a` and `b` are equal, else how many entries each alone has and the
// first few (gtest would print both lists whole).
template <typename T>
std::string SortedDifference(const std::vector<T>& a, const std::vector<T>& b) {
  std::vector<T> only_a;
  std::vector<T> only_b;
  std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(only_a));
  std::set_difference(b.begin(), b.end(), a.begin(), a.end(), std::back_inserter(only_b));
  if (only_a.empty() && only_b.empty()) return "";
  auto first = [](const std::vector<T>& items) {
    std::string out;
    for (size_t i = 0; i < std::min<size_t>(items.size(), 3); ++i) {
      absl::StrAppend(&out, " (", absl::StrJoin(items[i], ", "), ")");
    }
    return out;
  };
  return absl::StrCat(only_a.size(), " only in the first:", first(only_a), "; ", only_b.size(),
                      " only in the second:", first(only_b));
}

bool BitwiseEqual(const std::vector<Point2>& a, absl::Span<const Point2> b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(Point2)) == 0);
}

// The backend fixture (the CUDA instance skips where this build or machine has none) that
// triangulates on its backend.
class DelaunayTest : public testing::BackendTest {
 protected:
  absl::StatusOr<Triangulation> Run(absl::Span<const Point2> points) {
    TriangulateOptions options;
    options.backend = GetParam();
    return Triangulate(points, options);
  }

  // Triangulates `points` and asserts that the result is valid; use with
  // ASSERT_NO_FATAL_FAILURE.
  void RunAndCheck(absl::Span<const Point2> points, Triangulation* out) {
    absl::StatusOr<Triangulation> result = Run(points);
    ASSERT_THAT(result, IsOk());
    EXPECT_EQ(result->backend, GetParam());
    EXPECT_TRUE(BitwiseEqual(result->points, points)) << "points are not the input as given";
    const absl::Status valid = CheckTriangulation(*result);
    ASSERT_THAT(valid, IsOk());
    *out = *std::move(result);
  }
};

// In the loops below a failure ends the inputs of one distribution (or file) only, so that one run
// reports every distribution that fails, each by its first failing input.

TEST_P(DelaunayTest, SmallInputsOfEveryDistribution) {
  for (const gen::NamedGenerator& generator : gen::AllDistributions()) {
    [&] {
      for (size_t n : {3, 4, 5, 6, 10, 17}) {
        for (uint64_t seed = 1; seed <= 10; ++seed) {
          SCOPED_TRACE(absl::StrCat(generator.name, " n=", n, " seed=", seed));
          Triangulation t;
          ASSERT_NO_FATAL_FAILURE(RunAndCheck(generator.generate(n, seed), &t));
        }
      }
    }();
  }
}

TEST_P(DelaunayTest, EveryDistribution) {
  for (const gen::NamedGenerator& generator : gen::AllDistributions()) {
    [&] {
      for (size_t n : {1000, 50000}) {
        SCOPED_TRACE(absl::StrCat(generator.name, " n=", n));
        Triangulation t;
        ASSERT_NO_FATAL_FAILURE(RunAndCheck(generator.generate(n, /*seed=*/42), &t));
      }
    }();
  }
}

TEST_P(DelaunayTest, RealDataSets) {
  const std::vector<std::string> files = testdata::PointFiles();
  ASSERT_FALSE(files.empty()) << "no *.bin files in " << testdata::DataDir();
  for (const std::string& file : files)
    [&] {
      SCOPED_TRACE(file);
      absl::StatusOr<std::vector<Point2>> points = ReadPointsBin(file);
      ASSERT_THAT(points, IsOk());
      Triangulation t;
      ASSERT_NO_FATAL_FAILURE(RunAndCheck(*points, &t));
      // data/README.md: the Autzen cloud holds 7 exact duplicates.
      if (std::filesystem::path(file).filename() == "lidar_autzen.bin") {
        EXPECT_EQ(t.num_unique, 110000u - 7u);
      }
    }();
}

// The ledger counts every buffer: the build holds at least the input and the mesh of 2n triangles
// (3 vertices, 3 neighbours each), and a linear-memory engine stays within a few hundred bytes
// a point.
TEST_P(DelaunayTest, PeakMemoryIsCountedAndLinear) {
  for (size_t n : {20000, 200000}) {
    SCOPED_TRACE(absl::StrCat("n=", n));
    Triangulation t;
    ASSERT_NO_FATAL_FAILURE(RunAndCheck(gen::Uniform(n, 5), &t));
    EXPECT_GE(t.peak_memory_bytes, n * (sizeof(Point2) + 2 * 6 * sizeof(int32_t)));
    EXPECT_LE(t.peak_memory_bytes, n * 400);
  }
}

TEST_P(DelaunayTest, Empty) {
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck({}, &t));
  EXPECT_EQ(t.num_unique, 0u);
  EXPECT_TRUE(t.representative.empty());
  EXPECT_TRUE(t.triangles.empty());
  EXPECT_TRUE(t.edges.empty());
}

TEST_P(DelaunayTest, OnePoint) {
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck({{3.5, -1.0}}, &t));
  EXPECT_EQ(t.num_unique, 1u);
  EXPECT_EQ(t.representative, std::vector<uint32_t>({0}));
  EXPECT_TRUE(t.triangles.empty());
  EXPECT_TRUE(t.edges.empty());
}

TEST_P(DelaunayTest, TwoPointsGivenInDecreasingOrder) {
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck({{5.0, 5.0}, {1.0, 1.0}}, &t));
  EXPECT_EQ(t.num_unique, 2u);
  EXPECT_TRUE(t.triangles.empty());
  EXPECT_EQ(t.edges, std::vector<Edge>({{0, 1}}));
}

TEST_P(DelaunayTest, ThreeCollinear) {
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck({{0, 0}, {2, 2}, {1, 1}}, &t));
  EXPECT_TRUE(t.triangles.empty());
  EXPECT_EQ(SortedEdges(t), std::vector<Edge>({{0, 2}, {1, 2}}));
}

TEST_P(DelaunayTest, AllDuplicates) {
  const std::vector<Point2> points(6, Point2{1.5, -2.0});
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck(points, &t));
  EXPECT_EQ(t.num_unique, 1u);
  EXPECT_EQ(t.representative, std::vector<uint32_t>(6, 0));
  EXPECT_TRUE(t.triangles.empty());
  EXPECT_TRUE(t.edges.empty());
}

TEST_P(DelaunayTest, NegativeZeroDuplicatesZero) {
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck({{0.0, 0.0}, {-0.0, 0.0}, {1, 0}, {0, 1}}, &t));
  EXPECT_EQ(t.num_unique, 3u);
  EXPECT_EQ(t.representative[1], 0u);
  EXPECT_EQ(t.triangles.size(), 1u);
}

TEST_P(DelaunayTest, CollinearUnsortedWithDuplicates) {
  // On y = 3x - 1; indices 3 and 6 repeat 0 and 1. Along the line: 4, 1, 2, 5, 0.
  const std::vector<Point2> points = {{4, 11}, {0, -1}, {2, 5}, {4, 11}, {-1, -4}, {3, 8}, {0, -1}};
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck(points, &t));
  EXPECT_EQ(t.num_unique, 5u);
  EXPECT_EQ(t.representative, std::vector<uint32_t>({0, 1, 2, 0, 4, 5, 1}));
  EXPECT_TRUE(t.triangles.empty());
  EXPECT_EQ(SortedEdges(t), std::vector<Edge>({{0, 5}, {1, 2}, {1, 4}, {2, 5}}));
}

TEST_P(DelaunayTest, VerticalCollinear) {
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck({{7, 3}, {7, -1}, {7, 10}, {7, 0}}, &t));
  EXPECT_TRUE(t.triangles.empty());
  EXPECT_EQ(SortedEdges(t), std::vector<Edge>({{0, 2}, {0, 3}, {1, 3}}));
}

TEST_P(DelaunayTest, ManyCollinearShuffledWithDuplicates) {
  std::vector<Point2> points;
  for (int i = 0; i < 20000; ++i) {
    const double x = static_cast<double>((i * 7919) % 10007);  // repeats after 10007
    points.push_back({x, 0.5 * x - 3.0});
  }
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck(points, &t));
  EXPECT_EQ(t.num_unique, 10007u);
  EXPECT_TRUE(t.triangles.empty());
  EXPECT_EQ(t.edges.size(), 10006u);
}

TEST_P(DelaunayTest, CollinearRunPlusOnePointOffTheLine) {
  std::vector<Point2> points;
  points.reserve(1001);
  for (int i = 0; i < 1000; ++i) points.push_back({static_cast<double>((i * 37) % 1000), 0.0});
  points.push_back({500.0, 1e-9});
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck(points, &t));
  // A fan from the apex over the 999 segments of the line.
  EXPECT_EQ(t.triangles.size(), 999u);
  EXPECT_EQ(t.edges.size(), 999u + 1000u);
}

// Hull sides that hold many points, in every arrangement the insertion meets: each collinear
// point must end as a hull vertex (CheckTriangulation: the boundary is the exact convex hull, every
// point a vertex, every edge locally Delaunay). Small lattices make points on a hull side also
// co-circular with interior ones; the shuffled orders put them in every insertion order.
TEST_P(DelaunayTest, ManyPointsOnHullSidesInAnyOrder) {
  std::mt19937_64 rng(7);
  for (int side : {3, 4, 7, 16, 40}) {
    for (int interior_percent : {0, 10, 60}) {
      for (int shape = 0; shape < 3; ++shape) {
        std::vector<Point2> points;
        std::bernoulli_distribution inside(interior_percent / 100.0);
        for (int i = 0; i <= side; ++i) {
          for (int j = 0; j <= side; ++j) {
            // 0: a square's lattice; 1: a right triangle's; 2: a parallelogram of slope 1/2 (two
            // parallel hull sides, as in parallel_lines).
            if (shape == 1 && i + j > side) continue;
            const bool on_hull = i == 0 || j == 0 || i == side || j == side || (shape == 1 && i + j == side);
            if (!on_hull && !inside(rng)) continue;
            const double x = shape == 2 ? 2.0 * j + i : j;
            points.push_back({x, static_cast<double>(shape == 2 ? j + 3 * i : i)});
          }
        }
        std::shuffle(points.begin(), points.end(), rng);
        SCOPED_TRACE(absl::StrCat("side=", side, " interior=", interior_percent, "% shape=", shape));
        Triangulation t;
        ASSERT_NO_FATAL_FAILURE(RunAndCheck(points, &t));
      }
    }
  }
}

TEST_P(DelaunayTest, CoCircularSquare) {
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, &t));
  EXPECT_EQ(t.triangles.size(), 2u);
  EXPECT_EQ(t.edges.size(), 5u);
}

TEST_P(DelaunayTest, PointInsideTriangleMakesAFan) {
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck({{0, 0}, {4, 0}, {0, 4}, {1, 1}}, &t));
  ASSERT_EQ(t.triangles.size(), 3u);
  EXPECT_EQ(CanonicalTriangles(t), std::vector<Tri>({{0, 1, 3}, {0, 3, 2}, {1, 2, 3}}));
  EXPECT_EQ(SortedEdges(t), std::vector<Edge>({{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}));
}

// Four co-circular points plus their centre, which lies on both diagonals: every triangle must use
// the centre, whatever Simulation of Simplicity decides for the co-circular quadruple.
TEST_P(DelaunayTest, CentreOfCoCircularPointsIsInEveryTriangle) {
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck({{1, 0}, {0, 1}, {-1, 0}, {0, -1}, {0, 0}}, &t));
  ASSERT_EQ(t.triangles.size(), 4u);
  for (const Tri& v : t.triangles) EXPECT_NE(std::find(v.begin(), v.end(), 4u), v.end());
}

// A convex kite A(0,0) B(4,0) C(2,1) D(2,-1): D lies inside the circle through A, B, C, so the
// Delaunay diagonal is the short one, CD.
TEST_P(DelaunayTest, KiteTakesTheShortDiagonal) {
  Triangulation t;
  ASSERT_NO_FATAL_FAILURE(RunAndCheck({{0, 0}, {4, 0}, {2, 1}, {2, -1}}, &t));
  EXPECT_EQ(CanonicalTriangles(t), std::vector<Tri>({{0, 3, 2}, {1, 2, 3}}));
}

// The triangulation scales its points by a power of two before the predicates see them (so that
// the filters work on tiny and huge coordinates); the scaling must be exact, so every scaled copy
// of a set has the same triangles as the set itself. The sets: lattice points (co-circular cells,
// collinear rows), and the same moved by single ulps, whose triangles their last bits decide (an
// inexact scaling loses them); copies from the subnormal range to the input domain's edge (2^500).
TEST_P(DelaunayTest, ScaledCopiesHaveTheSameTriangles) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> coordinate(0, 63);
  std::bernoulli_distribution up(0.5);
  std::vector<Point2> lattice;
  std::vector<Point2> nudged;  // the lattice moved to [64, 128) and each coordinate by one ulp
  for (int i = 0; i < 600; ++i) {
    const Point2 p{1.0 * coordinate(rng), 1.0 * coordinate(rng)};
    lattice.push_back(p);
    nudged.push_back(
        {std::nextafter(p.x + 64.0, up(rng) ? 128.0 : 0.0), std::nextafter(p.y + 64.0, up(rng) ? 128.0 : 0.0)});
  }
  // Exponents that keep every coordinate of the set exact (the lattice's small integers fit the
  // subnormal range; the nudged set's last bits, 2^-46, must stay above 2^-1074).
  const std::vector<std::pair<const std::vector<Point2>*, std::vector<int>>> cases = {
      {&lattice, {-1070, -1000, 300, 493}}, {&nudged, {-1020, -600, 300, 490}}};
  for (const auto& [points, exponents] : cases) {
    Triangulation reference;
    ASSERT_NO_FATAL_FAILURE(RunAndCheck(*points, &reference));
    for (int exponent : exponents) {
      SCOPED_TRACE(absl::StrCat(points->size(), " points scaled by 2^", exponent));
      std::vector<Point2> scaled;
      for (const Point2& p : *points) scaled.push_back({std::ldexp(p.x, exponent), std::ldexp(p.y, exponent)});
      Triangulation t;
      ASSERT_NO_FATAL_FAILURE(RunAndCheck(scaled, &t));
      EXPECT_EQ(t.num_unique, reference.num_unique);
      EXPECT_EQ(CanonicalTriangles(t), CanonicalTriangles(reference));
      EXPECT_EQ(SortedEdges(t), SortedEdges(reference));
    }
  }
}

TEST_P(DelaunayTest, NaNIsRejectedWithItsIndex) {
  std::vector<Point2> points = gen::Uniform(10, 7);
  points[5].x = kNaN;
  const absl::StatusOr<Triangulation> result = Run(points);
  ASSERT_THAT(result.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(result.status().message().find("5"), absl::string_view::npos) << result.status();
}

TEST_P(DelaunayTest, InfinityIsRejectedWithItsIndex) {
  std::vector<Point2> points = gen::Uniform(10, 7);
  points[5].y = kInf;
  absl::StatusOr<Triangulation> result = Run(points);
  ASSERT_THAT(result.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(result.status().message().find("5"), absl::string_view::npos) << result.status();

  points = gen::Uniform(20, 7);
  points[13].x = -kInf;
  points[17].y = kNaN;  // only the first bad index is named
  result = Run(points);
  ASSERT_THAT(result.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(result.status().message().find("13"), absl::string_view::npos) << result.status();
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(DelaunayTest);

TEST(DelaunayBackendTest, CudaWithoutGpuIsUnavailable) {
  if (CudaBackendAvailable()) GTEST_SKIP() << "a GPU is visible";
  TriangulateOptions options;
  options.backend = Backend::kCuda;
  const absl::StatusOr<Triangulation> result = Triangulate(gen::Uniform(10, 1), options);
  EXPECT_THAT(result.status(), StatusIs(absl::StatusCode::kUnavailable));
}

TEST(DelaunayBackendTest, AutoPicksCudaExactlyWhenAvailable) {
  const absl::StatusOr<Triangulation> result = Triangulate(gen::Uniform(100, 1));
  ASSERT_THAT(result, IsOk());
  EXPECT_EQ(result->backend, CudaBackendAvailable() ? Backend::kCuda : Backend::kCpu);
}

// Simulation of Simplicity makes the triangulation unique even for degenerate input, so both
// backends must produce the same triangles, edges and representatives.
TEST(DelaunayBackendTest, CpuAndCudaAgree) {
  if (!CudaBackendAvailable()) GTEST_SKIP() << "no CUDA backend in this build, or no visible GPU";
  for (const gen::NamedGenerator& generator : gen::AllDistributions()) {
    for (size_t n : {10, 1000, 50000}) {
      SCOPED_TRACE(absl::StrCat(generator.name, " n=", n));
      const std::vector<Point2> points = generator.generate(n, /*seed=*/3);
      TriangulateOptions cpu_options;
      cpu_options.backend = Backend::kCpu;
      TriangulateOptions cuda_options;
      cuda_options.backend = Backend::kCuda;
      const absl::StatusOr<Triangulation> cpu = Triangulate(points, cpu_options);
      const absl::StatusOr<Triangulation> cuda = Triangulate(points, cuda_options);
      ASSERT_THAT(cpu, IsOk());
      ASSERT_THAT(cuda, IsOk());
      EXPECT_EQ(cpu->representative, cuda->representative);
      EXPECT_EQ(SortedDifference(CanonicalTriangles(*cpu), CanonicalTriangles(*cuda)), "")
          << "triangles, first = CPU, second = CUDA";
      EXPECT_EQ(SortedDifference(SortedEdges(*cpu), SortedEdges(*cuda)), "") << "edges, first = CPU, second = CUDA";
    }
  }
}

}  // namespace
}  // namespace galpha
