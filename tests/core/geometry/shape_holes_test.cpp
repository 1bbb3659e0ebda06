// Holes of assembled shapes: listed with exact areas on hand-made complexes (a square frame with a
// square hole, two holes of different sizes, a large offset), filled below an area with the
// shape's area growing by the hole's and its WKT still one POLYGON.
#include "core/geometry/shape_holes.hpp"

#include <gmpxx.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/geometry/shape.hpp"
#include "gtest/gtest.h"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::IsOk;

// A grid of (n + 1) x (n + 1) points with spacing 1 from (x0, y0), and the two counter-clockwise
// triangles of every unit square except those in `empty` (squares by their lower-left corner).
struct HoleGrid {
  std::vector<Point2> points;
  std::vector<std::array<uint32_t, 3>> triangles;
};

HoleGrid MakeGrid(int n, double x0, double y0, const std::vector<std::array<int, 2>>& empty) {
  HoleGrid g;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) g.points.push_back({x0 + i, y0 + j});
  }
  auto id = [n](int i, int j) { return static_cast<uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      bool skip = false;
      for (const auto& e : empty) skip |= e[0] == i && e[1] == j;
      if (skip) continue;
      g.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      g.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return g;
}

absl::StatusOr<ShapeGeometry> Assemble(const HoleGrid& g) {
  ShapeComplex complex;
  complex.points = g.points;
  complex.triangles = g.triangles;
  return AssembleShape(complex);
}

TEST(ShapeHolesTest, ListsEachHoleWithItsArea) {
  // 6 x 6 squares; a 2 x 2 hole at (1, 1) and a 1 x 1 hole at (4, 4).
  const HoleGrid g = MakeGrid(6, 0, 0, {{1, 1}, {2, 1}, {1, 2}, {2, 2}, {4, 4}});
  const absl::StatusOr<ShapeGeometry> shape = Assemble(g);
  ASSERT_THAT(shape, IsOk());
  ASSERT_EQ(shape->polygons.size(), 1u);
  ASSERT_EQ(shape->polygons[0].holes.size(), 2u);
  EXPECT_EQ(shape->area, 31.0);
  const std::vector<ShapeHole> holes = ListHoles(*shape, g.points, 0.0);
  ASSERT_EQ(holes.size(), 2u);
  EXPECT_EQ(holes[0].area, 4.0);
  EXPECT_EQ(holes[0].ring.size(), 8u);
  EXPECT_EQ(holes[1].area, 1.0);
  EXPECT_EQ(holes[1].ring.size(), 4u);
  EXPECT_EQ(ListHoles(*shape, g.points, 1.5).size(), 1u);
  EXPECT_EQ(ListHoles(*shape, g.points, 4.0).size(), 1u) << "the bound is inclusive";
  EXPECT_TRUE(ListHoles(*shape, g.points, 4.5).empty());
}

TEST(ShapeHolesTest, FillsTheSmallHolesOnly) {
  const HoleGrid g = MakeGrid(6, 0, 0, {{1, 1}, {2, 1}, {1, 2}, {2, 2}, {4, 4}});
  absl::StatusOr<ShapeGeometry> shape = Assemble(g);
  ASSERT_THAT(shape, IsOk());
  EXPECT_EQ(FillHolesSmallerThan(&*shape, g.points, 2.0), 1u);
  ASSERT_EQ(shape->polygons[0].holes.size(), 1u);
  EXPECT_EQ(RingArea(shape->polygons[0].holes[0], g.points), 4.0);
  EXPECT_EQ(shape->area, 32.0);
  EXPECT_EQ(ShapeToWkt(*shape, g.points).rfind("POLYGON ((", 0), 0u);
  EXPECT_EQ(FillHolesSmallerThan(&*shape, g.points, 100.0), 1u);
  EXPECT_TRUE(shape->polygons[0].holes.empty());
  EXPECT_EQ(shape->area, 36.0);
  EXPECT_EQ(FillHolesSmallerThan(&*shape, g.points, 100.0), 0u);
}

TEST(ShapeHolesTest, AreasSurviveALargeOffset) {
  // At 1e9 the products of absolute coordinates would lose the unit squares; differences keep them.
  const HoleGrid g = MakeGrid(4, 1e9, -3e9, {{1, 1}, {2, 1}});
  const absl::StatusOr<ShapeGeometry> shape = Assemble(g);
  ASSERT_THAT(shape, IsOk());
  const std::vector<ShapeHole> holes = ListHoles(*shape, g.points, 0.0);
  ASSERT_EQ(holes.size(), 1u);
  EXPECT_EQ(holes[0].area, 2.0);
}

// RingArea is the double nearest to the exact area (checked against both neighbouring doubles in
// GMP rationals), on rings whose shoelace products round: random coordinates at many scales and
// offsets. A shoelace summed in doubles misses on a share of these.
TEST(ShapeHolesTest, RingAreaIsTheNearestDoubleOfTheExactArea) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const double scale = std::ldexp(1.0, static_cast<int>(rng() % 60) - 30);
    const double offset = (trial % 3 == 0) ? 1e9 : 0.0;
    std::vector<Point2> points;
    std::vector<uint32_t> ring;
    for (uint32_t i = 0; i < 3 + rng() % 6; ++i) {
      points.push_back({offset + scale * unit(rng), offset + scale * unit(rng)});
      ring.push_back(i);
    }
    mpq_class twice = 0;
    for (size_t i = 0; i < ring.size(); ++i) {
      const Point2 a = points[ring[i]], b = points[ring[(i + 1) % ring.size()]];
      twice += mpq_class(a.x) * mpq_class(b.y) - mpq_class(b.x) * mpq_class(a.y);
    }
    const mpq_class exact = abs(twice) / 2;
    const double got = RingArea(ring, points);
    const mpq_class error = abs(mpq_class(got) - exact);
    for (double neighbour : {std::nextafter(got, 0.0), std::nextafter(got, INFINITY)}) {
      ASSERT_LE(error, abs(mpq_class(neighbour) - exact)) << "trial " << trial;
    }
    ++checked;
  }
  EXPECT_EQ(checked, 2000);
}

}  // namespace
}  // namespace galpha
