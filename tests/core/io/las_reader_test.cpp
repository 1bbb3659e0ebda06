// LAS point clouds written byte by byte (tests/support/las_bytes.hpp), read back with
// ReadLasPoints: formats 0, 1, 3 and 6, versions 1.0 to 1.4, the WKT of the CRS from a VLR or an
// EVLR, the coordinates checked bit for bit against offset + scale * X computed independently in
// binary128 (exact products and sums, rounded once each), and every refusal with its message.
#include "core/io/las_reader.hpp"

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
#include "core/base/scaled_coordinate.hpp"
#include "core/io/point_formats.hpp"
#include "tests/support/las_bytes.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using galpha::testing::IsOk;
using galpha::testing::LasFileBytes;
using galpha::testing::LasGeoKeysRecord;
using galpha::testing::LasRecord;
using galpha::testing::LasSpec;
using galpha::testing::LasWktRecord;
using galpha::testing::StatusIs;
using ::testing::HasSubstr;

uint64_t Bits(double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}

// offset + scale * X rounded twice, computed without the code under test: in binary128 the product
// of a 53-bit scale and a 32-bit X is exact, so converting it to double rounds it once, correctly;
// the sum of two doubles is exact in binary128 when their exponents are close (checked), so its
// conversion is the correctly rounded sum.
double TwoRoundings(double offset, double scale, int32_t x) {
  const __float128 exact_product = static_cast<__float128>(scale) * x;
  const double product = static_cast<double>(exact_product);
  const __float128 exact_sum = static_cast<__float128>(offset) + product;
  EXPECT_TRUE(exact_sum - offset == product) << "the sum is not exact in binary128: pick closer values";
  return static_cast<double>(exact_sum);
}

std::string WriteLas(const std::string& name, const std::string& bytes) {
  std::string path = std::filesystem::temp_directory_path() / absl::StrCat("las_reader_test_", getpid(), "_", name);
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

absl::StatusOr<GeoreferencedPoints> Read(const std::string& name, const LasSpec& spec,
                                         uint64_t max_points = std::numeric_limits<uint64_t>::max()) {
  const std::string path = WriteLas(name, LasFileBytes(spec));
  absl::StatusOr<GeoreferencedPoints> read = ReadLasPoints(path, max_points);
  std::filesystem::remove(path);
  return read;
}

void ExpectExact(const absl::StatusOr<GeoreferencedPoints>& read, const LasSpec& spec) {
  ASSERT_THAT(read, IsOk());
  ASSERT_EQ(read->points.size(), spec.xy.size());
  for (size_t i = 0; i < spec.xy.size(); ++i) {
    SCOPED_TRACE(absl::StrCat("point ", i, ": X ", spec.xy[i].first, ", Y ", spec.xy[i].second));
    EXPECT_EQ(Bits(read->points[i].x), Bits(TwoRoundings(spec.offset[0], spec.scale[0], spec.xy[i].first)));
    EXPECT_EQ(Bits(read->points[i].y), Bits(TwoRoundings(spec.offset[1], spec.scale[1], spec.xy[i].second)));
  }
}

// Integers at the edges of int32 and around zero.
const std::vector<std::pair<int32_t, int32_t>> kEdgeIntegers = {
    {0, 0}, {1, -1}, {-2147483647 - 1, 2147483647}, {123456789, -987654321}, {3, 7}, {-3, 100000}};

TEST(ScaledCoordinate, IsNeverFused) {
  // scale 0.1, X 3, offset -0.3: the product rounds to 0.30000000000000004 first, so two roundings
  // give 2^-54 and one fused rounding another value.
  ASSERT_NE(TwoRoundings(-0.3, 0.1, 3), std::fma(0.1, 3.0, -0.3));
  EXPECT_EQ(Bits(ScaledCoordinate(-0.3, 0.1, 3)), Bits(TwoRoundings(-0.3, 0.1, 3)));
  EXPECT_EQ(ScaledCoordinate(-0.3, 0.1, 3), 5.551115123125783e-17);
}

TEST(LasReaderTest, Format0Las12WithoutCrs) {
  LasSpec spec;
  spec.minor = 2;
  spec.format = 0;
  spec.scale[0] = 0.01;
  spec.scale[1] = 0.001;
  spec.offset[0] = 637000.0;
  spec.offset[1] = 849000.0;
  spec.xy = kEdgeIntegers;
  const auto read = Read("f0.las", spec);
  ExpectExact(read, spec);
  EXPECT_FALSE(read->crs.has_value());
  EXPECT_EQ(read->points[4].x, 637000.03);  // a value worked by hand: 0.03 then 637000.03
}

TEST(LasReaderTest, Format1Las10AndTheFusedCase) {
  LasSpec spec;
  spec.minor = 0;
  spec.format = 1;
  spec.scale[0] = 0.1;
  spec.scale[1] = 0.1;
  spec.offset[0] = -0.3;
  spec.offset[1] = 0.5;
  spec.xy = {{3, 3}, {-7, 11}, {1000000, -1000000}};
  const auto read = Read("f1.las", spec);
  ExpectExact(read, spec);
  EXPECT_EQ(read->points[0].x, 5.551115123125783e-17);
}

TEST(LasReaderTest, Format3Las12WithAWktVlrAfterAnotherVlr) {
  LasSpec spec;
  spec.minor = 2;
  spec.format = 3;
  spec.scale[0] = spec.scale[1] = 0.25;
  spec.offset[0] = 500000.0;
  spec.offset[1] = 4000000.0;
  spec.xy = kEdgeIntegers;
  const std::string wkt = "PROJCS[\"NAD83 / UTM zone 10N\",GEOGCS[\"NAD83\"],AUTHORITY[\"EPSG\",\"26910\"]]";
  spec.vlrs = {LasRecord{"LASF_Projection", 34735, std::string(16, '\1')}, LasRecord{"other", 2112, "not this"},
               LasWktRecord(wkt), LasWktRecord("a second one is ignored")};
  const auto read = Read("f3.las", spec);
  ExpectExact(read, spec);
  ASSERT_TRUE(read->crs.has_value());
  EXPECT_EQ(*read->crs, wkt);
}

// GeoTIFF keys (record 34735) name the CRS by EPSG code where no WKT record does; the codes and
// model types are GeoTIFF 1.0's (1024 model: 1 projected, 2 geographic; 2048 geographic; 3072
// projected; 32767 user-defined).
TEST(LasReaderTest, GeoTiffKeysGiveAnEpsgCode) {
  LasSpec spec;
  spec.xy = kEdgeIntegers;
  const auto crs_of = [&](const std::vector<LasRecord>& vlrs, const std::string& name) {
    spec.vlrs = vlrs;
    const auto read = Read(name, spec);
    EXPECT_TRUE(read.ok()) << read.status();
    return read.ok() ? read->crs.value_or("(none)") : "(error)";
  };
  // NAD83 / UTM 10N on NAD83, as LAStools writes it (with a key stored elsewhere, skipped).
  EXPECT_EQ(crs_of({LasGeoKeysRecord({{1024, 0, 1, 1},
                                      {1025, 0, 1, 1},
                                      {2048, 0, 1, 4269},
                                      {3072, 0, 1, 26910},
                                      {3076, 0, 1, 9001},
                                      {4099, 34736, 1, 0}})},
                   "projected.las"),
            "EPSG:26910");
  EXPECT_EQ(crs_of({LasGeoKeysRecord({{1024, 0, 1, 2}, {2048, 0, 1, 4326}})}, "geographic.las"), "EPSG:4326");
  // No model type: the projected code if there is one, else the geographic one.
  EXPECT_EQ(crs_of({LasGeoKeysRecord({{2048, 0, 1, 4326}})}, "bare.las"), "EPSG:4326");
  // A user-defined projection is not its geographic base (the coordinates are not degrees).
  EXPECT_EQ(crs_of({LasGeoKeysRecord({{1024, 0, 1, 1}, {2048, 0, 1, 4269}, {3072, 0, 1, 32767}})}, "user.las"),
            "(none)");
  EXPECT_EQ(crs_of({LasGeoKeysRecord({{1024, 0, 1, 2}, {2048, 0, 1, 32767}})}, "user_geo.las"), "(none)");
  // Malformed directories name nothing: another version, keys past the record's end.
  EXPECT_EQ(crs_of({LasGeoKeysRecord({{3072, 0, 1, 26910}}, /*version=*/2)}, "version.las"), "(none)");
  LasRecord cut = LasGeoKeysRecord({{3072, 0, 1, 26910}});
  cut.body.resize(cut.body.size() - 2);
  EXPECT_EQ(crs_of({cut}, "cut.las"), "(none)");
  // A WKT record wins, before or after the keys.
  const std::string wkt = "PROJCS[\"NAD83 / UTM zone 11N\"]";
  EXPECT_EQ(crs_of({LasGeoKeysRecord({{3072, 0, 1, 26910}}), LasWktRecord(wkt)}, "both.las"), wkt);
  EXPECT_EQ(crs_of({LasWktRecord(wkt), LasGeoKeysRecord({{3072, 0, 1, 26910}})}, "both2.las"), wkt);
}

TEST(LasReaderTest, Format6Las14With64BitCountsAndAWktEvlr) {
  LasSpec spec;
  spec.minor = 4;
  spec.format = 6;
  spec.record_length = 30 + 4;  // extra bytes after the format's fields
  spec.scale[0] = 0.001;
  spec.scale[1] = 1e-7;
  spec.offset[0] = -1234.5;
  spec.offset[1] = 45.0;
  spec.xy = kEdgeIntegers;
  spec.evlrs = {LasRecord{"LASF_Spec", 65535, std::string(100, 'w')}, LasWktRecord("GEOGCRS[\"WGS 84\"]")};
  const auto read = Read("f6.las", spec);
  ExpectExact(read, spec);
  ASSERT_TRUE(read->crs.has_value());
  EXPECT_EQ(*read->crs, "GEOGCRS[\"WGS 84\"]");

  // The same with the WKT in a VLR, and a legacy count that agrees (allowed for formats 0-5).
  LasSpec in_vlr = spec;
  in_vlr.evlrs.clear();
  in_vlr.vlrs = {LasWktRecord("COMPD_CS[\"x\"]")};
  const auto read_vlr = Read("f6vlr.las", in_vlr);
  ExpectExact(read_vlr, in_vlr);
  EXPECT_EQ(read_vlr->crs.value_or(""), "COMPD_CS[\"x\"]");

  LasSpec format1 = spec;
  format1.format = 1;
  format1.record_length = -1;
  format1.legacy_count = static_cast<int64_t>(spec.xy.size());
  ExpectExact(Read("f1_14.las", format1), format1);
  // A 1.4 file whose writer left the 64-bit count at zero: the legacy count is used.
  format1.count64 = 0;
  ExpectExact(Read("f1_14_legacy.las", format1), format1);
}

TEST(LasReaderTest, ReadsInChunksAndKeepsTheOrder) {
  // 70,000 records of 20 bytes: 1.4 MB, more than one 1 MiB chunk.
  LasSpec spec;
  spec.format = 0;
  spec.scale[0] = 0.01;
  spec.scale[1] = 0.02;
  spec.offset[0] = 10.0;
  for (int32_t i = 0; i < 70000; ++i) spec.xy.emplace_back(i * 7919 - 250000000, -i);
  ExpectExact(Read("many.las", spec), spec);
  EXPECT_EQ(Read("many.las", spec, 70000)->points.size(), 70000u);
}

TEST(LasReaderTest, EmptyCloud) {
  LasSpec spec;
  const auto read = Read("empty.las", spec);
  ASSERT_THAT(read, IsOk());
  EXPECT_TRUE(read->points.empty());
}

void ExpectRefused(const std::string& name, const LasSpec& spec, absl::StatusCode code, const std::string& needle) {
  SCOPED_TRACE(name);
  EXPECT_THAT(Read(name, spec), StatusIs(code, HasSubstr(needle)));
}

TEST(LasReaderTest, RefusesWhatIsNotAnUncompressedLasFile) {
  const auto kInvalid = absl::StatusCode::kInvalidArgument;
  const auto kDataLoss = absl::StatusCode::kDataLoss;
  LasSpec good;
  good.xy = kEdgeIntegers;

  LasSpec spec = good;
  spec.format_byte = 0x80 | 3;
  ExpectRefused("laz_bit7.las", spec, kInvalid, "compressed (LAZ: point data record format byte 131");
  spec.format_byte = 0x40 | 1;
  ExpectRefused("laz_bit6.las", spec, kInvalid, "compressed (LAZ");
  spec = good;
  spec.vlrs = {LasRecord{"laszip encoded", 22204, std::string(34, '\0')}};
  ExpectRefused("laz_vlr.las", spec, kInvalid, "compressed (LAZ: it has a LASzip record)");

  spec = good;
  spec.major = 2;
  ExpectRefused("v20.las", spec, kInvalid, "LAS version 2.2: 1.0 to 1.4 are read");
  spec = good;
  spec.minor = 5;
  ExpectRefused("v15.las", spec, kInvalid, "LAS version 1.5");
  spec = good;
  spec.minor = 4;
  spec.header_size = 235;
  ExpectRefused("small14.las", spec, kInvalid, "the header size is 235 bytes, fewer than LAS 1.4's 375");
  spec = good;
  spec.format = 11;
  spec.record_length = 40;
  ExpectRefused("f11.las", spec, kInvalid, "point data record format 11 is not defined");
  spec = good;
  spec.format = 6;
  ExpectRefused("f6in12.las", spec, kInvalid, "point data record format 6 needs LAS 1.4; the file is LAS 1.2");
  spec = good;
  spec.format = 3;
  spec.record_length = 28;
  ExpectRefused("short_record.las", spec, kInvalid,
                "the point data record length is 28 bytes, fewer than the 34 that point data record format 3 needs");
  spec = good;
  spec.scale[0] = 0.0;
  ExpectRefused("zero_scale.las", spec, kInvalid, "the x scale factor is 0: it must be finite and nonzero");
  spec = good;
  spec.scale[1] = std::numeric_limits<double>::quiet_NaN();
  ExpectRefused("nan_scale.las", spec, kInvalid, "the y scale factor is nan");
  spec = good;
  spec.offset[0] = std::numeric_limits<double>::infinity();
  ExpectRefused("inf_offset.las", spec, kInvalid, "the x offset is inf: it must be finite");
  spec = good;
  spec.minor = 4;
  spec.format = 1;
  spec.legacy_count = 5;
  ExpectRefused("counts.las", spec, kInvalid, "the legacy point count (5) and the 64-bit point count (6) disagree");
  spec = good;
  spec.point_data_offset = 100;
  ExpectRefused("inside_header.las", spec, kInvalid, "the point data starts at byte 100, inside the 227-byte header");
  spec = good;
  spec.vlrs = {LasWktRecord("PROJCS[]")};
  spec.point_data_offset = 227 + 54 + 4;
  ExpectRefused("vlr_past_points.las", spec, kInvalid,
                "variable length record 0 of 1 (at byte 227, 65 bytes) runs past the start of the point data at "
                "byte 285");
  spec = good;
  spec.vlrs = {LasWktRecord("PROJCS[]")};
  spec.point_data_offset = 227 + 20;
  ExpectRefused("vlr_header_past_points.las", spec, kInvalid, "variable length record 0 of 1 (at byte 227) runs past");

  // Truncated files.
  spec = good;
  spec.drop_tail = 1;
  ExpectRefused("truncated.las", spec, kDataLoss,
                "is truncated: its header says 6 points of 20 bytes from byte 227, but it has 346 bytes, room for 5");
  spec = good;
  spec.legacy_count = 1000000000;
  ExpectRefused("huge_count.las", spec, kDataLoss, "its header says 1000000000 points of 20 bytes");
  spec = good;
  spec.minor = 4;
  spec.format = 6;
  spec.count64 = int64_t{1} << 62;
  ExpectRefused("huge_count64.las", spec, kDataLoss, "its header says 4611686018427387904 points");
  spec = good;
  spec.xy.clear();
  spec.drop_tail = 27;
  ExpectRefused("short_header.las", spec, kDataLoss, "is truncated: 200 bytes, fewer than the 227-byte LAS header");
  spec = good;
  spec.xy.clear();
  spec.point_data_offset = 400;
  spec.drop_tail = 400 - 227;
  ExpectRefused("points_past_end.las", spec, kDataLoss,
                "is truncated: 227 bytes, but its point data starts at byte 400");
  spec = good;
  spec.minor = 4;
  spec.evlrs = {LasWktRecord("GEOGCRS[]")};
  spec.drop_tail = 3;
  ExpectRefused("evlr_truncated.las", spec, kDataLoss, "extended variable length record 0 of 1 (at byte 495, 12 bytes");
  spec.drop_tail = 0;
  spec.evlr_start = 1 << 20;
  ExpectRefused("evlr_past_end.las", spec, kDataLoss, "extended variable length record 0 of 1 (at byte 1048576)");

  const std::string not_las = WriteLas("not_las.las", "x,y\n1,2\n");
  EXPECT_THAT(ReadLasPoints(not_las), StatusIs(kInvalid, HasSubstr("not a LAS file (it does not start with the "
                                                                   "signature 'LASF')")));
  std::filesystem::remove(not_las);
  const std::string tiny = WriteLas("tiny.las", "LA");
  EXPECT_THAT(ReadLasPoints(tiny), StatusIs(kDataLoss, HasSubstr("2 bytes, fewer than the 227-byte LAS header")));
  std::filesystem::remove(tiny);
  EXPECT_THAT(ReadLasPoints("/nonexistent/cloud.las"),
              StatusIs(absl::StatusCode::kNotFound, HasSubstr("points file '/nonexistent/cloud.las' does not exist")));
  EXPECT_THAT(ReadLasPoints(std::filesystem::temp_directory_path()),
              StatusIs(kInvalid, HasSubstr("is not a regular file")));
}

TEST(LasReaderTest, MaxPointsIsDecidedFromTheHeader) {
  LasSpec spec;
  spec.xy = kEdgeIntegers;
  EXPECT_THAT(Read("limit.las", spec, 6), IsOk());
  EXPECT_THAT(Read("limit.las", spec, 5),
              StatusIs(absl::StatusCode::kResourceExhausted, HasSubstr("has 6 points: more than 5, the limit")));
  // Decided before anything is allocated: a header claiming 2^62 points in a file that has them
  // would be refused the same way; here the count is checked against the file first (truncated).
}

TEST(LasReaderTest, ReadPointsFileTakesLasAndRefusesLazAndGdalSourcesByName) {
  LasSpec spec;
  spec.xy = {{1, 2}, {3, 4}};
  const std::string las = WriteLas("by_extension.LAS", LasFileBytes(spec));
  const absl::StatusOr<std::vector<Point2>> points = ReadPointsFile(las);
  ASSERT_THAT(points, IsOk());
  ASSERT_EQ(points->size(), 2u);
  EXPECT_EQ((*points)[1].x, 0.03);
  std::filesystem::remove(las);
  const std::string laz = WriteLas("compressed.laz", LasFileBytes(spec));
  EXPECT_THAT(ReadPointsFile(laz),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("is compressed LAS (LAZ), which is not read")));
  std::filesystem::remove(laz);
  const std::string gpkg = WriteLas("layer.gpkg", "SQLite format 3");
  EXPECT_THAT(ReadPointsFile(gpkg),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("is a GDAL vector source: read it with")));
  std::filesystem::remove(gpkg);
}

}  // namespace
}  // namespace galpha
