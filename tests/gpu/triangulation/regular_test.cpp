// TriangulateWeighted() on every backend: its input domain, the cases with known answers (hidden
// duplicates, hidden points on a line, weights that change nothing), and CUDA == CPU bit for bit.
// Edge-by-edge agreement with CGAL on every distribution is regular_cgal_test's.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gpu/triangulation/delaunay.hpp"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"
#include "tests/support/triangulation_sets.hpp"
#include "tests/support/weight_generators.hpp"

namespace galpha {
namespace {

using testing::CanonicalTriangles;
using ::testing::HasSubstr;
using testing::IsOk;
using testing::SortedEdges;
using testing::StatusIs;

using Edge = std::array<uint32_t, 2>;
using Tri = std::array<uint32_t, 3>;

class RegularTest : public testing::BackendTest {
 protected:
  absl::StatusOr<Triangulation> Run(const std::vector<Point2>& points, const std::vector<double>& weights) {
    TriangulateOptions options;
    options.backend = GetParam();
    return TriangulateWeighted(points, weights, options);
  }
};

TEST_P(RegularTest, WeightsOutsideTheDomainAreRefusedByIndex) {
  const std::vector<Point2> points = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
  EXPECT_THAT(Run(points, {0, 0, 0}),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("3 weights for 4 points")));
  EXPECT_THAT(Run(points, {0, 0, std::numeric_limits<double>::quiet_NaN(), 0}),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("weight 2 is not finite")));
  EXPECT_THAT(Run(points, {0, -std::numeric_limits<double>::infinity(), 0, 0}),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("weight 1 is not finite")));
  EXPECT_THAT(Run(points, {0, 0, 0, 0x1p1000}),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("weight 3 (1.0715086071862673e+301)")));
  // sqrt(1e-300) = 1e-150 is 2^437 or more times below the coordinates' 1.
  EXPECT_THAT(Run(points, {0, 1e-300, 0, 0}),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("weight 1 (1e-300) is out of scale")));
  // Negative weights are valid.
  EXPECT_THAT(Run(points, {-1, -2, 0.5, 0}), IsOk());
}

TEST_P(RegularTest, ZeroOrEqualWeightsGiveTheDelaunayTriangulation) {
  for (const gen::NamedGenerator& generator : gen::AllDistributions()) {
    if (!generator.general_position) continue;
    SCOPED_TRACE(generator.name);
    const std::vector<Point2> points = generator.generate(2000, /*seed=*/5);
    TriangulateOptions options;
    options.backend = GetParam();
    const absl::StatusOr<Triangulation> delaunay = Triangulate(points, options);
    ASSERT_THAT(delaunay, IsOk());
    for (const std::string kind : {"zero", "equal"}) {
      const absl::StatusOr<Triangulation> regular = Run(points, gen::Weights(kind, points, 1));
      ASSERT_THAT(regular, IsOk());
      EXPECT_TRUE(regular->hidden.empty()) << kind;
      EXPECT_EQ(CanonicalTriangles(*regular), CanonicalTriangles(*delaunay)) << kind;
      EXPECT_EQ(regular->representative, delaunay->representative) << kind;
    }
  }
}

TEST_P(RegularTest, TheHeaviestPointOfAPositionHidesTheOthers) {
  // Points 0 and 3 share a position; 3 is heavier and stays, 0 is hidden. Points 1 and 4 are the
  // same weighted point: 4 is a duplicate of 1, not hidden.
  const std::vector<Point2> points = {{0, 0}, {4, 0}, {0, 4}, {0, 0}, {4, 0}};
  const absl::StatusOr<Triangulation> t = Run(points, {1, 0, 0, 2, 0});
  ASSERT_THAT(t, IsOk());
  EXPECT_EQ(t->hidden, std::vector<uint32_t>({0}));
  EXPECT_EQ(t->representative, std::vector<uint32_t>({0, 1, 2, 3, 1}));
  EXPECT_EQ(t->num_unique, 4u);
  EXPECT_EQ(CanonicalTriangles(*t), std::vector<Tri>({{1, 2, 3}}));
}

TEST_P(RegularTest, APointUnderTheLiftedTriangleStaysAPointAboveItIsHidden) {
  // The lifts of (0,0), (4,0), (0,4) (weights 0) span the plane z = 4x + 4y: 8 at (1,1), whose own
  // lift is 2 - w. Below the plane (w > -6): a vertex; above it (w < -6): hidden.
  const std::vector<Point2> points = {{0, 0}, {4, 0}, {0, 4}, {1, 1}};
  const absl::StatusOr<Triangulation> in = Run(points, {0, 0, 0, -5.5});
  ASSERT_THAT(in, IsOk());
  EXPECT_TRUE(in->hidden.empty());
  EXPECT_EQ(in->triangles.size(), 3u);
  const absl::StatusOr<Triangulation> out = Run(points, {0, 0, 0, -6.5});
  ASSERT_THAT(out, IsOk());
  EXPECT_EQ(out->hidden, std::vector<uint32_t>({3}));
  EXPECT_EQ(CanonicalTriangles(*out), std::vector<Tri>({{0, 1, 2}}));
}

TEST_P(RegularTest, HeavyCornersHideEveryPointInside) {
  // Three corners whose disks cover the triangle between them hide every point inside it.
  std::vector<Point2> points = {{0, 0}, {10, 0}, {0, 10}};
  std::vector<double> weights = {100, 100, 100};
  const std::vector<Point2> inside = gen::Uniform(500, 3);
  for (const Point2& p : inside) {
    points.push_back({1 + 3 * p.x, 1 + 3 * p.y});
    weights.push_back(0.0);
  }
  const absl::StatusOr<Triangulation> t = Run(points, weights);
  ASSERT_THAT(t, IsOk());
  EXPECT_EQ(t->hidden.size(), inside.size());
  EXPECT_EQ(CanonicalTriangles(*t), std::vector<Tri>({{0, 1, 2}}));
}

TEST_P(RegularTest, OnALineTheChainSkipsThePointsAboveIt) {
  // Along the x axis the lifts are x^2 - w: at x = 0..4 they are -3, 1, -1, 1, 16. The lift at
  // x = 1 lies above the chord from x = 0 to x = 2 (-2 there): hidden; the others form a convex
  // chain.
  const std::vector<Point2> points = {{2, 0}, {0, 0}, {1, 0}, {3, 0}, {4, 0}};
  const absl::StatusOr<Triangulation> t = Run(points, {5, 3, 0, 8, 0});
  ASSERT_THAT(t, IsOk());
  EXPECT_TRUE(t->triangles.empty());
  EXPECT_EQ(t->hidden, std::vector<uint32_t>({2}));
  EXPECT_EQ(SortedEdges(*t), std::vector<Edge>({{0, 1}, {0, 3}, {3, 4}}));
}

TEST_P(RegularTest, HullPointsBetweenCollinearNeighboursCanBeHidden) {
  // (2,0) lies on the hull edge from (0,0) to (4,0); light, its lift is above their chord.
  const std::vector<Point2> points = {{0, 0}, {4, 0}, {2, 3}, {2, 0}};
  const absl::StatusOr<Triangulation> hidden = Run(points, {5, 5, 0, 0});
  ASSERT_THAT(hidden, IsOk());
  EXPECT_EQ(hidden->hidden, std::vector<uint32_t>({3}));
  EXPECT_EQ(CanonicalTriangles(*hidden), std::vector<Tri>({{0, 1, 2}}));
  const absl::StatusOr<Triangulation> kept = Run(points, {0, 0, 0, 0});
  ASSERT_THAT(kept, IsOk());
  EXPECT_TRUE(kept->hidden.empty());
  EXPECT_EQ(kept->triangles.size(), 2u);
}

// Every array of two triangulations, in order (not only the same sets).
void ExpectIdentical(const Triangulation& a, const Triangulation& b) {
  EXPECT_EQ(a.representative, b.representative);
  EXPECT_EQ(a.hidden, b.hidden);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.neighbors, b.neighbors);
  EXPECT_EQ(a.tri_edge_begin, b.tri_edge_begin);
  EXPECT_EQ(a.edges, b.edges);
}

TEST_P(RegularTest, RepeatedBuildsAreIdenticalArrayForArray) {
  // The removal of hidden vertices races on which triangle names a vertex's star; the result must
  // not depend on it (regular_removal.cuh starts each star at its smallest neighbour).
  for (const std::string kind : {"uniform", "one_huge", "many_hidden"}) {
    SCOPED_TRACE(kind);
    const std::vector<Point2> points = gen::Uniform(20000, 9);
    const std::vector<double> weights = gen::Weights(kind, points, 10);
    const absl::StatusOr<Triangulation> first = Run(points, weights);
    const absl::StatusOr<Triangulation> second = Run(points, weights);
    ASSERT_THAT(first, IsOk());
    ASSERT_THAT(second, IsOk());
    ExpectIdentical(*first, *second);
  }
}

// Simulation of Simplicity on ranks both backends compute alike makes the regular triangulation
// unique, and every step that builds it is deterministic, so both backends give the same arrays:
// triangles in the same order, neighbours, edges, representatives and hidden points.
TEST(RegularBackendTest, CpuAndCudaAgree) {
  if (!CudaBackendAvailable()) GTEST_SKIP() << "no CUDA backend in this build, or no visible GPU";
  for (const gen::NamedGenerator& generator : gen::AllDistributions()) {
    for (const std::string& kind : gen::WeightKinds()) {
      for (const size_t n : {1000, 50000}) {
        SCOPED_TRACE(absl::StrCat(generator.name, " ", kind, " n=", n));
        const std::vector<Point2> points = generator.generate(n, /*seed=*/3);
        const std::vector<double> weights = gen::Weights(kind, points, /*seed=*/4);
        TriangulateOptions cpu_options, cuda_options;
        cpu_options.backend = Backend::kCpu;
        cuda_options.backend = Backend::kCuda;
        const absl::StatusOr<Triangulation> cpu = TriangulateWeighted(points, weights, cpu_options);
        const absl::StatusOr<Triangulation> cuda = TriangulateWeighted(points, weights, cuda_options);
        ASSERT_THAT(cpu, IsOk());
        ASSERT_THAT(cuda, IsOk());
        ExpectIdentical(*cpu, *cuda);
      }
    }
  }
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(RegularTest);

}  // namespace
}  // namespace galpha
