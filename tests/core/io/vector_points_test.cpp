// GDAL vector sources written with GDAL's own API from known points (tests/support/
// vector_file_writer.hpp), read back with ReadVectorPoints: every double bit for bit, the layer
// chosen by name, the CRS, the limit and the refusals. Skipped, saying so, in a build without GDAL,
// where the refusal itself is tested.
#include "core/io/vector_points.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "tests/support/status_matchers.hpp"
#include "tests/support/vector_file_writer.hpp"

namespace galpha {
namespace {

using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using galpha::testing::VectorFeature;
using galpha::testing::VectorGeometry;
using galpha::testing::VectorLayer;
using galpha::testing::WriteVectorFile;
using ::testing::HasSubstr;

#define GALPHA_SKIP_WITHOUT_GDAL()                                                                       \
  if (!VectorPointsAvailable()) {                                                                        \
    GTEST_SKIP() << "built without GDAL (GALPHA_WITH_GDAL=OFF): Shapefiles, GeoPackages and FlatGeobuf " \
                    "files are refused (VectorPointsTest.RefusedByABuildWithoutGdal)";                   \
  }

uint64_t Bits(double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}

// Doubles that a decimal detour would change: thirds, neighbours of round numbers, UTM-sized values
// with full mantissas, a subnormal, a negative zero.
const std::vector<Point2> kAwkward = {
    {1.0 / 3.0, -2.0 / 3.0},
    {std::nextafter(637000.25, 1e9), std::nextafter(4500000.0, 0.0)},
    {0.1 + 0.2, 1e-310},
    {-0.0, 123456789.123456789},
    {-1e15 - 0.5, 9007199254740993.0},
};

std::string TempPath(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / absl::StrCat("vector_points_test_", getpid());
  std::filesystem::create_directories(dir);
  return dir / name;
}

class VectorPointsTest : public ::testing::Test {
 protected:
  void TearDown() override {
    std::filesystem::remove_all(std::filesystem::temp_directory_path() / absl::StrCat("vector_points_test_", getpid()));
  }
};

std::vector<VectorFeature> PointFeatures(const std::vector<Point2>& points) {
  std::vector<VectorFeature> features;
  features.reserve(points.size());
  for (const Point2& p : points) features.push_back({VectorGeometry::kPoint, {p}});
  return features;
}

void ExpectPoints(const absl::StatusOr<GeoreferencedPoints>& read, const std::vector<Point2>& want) {
  ASSERT_THAT(read, IsOk());
  ASSERT_EQ(read->points.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(Bits(read->points[i].x), Bits(want[i].x)) << "point " << i;
    EXPECT_EQ(Bits(read->points[i].y), Bits(want[i].y)) << "point " << i;
  }
}

TEST_F(VectorPointsTest, RefusedByABuildWithoutGdal) {
  if (VectorPointsAvailable()) GTEST_SKIP() << "built with GDAL: the refusal is for builds without it";
  EXPECT_THAT(ReadVectorPoints(TempPath("any.gpkg")),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("this build has no GDAL")));
}

TEST_F(VectorPointsTest, GeoPackageLayersPointsMultipointsAndTheCrs) {
  GALPHA_SKIP_WITHOUT_GDAL();
  VectorLayer sites{"sites", {}, "EPSG:32610"};
  sites.features = PointFeatures({kAwkward[0], kAwkward[1]});
  sites.features.push_back({VectorGeometry::kNone, {}});   // unlocated: skipped
  sites.features.push_back({VectorGeometry::kPoint, {}});  // POINT EMPTY: skipped
  sites.features.push_back({VectorGeometry::kMultiPoint, {kAwkward[2], kAwkward[3]}});
  sites.features.push_back({VectorGeometry::kPoint, {kAwkward[4]}});
  const VectorLayer other{"other", PointFeatures({{5, 6}, {7, 8}}), ""};
  const std::string path = TempPath("two_layers.gpkg");
  ASSERT_THAT(WriteVectorFile(path, "GPKG", {sites, other}), IsOk());

  const auto first = ReadVectorPoints(path);
  ExpectPoints(first, kAwkward);
  EXPECT_EQ(first->crs.value_or("none"), "EPSG:32610");
  const auto named = ReadVectorPoints(path, "other");
  ExpectPoints(named, {{5, 6}, {7, 8}});
  EXPECT_FALSE(named->crs.has_value()) << *named->crs;  // GeoPackage's "undefined geographic SRS"
  EXPECT_THAT(
      ReadVectorPoints(path, "roads"),
      StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("has no layer 'roads' (its layers: 'sites', 'other')")));
}

TEST_F(VectorPointsTest, ShapefilePointsAndMultipoints) {
  GALPHA_SKIP_WITHOUT_GDAL();
  const std::string points = TempPath("points.shp");
  ASSERT_THAT(WriteVectorFile(points, "ESRI Shapefile", {{"points", PointFeatures(kAwkward), "EPSG:4326"}}), IsOk());
  const auto read = ReadVectorPoints(points);
  ExpectPoints(read, kAwkward);
  EXPECT_TRUE(read->crs.has_value());  // EPSG:4326, or the WKT of the .prj where GDAL finds no code
  ExpectPoints(ReadVectorPoints(points, "points"), kAwkward);

  const std::string multi = TempPath("multi.shp");
  ASSERT_THAT(WriteVectorFile(multi, "ESRI Shapefile",
                              {{"multi",
                                {{VectorGeometry::kMultiPoint, {kAwkward[0], kAwkward[1], kAwkward[2]}},
                                 {VectorGeometry::kMultiPoint, {kAwkward[3], kAwkward[4]}}},
                                ""}}),
              IsOk());
  const auto read_multi = ReadVectorPoints(multi);
  ExpectPoints(read_multi, kAwkward);
  EXPECT_FALSE(read_multi->crs.has_value());
}

TEST_F(VectorPointsTest, FlatGeobufMixedPointsAndMultipoints) {
  GALPHA_SKIP_WITHOUT_GDAL();
  const std::string path = TempPath("mixed.fgb");
  ASSERT_THAT(WriteVectorFile(path, "FlatGeobuf",
                              {{"mixed",
                                {{VectorGeometry::kMultiPoint, {kAwkward[0], kAwkward[1]}},
                                 {VectorGeometry::kPoint, {kAwkward[2]}},
                                 {VectorGeometry::kMultiPoint, {kAwkward[3], kAwkward[4]}}},
                                "EPSG:3857"}}),
              IsOk());
  const auto read = ReadVectorPoints(path);
  ExpectPoints(read, kAwkward);
  EXPECT_EQ(read->crs.value_or("none"), "EPSG:3857");
}

TEST_F(VectorPointsTest, ACrsWithoutACodeIsCarriedAsWkt) {
  GALPHA_SKIP_WITHOUT_GDAL();
  const std::string path = TempPath("custom_crs.gpkg");
  ASSERT_THAT(WriteVectorFile(path, "GPKG",
                              {{"local", PointFeatures({{1, 2}}),
                                "+proj=tmerc +lat_0=0 +lon_0=10.5 +k=0.9996 +x_0=250000 +y_0=0 +ellps=GRS80 "
                                "+units=m +no_defs"}}),
              IsOk());
  const auto read = ReadVectorPoints(path);
  ASSERT_THAT(read, IsOk());
  ASSERT_TRUE(read->crs.has_value());
  EXPECT_NE(read->crs->find("Transverse Mercator"), std::string::npos) << *read->crs;
  EXPECT_NE(read->crs->find("10.5"), std::string::npos) << *read->crs;
}

TEST_F(VectorPointsTest, OtherGeometriesAreRefusedNamingTheFeature) {
  GALPHA_SKIP_WITHOUT_GDAL();
  const std::string path = TempPath("line.gpkg");
  ASSERT_THAT(
      WriteVectorFile(
          path, "GPKG",
          {{"mixed", {{VectorGeometry::kPoint, {{0, 0}}}, {VectorGeometry::kLineString, {{0, 0}, {1, 1}}}}, ""}}),
      IsOk());
  EXPECT_THAT(ReadVectorPoints(path),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       HasSubstr(absl::StrCat("points file '", path,
                                              "', layer 'mixed': feature 2 is a Line String; only points and "
                                              "multipoints are read"))));
}

TEST_F(VectorPointsTest, MaxPointsStopsTheRead) {
  GALPHA_SKIP_WITHOUT_GDAL();
  const std::string path = TempPath("five.fgb");
  ASSERT_THAT(WriteVectorFile(path, "FlatGeobuf",
                              {{"five",
                                {{VectorGeometry::kMultiPoint, {kAwkward[0], kAwkward[1], kAwkward[2]}},
                                 {VectorGeometry::kMultiPoint, {kAwkward[3], kAwkward[4]}}},
                                ""}}),
              IsOk());
  ExpectPoints(ReadVectorPoints(path, "", 5), kAwkward);
  EXPECT_THAT(
      ReadVectorPoints(path, "", 4),
      StatusIs(absl::StatusCode::kResourceExhausted,
               HasSubstr(absl::StrCat("points file '", path, "', layer 'five': more than 4 points, the limit"))));
  EXPECT_THAT(ReadVectorPoints(path, "", 2), StatusIs(absl::StatusCode::kResourceExhausted));
}

TEST_F(VectorPointsTest, FilesThatAreNotWhatTheirNameSays) {
  GALPHA_SKIP_WITHOUT_GDAL();
  const std::string garbage = TempPath("garbage.gpkg");
  std::ofstream(garbage) << "x,y\n1,2\n";
  EXPECT_THAT(ReadVectorPoints(garbage),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       HasSubstr(absl::StrCat("cannot open points file '", garbage, "' as GPKG"))));
  EXPECT_THAT(ReadVectorPoints(TempPath("missing.fgb")),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("as FlatGeobuf")));
  EXPECT_THAT(ReadVectorPoints(TempPath("points.csv")),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("not a Shapefile, GeoPackage or FlatGeobuf")));
}

}  // namespace
}  // namespace galpha
