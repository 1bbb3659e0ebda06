// AssembleShape and its writers, with GEOS as the independent oracle: the WKT must parse into a
// valid MultiPolygon (GEOSisValid) whose area is the triangles' and which equals (GEOSEquals) the
// GEOS union of the triangles, with as many polygons and holes as that union. Hand-made pinch
// configurations, then random subsets of real triangulations (random points, and a grid full of
// pinch vertices). The GeoJSON is parsed back with nlohmann-json, the SVG checked for its parts.
#include "core/geometry/shape.hpp"

#include <geos_c.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gpu/triangulation/delaunay.hpp"
#include "tests/support/geos.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::IsOk;
using testing::StatusIs;

using Tri = std::array<uint32_t, 3>;
using Edge = std::array<uint32_t, 2>;

using testing::Geos;

// ---- Independent facts about a set of triangles ------------------------------------------------

double TriangleAreaSum(absl::Span<const Point2> p, const std::vector<Tri>& tris) {
  double sum = 0.0;
  for (const Tri& t : tris) {
    const Point2 a = p[t[0]], b = p[t[1]], c = p[t[2]];
    sum += 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
  }
  return sum;
}

// Directed triangle edges whose reverse is not one: each must be in exactly one ring.
std::multiset<std::pair<uint32_t, uint32_t>> BoundaryEdges(const std::vector<Tri>& tris) {
  std::set<std::pair<uint32_t, uint32_t>> directed;
  for (const Tri& t : tris) {
    for (int k = 0; k < 3; ++k) directed.insert({t[k], t[(k + 1) % 3]});
  }
  std::multiset<std::pair<uint32_t, uint32_t>> boundary;
  for (const auto& [a, b] : directed) {
    if (!directed.count({b, a})) boundary.insert({a, b});
  }
  return boundary;
}

size_t CountOf(const std::string& text, const std::string& what) {
  size_t count = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++count;
  return count;
}

// ---- The checks every case goes through ---------------------------------------------------------

struct Expected {
  int polygons = -1;  // -1: only the GEOS union decides
  int holes = -1;
};

void CheckRingStructure(const ShapeGeometry& shape, const std::vector<Tri>& tris) {
  std::multiset<std::pair<uint32_t, uint32_t>> ring_edges;
  auto add_ring = [&](const std::vector<uint32_t>& ring) {
    ASSERT_GE(ring.size(), 3u);
    EXPECT_EQ(ring[0], *std::min_element(ring.begin(), ring.end())) << "ring must start at its smallest index";
    EXPECT_EQ(std::set<uint32_t>(ring.begin(), ring.end()).size(), ring.size()) << "ring touches itself";
    for (size_t i = 0; i < ring.size(); ++i) ring_edges.insert({ring[i], ring[(i + 1) % ring.size()]});
  };
  for (const ShapePolygon& polygon : shape.polygons) {
    add_ring(polygon.outer);
    for (const auto& hole : polygon.holes) add_ring(hole);
    EXPECT_TRUE(std::is_sorted(polygon.holes.begin(), polygon.holes.end()));
  }
  EXPECT_TRUE(std::is_sorted(shape.polygons.begin(), shape.polygons.end(),
                             [](const ShapePolygon& a, const ShapePolygon& b) { return a.outer < b.outer; }));
  EXPECT_EQ(ring_edges, BoundaryEdges(tris)) << "every boundary edge in exactly one ring";
}

void CheckGeoJson(const ShapeGeometry& shape, absl::Span<const Point2> points) {
  const auto json = nlohmann::json::parse(ShapeToGeoJson(shape, points), nullptr, /*allow_exceptions=*/false);
  ASSERT_FALSE(json.is_discarded()) << ShapeToGeoJson(shape, points);
  ASSERT_EQ(json["type"], "FeatureCollection");
  const size_t parts = !shape.polygons.empty() + !shape.singular_edges.empty() + !shape.isolated_points.empty();
  ASSERT_EQ(json["features"].size(), parts);
  auto expect_position = [&](const nlohmann::json& position, uint32_t index) {
    ASSERT_EQ(position.size(), 2u);
    EXPECT_EQ(position[0].get<double>(), points[index].x);  // the shortest text reads back exactly
    EXPECT_EQ(position[1].get<double>(), points[index].y);
  };
  auto expect_ring = [&](const nlohmann::json& ring, const std::vector<uint32_t>& want) {
    ASSERT_EQ(ring.size(), want.size() + 1);
    for (size_t i = 0; i <= want.size(); ++i) expect_position(ring[i], want[i % want.size()]);
  };
  for (const auto& feature : json["features"]) {
    EXPECT_EQ(feature["type"], "Feature");
    const auto& geometry = feature["geometry"];
    const auto& coordinates = geometry["coordinates"];
    const std::string kind = feature["properties"]["kind"];
    if (kind == "polygons") {
      EXPECT_EQ(geometry["type"], "MultiPolygon");
      ASSERT_EQ(coordinates.size(), shape.polygons.size());
      for (size_t p = 0; p < shape.polygons.size(); ++p) {
        ASSERT_EQ(coordinates[p].size(), 1 + shape.polygons[p].holes.size());
        expect_ring(coordinates[p][0], shape.polygons[p].outer);
        for (size_t h = 0; h < shape.polygons[p].holes.size(); ++h) {
          expect_ring(coordinates[p][h + 1], shape.polygons[p].holes[h]);
        }
      }
      EXPECT_EQ(feature["properties"]["area"].get<double>(), shape.area);
    } else if (kind == "singular_edges") {
      EXPECT_EQ(geometry["type"], "MultiLineString");
      ASSERT_EQ(coordinates.size(), shape.singular_edges.size());
      for (size_t e = 0; e < shape.singular_edges.size(); ++e) {
        ASSERT_EQ(coordinates[e].size(), 2u);
        expect_position(coordinates[e][0], shape.singular_edges[e][0]);
        expect_position(coordinates[e][1], shape.singular_edges[e][1]);
      }
    } else {
      EXPECT_EQ(kind, "isolated_points");
      EXPECT_EQ(geometry["type"], "MultiPoint");
      ASSERT_EQ(coordinates.size(), shape.isolated_points.size());
      for (size_t i = 0; i < shape.isolated_points.size(); ++i) {
        expect_position(coordinates[i], shape.isolated_points[i]);
      }
    }
  }
}

void CheckSvg(const ShapeGeometry& shape, absl::Span<const Point2> points) {
  const std::string svg = ShapeToSvg(shape, points);
  EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u) << svg.substr(0, 200);
  EXPECT_EQ(CountOf(svg, "viewBox=\""), 1u);
  EXPECT_EQ(CountOf(svg, "<path "), shape.polygons.size());
  EXPECT_EQ(CountOf(svg, "fill-rule=\"evenodd\""), 1u);
  EXPECT_EQ(CountOf(svg, "<line "), shape.singular_edges.size());
  EXPECT_EQ(CountOf(svg, "<circle "), shape.isolated_points.size());
  EXPECT_EQ(CountOf(svg, "<g"), CountOf(svg, "</g>"));
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
  EXPECT_EQ(svg.find("nan"), std::string::npos);
}

// Assembles the complex and checks it against GEOS and the structural rules; returns the shape.
ShapeGeometry CheckShape(absl::Span<const Point2> points, const std::vector<Tri>& tris,
                         const std::vector<Edge>& singular = {}, const std::vector<uint32_t>& isolated = {},
                         Expected expected = {}) {
  const ShapeComplex complex{points, tris, singular, isolated};
  const absl::StatusOr<ShapeGeometry> assembled = AssembleShape(complex);
  EXPECT_THAT(assembled, IsOk());
  if (!assembled.ok()) return {};
  const ShapeGeometry& shape = *assembled;
  CheckRingStructure(shape, tris);

  const double area = TriangleAreaSum(points, tris);
  EXPECT_NEAR(shape.area, area, 1e-12 * area);
  size_t holes = 0;
  for (const ShapePolygon& polygon : shape.polygons) holes += polygon.holes.size();
  if (expected.polygons >= 0) {
    EXPECT_EQ(shape.polygons.size(), static_cast<size_t>(expected.polygons));
  }
  if (expected.holes >= 0) {
    EXPECT_EQ(holes, static_cast<size_t>(expected.holes));
  }

  // The same complex with the triangles shuffled and rotated assembles identically.
  ShapeComplex shuffled = complex;
  std::mt19937_64 rng(7);
  std::shuffle(shuffled.triangles.begin(), shuffled.triangles.end(), rng);
  for (Tri& t : shuffled.triangles) std::rotate(t.begin(), t.begin() + rng() % 3, t.end());
  std::reverse(shuffled.isolated_points.begin(), shuffled.isolated_points.end());
  const auto again = AssembleShape(shuffled);
  EXPECT_THAT(again, IsOk());
  if (again.ok()) {
    EXPECT_EQ(ShapeToWkt(*again, points), ShapeToWkt(shape, points)) << "order must not depend on input order";
  }

  Geos geos;
  const std::string wkt = ShapeToWkt(shape, points);
  const Geos::Geom collection = geos.ReadWkt(wkt);
  EXPECT_NE(collection, nullptr) << wkt;
  if (collection == nullptr) return shape;
  // The simplest type that holds the shape: POLYGON, MULTIPOLYGON (EMPTY when there is nothing),
  // or a GEOMETRYCOLLECTION of a MULTIPOLYGON, a MULTILINESTRING and a MULTIPOINT when singular
  // edges or isolated points are present. GEOS treats a single geometry as its own only part.
  const bool polygons_only = shape.singular_edges.empty() && shape.isolated_points.empty();
  const int type = GEOSGeomTypeId_r(geos.ctx(), collection.get());
  if (!polygons_only) {
    EXPECT_EQ(type, GEOS_GEOMETRYCOLLECTION) << wkt;
  } else if (shape.polygons.size() == 1) {
    EXPECT_EQ(type, GEOS_POLYGON) << wkt;
  } else {
    EXPECT_EQ(type, GEOS_MULTIPOLYGON) << wkt;
    EXPECT_EQ(GEOSisEmpty_r(geos.ctx(), collection.get()), shape.polygons.empty() ? 1 : 0) << wkt;
  }
  int part = 0;
  if (!shape.polygons.empty()) {
    const GEOSGeometry* multi =
        polygons_only ? collection.get() : GEOSGetGeometryN_r(geos.ctx(), collection.get(), part++);
    if (!polygons_only) {
      EXPECT_EQ(GEOSGeomTypeId_r(geos.ctx(), multi), GEOS_MULTIPOLYGON);
    }
    EXPECT_EQ(GEOSisValid_r(geos.ctx(), multi), 1) << geos.ValidReason(multi) << "\n" << wkt;
    EXPECT_EQ(GEOSGetNumGeometries_r(geos.ctx(), multi), static_cast<int>(shape.polygons.size()));
    double geos_area = 0.0;
    GEOSArea_r(geos.ctx(), multi, &geos_area);
    EXPECT_NEAR(geos_area, area, 1e-9 * area);
    for (int p = 0; p < GEOSGetNumGeometries_r(geos.ctx(), multi); ++p) {
      const GEOSGeometry* polygon = GEOSGetGeometryN_r(geos.ctx(), multi, p);
      EXPECT_TRUE(geos.IsCcw(GEOSGetExteriorRing_r(geos.ctx(), polygon))) << "polygon " << p;
      for (int h = 0; h < GEOSGetNumInteriorRings_r(geos.ctx(), polygon); ++h) {
        EXPECT_FALSE(geos.IsCcw(GEOSGetInteriorRingN_r(geos.ctx(), polygon, h))) << "polygon " << p;
      }
    }
    // The union GEOS computes from the triangles alone: same point set, same polygons and holes.
    const Geos::Geom merged = geos.UnionOfTriangles(points, tris);
    EXPECT_NE(merged, nullptr);
    if (merged != nullptr) {
      EXPECT_EQ(GEOSEquals_r(geos.ctx(), multi, merged.get()), 1) << wkt;
      EXPECT_EQ(GEOSGetNumGeometries_r(geos.ctx(), merged.get()), static_cast<int>(shape.polygons.size()));
      int geos_holes = 0;
      for (int p = 0; p < GEOSGetNumGeometries_r(geos.ctx(), merged.get()); ++p) {
        geos_holes += GEOSGetNumInteriorRings_r(geos.ctx(), GEOSGetGeometryN_r(geos.ctx(), merged.get(), p));
      }
      EXPECT_EQ(static_cast<size_t>(geos_holes), holes);
    }
  }
  if (!shape.singular_edges.empty()) {
    const GEOSGeometry* lines = GEOSGetGeometryN_r(geos.ctx(), collection.get(), part++);
    EXPECT_EQ(GEOSGeomTypeId_r(geos.ctx(), lines), GEOS_MULTILINESTRING);
    EXPECT_EQ(GEOSGetNumGeometries_r(geos.ctx(), lines), static_cast<int>(shape.singular_edges.size()));
  }
  if (!shape.isolated_points.empty()) {
    const GEOSGeometry* multipoint = GEOSGetGeometryN_r(geos.ctx(), collection.get(), part++);
    EXPECT_EQ(GEOSGeomTypeId_r(geos.ctx(), multipoint), GEOS_MULTIPOINT);
    EXPECT_EQ(GEOSGetNumGeometries_r(geos.ctx(), multipoint), static_cast<int>(shape.isolated_points.size()));
  }
  if (!polygons_only) {
    EXPECT_EQ(GEOSGetNumGeometries_r(geos.ctx(), collection.get()), part);
  }

  CheckGeoJson(shape, points);
  CheckSvg(shape, points);
  return shape;
}

// ---- Hand-made configurations on an integer grid -----------------------------------------------

// A width x height grid of points; (x, y) has index y * width + x.
struct Grid {
  uint32_t width, height;
  std::vector<Point2> points;
  Grid(uint32_t w, uint32_t h) : width(w), height(h) {
    for (uint32_t y = 0; y < h; ++y) {
      for (uint32_t x = 0; x < w; ++x) points.push_back({double(x), double(y)});
    }
  }
  uint32_t At(uint32_t x, uint32_t y) const { return y * width + x; }
  // The unit cell with lower-left corner (x, y), split along its rising diagonal.
  void AddCell(std::vector<Tri>& tris, uint32_t x, uint32_t y) const {
    tris.push_back({At(x, y), At(x + 1, y), At(x + 1, y + 1)});
    tris.push_back({At(x, y), At(x + 1, y + 1), At(x, y + 1)});
  }
  // The cells (x, y) with lo <= x, y < hi on the border of that square: a ring of cells.
  void AddCellRing(std::vector<Tri>& tris, uint32_t lo, uint32_t hi) const {
    for (uint32_t y = lo; y < hi; ++y) {
      for (uint32_t x = lo; x < hi; ++x) {
        if (x == lo || y == lo || x == hi - 1 || y == hi - 1) AddCell(tris, x, y);
      }
    }
  }
  // Triangle k (0..7) of the fan around (cx, cy) through its 8 grid neighbours, ccw from east.
  Tri Fan(uint32_t cx, uint32_t cy, int k) const {
    static constexpr int kDx[8] = {1, 1, 0, -1, -1, -1, 0, 1}, kDy[8] = {0, 1, 1, 1, 0, -1, -1, -1};
    auto ring = [&](int i) { return At(cx + kDx[i % 8], cy + kDy[i % 8]); };
    return {At(cx, cy), ring(k), ring(k + 1)};
  }
};

void RemoveCell(std::vector<Tri>& tris, const Grid& g, uint32_t x, uint32_t y) {
  std::vector<Tri> cell;
  g.AddCell(cell, x, y);
  tris.erase(std::remove_if(tris.begin(), tris.end(), [&](const Tri& t) { return t == cell[0] || t == cell[1]; }),
             tris.end());
}

TEST(AssembleShapeTest, OneTriangleAndTwoSharingAnEdge) {
  const Grid g(2, 2);
  const ShapeGeometry one = CheckShape(g.points, {{0, 1, 3}}, {}, {}, {1, 0});
  ASSERT_EQ(one.polygons.size(), 1u);
  EXPECT_EQ(one.polygons[0].outer, (std::vector<uint32_t>{0, 1, 3}));
  EXPECT_EQ(one.area, 0.5);
  EXPECT_EQ(ShapeToWkt(one, g.points), "POLYGON ((0 0, 1 0, 1 1, 0 0))");
  std::vector<Tri> cell;
  g.AddCell(cell, 0, 0);
  const ShapeGeometry square = CheckShape(g.points, cell, {}, {}, {1, 0});
  EXPECT_EQ(square.polygons[0].outer, (std::vector<uint32_t>{0, 1, 3, 2}));
}

TEST(AssembleShapeTest, TwoTrianglesTouchingAtAVertexAreTwoPolygons) {
  const Grid g(3, 3);
  CheckShape(g.points, {{g.At(0, 0), g.At(1, 0), g.At(1, 1)}, {g.At(1, 1), g.At(2, 1), g.At(2, 2)}}, {}, {}, {2, 0});
}

TEST(AssembleShapeTest, RingOfCellsAroundAHole) {
  const Grid g(4, 4);
  std::vector<Tri> tris;
  g.AddCellRing(tris, 0, 3);
  const ShapeGeometry shape = CheckShape(g.points, tris, {}, {}, {1, 1});
  EXPECT_EQ(shape.polygons[0].holes[0], (std::vector<uint32_t>{g.At(1, 1), g.At(1, 2), g.At(2, 2), g.At(2, 1)}));
}

TEST(AssembleShapeTest, HoleTouchingTheOuterRingAtAVertex) {
  const Grid g(4, 4);  // the ring without its corner cell: a C whose ends touch at (2, 2)
  std::vector<Tri> tris;
  g.AddCellRing(tris, 0, 3);
  RemoveCell(tris, g, 2, 2);
  CheckShape(g.points, tris, {}, {}, {1, 1});
}

TEST(AssembleShapeTest, TwoHolesTouchingAtAVertex) {
  const Grid g(5, 5);  // a ring of cells around 2 x 2 cells of which two diagonal ones are missing
  std::vector<Tri> tris;
  g.AddCellRing(tris, 0, 4);
  g.AddCell(tris, 1, 2);
  g.AddCell(tris, 2, 1);
  CheckShape(g.points, tris, {}, {}, {1, 2});
}

TEST(AssembleShapeTest, TriangleTouchingAPieceAtTwoVertices) {
  const Grid g(4, 4);  // the corner cell keeps only its outer triangle, which shares no edge
  std::vector<Tri> tris;
  g.AddCellRing(tris, 0, 3);
  RemoveCell(tris, g, 2, 2);
  tris.push_back({g.At(3, 2), g.At(3, 3), g.At(2, 3)});
  CheckShape(g.points, tris, {}, {}, {2, 1});
}

TEST(AssembleShapeTest, BowTiesAroundOneVertex) {
  const Grid g(3, 3);
  CheckShape(g.points, {g.Fan(1, 1, 0), g.Fan(1, 1, 1), g.Fan(1, 1, 4), g.Fan(1, 1, 5)}, {}, {}, {2, 0});
  CheckShape(g.points, {g.Fan(1, 1, 0), g.Fan(1, 1, 2), g.Fan(1, 1, 4), g.Fan(1, 1, 6)}, {}, {}, {4, 0});
  CheckShape(g.points, {g.Fan(1, 1, 0), g.Fan(1, 1, 1), g.Fan(1, 1, 2), g.Fan(1, 1, 5)}, {}, {}, {2, 0});
}

TEST(AssembleShapeTest, PieceTouchingItselfThreeTimesAtOneVertex) {
  const Grid g(5, 5);  // a ring of cells, and a fan inside it with three triangular gaps at (2, 2)
  std::vector<Tri> tris;
  g.AddCellRing(tris, 0, 4);
  for (int k : {0, 1, 3, 5, 6}) tris.push_back(g.Fan(2, 2, k));
  CheckShape(g.points, tris, {}, {}, {1, 3});
}

TEST(AssembleShapeTest, TwoPiecesTouchingTwiceAroundAnEnclosedRegion) {
  const Grid g(4, 4);  // the ring without two opposite corners: two L's, no polygon has the hole
  std::vector<Tri> tris;
  g.AddCellRing(tris, 0, 3);
  RemoveCell(tris, g, 0, 0);
  RemoveCell(tris, g, 2, 2);
  CheckShape(g.points, tris, {}, {}, {2, 0});
}

TEST(AssembleShapeTest, IslandTouchingTheShoreOfItsLake) {
  const Grid g(6, 6);
  std::vector<Tri> tris;
  g.AddCellRing(tris, 0, 5);
  g.AddCell(tris, 1, 1);  // joined to the ring through edges
  g.AddCell(tris, 2, 2);  // the island, touching cell (1, 1) at (2, 2)
  CheckShape(g.points, tris, {}, {}, {2, 1});
}

TEST(AssembleShapeTest, EmptyAndLowerDimensionalParts) {
  const Grid g(3, 3);
  const ShapeGeometry empty = CheckShape(g.points, {});
  EXPECT_EQ(ShapeToWkt(empty, g.points), "MULTIPOLYGON EMPTY");
  EXPECT_EQ(ShapeToGeoJson(empty, g.points), "{\"type\":\"FeatureCollection\",\"features\":[]}");
  const ShapeGeometry parts = CheckShape(g.points, {{0, 1, 4}}, {{8, 5}, {5, 8}, {6, 7}}, {2, 2});
  EXPECT_EQ(parts.singular_edges, (std::vector<Edge>{{5, 8}, {6, 7}}));
  EXPECT_EQ(parts.isolated_points, (std::vector<uint32_t>{2}));
  EXPECT_EQ(ShapeToWkt(parts, g.points),
            "GEOMETRYCOLLECTION (MULTIPOLYGON (((0 0, 1 0, 1 1, 0 0))), MULTILINESTRING ((2 1, 2 2), "
            "(0 2, 1 2)), MULTIPOINT ((2 0)))");
  const ShapeGeometry no_polygon = CheckShape(g.points, {}, {{0, 1}}, {});
  EXPECT_EQ(ShapeToWkt(no_polygon, g.points), "GEOMETRYCOLLECTION (MULTILINESTRING ((0 0, 1 0)))");
}

TEST(AssembleShapeTest, WktIsPolygonOrMultiPolygonWithoutLowerDimensionalParts) {
  const Grid g(4, 3);
  std::vector<Tri> tris;
  g.AddCell(tris, 0, 0);
  g.AddCell(tris, 2, 1);  // apart from the first
  const ShapeGeometry two = CheckShape(g.points, tris, {}, {}, {2, 0});
  EXPECT_EQ(ShapeToWkt(two, g.points), "MULTIPOLYGON (((0 0, 1 0, 1 1, 0 1, 0 0)), ((2 1, 3 1, 3 2, 2 2, 2 1)))");
  // The same polygons with an isolated point: a collection, the polygons still a MULTIPOLYGON.
  const ShapeGeometry with_point = CheckShape(g.points, {tris[0], tris[1]}, {}, {11}, {1, 0});
  EXPECT_EQ(ShapeToWkt(with_point, g.points),
            "GEOMETRYCOLLECTION (MULTIPOLYGON (((0 0, 1 0, 1 1, 0 1, 0 0))), MULTIPOINT ((3 2)))");
}

TEST(AssembleShapeTest, WritersPrintShortestRoundTripCoordinates) {
  // %.17g wrote 0.1 as 0.10000000000000001 and 1/3 with 17 digits; their shortest texts are
  // shorter and read back the same. A large offset and a tiny coordinate keep the digits they need.
  const std::vector<Point2> points = {{0.1, 0.2}, {1.0 / 3.0, 0.2}, {0.1, 1e-300}, {-2.5e15, 4503599627370497.0}};
  const ShapeGeometry shape = CheckShape(points, {{0, 2, 1}}, {}, {3});
  ASSERT_EQ(shape.polygons.size(), 1u);
  EXPECT_EQ(ShapeToWkt(shape, points),
            "GEOMETRYCOLLECTION (MULTIPOLYGON (((0.1 0.2, 0.1 1e-300, 0.3333333333333333 0.2, 0.1 0.2))), "
            "MULTIPOINT ((-2.5e+15 4503599627370497)))");
  const std::string geojson = ShapeToGeoJson(shape, points);
  EXPECT_NE(geojson.find("[[[[0.1,0.2],[0.1,1e-300],[0.3333333333333333,0.2],[0.1,0.2]]]]"), std::string::npos)
      << geojson;
  EXPECT_NE(geojson.find("\"coordinates\":[[-2.5e+15,4503599627370497]]"), std::string::npos) << geojson;
}

TEST(AssembleShapeTest, BadInputIsInvalidArgumentNamingTheIndex) {
  const Grid g(2, 2);
  auto expect_error = [&](const ShapeComplex& complex, const std::string& needle) {
    const auto got = AssembleShape(complex);
    ASSERT_THAT(got.status(), StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_NE(got.status().message().find(needle), absl::string_view::npos) << got.status();
  };
  expect_error({g.points, {{0, 1, 7}}, {}, {}}, "index 7");
  expect_error({g.points, {}, {{0, 4}}, {}}, "index 4");
  expect_error({g.points, {}, {}, {1, 9}}, "index 9");
  expect_error({g.points, {{0, 3, 1}}, {}, {}}, "counter-clockwise");
  expect_error({g.points, {{0, 1, 3}, {1, 3, 0}}, {}, {}}, "overlap");
}

// ---- Random subsets of real triangulations ------------------------------------------------------

TriangulateOptions CpuOptions() {
  TriangulateOptions options;
  options.backend = Backend::kCpu;
  return options;
}

TEST(AssembleShapeTest, RandomSubsetsOfTriangulations) {
  for (const char* name : {"uniform", "grid", "clustered", "with_duplicates", "circle", "huge_offset_1e9"}) {
    const gen::NamedGenerator* generator = gen::FindDistribution(name);
    ASSERT_NE(generator, nullptr) << name;
    for (uint64_t seed : {1, 2, 3}) {
      const std::vector<Point2> points = generator->generate(400, seed);
      const auto triangulation = Triangulate(points, CpuOptions());
      ASSERT_THAT(triangulation, IsOk());
      for (double density : {0.3, 0.5, 0.7, 0.9}) {
        SCOPED_TRACE(absl::StrCat(name, " seed ", seed, " density ", density));
        std::mt19937_64 rng(seed * 1000 + static_cast<uint64_t>(density * 10));
        std::bernoulli_distribution keep(density);
        std::vector<Tri> tris;
        std::set<uint32_t> covered;
        std::set<std::pair<uint32_t, uint32_t>> tri_edges;
        for (const Tri& t : triangulation->triangles) {
          if (!keep(rng)) continue;
          tris.push_back(t);
          for (int k = 0; k < 3; ++k) {
            covered.insert(t[k]);
            tri_edges.insert({std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])});
          }
        }
        // Some edges outside every kept triangle become singular; some untouched vertices isolated.
        std::vector<Edge> singular;
        std::bernoulli_distribution coin(0.3);
        for (const Edge& e : triangulation->edges) {
          if (!tri_edges.count({e[0], e[1]}) && coin(rng)) {
            singular.push_back(e);
            covered.insert(e[0]);
            covered.insert(e[1]);
          }
        }
        std::vector<uint32_t> isolated;
        for (const Edge& e : triangulation->edges) {
          for (uint32_t v : e) {
            if (!covered.count(v) && coin(rng)) isolated.push_back(v);
          }
        }
        CheckShape(points, tris, singular, isolated);
      }
    }
  }
}

TEST(AssembleShapeTest, WholeTriangulationIsOnePolygonWithoutHoles) {
  const std::vector<Point2> points = gen::Grid(900, 5);
  const auto triangulation = Triangulate(points, CpuOptions());
  ASSERT_THAT(triangulation, IsOk());
  CheckShape(points, triangulation->triangles, {}, {}, {1, 0});
}

}  // namespace
}  // namespace galpha
