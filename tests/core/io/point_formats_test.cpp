// Point files: delimited text, .npy (bytes written here by hand, as NumPy lays them out) and the
// raw .bin format, read through ReadPointsFile; and the errors, each naming the file and the place.
#include "core/io/point_formats.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "absl/strings/str_cat.h"
#include "core/io/point_io.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::IsOk;
using testing::StatusIs;

std::vector<Point2> Points(std::initializer_list<Point2> list) { return list; }

void ExpectPoints(const absl::StatusOr<std::vector<Point2>>& got, const std::vector<Point2>& want) {
  ASSERT_THAT(got, IsOk());
  ASSERT_EQ(got->size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ((*got)[i].x, want[i].x) << "point " << i;
    EXPECT_EQ((*got)[i].y, want[i].y) << "point " << i;
  }
}

TEST(ParsePointsTextTest, CsvWithHeaderExtraColumnsCommentsAndCrlf) {
  const std::string text = "# exported\r\nlon,lat,elevation\r\n1.5,-2,10\r\n\r\n3e-3,4.25,11\r\n";
  ExpectPoints(ParsePointsText(text, "a.csv"), Points({{1.5, -2.0}, {3e-3, 4.25}}));
}

TEST(ParsePointsTextTest, TsvWhitespaceAndSemicolons) {
  ExpectPoints(ParsePointsText("1\t2\n3\t4\n", "t.tsv"), Points({{1, 2}, {3, 4}}));
  ExpectPoints(ParsePointsText("  1   2  9\n-3 +4\n", "w.txt"), Points({{1, 2}, {-3, 4}}));
  ExpectPoints(ParsePointsText("x;y\n0.5;0.25\n", "s.csv"), Points({{0.5, 0.25}}));
}

TEST(ParsePointsTextTest, ExactDecimalRoundTripOfDoubles) {
  const double x = 0.1, y = 1e-300;
  ExpectPoints(ParsePointsText("0.1,1e-300\n1.7976931348623157e308,-0\n", "r.csv"),
               Points({{x, y}, {1.7976931348623157e308, -0.0}}));
}

TEST(ParsePointsTextTest, EmptyAndHeaderOnlyGiveNoPoints) {
  ExpectPoints(ParsePointsText("", "e.csv"), {});
  ExpectPoints(ParsePointsText("x,y\n", "h.csv"), {});
}

TEST(ParsePointsTextTest, BadLineIsNamedByNumber) {
  const auto got = ParsePointsText("x,y\n1,2\n3\n", "bad.csv");
  ASSERT_THAT(got.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(got.status().message().find("bad.csv:3"), absl::string_view::npos) << got.status();
  // An empty field is a missing coordinate, not a reason to take the next column.
  const auto empty = ParsePointsText("1,2\n3,,4\n", "e.csv");
  ASSERT_THAT(empty.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(empty.status().message().find("e.csv:2"), absl::string_view::npos) << empty.status();
  // A first line of one number is a bad data line, not a header.
  const auto lone = ParsePointsText("1\n2,3\n", "l.csv");
  ASSERT_THAT(lone.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(lone.status().message().find("l.csv:1"), absl::string_view::npos) << lone.status();
  const auto word = ParsePointsText("1,2\n3,four\n", "w.csv");
  ASSERT_THAT(word.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(word.status().message().find("w.csv:2"), absl::string_view::npos) << word.status();
}

// The bytes of an .npy file: magic, version, header length, header padded to 64 bytes, data.
std::string Npy(const std::string& dict, const std::vector<double>& values, int version = 1, bool big_endian = false) {
  const size_t length_width = version == 1 ? 2 : 4;
  std::string header = dict;
  while ((6 + 2 + length_width + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string out("\x93NUMPY", 6);
  out += static_cast<char>(version);
  out += '\0';
  for (size_t i = 0; i < length_width; ++i) out += static_cast<char>((header.size() >> (8 * i)) & 0xff);
  out += header;
  for (double v : values) {
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    for (int i = 0; i < 8; ++i) out += static_cast<char>((bits >> (8 * (big_endian ? 7 - i : i))) & 0xff);
  }
  return out;
}

TEST(ParsePointsNpyTest, COrderFortranOrderBigEndianVersion2) {
  ExpectPoints(
      ParsePointsNpy(Npy("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2), }", {1, 2, 3, 4}), "c.npy"),
      Points({{1, 2}, {3, 4}}));
  ExpectPoints(ParsePointsNpy(Npy("{'descr': '<f8', 'fortran_order': True, 'shape': (2, 2), }", {1, 3, 2, 4}), "f.npy"),
               Points({{1, 2}, {3, 4}}));
  ExpectPoints(
      ParsePointsNpy(Npy("{'descr': '>f8', 'fortran_order': False, 'shape': (1, 2), }", {5, -6}, 1, true), "b.npy"),
      Points({{5, -6}}));
  ExpectPoints(ParsePointsNpy(Npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1, 2), }", {7, 8}, 2), "v2.npy"),
               Points({{7, 8}}));
  ExpectPoints(ParsePointsNpy(Npy("{'descr': '<f8', 'fortran_order': False, 'shape': (0, 2), }", {}), "0.npy"), {});
}

TEST(ParsePointsNpyTest, WrongDtypeShapeMagicAndSizeAreErrors) {
  const auto f4 = ParsePointsNpy(Npy("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2), }", {1, 2}), "f4.npy");
  ASSERT_THAT(f4.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(f4.status().message().find("'<f4'"), absl::string_view::npos) << f4.status();
  const auto three =
      ParsePointsNpy(Npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3), }", {1, 2, 3}), "3.npy");
  EXPECT_THAT(three.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  const auto flat =
      ParsePointsNpy(Npy("{'descr': '<f8', 'fortran_order': False, 'shape': (4,), }", {1, 2, 3, 4}), "1d.npy");
  EXPECT_THAT(flat.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_THAT(ParsePointsNpy("PK\x03\x04 not numpy", "z.npy").status(), StatusIs(absl::StatusCode::kInvalidArgument));
  std::string truncated = Npy("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2), }", {1, 2, 3, 4});
  truncated.resize(truncated.size() - 8);
  const auto short_data = ParsePointsNpy(truncated, "t.npy");
  ASSERT_THAT(short_data.status(), StatusIs(absl::StatusCode::kDataLoss));
  EXPECT_NE(short_data.status().message().find("t.npy"), absl::string_view::npos);
}

TEST(ParsePointsGeoJsonTest, FeatureCollectionOfPointsAndMultiPoints) {
  const std::string text = R"({"type": "FeatureCollection", "features": [
      {"type": "Feature", "properties": {"name": "a"}, "geometry": {"type": "Point", "coordinates": [1.5, -2]}},
      {"type": "Feature", "properties": {}, "geometry": {"type": "MultiPoint", "coordinates": [[3, 4, 100], [5e-3, 6]]}}
  ]})";
  ExpectPoints(ParsePointsGeoJson(text, "f.geojson"), Points({{1.5, -2}, {3, 4}, {5e-3, 6}}));
}

TEST(ParsePointsGeoJsonTest, BareGeometriesAndGeometryCollection) {
  ExpectPoints(ParsePointsGeoJson(R"({"type": "Point", "coordinates": [0.1, 0.2]})", "p.json"), Points({{0.1, 0.2}}));
  ExpectPoints(ParsePointsGeoJson(R"({"type": "GeometryCollection", "geometries": [
                                       {"type": "Point", "coordinates": [1, 2]},
                                       {"type": "MultiPoint", "coordinates": []}]})",
                                  "g.json"),
               Points({{1, 2}}));
  // RFC 7946 3.2: an unlocated feature has a null geometry; it holds no point.
  ExpectPoints(ParsePointsGeoJson(R"({"type": "FeatureCollection", "features": [
                                       {"type": "Feature", "geometry": null, "properties": {}},
                                       {"type": "Feature", "geometry": {"type": "Point", "coordinates": [3, 4]}}]})",
                                  "u.json"),
               Points({{3, 4}}));
}

TEST(ParsePointsGeoJsonTest, NumbersBeyondADoubleAreAnErrorNotACrash) {
  // Found by tests/fuzz: nlohmann::json throws out_of_range (not parse_error) for 1e400.
  const auto overflow = ParsePointsGeoJson(R"({"type": "Point", "coordinates": [1e400, 0]})", "big.json");
  ASSERT_THAT(overflow.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(overflow.status().message().find("big.json"), std::string::npos) << overflow.status();
}

TEST(ParsePointsGeoJsonTest, CrsIsWgs84UnlessACrsMemberNamesAnother) {
  const absl::StatusOr<GeoreferencedPoints> plain =
      ParseGeoreferencedGeoJson(R"({"type":"Point","coordinates":[1.5,2.5]})", "p");
  ASSERT_THAT(plain, IsOk());
  EXPECT_EQ(plain->crs, "OGC:CRS84");  // RFC 7946
  ASSERT_EQ(plain->points.size(), 1u);
  EXPECT_EQ(plain->points[0].x, 1.5);
  const absl::StatusOr<GeoreferencedPoints> named = ParseGeoreferencedGeoJson(
      R"({"type":"MultiPoint","crs":{"type":"name","properties":{"name":"urn:ogc:def:crs:EPSG::3857"}},)"
      R"("coordinates":[[1,2]]})",
      "n");
  ASSERT_THAT(named, IsOk());
  EXPECT_EQ(named->crs, "urn:ogc:def:crs:EPSG::3857");
  const absl::StatusOr<GeoreferencedPoints> coded = ParseGeoreferencedGeoJson(
      R"({"type":"Point","crs":{"type":"EPSG","properties":{"code":32610}},"coordinates":[1,2]})", "c");
  ASSERT_THAT(coded, IsOk());
  EXPECT_EQ(coded->crs, "EPSG:32610");
  EXPECT_THAT(ParseGeoreferencedGeoJson(R"({"type":"Point","crs":{"type":"link"},"coordinates":[1,2]})", "bad"),
              StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("bad: the crs member")));
}

TEST(ParsePointsGeoJsonTest, ErrorsNameThePlace) {
  const auto line = ParsePointsGeoJson(R"({"type": "FeatureCollection", "features": [
      {"type": "Feature", "geometry": {"type": "Point", "coordinates": [1, 2]}},
      {"type": "Feature", "geometry": {"type": "LineString", "coordinates": [[1, 2], [3, 4]]}}]})",
                                       "l.geojson");
  ASSERT_THAT(line.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(line.status().message().find("features[1].geometry"), absl::string_view::npos) << line.status();
  EXPECT_NE(line.status().message().find("LineString"), absl::string_view::npos) << line.status();
  const auto text = ParsePointsGeoJson(R"({"type": "MultiPoint", "coordinates": [[1, 2], ["3", 4]]})", "s.json");
  ASSERT_THAT(text.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(text.status().message().find("coordinates[1]"), absl::string_view::npos) << text.status();
  const auto broken = ParsePointsGeoJson(R"({"type": "Point", "coordinates": [1, 2)", "b.json");
  ASSERT_THAT(broken.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(broken.status().message().find("not valid JSON"), absl::string_view::npos) << broken.status();
  EXPECT_THAT(ParsePointsGeoJson(R"({"type": "Feature"})", "n.json").status(),
              StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_THAT(ParsePointsGeoJson(R"([1, 2])", "a.json").status(), StatusIs(absl::StatusCode::kInvalidArgument));
}

class ReadPointsFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           absl::StrCat("galpha_point_formats_", ::testing::UnitTest::GetInstance()->random_seed(), "_", getpid());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& bytes) {
    std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  std::filesystem::path dir_;
};

TEST_F(ReadPointsFileTest, ChoosesTheFormatByExtension) {
  ExpectPoints(ReadPointsFile(Write("p.csv", "x,y\n1,2\n")), Points({{1, 2}}));
  ExpectPoints(ReadPointsFile(Write("p.XYZ", "1 2 3\n")), Points({{1, 2}}));
  ExpectPoints(ReadPointsFile(Write("p.geojson", R"({"type": "Point", "coordinates": [9, 10]})")), Points({{9, 10}}));
  ExpectPoints(
      ReadPointsFile(Write("p.npy", Npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1, 2), }", {3, 4}))),
      Points({{3, 4}}));
  const std::string bin = (dir_ / "p.bin").string();
  ASSERT_THAT(WritePointsBin(bin, Points({{5, 6}, {7, 8}})), IsOk());
  ExpectPoints(ReadPointsFile(bin), Points({{5, 6}, {7, 8}}));
}

TEST_F(ReadPointsFileTest, MissingFileIsNotFoundForEveryFormat) {
  for (const char* name : {"none.csv", "none.npy", "none.bin"}) {
    const auto got = ReadPointsFile((dir_ / name).string());
    EXPECT_THAT(got.status(), StatusIs(absl::StatusCode::kNotFound)) << name;
  }
}

TEST_F(ReadPointsFileTest, DirectoryIsInvalidArgumentForEveryFormat) {
  for (const char* name : {"d.csv", "d.npy", "d.bin", "d.geojson"}) {
    std::filesystem::create_directories(dir_ / name);
    const auto got = ReadPointsFile((dir_ / name).string());
    EXPECT_THAT(got.status(), StatusIs(absl::StatusCode::kInvalidArgument)) << name;
    EXPECT_NE(got.status().message().find("directory"), absl::string_view::npos) << got.status();
  }
}

TEST_F(ReadPointsFileTest, TruncatedBinIsDataLoss) {
  const std::string bin = (dir_ / "t.bin").string();
  ASSERT_THAT(WritePointsBin(bin, Points({{5, 6}, {7, 8}})), IsOk());
  std::filesystem::resize_file(bin, 8 + 16 + 8);
  EXPECT_THAT(ReadPointsFile(bin).status(), StatusIs(absl::StatusCode::kDataLoss));
}

// Weighted points: (x, y, weight) in every format that carries a weight.
void ExpectWeighted(const absl::StatusOr<GeoreferencedPoints>& got, const std::vector<Point2>& points,
                    const std::vector<double>& weights) {
  ASSERT_THAT(got, IsOk());
  ExpectPoints(got->points, points);
  EXPECT_EQ(got->weights, weights);
}

TEST(WeightedPointsTest, TextTakesTheThirdFieldAsTheWeight) {
  ExpectWeighted(ParseWeightedPointsText("x,y,radius,name\n1,2,0.5,a\n# note\n3 4 -1e-3\n", "w.csv"),
                 Points({{1, 2}, {3, 4}}), {0.5, -1e-3});
  const auto two = ParseWeightedPointsText("1,2,3\n4,5\n", "two.csv");
  ASSERT_THAT(two.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(two.status().message().find("two.csv:2: expected x, y and a weight"), absl::string_view::npos)
      << two.status();
  const auto word = ParseWeightedPointsText("1,2,3\n4,5,big\n", "word.csv");
  EXPECT_NE(word.status().message().find("word.csv:2"), absl::string_view::npos) << word.status();
}

TEST(WeightedPointsTest, NpyOfThreeColumnsInBothOrders) {
  ExpectWeighted(ParseWeightedPointsNpy(
                     Npy("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }", {1, 2, 3, 4, 5, 6}), "c.npy"),
                 Points({{1, 2}, {4, 5}}), {3, 6});
  ExpectWeighted(ParseWeightedPointsNpy(
                     Npy("{'descr': '<f8', 'fortran_order': True, 'shape': (2, 3), }", {1, 4, 2, 5, 3, 6}), "f.npy"),
                 Points({{1, 2}, {4, 5}}), {3, 6});
  const auto pairs =
      ParseWeightedPointsNpy(Npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1, 2), }", {1, 2}), "2.npy");
  ASSERT_THAT(pairs.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(pairs.status().message().find("(N, 3) is needed"), absl::string_view::npos) << pairs.status();
}

TEST(WeightedPointsTest, GeoJsonTakesTheNamedProperty) {
  const std::string doc = R"({"type": "FeatureCollection", "features": [
      {"type": "Feature", "properties": {"r": 1.5}, "geometry": {"type": "Point", "coordinates": [1, 2]}},
      {"type": "Feature", "properties": {"r": "0.25"},
       "geometry": {"type": "MultiPoint", "coordinates": [[3, 4], [5, 6]]}}]})";
  ExpectWeighted(ParseWeightedGeoJson(doc, "w.geojson", "r"), Points({{1, 2}, {3, 4}, {5, 6}}), {1.5, 0.25, 0.25});
  const std::string missing = R"({"type": "FeatureCollection", "features": [
      {"type": "Feature", "properties": {"r": 1}, "geometry": {"type": "Point", "coordinates": [1, 2]}},
      {"type": "Feature", "properties": {"r": null}, "geometry": {"type": "Point", "coordinates": [3, 4]}}]})";
  const auto got = ParseWeightedGeoJson(missing, "m.geojson", "r");
  ASSERT_THAT(got.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(got.status().message().find("point 1 (in document order) has no property 'r'"), absl::string_view::npos)
      << got.status();
}

TEST_F(ReadPointsFileTest, WeightedFilesByExtensionAndTheWeightedBinFlag) {
  ExpectWeighted(ReadWeightedPointsFile(Write("w.csv", "1,2,3\n")), Points({{1, 2}}), {3});
  ExpectWeighted(ReadWeightedPointsFile(
                     Write("w.npy", Npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3), }", {7, 8, 9}))),
                 Points({{7, 8}}), {9});
  const std::string geojson = Write("w.geojson", R"({"type": "Feature", "properties": {"w": 4},
      "geometry": {"type": "Point", "coordinates": [5, 6]}})");
  ExpectWeighted(ReadWeightedPointsFile(geojson, "w"), Points({{5, 6}}), {4});
  EXPECT_THAT(ReadWeightedPointsFile(geojson).status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_THAT(ReadWeightedPointsFile(Write("x.csv", "1,2,3\n"), "w").status(),
              StatusIs(absl::StatusCode::kInvalidArgument));
  const std::string bin = (dir_ / "w.bin").string();
  ASSERT_THAT(WriteWeightedPointsBin(bin, Points({{5, 6}, {-7, 8}}), std::vector<double>{0.5, -2}), IsOk());
  ExpectWeighted(ReadWeightedPointsFile(bin), Points({{5, 6}, {-7, 8}}), {0.5, -2});
  EXPECT_EQ(std::filesystem::file_size(bin), 8u + 2 * 24);
  // Each kind of .bin refuses to be read as the other, by name.
  const auto as_plain = ReadPointsFile(bin);
  ASSERT_THAT(as_plain.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(as_plain.status().message().find("is weighted"), absl::string_view::npos) << as_plain.status();
  const std::string plain = (dir_ / "p.bin").string();
  ASSERT_THAT(WritePointsBin(plain, Points({{1, 2}})), IsOk());
  const auto as_weighted = ReadWeightedPointsFile(plain);
  ASSERT_THAT(as_weighted.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(as_weighted.status().message().find("without weights"), absl::string_view::npos) << as_weighted.status();
  std::filesystem::resize_file(bin, 8 + 24 + 8);
  EXPECT_THAT(ReadWeightedPointsFile(bin).status(), StatusIs(absl::StatusCode::kDataLoss));
}

}  // namespace
}  // namespace galpha
