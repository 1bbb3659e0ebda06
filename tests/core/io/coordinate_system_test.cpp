// Coordinate reference systems against independent references: PROJ's geodesics (GeographicLib's
// algorithm, geodesic.h) for the local projection's distances, values computed with pyproj for the
// transformation to WGS84, and inverse transformations for round trips. Skipped without PROJ.
#include "core/io/coordinate_system.hpp"

#include <gtest/gtest.h>

#ifdef GALPHA_WITH_PROJ
#include <geodesic.h>
#endif

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using ::testing::HasSubstr;
using testing::IsOk;
using testing::StatusIs;

#ifdef GALPHA_WITH_PROJ

/// Geodesic distance in metres on WGS84 (GeographicLib's algorithm as PROJ ships it).
double GeodesicMetres(double lat1, double lon1, double lat2, double lon2) {
  geod_geodesic g{};
  geod_init(&g, 6378137.0, 1 / 298.257223563);
  double s12 = 0, azi1 = 0, azi2 = 0;
  geod_inverse(&g, lat1, lon1, lat2, lon2, &s12, &azi1, &azi2);
  return s12;
}

TEST(CoordinateSystemTest, DescribesHorizontalCrss) {
  absl::StatusOr<CrsInfo> wgs84 = DescribeCrs("EPSG:4326");
  ASSERT_THAT(wgs84, IsOk());
  EXPECT_TRUE(wgs84->geographic);
  EXPECT_EQ(wgs84->id, "EPSG:4326");
  EXPECT_EQ(wgs84->name, "WGS 84");
  absl::StatusOr<CrsInfo> utm = DescribeCrs("EPSG:32610");
  ASSERT_THAT(utm, IsOk());
  EXPECT_FALSE(utm->geographic);
  EXPECT_EQ(utm->name, "WGS 84 / UTM zone 10N");
  // A compound CRS (LAS files state horizontal + vertical) and a 3D geographic one.
  absl::StatusOr<CrsInfo> compound = DescribeCrs("EPSG:32610+5703");
  ASSERT_THAT(compound, IsOk());
  EXPECT_FALSE(compound->geographic);
  EXPECT_EQ(compound->name, "WGS 84 / UTM zone 10N");
  absl::StatusOr<CrsInfo> three_d = DescribeCrs("EPSG:4979");
  ASSERT_THAT(three_d, IsOk());
  EXPECT_TRUE(three_d->geographic);

  EXPECT_THAT(DescribeCrs("EPSG:4978"), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("geocentric")));
  EXPECT_THAT(DescribeCrs("not a crs"), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("not understood")));
  EXPECT_THAT(DescribeCrs("+proj=merc"), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("not a CRS")));
}

/// Random points in a box of longitudes and latitudes (degrees).
std::vector<Point2> LonLatBox(double lon0, double lon1, double lat0, double lat1, int n, uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> lon(lon0, lon1), lat(lat0, lat1);
  std::vector<Point2> points(static_cast<size_t>(n));
  for (Point2& p : points) p = {lon(random), lat(random)};
  return points;
}

/// The local projection is azimuthal equidistant: a point's distance from the projection's
/// origin is its geodesic distance from the centre. The centre is where (0, 0) maps back to.
void ExpectEquidistant(const std::vector<Point2>& lonlat, const LocalMetres& local, double centre_lat,
                       double centre_lon) {
  ASSERT_EQ(local.points.size(), lonlat.size());
  for (size_t i = 0; i < lonlat.size(); ++i) {
    const double expected = GeodesicMetres(centre_lat, centre_lon, lonlat[i].y, lonlat[i].x);
    EXPECT_NEAR(std::hypot(local.points[i].x, local.points[i].y), expected, 1e-3) << i;
  }
}

TEST(CoordinateSystemTest, GeographicSetsAreProjectedAboutTheirCentre) {
  absl::StatusOr<CrsInfo> wgs84 = DescribeCrs("EPSG:4326");
  ASSERT_THAT(wgs84, IsOk());
  // Around Autzen (Oregon): the centre is the middle of the box.
  const std::vector<Point2> autzen = LonLatBox(-123.2, -122.8, 43.9, 44.3, 500, 1);
  absl::StatusOr<LocalMetres> local = ProjectToLocalMetres(*wgs84, autzen);
  ASSERT_THAT(local, IsOk());
  double lon_min = 180, lon_max = -180, lat_min = 90, lat_max = -90;
  for (const Point2& p : autzen) {
    lon_min = std::min(lon_min, p.x), lon_max = std::max(lon_max, p.x);
    lat_min = std::min(lat_min, p.y), lat_max = std::max(lat_max, p.y);
  }
  ExpectEquidistant(autzen, *local, (lat_min + lat_max) / 2, (lon_min + lon_max) / 2);
  EXPECT_NE(local->projection.find("+proj=aeqd"), std::string::npos) << local->projection;
  EXPECT_LT(local->radius_degrees, 0.3);
  // Pairwise distances (what alpha measures) are geodesic ones within the projection's scale error.
  for (size_t i = 1; i < autzen.size(); i += 7) {
    const double metres =
        std::hypot(local->points[i].x - local->points[i - 1].x, local->points[i].y - local->points[i - 1].y);
    const double geodesic = GeodesicMetres(autzen[i - 1].y, autzen[i - 1].x, autzen[i].y, autzen[i].x);
    EXPECT_NEAR(metres, geodesic, 1e-4 * geodesic) << i;
  }

  // Across the antimeridian (Fiji): centred on it, neighbours across it stay neighbours.
  // (The extreme corners fix the centre: the middle of the latitudes and of the longitude arc.)
  std::vector<Point2> fiji = LonLatBox(179.5, 180.0, -17.5, -16.5, 200, 2);
  for (const Point2& p : LonLatBox(-180.0, -179.5, -17.5, -16.5, 200, 3)) fiji.push_back(p);
  fiji.push_back({179.5, -17.5});
  fiji.push_back({-179.5, -16.5});
  local = ProjectToLocalMetres(*wgs84, fiji);
  ASSERT_THAT(local, IsOk());
  EXPECT_LT(local->radius_degrees, 1.0);
  ExpectEquidistant(fiji, *local, -17.0, 180.0);

  // Around the north pole: every longitude, centred on the pole.
  const std::vector<Point2> arctic = LonLatBox(-180.0, 180.0, 80.0, 89.0, 300, 4);
  local = ProjectToLocalMetres(*wgs84, arctic);
  ASSERT_THAT(local, IsOk());
  ExpectEquidistant(arctic, *local, 90.0, 0.0);
  EXPECT_LE(local->radius_degrees, 10.0);
}

TEST(CoordinateSystemTest, WhatCannotBeProjectedIsRefused) {
  absl::StatusOr<CrsInfo> wgs84 = DescribeCrs("EPSG:4326");
  ASSERT_THAT(wgs84, IsOk());
  const std::vector<Point2> planar = {{10, 20}, {500000, 4000000}};
  EXPECT_THAT(ProjectToLocalMetres(*wgs84, planar),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("point 1 (5e+05, 4e+06) is not a longitude")));
  const std::vector<Point2> world = LonLatBox(-180.0, 180.0, -60.0, 60.0, 100, 5);
  EXPECT_THAT(ProjectToLocalMetres(*wgs84, world),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("both hemispheres")));
  absl::StatusOr<CrsInfo> utm = DescribeCrs("EPSG:32610");
  ASSERT_THAT(utm, IsOk());
  EXPECT_THAT(ProjectToLocalMetres(*utm, planar), StatusIs(absl::StatusCode::kInvalidArgument));
}

TEST(CoordinateSystemTest, ToWgs84LonLat) {
  absl::StatusOr<CrsInfo> wgs84 = DescribeCrs("EPSG:4326");
  ASSERT_THAT(wgs84, IsOk());
  const std::vector<Point2> lonlat = {{-123.1, 44.1}, {0.1, 0.2}, {179.99999999999997, -89.5}};
  absl::StatusOr<std::vector<Point2>> same = ToWgs84LonLat(*wgs84, lonlat);
  ASSERT_THAT(same, IsOk());
  for (size_t i = 0; i < lonlat.size(); ++i) {
    EXPECT_EQ((*same)[i].x, lonlat[i].x);  // bit for bit: no round trip through PROJ
    EXPECT_EQ((*same)[i].y, lonlat[i].y);
  }
  // UTM 10N to WGS84: pyproj's values (Transformer.from_crs("EPSG:32610", "OGC:CRS84")).
  absl::StatusOr<CrsInfo> utm = DescribeCrs("EPSG:32610");
  ASSERT_THAT(utm, IsOk());
  absl::StatusOr<std::vector<Point2>> converted = ToWgs84LonLat(*utm, {{500000, 5000000}, {636000, 4902000}});
  ASSERT_THAT(converted, IsOk());
  EXPECT_NEAR((*converted)[0].x, -123.00000000000001, 1e-9);
  EXPECT_NEAR((*converted)[0].y, 45.153477183356024, 1e-9);
  EXPECT_NEAR((*converted)[1].x, -121.29628312270205, 1e-9);
  EXPECT_NEAR((*converted)[1].y, 44.258537031002064, 1e-9);
}

#else

TEST(CoordinateSystemTest, RefusedWithoutProj) {
  EXPECT_THAT(DescribeCrs("EPSG:4326"), StatusIs(absl::StatusCode::kFailedPrecondition, HasSubstr("GALPHA_WITH_PROJ")));
}

#endif

}  // namespace
}  // namespace galpha
