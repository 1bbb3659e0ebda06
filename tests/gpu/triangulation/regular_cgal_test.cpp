// Our regular (weighted Delaunay) triangulation against CGAL's Regular_triangulation_2: the same
// hidden points and, edge by edge, the same triangulation, on every point distribution with every
// kind of weights, on both backends.
//
// The regular triangulation of weighted points in general position is unique. Under exact power
// ties (four lifts on one plane: integer weights on a grid, equal weights on co-circular points)
// both break ties by a symbolic perturbation that raises the lift of the lexicographically largest
// point first (core/exact/power.hpp); where that first term decides, the two agree, so an edge only
// one of them has must be the diagonal of two triangles whose four lifts are exactly coplanar.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_2.h>
#include <CGAL/Regular_triangulation_face_base_2.h>
#include <CGAL/Regular_triangulation_vertex_base_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <iterator>
#include <map>
#include <numeric>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/exact/power.hpp"
#include "core/exact/predicates.hpp"
#include "gpu/triangulation/delaunay.hpp"
#include "gtest/gtest.h"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"
#include "tests/support/weight_generators.hpp"

namespace galpha {
namespace {

using testing::IsOk;

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase =
    CGAL::Triangulation_vertex_base_with_info_2<uint32_t, Kernel, CGAL::Regular_triangulation_vertex_base_2<Kernel>>;
using FaceBase = CGAL::Regular_triangulation_face_base_2<Kernel>;
using DataStructure = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
using CgalRegular = CGAL::Regular_triangulation_2<Kernel, DataStructure>;
using Edge = std::array<uint32_t, 2>;

Edge Undirected(uint32_t a, uint32_t b) { return {std::min(a, b), std::max(a, b)}; }

// The input's first occurrence of each (point, weight), as CGAL gets it (CGAL keeps one vertex for
// equal weighted points and would drop later copies without telling).
std::vector<uint32_t> FirstOccurrences(const std::vector<Point2>& points, const std::vector<double>& weights) {
  std::map<std::tuple<double, double, double>, uint32_t> first;
  std::vector<uint32_t> out;
  for (uint32_t i = 0; i < points.size(); ++i) {
    if (first.emplace(std::make_tuple(points[i].x + 0.0, points[i].y + 0.0, weights[i] + 0.0), i).second) {
      out.push_back(i);
    }
  }
  return out;
}

struct CgalResult {
  std::vector<Edge> edges;
  std::vector<uint32_t> hidden;
  size_t num_faces = 0;
};

CgalResult TriangulateWithCgal(const std::vector<Point2>& points, const std::vector<double>& weights) {
  std::vector<std::pair<Kernel::Weighted_point_2, uint32_t>> input;
  for (const uint32_t i : FirstOccurrences(points, weights)) {
    input.emplace_back(Kernel::Weighted_point_2(Kernel::Point_2(points[i].x, points[i].y), weights[i]), i);
  }
  CgalRegular rt(input.begin(), input.end());
  CgalResult result;
  for (auto e = rt.finite_edges_begin(); e != rt.finite_edges_end(); ++e) {
    result.edges.push_back(Undirected(e->first->vertex(CgalRegular::cw(e->second))->info(),
                                      e->first->vertex(CgalRegular::ccw(e->second))->info()));
  }
  std::sort(result.edges.begin(), result.edges.end());
  for (auto v = rt.hidden_vertices_begin(); v != rt.hidden_vertices_end(); ++v) result.hidden.push_back(v->info());
  std::sort(result.hidden.begin(), result.hidden.end());
  result.num_faces = rt.dimension() == 2 ? rt.number_of_faces() : 0;
  return result;
}

// Ours, with copies of a hidden point reduced to its first occurrence (as CGAL reports them).
std::vector<uint32_t> OurHiddenFirstOccurrences(const Triangulation& t) {
  std::vector<uint32_t> hidden;
  for (const uint32_t i : t.hidden) {
    if (t.representative[i] == i) hidden.push_back(i);
  }
  return hidden;
}

// Whether CGAL's tie rule leaves the tie of these four points to its second term, where ours and
// CGAL's may differ: the three points other than the lexicographically largest are collinear.
bool BeyondTheFirstTieTerm(const std::array<Point2, 4>& q) {
  int top = 0;
  for (int i = 1; i < 4; ++i) {
    if (LexLess(q[top], q[i])) top = i;
  }
  Point2 others[3];
  for (int i = 0, k = 0; i < 4; ++i) {
    if (i != top) others[k++] = q[i];
  }
  return Orient2dSign(others[0], others[1], others[2]) == 0;
}

// Whether our interior edge `edge` is the diagonal of two triangles whose lifts are coplanar, and
// CGAL's tie rule would not decide that tie as ours does (BeyondTheFirstTieTerm).
bool OnAPowerTie(const Triangulation& t, const std::vector<double>& w, Edge edge) {
  for (size_t a = 0; a < t.triangles.size(); ++a) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t p = t.triangles[a][(k + 1) % 3], q = t.triangles[a][(k + 2) % 3];
      if (Undirected(p, q) != edge || t.neighbors[a][k] == Triangulation::kNoNeighbor) continue;
      const auto& nb = t.triangles[static_cast<size_t>(t.neighbors[a][k])];
      uint32_t s = nb[0];
      for (const uint32_t v : nb) {
        if (v != p && v != q) s = v;
      }
      const auto& x = t.triangles[a];
      const std::vector<Point2>& pt = t.points;
      return PowerSign(pt[x[0]], w[x[0]], pt[x[1]], w[x[1]], pt[x[2]], w[x[2]], pt[s], w[s]) == 0 &&
             BeyondTheFirstTieTerm({pt[x[0]], pt[x[1]], pt[x[2]], pt[s]});
    }
  }
  return false;
}

void CheckAgainstCgal(const std::vector<Point2>& points, const std::vector<double>& weights, Backend backend) {
  TriangulateOptions options;
  options.backend = backend;
  const absl::StatusOr<Triangulation> t = TriangulateWeighted(points, weights, options);
  ASSERT_THAT(t, IsOk());
  const CgalResult cgal = TriangulateWithCgal(points, weights);
  EXPECT_EQ(OurHiddenFirstOccurrences(*t), cgal.hidden) << "hidden points, first = ours, second = CGAL's";
  EXPECT_EQ(t->triangles.size(), cgal.num_faces);
  std::vector<Edge> ours = t->edges;
  std::sort(ours.begin(), ours.end());
  std::vector<Edge> ours_only, theirs_only;
  std::set_difference(ours.begin(), ours.end(), cgal.edges.begin(), cgal.edges.end(), std::back_inserter(ours_only));
  std::set_difference(cgal.edges.begin(), cgal.edges.end(), ours.begin(), ours.end(), std::back_inserter(theirs_only));
  EXPECT_EQ(ours_only.size(), theirs_only.size());
  int reported = 0;
  for (const Edge& e : ours_only) {
    if (!OnAPowerTie(*t, weights, e) && reported++ < 10) {
      ADD_FAILURE() << "edge (" << e[0] << ", " << e[1] << ") is ours only, not on a power tie CGAL breaks otherwise";
    }
  }
  for (const Edge& e : theirs_only) {
    if (reported++ < 10 && ours_only.empty()) ADD_FAILURE() << "edge (" << e[0] << ", " << e[1] << ") is CGAL's only";
  }
}

class RegularCgalTest : public testing::BackendTest {};

TEST_P(RegularCgalTest, EveryDistributionWithEveryKindOfWeights) {
  for (const gen::NamedGenerator& generator : gen::AllDistributions()) {
    for (const std::string& kind : gen::WeightKinds()) {
      for (const size_t n : {40, 3000}) {
        SCOPED_TRACE(absl::StrCat(generator.name, " ", kind, " n=", n));
        const std::vector<Point2> points = generator.generate(n, /*seed=*/7);
        CheckAgainstCgal(points, gen::Weights(kind, points, /*seed=*/8), GetParam());
        if (HasFatalFailure()) return;
      }
    }
  }
}

TEST_P(RegularCgalTest, ManySmallRandomSets) {
  // Small sets reach the corner cases (hidden first triangle, hidden hull points, all but a few
  // hidden, collinear survivors) far more often than large ones.
  for (uint64_t seed = 0; seed < 300; ++seed) {
    const size_t n = 3 + seed % 17;
    const std::vector<Point2> points =
        seed % 3 == 0 ? gen::Grid(n, seed) : (seed % 3 == 1 ? gen::ParallelLines(n, seed) : gen::Uniform(n, seed));
    const std::string kind = gen::WeightKinds()[seed % gen::WeightKinds().size()];
    SCOPED_TRACE(absl::StrCat("seed ", seed, " n=", n, " ", kind));
    CheckAgainstCgal(points, gen::Weights(kind, points, seed), GetParam());
    if (HasFatalFailure()) return;
  }
}

TEST_P(RegularCgalTest, ExactTiesAreBrokenAsCgalBreaksThem) {
  // A point whose lift lies exactly on the plane of a triangle's lifts: hidden or not by the tie
  // rule. The triangle (0,0), (4,0), (0,4) with weights 0 has the lifted plane z = 4x + 4y; at
  // (1,1) a weight of -6 puts the lift on it. (4,0) is the largest: CGAL keeps (1,1). Mirrored
  // (x -> -x), (1,1) becomes the largest of the four (-1,1) and is hidden.
  CheckAgainstCgal({{0, 0}, {4, 0}, {0, 4}, {1, 1}}, {0, 0, 0, -6}, GetParam());
  CheckAgainstCgal({{0, 0}, {-4, 0}, {0, 4}, {-1, 1}}, {0, 0, 0, -6}, GetParam());
  // Four cocircular points with equal weights: the diagonal of the square is the tie rule's.
  CheckAgainstCgal({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {2, 2, 2, 2}, GetParam());
  CheckAgainstCgal({{0, 0}, {2, 1}, {1, 3}, {-1, 2}}, {0, 0, 0, 0}, GetParam());
  // Integer grids with integer weights: ties everywhere.
  for (uint64_t seed = 0; seed < 20; ++seed) {
    const std::vector<Point2> points = gen::Grid(25 + seed * 7, seed);
    CheckAgainstCgal(points, gen::Weights("integers", points, seed), GetParam());
    CheckAgainstCgal(points, gen::Weights("equal", points, seed), GetParam());
  }
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(RegularCgalTest);

}  // namespace
}  // namespace galpha
