// Our Delaunay triangulation against CGAL's Delaunay_triangulation_2, edge by edge.
//
// In general position the Delaunay triangulation is unique, so the undirected edge sets must be
// equal. With exactly co-circular quadruples (grids, circles, real data) both are correct yet may
// choose different diagonals; then every edge one has and the other lacks must be the diagonal of
// two triangles whose four vertices are exactly co-circular, and the counts and hulls (which do not
// depend on that choice) must still agree. That makes the comparison meaningful on every input.
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <iterator>
#include <numeric>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/exact/predicates.hpp"
#include "core/io/point_io.hpp"
#include "gpu/triangulation/delaunay.hpp"
#include "gpu/triangulation/triangulation_checks.hpp"
#include "gtest/gtest.h"
#include "tests/support/data_files.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::IsOk;

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<uint32_t, Kernel>;
using DataStructure = CGAL::Triangulation_data_structure_2<VertexBase>;
using CgalDelaunay = CGAL::Delaunay_triangulation_2<Kernel, DataStructure>;
using Edge = std::array<uint32_t, 2>;

Edge Undirected(uint32_t a, uint32_t b) { return {std::min(a, b), std::max(a, b)}; }
uint64_t DirectedKey(uint32_t from, uint32_t to) { return (uint64_t{from} << 32) | to; }

// CGAL's triangulation of the distinct points, each carrying the input index of its first
// occurrence (found here, independently of the engine's representatives).
CgalDelaunay TriangulateWithCgal(const std::vector<Point2>& points) {
  std::vector<uint32_t> order(points.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return LexLess(points[a], points[b]); });
  std::vector<std::pair<Kernel::Point_2, uint32_t>> firsts;
  for (size_t r = 0; r < order.size(); ++r) {
    const uint32_t i = order[r];
    if (r > 0 && points[i] == points[order[r - 1]]) continue;
    firsts.emplace_back(Kernel::Point_2(points[i].x, points[i].y), i);
  }
  // The range insertion spatially sorts: CGAL's fast path.
  return CgalDelaunay(firsts.begin(), firsts.end());
}

std::vector<Edge> CgalEdges(const CgalDelaunay& dt) {
  std::vector<Edge> edges;
  for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
    const auto face = e->first;
    const int i = e->second;
    edges.push_back(Undirected(face->vertex(CgalDelaunay::cw(i))->info(), face->vertex(CgalDelaunay::ccw(i))->info()));
  }
  std::sort(edges.begin(), edges.end());
  return edges;
}

std::vector<uint32_t> CgalHullVertices(const CgalDelaunay& dt) {
  std::vector<uint32_t> hull;
  if (dt.dimension() < 2) return hull;
  auto v = dt.incident_vertices(dt.infinite_vertex());
  const auto done = v;
  do {
    hull.push_back(v->info());
  } while (++v != done);
  std::sort(hull.begin(), hull.end());
  return hull;
}

std::vector<uint32_t> OurHullVertices(const Triangulation& t) {
  std::vector<uint32_t> hull;
  for (size_t tri = 0; tri < t.triangles.size(); ++tri) {
    for (int k = 0; k < 3; ++k) {
      if (t.neighbors[tri][k] == Triangulation::kNoNeighbor) {
        hull.push_back(t.triangles[tri][(k + 1) % 3]);
      }
    }
  }
  std::sort(hull.begin(), hull.end());
  return hull;
}

// Why an edge that only one triangulation has is acceptable, or what is wrong with it.
struct EdgeVerdict {
  bool co_circular = false;
  std::string why;
};

// `edge` in our triangulation: acceptable iff it is interior and its two triangles' four vertices
// are exactly co-circular.
EdgeVerdict JudgeOurEdge(const Triangulation& t, const std::unordered_map<uint64_t, uint32_t>& directed, Edge edge) {
  const auto forward = directed.find(DirectedKey(edge[0], edge[1]));
  const auto backward = directed.find(DirectedKey(edge[1], edge[0]));
  if (forward == directed.end() || backward == directed.end()) {
    return {false, "a hull edge of ours only"};
  }
  const auto& abc = t.triangles[forward->second / 3];
  const uint32_t d = t.triangles[backward->second / 3][backward->second % 3];
  const std::vector<Point2>& p = t.points;
  const int in_circle = InCircleSign(p[abc[0]], p[abc[1]], p[abc[2]], p[d]);
  return {in_circle == 0, absl::StrCat("ours only, in-circle sign ", in_circle)};
}

// `edge` in CGAL's triangulation: the same question on CGAL's two faces.
EdgeVerdict JudgeCgalEdge(const CgalDelaunay& dt, const std::unordered_map<uint64_t, CgalDelaunay::Edge>& cgal_edges,
                          Edge edge) {
  const CgalDelaunay::Edge& e = cgal_edges.at(DirectedKey(edge[0], edge[1]));
  const auto face = e.first;
  const auto mirror = face->neighbor(e.second);
  if (dt.is_infinite(face) || dt.is_infinite(mirror)) return {false, "a hull edge of CGAL's only"};
  auto point = [](CgalDelaunay::Vertex_handle v) { return Point2{v->point().x(), v->point().y()}; };
  const int in_circle = InCircleSign(point(face->vertex(0)), point(face->vertex(1)), point(face->vertex(2)),
                                     point(dt.mirror_vertex(face, e.second)));
  return {in_circle == 0, absl::StrCat("CGAL's only, in-circle sign ", in_circle)};
}

// Compares `t` (already validated) with CGAL; `require_identical` for general-position input.
void ExpectMatchesCgal(const Triangulation& t, bool require_identical) {
  const CgalDelaunay dt = TriangulateWithCgal(t.points);
  ASSERT_EQ(dt.number_of_vertices(), t.num_unique);
  const std::vector<Edge> theirs = CgalEdges(dt);
  std::vector<Edge> ours = t.edges;
  std::sort(ours.begin(), ours.end());

  // Counts and hull do not depend on how co-circular ties are broken.
  EXPECT_EQ(t.triangles.size(), dt.dimension() == 2 ? dt.number_of_faces() : 0u);
  EXPECT_EQ(ours.size(), theirs.size());
  EXPECT_EQ(OurHullVertices(t), CgalHullVertices(dt));

  std::vector<Edge> ours_only;
  std::vector<Edge> theirs_only;
  std::set_difference(ours.begin(), ours.end(), theirs.begin(), theirs.end(), std::back_inserter(ours_only));
  std::set_difference(theirs.begin(), theirs.end(), ours.begin(), ours.end(), std::back_inserter(theirs_only));
  if (require_identical) {
    EXPECT_TRUE(ours_only.empty() && theirs_only.empty())
        << ours_only.size() << " edges only in ours, " << theirs_only.size()
        << " only in CGAL's, for input in general position";
  }

  std::unordered_map<uint64_t, uint32_t> directed;
  for (size_t tri = 0; tri < t.triangles.size(); ++tri) {
    for (int k = 0; k < 3; ++k) {
      directed.emplace(DirectedKey(t.triangles[tri][(k + 1) % 3], t.triangles[tri][(k + 2) % 3]),
                       static_cast<uint32_t>(3 * tri + k));
    }
  }
  std::unordered_map<uint64_t, CgalDelaunay::Edge> cgal_edges;
  for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
    const Edge edge = Undirected(e->first->vertex(CgalDelaunay::cw(e->second))->info(),
                                 e->first->vertex(CgalDelaunay::ccw(e->second))->info());
    cgal_edges.emplace(DirectedKey(edge[0], edge[1]), *e);
  }

  int reported = 0;
  auto judge = [&](Edge edge, const EdgeVerdict& verdict) {
    if (verdict.co_circular || reported >= 10) return;
    ++reported;
    ADD_FAILURE() << "edge (" << edge[0] << ", " << edge[1] << ") is " << verdict.why
                  << ": not explained by a co-circular quadruple";
  };
  for (const Edge& edge : ours_only) judge(edge, JudgeOurEdge(t, directed, edge));
  for (const Edge& edge : theirs_only) judge(edge, JudgeCgalEdge(dt, cgal_edges, edge));
}

std::vector<Backend> BackendsToTest() {
  std::vector<Backend> backends = {Backend::kCpu};
  if (CudaBackendAvailable()) backends.push_back(Backend::kCuda);
  return backends;
}

// Triangulates on `backend`, validates, and compares with CGAL.
void CheckAgainstCgal(const std::vector<Point2>& points, Backend backend, bool general_position) {
  SCOPED_TRACE(BackendName(backend));
  TriangulateOptions options;
  options.backend = backend;
  const absl::StatusOr<Triangulation> t = Triangulate(points, options);
  ASSERT_THAT(t, IsOk());
  const absl::Status valid = CheckTriangulation(*t);
  EXPECT_THAT(valid, IsOk());
  // Compare even an invalid result (CGAL's view helps to diagnose it), unless its arrays are
  // malformed and cannot be indexed safely.
  if (valid.code() == absl::StatusCode::kFailedPrecondition) return;
  ExpectMatchesCgal(*t, general_position);
}

TEST(DelaunayCgalTest, EveryDistribution) {
  for (const gen::NamedGenerator& generator : gen::AllDistributions()) {
    for (size_t n : {10, 1000, 20000}) {
      SCOPED_TRACE(absl::StrCat(generator.name, " n=", n));
      const std::vector<Point2> points = generator.generate(n, /*seed=*/5);
      for (Backend backend : BackendsToTest()) {
        ASSERT_NO_FATAL_FAILURE(CheckAgainstCgal(points, backend, generator.general_position));
      }
    }
  }
}

TEST(DelaunayCgalTest, RealDataSets) {
  const std::vector<std::string> files = testdata::PointFiles();
  ASSERT_FALSE(files.empty()) << "no *.bin files in " << testdata::DataDir();
  for (const std::string& file : files) {
    SCOPED_TRACE(file);
    const absl::StatusOr<std::vector<Point2>> points = ReadPointsBin(file);
    ASSERT_THAT(points, IsOk());
    for (Backend backend : BackendsToTest()) {
      // Real data may hold co-circular quadruples: differences must be explained by them.
      ASSERT_NO_FATAL_FAILURE(CheckAgainstCgal(*points, backend, /*general_position=*/false));
    }
  }
}

}  // namespace
}  // namespace galpha
