// The shapes of the alpha family, checked by GEOS: valid, with the interior triangles' area, one
// polygon per solid component, equal to GEOS's union of the triangles, with the singular edges and
// isolated points the classes name.
#include <geos_c.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <vector>

#include "absl/types/span.h"
#include "core/family/alpha_family.hpp"
#include "core/geometry/shape.hpp"
#include "core/io/point_formats.hpp"
#include "gtest/gtest.h"
#include "tests/gpu/alpha/alpha_family_fixture.hpp"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/data_files.hpp"
#include "tests/support/geos.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::Case;
using testing::Edge;
using testing::Geos;
using testing::IsOk;
using testing::Tri;

// Edge-connected pieces of a set of triangles (union-find over shared edges).
size_t EdgeConnectedPieces(const std::vector<Tri>& tris) {
  std::vector<uint32_t> parent(tris.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::map<Edge, uint32_t> first;
  size_t pieces = tris.size();
  for (uint32_t t = 0; t < tris.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = tris[t][k], b = tris[t][(k + 1) % 3];
      const auto [it, inserted] = first.emplace(Edge{std::min(a, b), std::max(a, b)}, t);
      if (inserted) continue;
      const uint32_t x = find(it->second), y = find(t);
      if (x != y) {
        parent[x] = y;
        --pieces;
      }
    }
  }
  return pieces;
}

void CheckShapeAt(const Geos& geos, const AlphaFamily& f, int64_t level) {
  SCOPED_TRACE(::testing::Message() << "level " << level << " of " << f.max_level());
  const absl::Span<const Point2> points = f.points();
  // What the classes say is in, independently of ComplexAt.
  const Classification classes = f.ClassifyAll(level, ClassifyMode::kGeneral, VertexRule::kReport);
  std::vector<Tri> interior;
  double area = 0.0;
  for (uint32_t t = 0; t < f.triangles().size(); ++t) {
    if (classes.triangles[t] != SimplexClass::kInterior) continue;
    const Tri& tr = f.triangles()[t];
    interior.push_back(tr);
    const Point2 a = points[tr[0]], b = points[tr[1]], c = points[tr[2]];
    area += 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
  }
  std::vector<Edge> singular;
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    if (classes.edges[e] == SimplexClass::kSingular) singular.push_back(f.edges()[e]);
  }
  std::vector<uint32_t> isolated;
  for (uint32_t v = 0; v < points.size(); ++v) {
    if (f.representative()[v] == v && classes.vertices[v] == SimplexClass::kSingular) isolated.push_back(v);
  }
  const size_t pieces = EdgeConnectedPieces(interior);
  ASSERT_EQ(f.SolidComponents(level), pieces);

  std::string general_wkt;
  for (ClassifyMode mode : {ClassifyMode::kGeneral, ClassifyMode::kRegularized}) {
    const bool general = mode == ClassifyMode::kGeneral;
    SCOPED_TRACE(general ? "GENERAL" : "REGULARIZED");
    const ShapeComplex complex = f.ComplexAt(level, mode);
    std::vector<Tri> got_tris = complex.triangles, want_tris = interior;
    std::sort(got_tris.begin(), got_tris.end());
    std::sort(want_tris.begin(), want_tris.end());
    ASSERT_EQ(got_tris, want_tris);
    const absl::StatusOr<ShapeGeometry> shape = AssembleShape(complex);
    ASSERT_THAT(shape, IsOk());
    ASSERT_EQ(shape->polygons.size(), pieces);
    EXPECT_NEAR(shape->area, area, 1e-9 * std::abs(area));
    std::vector<Edge> want_singular = general ? singular : std::vector<Edge>{};
    std::sort(want_singular.begin(), want_singular.end());
    ASSERT_EQ(shape->singular_edges, want_singular);
    ASSERT_EQ(shape->isolated_points, general ? isolated : std::vector<uint32_t>{});
    if (!general) {
      // REGULARIZED shapes are polygons alone: a POLYGON, or a MULTIPOLYGON (EMPTY for none).
      const Geos::Geom polygonal = geos.ReadWkt(ShapeToWkt(*shape, points));
      ASSERT_NE(polygonal, nullptr);
      EXPECT_EQ(GEOSGeomTypeId_r(geos.ctx(), polygonal.get()), pieces == 1 ? GEOS_POLYGON : GEOS_MULTIPOLYGON);
      continue;
    }

    const std::string wkt = ShapeToWkt(*shape, points);
    const Geos::Geom collection = geos.ReadWkt(wkt);
    ASSERT_NE(collection, nullptr);
    // Polygons alone are a POLYGON or MULTIPOLYGON (GEOS counts a single geometry as its own only
    // part); with singular edges or isolated points, a collection whose first part is a MULTIPOLYGON.
    const bool polygons_only = singular.empty() && isolated.empty();
    int part = 0;
    if (polygons_only) {
      ASSERT_EQ(GEOSGeomTypeId_r(geos.ctx(), collection.get()), pieces == 1 ? GEOS_POLYGON : GEOS_MULTIPOLYGON);
    } else {
      ASSERT_EQ(GEOSGeomTypeId_r(geos.ctx(), collection.get()), GEOS_GEOMETRYCOLLECTION);
    }
    if (!shape->polygons.empty()) {
      const GEOSGeometry* multi =
          polygons_only ? collection.get() : GEOSGetGeometryN_r(geos.ctx(), collection.get(), part++);
      if (!polygons_only) {
        ASSERT_EQ(GEOSGeomTypeId_r(geos.ctx(), multi), GEOS_MULTIPOLYGON);
      }
      EXPECT_EQ(GEOSisValid_r(geos.ctx(), multi), 1) << geos.ValidReason(multi);
      EXPECT_EQ(GEOSGetNumGeometries_r(geos.ctx(), multi), static_cast<int>(pieces));
      double geos_area = 0.0;
      GEOSArea_r(geos.ctx(), multi, &geos_area);
      EXPECT_NEAR(geos_area, area, 1e-9 * std::abs(area));
      const Geos::Geom merged = geos.UnionOfTriangles(points, interior);
      ASSERT_NE(merged, nullptr);
      EXPECT_EQ(GEOSEquals_r(geos.ctx(), multi, merged.get()), 1);
    } else {
      EXPECT_EQ(pieces, 0u);
    }
    if (!shape->singular_edges.empty()) {
      const GEOSGeometry* lines = GEOSGetGeometryN_r(geos.ctx(), collection.get(), part++);
      ASSERT_EQ(GEOSGeomTypeId_r(geos.ctx(), lines), GEOS_MULTILINESTRING);
      EXPECT_EQ(GEOSGetNumGeometries_r(geos.ctx(), lines), static_cast<int>(singular.size()));
    }
    if (!shape->isolated_points.empty()) {
      const GEOSGeometry* multipoint = GEOSGetGeometryN_r(geos.ctx(), collection.get(), part++);
      ASSERT_EQ(GEOSGeomTypeId_r(geos.ctx(), multipoint), GEOS_MULTIPOINT);
      EXPECT_EQ(GEOSGetNumGeometries_r(geos.ctx(), multipoint), static_cast<int>(isolated.size()));
    }
    if (!polygons_only) {
      EXPECT_EQ(GEOSGetNumGeometries_r(geos.ctx(), collection.get()), part);
    }
  }
}

void CheckShapes(const AlphaFamily& f) {
  const Geos geos;
  const int64_t k = f.max_level();
  constexpr int64_t kLevels = 8;
  std::set<int64_t> levels = {0, k};
  for (int64_t i = 1; i < kLevels; ++i) levels.insert(k * i / kLevels);
  // Where the shape is richest: just before every point is covered, and the optimal levels.
  if (f.SolidLevel()) levels.insert(std::max<int64_t>(0, *f.SolidLevel() - 1));
  if (f.OptimalLevelGeneral(1)) levels.insert(*f.OptimalLevelGeneral(1));
  for (int64_t level : levels) {
    CheckShapeAt(geos, f, level);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

using ShapesTest = testing::AlphaFamilyTest;

TEST_P(ShapesTest, GeneratedInputs) {
  const std::vector<Case> cases = {
      {"uniform", gen::Uniform(2000, 41)}, {"grid", gen::Grid(1600, 42)}, {"clustered", gen::Clustered(2000, 43)}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    absl::StatusOr<AlphaFamily> built = Build(c.points);
    ASSERT_THAT(built, IsOk());
    CheckShapes(*built);
    if (HasFatalFailure()) return;
  }
}

TEST_P(ShapesTest, RealDataSet) {
  const std::vector<std::string> files = testdata::PointFiles();
  ASSERT_FALSE(files.empty());
  // The GPS tracks: thin traces far apart, in degrees (the smallest real set).
  std::string file = files.front();
  for (const std::string& candidate : files) {
    if (candidate.find("gps_tracks") != std::string::npos) file = candidate;
  }
  SCOPED_TRACE(file);
  absl::StatusOr<std::vector<Point2>> points = ReadPointsFile(file);
  ASSERT_THAT(points, IsOk());
  absl::StatusOr<AlphaFamily> built = Build(*points);
  ASSERT_THAT(built, IsOk());
  CheckShapes(*built);
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(ShapesTest);

}  // namespace
}  // namespace galpha
