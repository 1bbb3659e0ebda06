// CheckTriangulation on hand-built triangulations: valid ones pass, and each corruption is caught by
// the property it breaks (a checker that never fails would make every engine test meaningless).
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "gpu/triangulation/delaunay.hpp"
#include "gpu/triangulation/triangulation_checks.hpp"
#include "gtest/gtest.h"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::IsOk;
using testing::StatusIs;

// Distinct points, representatives = identity.
Triangulation WithPoints(std::vector<Point2> points) {
  Triangulation t;
  t.points = std::move(points);
  for (uint32_t i = 0; i < t.points.size(); ++i) t.representative.push_back(i);
  t.num_unique = static_cast<uint32_t>(t.points.size());
  return t;
}

// The square (0,0) (2,0) (2,2) (0,2) and its centre 4, four triangles around the centre; neighbours
// and the owned edges worked out by hand from the report "Computing 2D Alpha Shapes Using GPU",
// section 3.1.
Triangulation SquareWithCentre() {
  Triangulation t = WithPoints({{0, 0}, {2, 0}, {2, 2}, {0, 2}, {1, 1}});
  t.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  t.neighbors = {{1, 3, -1}, {2, 0, -1}, {3, 1, -1}, {0, 2, -1}};
  t.tri_edge_begin = {0, 2, 4, 6};
  t.edges = {{0, 1}, {1, 4}, {1, 2}, {2, 4}, {2, 3}, {3, 4}, {0, 3}, {0, 4}};
  return t;
}

// 3 = (1, 0) lies on the hull edge from 0 to 1 and must be a hull vertex.
Triangulation CollinearHullPoint() {
  Triangulation t = WithPoints({{0, 0}, {2, 0}, {1, 2}, {1, 0}});
  t.triangles = {{0, 3, 2}, {3, 1, 2}};
  t.neighbors = {{1, -1, -1}, {-1, 0, -1}};
  t.tri_edge_begin = {0, 2};
  t.edges = {{0, 3}, {0, 2}, {1, 3}, {1, 2}, {2, 3}};
  return t;
}

// Expects a failure of `code` whose message contains `fragment`.
void ExpectViolation(const Triangulation& t, absl::StatusCode code, const std::string& fragment) {
  const absl::Status status = CheckTriangulation(t);
  EXPECT_THAT(status, StatusIs(code));
  EXPECT_NE(status.message().find(fragment), absl::string_view::npos)
      << "message lacks \"" << fragment << "\": " << status;
}

TEST(TriangulationChecksTest, ValidTriangulationsPass) {
  EXPECT_THAT(CheckTriangulation(SquareWithCentre()), IsOk());
  EXPECT_THAT(CheckTriangulation(CollinearHullPoint()), IsOk());
}

TEST(TriangulationChecksTest, ValidEdgeOnlyOutputsPass) {
  EXPECT_THAT(CheckTriangulation(WithPoints({})), IsOk());
  EXPECT_THAT(CheckTriangulation(WithPoints({{1, 1}})), IsOk());
  Triangulation line = WithPoints({{0, 0}, {2, 2}, {1, 1}});
  line.edges = {{1, 2}, {0, 2}};
  EXPECT_THAT(CheckTriangulation(line), IsOk());
}

TEST(TriangulationChecksTest, DuplicateMustMapToFirstOccurrence) {
  Triangulation t = SquareWithCentre();
  t.points.push_back({0, 0});
  t.representative.push_back(5);
  ExpectViolation(t, absl::StatusCode::kInternal, "representative[5]");
  t.representative.back() = 0;
  EXPECT_THAT(CheckTriangulation(t), IsOk());
  t.num_unique = 6;
  ExpectViolation(t, absl::StatusCode::kInternal, "num_unique");
}

TEST(TriangulationChecksTest, MalformedArraysAreFailedPrecondition) {
  Triangulation t = SquareWithCentre();
  t.neighbors.pop_back();
  ExpectViolation(t, absl::StatusCode::kFailedPrecondition, "neighbour triples");
  t = SquareWithCentre();
  t.triangles[2][1] = 99;
  ExpectViolation(t, absl::StatusCode::kFailedPrecondition, "out of range");
}

TEST(TriangulationChecksTest, ClockwiseTriangle) {
  Triangulation t = SquareWithCentre();
  std::swap(t.triangles[0][0], t.triangles[0][1]);
  ExpectViolation(t, absl::StatusCode::kInternal, "not strictly counter-clockwise");
}

TEST(TriangulationChecksTest, AsymmetricNeighbours) {
  Triangulation t = SquareWithCentre();
  t.neighbors[0][0] = 2;
  ExpectViolation(t, absl::StatusCode::kInternal, "neighbour symmetry");
}

TEST(TriangulationChecksTest, MissingNeighbourLink) {
  Triangulation t = SquareWithCentre();
  t.neighbors[0][0] = Triangulation::kNoNeighbor;
  t.neighbors[1][1] = Triangulation::kNoNeighbor;
  ExpectViolation(t, absl::StatusCode::kInternal, "holds its reverse");
}

TEST(TriangulationChecksTest, OverlappingTriangles) {
  Triangulation t = SquareWithCentre();
  t.triangles.push_back(t.triangles[0]);
  t.neighbors.push_back({-1, -1, -1});
  t.tri_edge_begin.push_back(8);
  ExpectViolation(t, absl::StatusCode::kInternal, "triangles overlap");
}

TEST(TriangulationChecksTest, EdgeListMustFollowOwnershipRule) {
  Triangulation t = SquareWithCentre();
  t.tri_edge_begin[2] = 3;
  ExpectViolation(t, absl::StatusCode::kInternal, "tri_edge_begin");
  t = SquareWithCentre();
  std::swap(t.edges[0], t.edges[1]);
  ExpectViolation(t, absl::StatusCode::kInternal, "edge list");
  t = SquareWithCentre();
  t.edges.push_back({0, 2});
  ExpectViolation(t, absl::StatusCode::kInternal, "edge list has 9 edges");
}

TEST(TriangulationChecksTest, EveryPointMustBeAVertex) {
  Triangulation t = SquareWithCentre();
  t.points.push_back({1.0, 0.5});
  t.representative.push_back(5);
  t.num_unique = 6;
  ExpectViolation(t, absl::StatusCode::kInternal, "point 5 (1, 0.5) is not a vertex");
}

TEST(TriangulationChecksTest, BoundaryMustBeTheConvexHull) {
  // The square with centre minus triangle (1, 2, 4): consistent, but the boundary dents in at 4.
  Triangulation t = WithPoints({{0, 0}, {2, 0}, {2, 2}, {0, 2}, {1, 1}});
  t.triangles = {{0, 1, 4}, {2, 3, 4}, {3, 0, 4}};
  t.neighbors = {{-1, 2, -1}, {2, -1, -1}, {0, 1, -1}};
  t.tri_edge_begin = {0, 2, 5};
  t.edges = {{0, 1}, {1, 4}, {2, 3}, {3, 4}, {2, 4}, {0, 3}, {0, 4}};
  ExpectViolation(t, absl::StatusCode::kInternal, "boundary differs from the convex hull");
}

TEST(TriangulationChecksTest, LongDiagonalOfAKiteIsNotDelaunay) {
  // D = 3 lies inside the circle through A = 0, B = 1, C = 2.
  Triangulation t = WithPoints({{0, 0}, {4, 0}, {2, 1}, {2, -1}});
  t.triangles = {{0, 1, 2}, {0, 3, 1}};
  t.neighbors = {{-1, -1, 1}, {-1, 0, -1}};
  t.tri_edge_begin = {0, 3};
  t.edges = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}};
  ExpectViolation(t, absl::StatusCode::kInternal, "not locally Delaunay");
}

TEST(TriangulationChecksTest, EdgeOnlyOutputs) {
  Triangulation line = WithPoints({{0, 0}, {2, 2}, {1, 1}});
  line.edges = {{0, 1}, {1, 2}};
  ExpectViolation(line, absl::StatusCode::kInternal, "collinear output");
  Triangulation missing = WithPoints({{0, 0}, {2, 2}, {1, 1}});
  missing.edges = {{0, 2}};
  ExpectViolation(missing, absl::StatusCode::kInternal, "collinear output has 1 edges");
  Triangulation bent = WithPoints({{0, 0}, {2, 2}, {1, 0}});
  bent.edges = {{0, 2}, {1, 2}};
  ExpectViolation(bent, absl::StatusCode::kInternal, "are not collinear");
}

}  // namespace
}  // namespace galpha
