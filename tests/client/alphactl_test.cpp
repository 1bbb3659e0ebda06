// alphactl as users run it: the real binary in a child process, on small inputs whose families are
// derived by hand (a square, a triangle, an obtuse triangle, collinear points, duplicates) and on a
// real data set, checking the exact output formats, the JSON, the exit codes and one-line errors.
#include <gtest/gtest.h>

#ifdef GALPHA_WITH_PROJ
#include <geodesic.h>
#endif

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "nlohmann/json.hpp"
#include "tests/support/data_files.hpp"
#include "tests/support/las_bytes.hpp"
#include "tests/support/vector_file_writer.hpp"

namespace {

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// Runs alphactl with `args`; `before` is shell text put in front of it (a pipe into it).
CommandResult Alphactl(const std::string& args, const std::string& before = "") {
  const std::string dir = std::filesystem::temp_directory_path() / ("alphactl_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string command =
      before + std::string(GALPHA_ALPHACTL) + " " + args + " >" + dir + "/out 2>" + dir + "/err";
  const int status = std::system(command.c_str());
  CommandResult run;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = Slurp(dir + "/out");
  run.err = Slurp(dir + "/err");
  std::filesystem::remove_all(dir);
  return run;
}

std::string WriteFile(const std::string& name, const std::string& text) {
  std::string path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path;
}

/// The raw format: little-endian uint64 N, then N pairs of float64 (this test runs on
/// little-endian hosts only, as the engine does).
std::string WriteBin(const std::string& name, const std::vector<std::array<double, 2>>& points) {
  std::string path = std::filesystem::temp_directory_path() / name;
  std::ofstream out(path, std::ios::binary);
  const uint64_t n = points.size();
  out.write(reinterpret_cast<const char*>(&n), sizeof n);
  for (const auto& p : points) out.write(reinterpret_cast<const char*>(p.data()), sizeof(double) * 2);
  return path;
}

std::string Lines(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  return text;
}

std::vector<std::string> SplitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The shortest decimal that reads back as `value`, as alphactl prints doubles (C++17's to_chars).
std::string Printed(double value) {
  char text[32];
  return std::string(text, std::to_chars(text, text + sizeof text, value).ptr);
}

/// Runs `args` on `file` and expects success; returns standard output.
std::string Succeeds(const std::string& command, const std::string& file, const std::string& options) {
  const CommandResult run = Alphactl(command + " " + Quote(file) + " " + options);
  EXPECT_EQ(run.exit_code, 0) << command << " " << options << ": " << run.err;
  EXPECT_TRUE(run.err.empty()) << run.err;
  return run.out;
}

/// A failure: the exit code, nothing on stdout, one line on stderr starting "alphactl: " that
/// contains `needle`.
void ExpectError(const CommandResult& run, int exit_code, const std::string& needle) {
  EXPECT_EQ(run.exit_code, exit_code) << run.err;
  EXPECT_TRUE(run.out.empty()) << run.out;
  EXPECT_EQ(run.err.rfind("alphactl: ", 0), 0u) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  EXPECT_NE(run.err.find(needle), std::string::npos) << "expected '" << needle << "' in: " << run.err;
}

// The unit square 0 (0,0), 1 (1,0), 2 (1,1), 3 (0,1): Delaunay triangles 013 and 123 (the
// diagonal 1-3: on a co-circular square the tie is broken by index). Sides: rho^2 = 1/4,
// unattached (the opposite vertices lie on their diametral circles, not inside). Triangles and the
// diagonal (their common hypotenuse, unattached): 1/2. Spectrum {1/4, 1/2}.
const std::string& SquareCsv() {
  static const std::string path = WriteFile("alphactl_unit_square.csv", "x,y\n0,0\n1,0\n1,1\n0,1\n");
  return path;
}

TEST(AlphactlTest, TriangulatesACsvAndPrintsOneJsonObject) {
  // A unit square with its centre: 4 triangles, 8 edges, 4 hull edges; one duplicate.
  const std::string path = WriteFile("alphactl_square.csv", "x,y\n0,0\n1,0\n0,1\n1,1\n0.5,0.5\n1,1\n");
  const CommandResult run = Alphactl("triangulate " + Quote(path) + " --backend=cpu");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["file"], path);
  EXPECT_EQ(j["points"], 6);
  EXPECT_EQ(j["distinct_points"], 5);
  EXPECT_EQ(j["duplicates"], 1);
  EXPECT_EQ(j["triangles"], 4);
  EXPECT_EQ(j["edges"], 8);
  EXPECT_EQ(j["hull_edges"], 4);
  EXPECT_EQ(j["backend"], "cpu");
  EXPECT_GT(j["peak_memory_bytes"].get<double>(), 0);
  EXPECT_TRUE(j["stage_ms"].contains("insert_and_flip"));
  std::filesystem::remove(path);
}

TEST(AlphactlTest, TriangulatesWeightedPointsWithRadiiOrSquaredRadii) {
  // Unit disks at (0,0), (4,0), (0,4) lift to -1, 15, 15; (2,2) with radius 3 lifts to -1, below
  // their plane z = 4x + 4y - 1 (15 there): a vertex. (1,1) with radius 0.1 lifts to 1.99, above
  // the plane of (0,0), (2,2) and (4,0) (z = 4x - 4y - 1: -1 there): hidden. As squared radii (3
  // and 0.1: lifts 5 and 1.9, that plane z = 4x - y - 1 at 2), nothing is hidden.
  const std::string path = WriteFile("alphactl_disks.csv", "x,y,r\n0,0,1\n4,0,1\n0,4,1\n1,1,0.1\n2,2,3\n");
  const nlohmann::json radius =
      nlohmann::json::parse(Alphactl("triangulate " + Quote(path) + " --backend=cpu --weights radius").out);
  EXPECT_EQ(radius["hidden_points"], 1);
  EXPECT_EQ(radius["triangles"], 2);
  const nlohmann::json squared =
      nlohmann::json::parse(Alphactl("triangulate " + Quote(path) + " --backend=cpu --weights squared").out);
  EXPECT_EQ(squared["hidden_points"], 0);
  EXPECT_EQ(squared["triangles"], 4);
  EXPECT_TRUE(
      nlohmann::json::parse(Alphactl("triangulate " + Quote(path) + " --backend=cpu").out)["hidden_points"].is_null());
  ExpectError(Alphactl("triangulate " + Quote(path) + " --weights diameter"), 2, "radius or squared");
  ExpectError(Alphactl("triangulate " + Quote(path) + " --weights radius --weight-property r"), 1,
              "applies to GeoJSON features");
  const std::string negative = WriteFile("alphactl_negative_radius.csv", "0 0 1\n1 0 -2\n0 1 1\n");
  ExpectError(Alphactl("triangulate " + Quote(negative) + " --weights radius"), 1, "point 1 has a negative radius");
  // As squared radii, negative values are valid.
  EXPECT_EQ(Alphactl("triangulate " + Quote(negative) + " --backend=cpu --weights squared").exit_code, 0);
  std::filesystem::remove(path);
  std::filesystem::remove(negative);
}

TEST(AlphactlTest, BuildsWeightedFamilies) {
  // Three unit disks at the corners of a triangle of side 2 and a disk of radius sqrt(0.5) inside
  // it (as in weighted_family_cgal_test): the edges between overlapping disks are born below 0,
  // and below -1 (minus the largest weight) nothing is in. (1,1) with radius 0.1 is hidden.
  const std::string path = WriteFile("alphactl_weighted.csv", "x,y,w\n0,0,1\n2,0,1\n1,1.75,1\n1,0.6,0.5\n1,1,0.01\n");
  const nlohmann::json summary =
      nlohmann::json::parse(Succeeds("summary", path, "--rank 0 --backend=cpu --weights squared"));
  EXPECT_EQ(summary["hidden_points"], nlohmann::json::array({4}));
  EXPECT_EQ(summary["vertices"]["EXTERIOR"], 1);  // the hidden point
  EXPECT_EQ(summary["vertices"]["SINGULAR"], 4);
  EXPECT_EQ(summary["alpha_sq"], -1.0);  // level 0 starts at minus the largest weight
  const std::vector<std::string> spectrum = SplitLines(Succeeds("spectrum", path, "--backend=cpu --weights squared"));
  ASSERT_FALSE(spectrum.empty());
  EXPECT_LT(std::stod(spectrum.front()), 0.0);
  const nlohmann::json below =
      nlohmann::json::parse(Succeeds("summary", path, "--alpha-sq -1.5 --backend=cpu --weights squared"));
  EXPECT_EQ(below["level"], -1);
  EXPECT_EQ(below["components"], 0);
  // The hidden point is EXTERIOR at every threshold, and named in classify's output as such.
  const std::string classes = Succeeds("classify", path, "--rank 3 --backend=cpu --weights squared");
  EXPECT_NE(classes.find("v 4 EXTERIOR\n"), std::string::npos) << classes;
  // --probe grows every radius before squaring: a water probe covers the hidden point too.
  const std::string radii = WriteFile("alphactl_radii.csv", "x,y,r\n0,0,1\n2,0,1\n1,1.75,1\n1,0.6,0.7\n");
  const nlohmann::json plain =
      nlohmann::json::parse(Succeeds("summary", radii, "--rank 0 --backend=cpu --weights radius"));
  const nlohmann::json grown =
      nlohmann::json::parse(Succeeds("summary", radii, "--rank 0 --backend=cpu --weights radius --probe 1.4"));
  EXPECT_EQ(plain["alpha_sq"], -1.0);  // minus the largest weight, 1^2
  EXPECT_EQ(grown["alpha_sq"], -(2.4 * 2.4));
  ExpectError(Alphactl("summary " + Quote(radii) + " --rank 0 --weights squared --probe 1.4"), 2,
              "needs --weights radius");
  ExpectError(Alphactl("summary " + Quote(radii) + " --rank 0 --weights radius --probe -1"), 2, "finite number >= 0");
  std::filesystem::remove(radii);
  // Unweighted summaries say so.
  EXPECT_TRUE(nlohmann::json::parse(Succeeds("summary", path, "--rank 0 --backend=cpu"))["hidden_points"].is_null());
  std::filesystem::remove(path);
}

TEST(AlphactlTest, FileNamesAreEscapedInTheJson) {
  const std::string path = WriteFile("alphactl_we\"ird\\name.csv", "0 0\n1 0\n0 1\n");
  const CommandResult run = Alphactl("triangulate " + Quote(path) + " --backend=cpu");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(nlohmann::json::parse(run.out)["file"], path);
  EXPECT_EQ(nlohmann::json::parse(Succeeds("summary", path, "--rank 0"))["file"], path);
  std::filesystem::remove(path);
  // A name that is not UTF-8 (Latin-1 e-acute) still gives valid JSON: the byte becomes U+FFFD.
  const std::string latin1 = WriteFile("alphactl_caf\xe9.csv", "0 0\n1 0\n0 1\n");
  const nlohmann::json summary = nlohmann::json::parse(Succeeds("summary", latin1, "--rank 0"));
  EXPECT_EQ(summary["file"], latin1.substr(0, latin1.size() - 5) + "\xef\xbf\xbd.csv");
  std::filesystem::remove(latin1);
}

TEST(AlphactlTest, HelpListsEveryCommandAndOption) {
  const CommandResult help = Alphactl("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_TRUE(help.err.empty());
  for (const char* word : {"triangulate",
                           "spectrum",
                           "classify",
                           "summary",
                           "shape",
                           "masterlist",
                           "optimal",
                           "bench",
                           "--alpha-sq",
                           "--alpha ",
                           "--rank",
                           "--mode",
                           "--vertex-rule",
                           "--format",
                           "--components",
                           "--repeat",
                           "--backend",
                           "--max-points",
                           "GLOBAL OPTIONS",
                           "geojson|wkt|svg",
                           "general|regularized",
                           "report|cgal",
                           "persistence",
                           "holes",
                           "--holes",
                           "--min-persistence",
                           "--dimension",
                           "--min-area",
                           "--min-hole-area",
                           "text|csv|json|svg",
                           "--weights radius|squared",
                           "--weight-property",
                           "--probe"}) {
    EXPECT_NE(help.out.find(word), std::string::npos) << word;
  }
  const CommandResult none = Alphactl("");
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_EQ(none.out, help.out);
  const CommandResult command_help = Alphactl("classify --help");
  EXPECT_EQ(command_help.exit_code, 0);
  EXPECT_EQ(command_help.out, help.out);
}

TEST(AlphactlTest, SpectrumsArePrintedExactly) {
  EXPECT_EQ(Succeeds("spectrum", SquareCsv(), ""), "0.25\n0.5\n");
  // (0,0), (4,0), (2,3): sides 16/4 and 13/4 (twice, one value), all unattached; circumradius^2
  // 169/36, printed as the shortest decimal that reads back as the double nearest it (%.17g said
  // 4.6944444444444446).
  const std::string triangle = WriteFile("alphactl_triangle.txt", "0 0\n4 0\n2 3\n");
  EXPECT_EQ(Succeeds("spectrum", triangle, "--backend=cpu"), Lines({"3.25", "4", "4.694444444444445"}));
  EXPECT_EQ(std::strtod("4.694444444444445", nullptr), 169.0 / 36.0);
  // Obtuse (0,0), (4,0), (2,1): the long edge is attached ((2,1) is inside its diametral circle),
  // so its 4 is not in the spectrum; the short edges 5/4, circumradius^2 (centre (2,-1.5)) 25/4.
  const std::string obtuse = WriteFile("alphactl_obtuse.txt", "0 0\n4 0\n2 1\n");
  EXPECT_EQ(Succeeds("spectrum", obtuse, ""), "1.25\n6.25\n");
  EXPECT_EQ(Succeeds("classify", obtuse, "--rank 1"),
            Lines({"v 0 REGULAR", "v 1 REGULAR", "v 2 REGULAR", "e 0 1 EXTERIOR", "e 0 2 SINGULAR", "e 1 2 SINGULAR",
                   "t 0 1 2 EXTERIOR"}));
  // The attached edge is born with its triangle; hull edges stay REGULAR.
  EXPECT_EQ(Succeeds("classify", obtuse, "--rank 2"),
            Lines({"v 0 REGULAR", "v 1 REGULAR", "v 2 REGULAR", "e 0 1 REGULAR", "e 0 2 REGULAR", "e 1 2 REGULAR",
                   "t 0 1 2 INTERIOR"}));
  std::filesystem::remove(triangle);
  std::filesystem::remove(obtuse);
}

TEST(AlphactlTest, ClassifiesTheSquareAtEveryRank) {
  const std::string& square = SquareCsv();
  EXPECT_EQ(Succeeds("classify", square, "--rank 0"),
            Lines({"v 0 SINGULAR", "v 1 SINGULAR", "v 2 SINGULAR", "v 3 SINGULAR", "e 0 1 EXTERIOR", "e 0 3 EXTERIOR",
                   "e 1 2 EXTERIOR", "e 1 3 EXTERIOR", "e 2 3 EXTERIOR", "t 0 1 3 EXTERIOR", "t 1 2 3 EXTERIOR"}));
  // alpha_sq = 1/4: the sides are in with no triangle; vertices are REGULAR by the rule of the
  // report "Computing 2D Alpha Shapes Using GPU" (an incident edge is in), SINGULAR by CGAL's (no
  // incident triangle).
  const std::string rank1_edges = Lines({"e 0 1 SINGULAR", "e 0 3 SINGULAR", "e 1 2 SINGULAR", "e 1 3 EXTERIOR",
                                         "e 2 3 SINGULAR", "t 0 1 3 EXTERIOR", "t 1 2 3 EXTERIOR"});
  EXPECT_EQ(Succeeds("classify", square, "--rank 1 --backend=cpu"),
            Lines({"v 0 REGULAR", "v 1 REGULAR", "v 2 REGULAR", "v 3 REGULAR"}) + rank1_edges);
  EXPECT_EQ(Succeeds("classify", square, "--rank 1 --vertex-rule cgal"),
            Lines({"v 0 SINGULAR", "v 1 SINGULAR", "v 2 SINGULAR", "v 3 SINGULAR"}) + rank1_edges);
  // Regularized: nothing bounds a triangle yet.
  EXPECT_EQ(Succeeds("classify", square, "--rank 1 --mode regularized"),
            Lines({"v 0 EXTERIOR", "v 1 EXTERIOR", "v 2 EXTERIOR", "v 3 EXTERIOR", "e 0 1 EXTERIOR", "e 0 3 EXTERIOR",
                   "e 1 2 EXTERIOR", "e 1 3 EXTERIOR", "e 2 3 EXTERIOR", "t 0 1 3 EXTERIOR", "t 1 2 3 EXTERIOR"}));
  const std::string all_in =
      Lines({"v 0 REGULAR", "v 1 REGULAR", "v 2 REGULAR", "v 3 REGULAR", "e 0 1 REGULAR", "e 0 3 REGULAR",
             "e 1 2 REGULAR", "e 1 3 INTERIOR", "e 2 3 REGULAR", "t 0 1 3 INTERIOR", "t 1 2 3 INTERIOR"});
  EXPECT_EQ(Succeeds("classify", square, "--rank 2"), all_in);
  EXPECT_EQ(Succeeds("classify", square, "--rank 2 --mode regularized --vertex-rule cgal"), all_in);

  // The raw binary format gives the same answers.
  const std::string bin = WriteBin("alphactl_unit_square.bin", {{{0, 0}}, {{1, 0}}, {{1, 1}}, {{0, 1}}});
  EXPECT_EQ(Succeeds("classify", bin, "--rank 2"), all_in);
  EXPECT_EQ(Succeeds("spectrum", bin, ""), "0.25\n0.5\n");
  std::filesystem::remove(bin);
}

TEST(AlphactlTest, ThresholdUnitsAgreeAndCompareExactly) {
  const std::string& square = SquareCsv();
  const std::string rank0 = Succeeds("classify", square, "--rank 0");
  const std::string rank1 = Succeeds("classify", square, "--rank 1");
  EXPECT_EQ(Succeeds("classify", square, "--alpha 0.5"), rank1);
  EXPECT_EQ(Succeeds("classify", square, "--alpha-sq 0.25"), rank1);
  EXPECT_EQ(Succeeds("classify", square, "--alpha-sq=0.3"), rank1);
  EXPECT_EQ(Succeeds("classify", square, "--alpha-sq 0.24999999999999997"), rank0);
  EXPECT_EQ(Succeeds("classify", square, "--alpha 0"), rank0);
  EXPECT_EQ(Succeeds("classify", square, "--alpha-sq 1e300"), Succeeds("classify", square, "--rank 2"));

  const nlohmann::json by_alpha = nlohmann::json::parse(Succeeds("summary", square, "--alpha 0.5"));
  EXPECT_EQ(by_alpha["level"], 1);
  EXPECT_EQ(by_alpha["alpha_sq"], 0.25);
  const nlohmann::json by_value = nlohmann::json::parse(Succeeds("summary", square, "--alpha-sq 0.3"));
  EXPECT_EQ(by_value["level"], 1);
  EXPECT_EQ(by_value["alpha_sq"], 0.3);
  const nlohmann::json negative = nlohmann::json::parse(Succeeds("summary", square, "--alpha-sq -1"));
  EXPECT_EQ(negative["level"], -1);
  EXPECT_EQ(negative["vertices"]["EXTERIOR"], 4);

  // (0,0), (4,0), (2,6): sides 4 and 10 (twice), circumradius^2 100/9, whose nearest double lies
  // below it: as --alpha-sq that double is compared exactly and the triangle is not yet in.
  const std::string tall = WriteFile("alphactl_tall.txt", "0 0\n4 0\n2 6\n");
  EXPECT_EQ(Succeeds("spectrum", tall, ""), Lines({"4", "10", "11.11111111111111"}));
  const nlohmann::json rank3 = nlohmann::json::parse(Succeeds("summary", tall, "--rank 3"));
  EXPECT_EQ(rank3["level"], 3);
  EXPECT_EQ(rank3["alpha_sq"], 100.0 / 9.0);
  EXPECT_EQ(rank3["triangles"]["INTERIOR"], 1);
  const nlohmann::json below = nlohmann::json::parse(Succeeds("summary", tall, "--alpha-sq " + Printed(100.0 / 9.0)));
  EXPECT_EQ(below["level"], 2);
  EXPECT_EQ(below["triangles"]["INTERIOR"], 0);
  std::filesystem::remove(tall);
}

TEST(AlphactlTest, SummaryIsOneJsonObjectWithItsKeysInOrder) {
  const CommandResult run = Alphactl("summary " + Quote(SquareCsv()) + " --rank 1 --backend=cpu");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1);
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(run.out);
  std::vector<std::string> keys;
  for (const auto& item : j.items()) keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{
                      "file",          "points",        "distinct_points", "duplicates", "hidden_points",
                      "spectrum_size", "level",         "alpha_sq",        "mode",       "vertex_rule",
                      "vertices",      "edges",         "triangles",       "components", "solid_components",
                      "holes",         "interior_area", "hull_area",       "crs",        "backend"}));
  const nlohmann::json expected = {{"file", SquareCsv()},
                                   {"points", 4},
                                   {"distinct_points", 4},
                                   {"duplicates", 0},
                                   {"hidden_points", nullptr},
                                   {"spectrum_size", 2},
                                   {"level", 1},
                                   {"alpha_sq", 0.25},
                                   {"mode", "general"},
                                   {"vertex_rule", "report"},
                                   {"vertices", {{"EXTERIOR", 0}, {"SINGULAR", 0}, {"REGULAR", 4}, {"INTERIOR", 0}}},
                                   {"edges", {{"EXTERIOR", 1}, {"SINGULAR", 4}, {"REGULAR", 0}, {"INTERIOR", 0}}},
                                   {"triangles", {{"EXTERIOR", 2}, {"SINGULAR", 0}, {"REGULAR", 0}, {"INTERIOR", 0}}},
                                   {"components", 1},
                                   {"solid_components", 0},
                                   {"holes", 1},  // the four sides enclose the square
                                   {"interior_area", 0.0},
                                   {"hull_area", 1.0},
                                   {"crs", nullptr},
                                   {"backend", "cpu"}};
  EXPECT_EQ(nlohmann::json::parse(run.out), expected);
  // Compact, doubles as their shortest text (0.25, not 0.25000000000000000; 0, not 0.0).
  EXPECT_NE(run.out.find("{\"file\":"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find(",\"alpha_sq\":0.25,\"mode\":\"general\","), std::string::npos) << run.out;
  EXPECT_NE(run.out.find(",\"interior_area\":0,"), std::string::npos) << run.out;

  const nlohmann::json full =
      nlohmann::json::parse(Succeeds("summary", SquareCsv(), "--rank 2 --mode regularized --vertex-rule cgal"));
  EXPECT_EQ(full["mode"], "regularized");
  EXPECT_EQ(full["vertex_rule"], "cgal");
  EXPECT_EQ(full["alpha_sq"], 0.5);
  EXPECT_EQ(full["edges"]["INTERIOR"], 1);
  EXPECT_EQ(full["triangles"]["INTERIOR"], 2);
  EXPECT_EQ(full["solid_components"], 1);
  EXPECT_EQ(full["holes"], 0);
  EXPECT_EQ(full["interior_area"], 1.0);
}

// The convex hull's area by Andrew's monotone chain and the shoelace formula, in long double: an
// oracle independent of the engine's triangles and of its area curve.
double ConvexHullArea(std::vector<std::array<double, 2>> p) {
  std::sort(p.begin(), p.end());
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return 0.0;
  auto cross = [](const std::array<double, 2>& o, const std::array<double, 2>& a, const std::array<double, 2>& b) {
    return (static_cast<long double>(a[0]) - o[0]) * (static_cast<long double>(b[1]) - o[1]) -
           (static_cast<long double>(a[1]) - o[1]) * (static_cast<long double>(b[0]) - o[0]);
  };
  std::vector<std::array<double, 2>> hull(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
    hull[k++] = p[i];
  }
  for (size_t i = p.size() - 1, lower = k + 1; i > 0; --i) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], p[i - 1]) <= 0) --k;
    hull[k++] = p[i - 1];
  }
  long double twice = 0;
  for (size_t i = 0; i + 1 < k; ++i) {
    twice +=
        static_cast<long double>(hull[i][0]) * hull[i + 1][1] - static_cast<long double>(hull[i + 1][0]) * hull[i][1];
  }
  return static_cast<double>(twice / 2);
}

TEST(AlphactlTest, AreaRatiosPickTheSmallestRankThatCoversThem) {
  // The unit square: both triangles come at rank 2, so every ratio in (0, 1] is rank 2.
  const std::string& square = SquareCsv();
  EXPECT_EQ(nlohmann::json::parse(Succeeds("summary", square, "--ratio 0"))["level"], 0);
  EXPECT_EQ(nlohmann::json::parse(Succeeds("summary", square, "--ratio 1e-300"))["level"], 2);
  EXPECT_EQ(nlohmann::json::parse(Succeeds("summary", square, "--ratio 1"))["level"], 2);
  EXPECT_EQ(Succeeds("shape", square, "--ratio 0.5 --format wkt"), Succeeds("shape", square, "--rank 2 --format wkt"));

  // Random points: the level of each ratio covers it, the level before does not (interior areas
  // summed in doubles: compared with a relative margin far above their rounding), and the hull's
  // area is the convex hull's.
  std::mt19937_64 random(2026);
  std::uniform_real_distribution<double> coordinate(-3.0, 7.0);
  std::vector<std::array<double, 2>> points(300);
  for (auto& p : points) p = {coordinate(random), coordinate(random)};
  const std::string file = WriteBin("alphactl_ratio.bin", points);
  for (double ratio : {0.1, 0.5, 0.9, 0.999, 1.0}) {
    SCOPED_TRACE(ratio);
    const nlohmann::json at =
        nlohmann::json::parse(Succeeds("summary", file, "--mode regularized --ratio " + Printed(ratio)));
    const int64_t level = at["level"].get<int64_t>();
    const double hull = at["hull_area"].get<double>();
    EXPECT_NEAR(hull, ConvexHullArea(points), 1e-12 * hull);
    EXPECT_GE(at["interior_area"].get<double>(), ratio * hull * (1 - 1e-12));
    ASSERT_GT(level, 0);
    const nlohmann::json before =
        nlohmann::json::parse(Succeeds("summary", file, "--mode regularized --rank " + std::to_string(level - 1)));
    EXPECT_LT(before["interior_area"].get<double>(), ratio * hull * (1 + 1e-12));
    EXPECT_EQ(Succeeds("shape", file, "--ratio " + Printed(ratio) + " --format wkt"),
              Succeeds("shape", file, "--rank " + std::to_string(level) + " --format wkt"));
  }

  ExpectError(Alphactl("summary " + Quote(square) + " --ratio 1.5"), 2, "--ratio '1.5' is outside 0..1");
  ExpectError(Alphactl("summary " + Quote(square) + " --ratio -0.1"), 2, "outside 0..1");
  ExpectError(Alphactl("summary " + Quote(square) + " --ratio 0.5 --rank 1"), 2, "give only one threshold");
  ExpectError(Alphactl("shape " + Quote(square) + " --ratio half --format wkt"), 2, "--ratio 'half'");
  std::filesystem::remove(file);
}

#ifdef GALPHA_WITH_GEMMI
TEST(AlphactlTest, StructuresGiveTheirAtomsInThePlaneAndSlabChosen) {
  // Four atoms of one model (the B conformation of C dropped): a section and projections.
  const std::string pdb = WriteFile("alphactl_atoms.pdb",
                                    "ATOM      1  N   ALA A   1       0.000   0.000   0.000  1.00  0.00           N\n"
                                    "ATOM      2  CA  ALA A   1       4.000   0.000   1.000  1.00  0.00           C\n"
                                    "ATOM      3  C  AALA A   1       4.000   3.000   2.000  0.50  0.00           C\n"
                                    "ATOM      4  C  BALA A   1       9.000   9.000   9.000  0.50  0.00           C\n"
                                    "ATOM      5  O   ALA A   1       0.000   3.000   3.000  1.00  0.00           O\n"
                                    "END\n");
  // xy: the 4 x 3 rectangle, area 12; the same as the same points as text.
  const std::string csv = WriteFile("alphactl_atoms.csv", "0 0\n4 0\n4 3\n0 3\n");
  EXPECT_EQ(Succeeds("spectrum", pdb, ""), Succeeds("spectrum", csv, ""));
  EXPECT_EQ(nlohmann::json::parse(Succeeds("summary", pdb, "--ratio 1"))["hull_area"], 12.0);
  // zx (z, x): (0,0), (1,4), (2,4), (3,0); a slab of y in [0, 1] keeps the first two atoms.
  EXPECT_EQ(nlohmann::json::parse(Succeeds("summary", pdb, "--plane zx --ratio 1"))["hull_area"], 8.0);
  EXPECT_EQ(nlohmann::json::parse(Succeeds("summary", pdb, "--slab 0:1 --rank 0"))["points"], 2);
  ExpectError(Alphactl("summary " + Quote(csv) + " --rank 0 --plane yz"), 1, "--plane and --slab apply to PDB");
  ExpectError(Alphactl("summary " + Quote(pdb) + " --rank 0 --slab 2:1"), 2, "--slab '2:1'");
  // --weights radius gives each atom its element's van der Waals radius (N 1.55, C 1.70, O 1.52):
  // the weighted family of the same disks written as text.
  const std::string disks = WriteFile("alphactl_atom_disks.csv", "0 0 1.55\n4 0 1.70\n4 3 1.70\n0 3 1.52\n");
  for (const char* options : {"--weights radius", "--weights radius --probe 1.4"}) {
    SCOPED_TRACE(options);
    EXPECT_EQ(Succeeds("spectrum", pdb, options), Succeeds("spectrum", disks, options));
    nlohmann::json from_atoms = nlohmann::json::parse(Succeeds("summary", pdb, std::string(options) + " --rank 2"));
    nlohmann::json from_text = nlohmann::json::parse(Succeeds("summary", disks, std::string(options) + " --rank 2"));
    from_atoms.erase("file");
    from_text.erase("file");
    EXPECT_EQ(from_atoms, from_text);
  }
  EXPECT_LT(std::stod(SplitLines(Succeeds("spectrum", pdb, "--weights radius")).front()), 0.0) << "the disks overlap";
  ExpectError(Alphactl("summary " + Quote(pdb) + " --rank 0 --weights squared"), 1,
              "its atoms carry radii (their elements' van der Waals radii): read them with --weights radius");
  std::filesystem::remove(pdb);
  std::filesystem::remove(csv);
  std::filesystem::remove(disks);
}
#endif  // GALPHA_WITH_GEMMI

#ifdef GALPHA_WITH_PROJ

// Longitude/latitude points around Eugene, Oregon (x longitude, y latitude), a ring of 40 and
// 60 random ones inside: a geographic set that alphactl computes in metres.
std::vector<std::array<double, 2>> LonLatPoints() {
  std::mt19937_64 random(44);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::array<double, 2>> points;
  for (int i = 0; i < 40; ++i) {
    const double angle = 2 * 3.14159265358979 * i / 40;
    points.push_back({-123.1 + 0.05 * std::cos(angle), 44.05 + 0.04 * std::sin(angle)});
  }
  for (int i = 0; i < 60; ++i) {
    const double r = 0.9 * std::sqrt(unit(random)), angle = 2 * 3.14159265358979 * unit(random);
    points.push_back({-123.1 + 0.05 * r * std::cos(angle), 44.05 + 0.04 * r * std::sin(angle)});
  }
  return points;
}

std::string PointsCsv(const std::vector<std::array<double, 2>>& points) {
  std::string text = "lon,lat\n";
  for (const auto& p : points) text += Printed(p[0]) + "," + Printed(p[1]) + "\n";
  return text;
}

/// The geodesic area (m^2, WGS84) of the ring of input points `ring` (GeographicLib's algorithm).
double GeodesicArea(const std::vector<std::array<double, 2>>& ring) {
  geod_geodesic g{};
  geod_init(&g, 6378137.0, 1 / 298.257223563);
  std::vector<double> lats, lons;
  for (const auto& p : ring) lats.push_back(p[1]), lons.push_back(p[0]);
  double area = 0, perimeter = 0;
  geod_polygonarea(&g, lats.data(), lons.data(), static_cast<int>(ring.size()), &area, &perimeter);
  return std::abs(area);
}

TEST(AlphactlTest, GeographicInputIsComputedInMetresAndWrittenInItsCrs) {
  const std::vector<std::array<double, 2>> points = LonLatPoints();
  const std::string csv = WriteFile("alphactl_lonlat.csv", PointsCsv(points));
  const nlohmann::json summary = nlohmann::json::parse(Succeeds("summary", csv, "--crs EPSG:4326 --ratio 1"));
  EXPECT_EQ(summary["crs"]["name"], "WGS 84");
  EXPECT_EQ(summary["crs"]["id"], "EPSG:4326");
  EXPECT_EQ(summary["crs"]["geographic"], true);
  EXPECT_NE(summary["crs"]["computed_in"].get<std::string>().find("+proj=aeqd"), std::string::npos);
  // The hull's area in square metres: the geodesic area of the ring of 40 (the convex hull),
  // within the local projection's distortion (aeqd is not equal-area: about 1e-7 here).
  std::vector<std::array<double, 2>> ring(points.begin(), points.begin() + 40);
  EXPECT_NEAR(summary["hull_area"].get<double>(), GeodesicArea(ring), 1e-6 * GeodesicArea(ring));
  EXPECT_NEAR(summary["interior_area"].get<double>(), summary["hull_area"].get<double>(), 1e-9 * GeodesicArea(ring));

  // Alpha is in metres: the spectrum's values are squared metres (neighbours are hundreds of
  // metres apart, so about 1e4 to 1e7), and --alpha takes metres.
  const std::vector<std::string> spectrum = SplitLines(Succeeds("spectrum", csv, "--crs EPSG:4326"));
  ASSERT_FALSE(spectrum.empty());
  EXPECT_GT(std::stod(spectrum.front()), 1e3);
  EXPECT_LT(std::stod(spectrum.back()), 1e8);
  const nlohmann::json by_metres = nlohmann::json::parse(Succeeds("summary", csv, "--crs EPSG:4326 --alpha 1000"));
  EXPECT_EQ(by_metres["alpha_sq"], 1e6);

  // GeoJSON (RFC 7946) and WKT carry the input's coordinates, bit for bit (WGS84 already).
  const nlohmann::json geojson =
      nlohmann::json::parse(Succeeds("shape", csv, "--crs EPSG:4326 --ratio 1 --format geojson"));
  const auto& outer = geojson["features"][0]["geometry"]["coordinates"][0][0];
  EXPECT_EQ(outer.size(), 41u);
  for (const auto& position : outer) {
    const std::array<double, 2> p = {position[0].get<double>(), position[1].get<double>()};
    EXPECT_NE(std::find(points.begin(), points.end(), p), points.end()) << position;
  }
  EXPECT_NE(Succeeds("shape", csv, "--crs EPSG:4326 --ratio 1 --format wkt")
                .find(Printed(points[0][0]) + " " + Printed(points[0][1])),
            std::string::npos);

  // SVG names the CRS of its coordinates.
  EXPECT_NE(Succeeds("shape", csv, "--crs EPSG:4326 --ratio 1 --format svg")
                .find("<desc>coordinates in CRS WGS 84 (EPSG:4326)</desc>"),
            std::string::npos);

  // A GeoJSON point file is WGS84 longitude/latitude (RFC 7946): the same family without --crs.
  std::string features = R"({"type":"FeatureCollection","features":[)";
  for (size_t i = 0; i < points.size(); ++i) {
    features += (i ? "," : "") +
                std::string(R"({"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[)") +
                Printed(points[i][0]) + "," + Printed(points[i][1]) + "]}}";
  }
  const std::string geojson_file = WriteFile("alphactl_lonlat.geojson", features + "]}");
  EXPECT_EQ(Succeeds("spectrum", geojson_file, ""), Succeeds("spectrum", csv, "--crs EPSG:4326"));
  EXPECT_EQ(nlohmann::json::parse(Succeeds("summary", geojson_file, "--rank 5"))["crs"]["id"], "OGC:CRS84");
  // --crs none: planar coordinates (squared degrees), as before CRSs.
  EXPECT_EQ(Succeeds("spectrum", geojson_file, "--crs none"), Succeeds("spectrum", csv, ""));
  EXPECT_TRUE(nlohmann::json::parse(Succeeds("summary", csv, "--rank 5"))["crs"].is_null());
  std::filesystem::remove(geojson_file);
  std::filesystem::remove(csv);
}

TEST(AlphactlTest, ProjectedInputStaysAndGeoJsonIsWgs84) {
  // UTM zone 10N (metres): computed as given; GeoJSON in longitude/latitude (pyproj's values for
  // (500000, 5000000): -123.00000000000001, 45.153477183356024).
  const std::string csv =
      WriteFile("alphactl_utm.csv", "x,y\n500000,5000000\n500100,5000000\n500100,5000100\n500000,5000100\n");
  EXPECT_EQ(Succeeds("spectrum", csv, "--crs EPSG:32610"), Succeeds("spectrum", csv, ""));
  const nlohmann::json summary = nlohmann::json::parse(Succeeds("summary", csv, "--crs EPSG:32610 --ratio 1"));
  EXPECT_EQ(summary["crs"]["geographic"], false);
  EXPECT_TRUE(summary["crs"]["computed_in"].is_null());
  EXPECT_EQ(summary["hull_area"], 10000.0);
  const nlohmann::json geojson =
      nlohmann::json::parse(Succeeds("shape", csv, "--crs EPSG:32610 --ratio 1 --format geojson"));
  EXPECT_EQ(geojson["features"][0]["properties"]["area"], 10000.0);
  const auto& first = geojson["features"][0]["geometry"]["coordinates"][0][0][0];
  EXPECT_NEAR(first[0].get<double>(), -123.00000000000001, 1e-9);
  EXPECT_NEAR(first[1].get<double>(), 45.153477183356024, 1e-9);
  // WKT stays in the input's CRS.
  EXPECT_NE(Succeeds("shape", csv, "--crs EPSG:32610 --ratio 1 --format wkt").find("5e+05 5e+06"), std::string::npos);
  // A GeoJSON file with a 2008-style crs member is in that CRS.
  const std::string named =
      WriteFile("alphactl_utm.geojson",
                R"({"type":"MultiPoint","crs":{"type":"name","properties":{"name":"urn:ogc:def:crs:EPSG::32610"}},)"
                R"("coordinates":[[500000,5000000],[500100,5000000],[500100,5000100],[500000,5000100]]})");
  EXPECT_EQ(nlohmann::json::parse(Succeeds("summary", named, "--rank 1"))["crs"]["name"], "WGS 84 / UTM zone 10N");
  EXPECT_EQ(Succeeds("spectrum", named, ""), Succeeds("spectrum", csv, ""));

  ExpectError(Alphactl("summary " + Quote(csv) + " --rank 1 --crs EPSG:4326"), 1,
              "point 0 (5e+05, 5e+06) is not a longitude and latitude");
  ExpectError(Alphactl("summary " + Quote(csv) + " --rank 1 --crs nonsense"), 1,
              "--crs: CRS 'nonsense' is not understood");
  ExpectError(Alphactl("summary " + Quote(csv) + " --rank 1 --crs EPSG:4978"), 1, "geocentric");
  std::filesystem::remove(named);
  std::filesystem::remove(csv);
}

#endif  // GALPHA_WITH_PROJ

// --group-by: each group's shape is the shape of that group's points alone (built as a file of
// their own: the oracle), in the order the groups first appear; a feature without the property is
// the group without a value.
TEST(AlphactlTest, GroupByGivesEachGroupsOwnShape) {
  std::mt19937_64 random(7);
  std::normal_distribution<double> spread(0.0, 1.0);
  std::map<std::string, std::vector<std::array<double, 2>>> by_group;
  std::string features;
  const std::vector<std::pair<std::string, std::array<double, 2>>> centres = {
      {"b", {0, 0}}, {"a", {20, 5}}, {"", {-10, 15}}};
  for (int i = 0; i < 240; ++i) {
    const auto& [group, centre] = centres[static_cast<size_t>(i % 3)];
    const std::array<double, 2> p = {centre[0] + spread(random), centre[1] + spread(random)};
    by_group[group].push_back(p);
    const std::string properties = group.empty() ? R"({"other":1})" : R"({"kind":")" + group + R"("})";
    features += (i ? "," : "") + std::string(R"({"type":"Feature","properties":)") + properties +
                R"(,"geometry":{"type":"Point","coordinates":[)" + Printed(p[0]) + "," + Printed(p[1]) + "]}}";
  }
  const std::string file =
      WriteFile("alphactl_groups.geojson", R"({"type":"FeatureCollection","features":[)" + features + "]}");
  const std::string options = "--crs none --ratio 0.7";
  const nlohmann::json grouped =
      nlohmann::json::parse(Succeeds("shape", file, options + " --group-by kind --format geojson"));
  ASSERT_EQ(grouped["features"].size(), 3u);
  const std::vector<std::string> wkt = SplitLines(Succeeds("shape", file, options + " --group-by kind --format wkt"));
  ASSERT_EQ(wkt.size(), 3u);
  const std::vector<std::string> order = {"b", "a", ""};
  for (size_t g = 0; g < 3; ++g) {
    SCOPED_TRACE(order[g]);
    std::string csv;
    for (const auto& p : by_group[order[g]]) csv += Printed(p[0]) + "," + Printed(p[1]) + "\n";
    const std::string alone = WriteFile("alphactl_group_alone.csv", csv);
    const nlohmann::json expected =
        nlohmann::json::parse(Succeeds("shape", alone, options + " --mode regularized --format geojson"));
    const nlohmann::json& feature = grouped["features"][g];
    if (order[g].empty()) {
      EXPECT_TRUE(feature["properties"]["group"].is_null());
    } else {
      EXPECT_EQ(feature["properties"]["group"], order[g]);
    }
    EXPECT_EQ(feature["properties"]["points"], 80);
    EXPECT_EQ(feature["geometry"], expected["features"][0]["geometry"]);
    EXPECT_EQ(feature["properties"]["area"], expected["features"][0]["properties"]["area"]);
    EXPECT_EQ(wkt[g],
              order[g] + "\t" + SplitLines(Succeeds("shape", alone, options + " --mode regularized --format wkt"))[0]);
    std::filesystem::remove(alone);
  }
  ExpectError(Alphactl("shape " + Quote(file) + " --ratio 0.5 --group-by nope --format wkt --crs none"), 1,
              "no feature has a property 'nope'");
  ExpectError(Alphactl("shape " + Quote(file) + " --ratio 0.5 --group-by kind --format svg"), 2, "not svg");
  ExpectError(Alphactl("shape " + Quote(file) + " --ratio 0.5 --group-by kind --format wkt --mode general"), 2,
              "leave out --mode general");
  ExpectError(Alphactl("shape " + Quote(SquareCsv()) + " --ratio 0.5 --group-by kind --format wkt"), 1,
              "--group-by reads the properties of GeoJSON features");
  std::filesystem::remove(file);
}

// triangulate --group-by: one packed build of all groups, each group's counts those of the
// group's points triangulated as a file of their own (the oracle), in the order the groups first
// appear; a group on one line has its chain's edges and no triangles.
TEST(AlphactlTest, TriangulateGroupByCountsEachGroupAsAlone) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::map<std::string, std::string> alone_csv;
  std::string features;
  auto add = [&](const std::string& group, double x, double y) {
    alone_csv[group] += Printed(x) + "," + Printed(y) + "\n";
    const std::string properties = group.empty() ? R"({"other":1})" : R"({"kind":")" + group + R"("})";
    features += (features.empty() ? "" : ",") + std::string(R"({"type":"Feature","properties":)") + properties +
                R"(,"geometry":{"type":"Point","coordinates":[)" + Printed(x) + "," + Printed(y) + "]}}";
  };
  for (int i = 0; i < 300; ++i) {
    add(i % 3 == 0   ? "field"
        : i % 3 == 1 ? ""
                     : "grid",
        i % 3 == 2 ? (i / 3) % 10 : unit(random), i % 3 == 2 ? (i / 30) : unit(random));
  }
  for (int i = 0; i < 7; ++i) add("fence", i * 0.5, 1.0);  // all on one line
  add("field", 0.5, 0.5);                                  // twice: a duplicate in its group
  add("field", 0.5, 0.5);
  const std::string file =
      WriteFile("alphactl_tri_groups.geojson", R"({"type":"FeatureCollection","features":[)" + features + "]}");
  const nlohmann::json grouped =
      nlohmann::json::parse(Succeeds("triangulate", file, "--backend=cpu --crs none --group-by kind"));
  ASSERT_EQ(grouped["groups"].size(), 4u);
  EXPECT_EQ(grouped["points"], 309);
  EXPECT_EQ(grouped["built_alone"], 0);
  EXPECT_EQ(grouped["backend"], "cpu");
  const std::vector<std::string> order = {"field", "", "grid", "fence"};
  for (size_t g = 0; g < order.size(); ++g) {
    SCOPED_TRACE(order[g]);
    const nlohmann::json& group = grouped["groups"][g];
    if (order[g].empty()) {
      EXPECT_TRUE(group["group"].is_null());
    } else {
      EXPECT_EQ(group["group"], order[g]);
    }
    const std::string alone = WriteFile("alphactl_tri_group_alone.csv", alone_csv[order[g]]);
    const nlohmann::json expected = nlohmann::json::parse(Succeeds("triangulate", alone, "--backend=cpu"));
    for (const char* key : {"points", "distinct_points", "duplicates", "triangles", "edges", "hull_edges"}) {
      EXPECT_EQ(group[key], expected[key]) << key;
    }
    std::filesystem::remove(alone);
  }
  EXPECT_EQ(grouped["groups"][3]["triangles"], 0);
  EXPECT_EQ(grouped["groups"][3]["edges"], 6);
  ExpectError(Alphactl("triangulate " + Quote(file) + " --group-by kind --weights radius --crs none"), 2,
              "--group-by triangulates unweighted groups");
  ExpectError(Alphactl("triangulate " + Quote(file) + " --group-by nope --crs none"), 1,
              "no feature has a property 'nope'");
  // A group outside the input domain is named by its value (the point's index is the group's own).
  const std::string huge = WriteFile(
      "alphactl_tri_groups_huge.geojson",
      R"({"type":"FeatureCollection","features":[)"
      R"({"type":"Feature","properties":{"kind":"a"},"geometry":{"type":"Point","coordinates":[0,0]}},)"
      R"({"type":"Feature","properties":{"kind":"b"},"geometry":{"type":"Point","coordinates":[1e200,0]}}]})");
  ExpectError(Alphactl("triangulate " + Quote(huge) + " --group-by kind --crs none"), 1,
              "group 'b': point 0 (1e+200, 0) has a coordinate of magnitude 2^500");
  std::filesystem::remove(huge);
  std::filesystem::remove(file);
}

TEST(AlphactlTest, ShapesInEveryFormat) {
  const std::string& square = SquareCsv();
  // WKT is the simplest type that holds the shape: one polygon is a POLYGON, in either mode;
  // singular edges or isolated points make a GEOMETRYCOLLECTION; nothing is MULTIPOLYGON EMPTY.
  EXPECT_EQ(Succeeds("shape", square, "--rank 2 --format wkt"), "POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))\n");
  EXPECT_EQ(Succeeds("shape", square, "--rank 2 --format wkt --mode regularized"),
            "POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))\n");
  EXPECT_EQ(Succeeds("shape", square, "--rank 1 --format=wkt"),
            "GEOMETRYCOLLECTION (MULTILINESTRING ((0 0, 1 0), (0 0, 0 1), (1 0, 1 1), (1 1, 0 1)))\n");
  EXPECT_EQ(Succeeds("shape", square, "--rank 0 --format wkt"),
            "GEOMETRYCOLLECTION (MULTIPOINT ((0 0), (1 0), (1 1), (0 1)))\n");
  EXPECT_EQ(Succeeds("shape", square, "--rank 1 --format wkt --mode regularized"), "MULTIPOLYGON EMPTY\n");

  const nlohmann::json geojson = nlohmann::json::parse(Succeeds("shape", square, "--alpha 1 --format geojson"));
  EXPECT_EQ(geojson["type"], "FeatureCollection");
  ASSERT_EQ(geojson["features"].size(), 1u);
  EXPECT_EQ(geojson["features"][0]["geometry"]["type"], "MultiPolygon");
  EXPECT_EQ(geojson["features"][0]["properties"]["area"], 1.0);
  EXPECT_EQ(geojson["features"][0]["geometry"]["coordinates"],
            nlohmann::json::parse("[[[[0,0],[1,0],[1,1],[0,1],[0,0]]]]"));

  const std::string svg = Succeeds("shape", square, "--rank 2 --format svg");
  EXPECT_EQ(svg.rfind("<svg", 0), 0u) << svg;
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
}

TEST(AlphactlTest, MasterListOfTheSquare) {
  // Ranks 1 and 2, grouped vertex < edge < triangle; within a group the family's (id) order.
  auto check = [](const std::string& out, std::vector<std::string> expected) {
    std::vector<std::string> lines = SplitLines(out);
    std::string kinds;
    for (const std::string& line : lines) kinds += line.substr(0, 1);
    EXPECT_TRUE(std::is_sorted(kinds.begin(), kinds.end(), [](char a, char b) {
      return std::string("vet").find(a) < std::string("vet").find(b);
    })) << out;
    std::sort(lines.begin(), lines.end());
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(lines, expected);
  };
  check(Succeeds("masterlist", SquareCsv(), "--rank 1"),
        {"v 0 MU_LOW", "v 1 MU_LOW", "v 2 MU_LOW", "v 3 MU_LOW", "e 0 1 RHO", "e 0 3 RHO", "e 1 2 RHO", "e 2 3 RHO"});
  check(Succeeds("masterlist", SquareCsv(), "--rank 2"),
        {"e 0 1 MU_LOW", "e 0 3 MU_LOW", "e 1 2 MU_LOW", "e 2 3 MU_LOW", "e 1 3 RHO", "e 1 3 MU_LOW", "e 1 3 MU_HIGH",
         "t 0 1 3 RHO", "t 1 2 3 RHO"});
  ExpectError(Alphactl("masterlist " + Quote(SquareCsv()) + " --rank 0"), 2, "--rank 0 is outside 1..2");
  ExpectError(Alphactl("masterlist " + Quote(SquareCsv()) + " --rank 3"), 2, "--rank 3 is outside 1..2");
  ExpectError(Alphactl("masterlist " + Quote(SquareCsv())), 2, "missing --rank");
}

TEST(AlphactlTest, OptimalRanks) {
  EXPECT_EQ(Succeeds("optimal", SquareCsv(), "--components 1"),
            "{\"components\":1,\"regularized\":{\"rank\":2,\"alpha_sq\":0.5,\"solid_components\":1,\"holes\":0},"
            "\"general\":{\"rank\":1,\"alpha_sq\":0.25,\"components\":1,\"holes\":1}}\n");
  EXPECT_EQ(Succeeds("optimal", SquareCsv(), "--components 4"),
            "{\"components\":4,\"regularized\":{\"rank\":2,\"alpha_sq\":0.5,\"solid_components\":1,\"holes\":0},"
            "\"general\":{\"rank\":0,\"alpha_sq\":0,\"components\":4,\"holes\":0}}\n");
  // At 1/4 the sides enclose a hole, which the triangles fill at 1/2: with at most 0 holes the
  // general answer moves there.
  EXPECT_EQ(Succeeds("optimal", SquareCsv(), "--components 1 --holes 0"),
            "{\"components\":1,\"holes\":0,\"regularized\":{\"rank\":2,\"alpha_sq\":0.5,\"solid_components\":1,"
            "\"holes\":0},\"general\":{\"rank\":2,\"alpha_sq\":0.5,\"components\":1,\"holes\":0}}\n");
  ExpectError(Alphactl("optimal " + Quote(SquareCsv()) + " --components 1 --holes -1"), 2, "--holes '-1'");
  // Two unit squares 9 apart: each square is connected at 1/4 and solid at 1/2.
  const std::string two = WriteFile("alphactl_two_squares.txt", "0 0\n1 0\n1 1\n0 1\n10 0\n11 0\n11 1\n10 1\n");
  const nlohmann::json j = nlohmann::json::parse(Succeeds("optimal", two, "--components 2"));
  EXPECT_EQ(j, nlohmann::json::parse("{\"components\":2,\"regularized\":{\"rank\":2,\"alpha_sq\":0.5,"
                                     "\"solid_components\":2,\"holes\":0},\"general\":{\"rank\":1,\"alpha_sq\":0.25,"
                                     "\"components\":2,\"holes\":2}}"));
  const nlohmann::json one = nlohmann::json::parse(Succeeds("optimal", two, "--components 1"));
  EXPECT_GT(one["general"]["rank"].get<int>(), 2);
  EXPECT_EQ(one["general"]["components"], 1);
  // Collinear points never have a triangle: no regularized answer.
  const std::string line = WriteFile("alphactl_line.txt", "0 0\n1 0\n3 0\n");
  EXPECT_EQ(Succeeds("optimal", line, "--components 1"),
            "{\"components\":1,\"regularized\":null,\"general\":{\"rank\":2,\"alpha_sq\":1,\"components\":1,"
            "\"holes\":0}}\n");
  ExpectError(Alphactl("optimal " + Quote(line) + " --components 0"), 2, "--components '0'");
  ExpectError(Alphactl("optimal " + Quote(line) + " --components x"), 2, "--components 'x'");
  ExpectError(Alphactl("optimal " + Quote(line)), 2, "missing --components");
  std::filesystem::remove(two);
  std::filesystem::remove(line);
}

// The unit square by hand: the four sides are born at 1/4 and join the four points (three H0 pairs
// by the elder rule: each later vertex dies as the edge in canonical order reaches it), the last
// side closes the square (an H1 class born at 1/4), and the triangles fill it at 1/2.
TEST(AlphactlTest, PersistenceOfTheSquareInEveryFormat) {
  EXPECT_EQ(Succeeds("persistence", SquareCsv(), ""),
            "H0 0 0.25 0 1 1 0-1\n"
            "H0 0 0.25 0 1 2 1-2\n"
            "H0 0 0.25 0 1 3 0-3\n"
            "H0 0 inf 0 - 0 -\n"
            "H1 0.25 0.5 1 2 2-3 1-2-3\n");
  EXPECT_EQ(Succeeds("persistence", SquareCsv(), "--dimension 1 --format csv"),
            "dimension,birth_alpha_sq,death_alpha_sq,birth_rank,death_rank,creator,killer\n"
            "1,0.25,0.5,1,2,2-3,1-2-3\n");
  const std::vector<std::string> json = SplitLines(Succeeds("persistence", SquareCsv(), "--format json"));
  ASSERT_EQ(json.size(), 5u);
  EXPECT_EQ(nlohmann::json::parse(json[3]),
            nlohmann::json::parse("{\"dimension\":0,\"birth_alpha_sq\":0,\"death_alpha_sq\":null,\"birth_rank\":0,"
                                  "\"death_rank\":null,\"creator\":[0],\"killer\":null}"));
  EXPECT_EQ(nlohmann::json::parse(json[4])["killer"], nlohmann::json::parse("[1,2,3]"));
  // The minimum persistence keeps the essential class whatever it is.
  EXPECT_EQ(Succeeds("persistence", SquareCsv(), "--min-persistence 0.3"), "H0 0 inf 0 - 0 -\n");
  const std::string svg = Succeeds("persistence", SquareCsv(), "--format svg");
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  // One circle a class, and the legend's two.
  size_t circles = 0;
  for (size_t at = svg.find("<circle"); at != std::string::npos; at = svg.find("<circle", at + 1)) ++circles;
  EXPECT_EQ(circles, 5u + 2u);
  ExpectError(Alphactl("persistence " + Quote(SquareCsv()) + " --dimension 2"), 2, "dimensions 0 and 1");
  ExpectError(Alphactl("persistence " + Quote(SquareCsv()) + " --min-persistence -1"), 2, "negative");
  ExpectError(Alphactl("persistence " + Quote(SquareCsv()) + " --format png"), 2, "'png'");
}

// A 12 x 12 integer grid without a 3 x 3 block: at alpha_sq 1/2 one octagonal hole of area 14 (a
// 4 x 4 square less the four corner triangles that are in).
TEST(AlphactlTest, HolesAreListedAndFilledBelowAnArea) {
  std::string text;
  for (int i = 0; i < 12; ++i) {
    for (int j = 0; j < 12; ++j) {
      if (i < 4 || i > 6 || j < 4 || j > 6) text += std::to_string(i) + " " + std::to_string(j) + "\n";
    }
  }
  const std::string grid = WriteFile("alphactl_holed_grid.txt", text);
  EXPECT_EQ(Succeeds("holes", grid, "--alpha-sq 0.5"),
            "14 0 POLYGON ((4 3, 5 3, 6 3, 7 4, 7 5, 7 6, 6 7, 5 7, 4 7, 3 6, 3 5, 3 4, 4 3))\n");
  EXPECT_EQ(Succeeds("holes", grid, "--alpha-sq 0.5 --min-area 14.5"), "");
  const nlohmann::json geojson = nlohmann::json::parse(Succeeds("holes", grid, "--alpha-sq 0.5 --format geojson"));
  ASSERT_EQ(geojson["features"].size(), 1u);
  EXPECT_EQ(geojson["features"][0]["properties"]["area"], 14);
  EXPECT_EQ(geojson["features"][0]["geometry"]["type"], "Polygon");
  const nlohmann::json summary = nlohmann::json::parse(Succeeds("summary", grid, "--alpha-sq 0.5 --mode regularized"));
  EXPECT_EQ(summary["holes"], 1);
  const std::string kept = Succeeds("shape", grid, "--alpha-sq 0.5 --mode regularized --format wkt");
  const std::string filled =
      Succeeds("shape", grid, "--alpha-sq 0.5 --mode regularized --format wkt --min-hole-area 20");
  EXPECT_NE(kept.find("), ("), std::string::npos) << kept;
  EXPECT_EQ(filled.find("), ("), std::string::npos) << filled;
  ExpectError(Alphactl("shape " + Quote(grid) + " --rank 1 --format wkt --min-hole-area -2"), 2, "negative");
  ExpectError(Alphactl("holes " + Quote(grid) + " --rank 1 --format svg"), 2, "'svg'");
  std::filesystem::remove(grid);
}

TEST(AlphactlTest, BenchPrintsEveryStageAndTheCounts) {
  const CommandResult triangulate = Alphactl("triangulate " + Quote(SquareCsv()) + " --backend=cpu");
  ASSERT_EQ(triangulate.exit_code, 0) << triangulate.err;
  const CommandResult run = Alphactl("bench " + Quote(SquareCsv()) + " --repeat 2 --backend=cpu");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::map<std::string, std::string> rows;
  for (const std::string& line : SplitLines(run.out)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string name, value, extra;
    fields >> name >> value;
    EXPECT_FALSE(fields >> extra) << line;
    rows[name] = value;
  }
  EXPECT_NE(run.out.find("best of 2 builds"), std::string::npos) << run.out;
  for (const auto& stage : nlohmann::json::parse(triangulate.out)["stage_ms"].items()) {
    EXPECT_TRUE(rows.count(stage.key())) << stage.key() << " in\n" << run.out;
  }
  for (const char* name :
       {"spectrum_sort", "master_list", "components", "total", "peak_memory_bytes", "bytes_per_point",
        "comparisons_filter", "comparisons_bounded_exact", "comparisons_cpu_fallback"}) {
    ASSERT_TRUE(rows.count(name)) << name << " in\n" << run.out;
    EXPECT_GE(std::stod(rows[name]), 0.0) << name;
  }
  EXPECT_GT(std::stod(rows["total"]), 0.0);
  EXPECT_GT(std::stoll(rows["peak_memory_bytes"]), 0);
  EXPECT_NEAR(std::stod(rows["bytes_per_point"]), std::stoll(rows["peak_memory_bytes"]) / 4.0, 0.051);
  // Six births in two exact ties: the spectrum sort compared at least one pair.
  EXPECT_GT(std::stoll(rows["comparisons_filter"]) + std::stoll(rows["comparisons_bounded_exact"]) +
                std::stoll(rows["comparisons_cpu_fallback"]),
            0);
  EXPECT_EQ(rows["spectrum_size"], "2");
  EXPECT_EQ(rows["backend"], "cpu");
  ExpectError(Alphactl("bench " + Quote(SquareCsv()) + " --repeat 0"), 2, "--repeat '0'");
}

TEST(AlphactlTest, DuplicatesAreNamedByTheirFirstOccurrence) {
  // The square with (0,0) again at 2 and (1,0) again at 4: points 0, 1, 3 (1,1), 5 (0,1).
  const std::string path = WriteFile("alphactl_duplicates.csv", "0,0\n1,0\n0,0\n1,1\n1,0\n0,1\n");
  EXPECT_EQ(Succeeds("classify", path, "--rank 2"),
            Lines({"v 0 REGULAR", "v 1 REGULAR", "v 3 REGULAR", "v 5 REGULAR", "e 0 1 REGULAR", "e 0 5 REGULAR",
                   "e 1 3 REGULAR", "e 1 5 INTERIOR", "e 3 5 REGULAR", "t 0 1 5 INTERIOR", "t 1 3 5 INTERIOR"}));
  const nlohmann::json j = nlohmann::json::parse(Succeeds("summary", path, "--rank 1"));
  EXPECT_EQ(j["points"], 6);
  EXPECT_EQ(j["distinct_points"], 4);
  EXPECT_EQ(j["duplicates"], 2);
  EXPECT_EQ(j["vertices"]["REGULAR"], 4);
  EXPECT_EQ(j["components"], 1);
  std::filesystem::remove(path);
}

TEST(AlphactlTest, CollinearAndTinyInputs) {
  // 0 (3,0), 1 (0,0), 2 (1,0) on a line: edges 1-2 (rho^2 1/4) and 0-2 (1); no triangles.
  const std::string line = WriteFile("alphactl_collinear.txt", "3 0\n0 0\n1 0\n");
  EXPECT_EQ(Succeeds("spectrum", line, ""), "0.25\n1\n");
  EXPECT_EQ(Succeeds("classify", line, "--rank 1"),
            Lines({"v 0 SINGULAR", "v 1 REGULAR", "v 2 REGULAR", "e 0 2 EXTERIOR", "e 1 2 SINGULAR"}));
  EXPECT_EQ(Succeeds("classify", line, "--alpha-sq 1e9"),
            Lines({"v 0 REGULAR", "v 1 REGULAR", "v 2 REGULAR", "e 0 2 SINGULAR", "e 1 2 SINGULAR"}));
  EXPECT_EQ(Succeeds("shape", line, "--rank 2 --format wkt"),
            "GEOMETRYCOLLECTION (MULTILINESTRING ((3 0, 1 0), (0 0, 1 0)))\n");

  const std::string one = WriteFile("alphactl_one.txt", "5 5\n");
  EXPECT_EQ(Succeeds("spectrum", one, ""), "");
  EXPECT_EQ(Succeeds("classify", one, "--rank 0"), "v 0 SINGULAR\n");
  EXPECT_EQ(Succeeds("shape", one, "--alpha-sq 7 --format wkt"), "GEOMETRYCOLLECTION (MULTIPOINT ((5 5)))\n");
  EXPECT_EQ(nlohmann::json::parse(Succeeds("summary", one, "--rank 0"))["components"], 1);
  ExpectError(Alphactl("classify " + Quote(one) + " --rank 1"), 2, "--rank 1 is outside 0..0");
  ExpectError(Alphactl("masterlist " + Quote(one) + " --rank 1"), 2, "the spectrum is empty");

  const std::string two = WriteBin("alphactl_two.bin", {{{0, 0}}, {{2, 0}}});
  EXPECT_EQ(Succeeds("spectrum", two, ""), "1\n");
  EXPECT_EQ(Succeeds("classify", two, "--rank 0"), "v 0 SINGULAR\nv 1 SINGULAR\ne 0 1 EXTERIOR\n");
  EXPECT_EQ(Succeeds("classify", two, "--alpha 1"), "v 0 REGULAR\nv 1 REGULAR\ne 0 1 SINGULAR\n");
  EXPECT_EQ(Succeeds("masterlist", two, "--rank 1"), "v 0 MU_LOW\nv 1 MU_LOW\ne 0 1 RHO\n");

  const std::string empty = WriteBin("alphactl_empty.bin", {});
  EXPECT_EQ(Succeeds("spectrum", empty, ""), "");
  EXPECT_EQ(Succeeds("classify", empty, "--rank 0"), "");
  EXPECT_EQ(nlohmann::json::parse(Succeeds("summary", empty, "--rank 0"))["points"], 0);
  for (const std::string& path : {line, one, two, empty}) std::filesystem::remove(path);
}

TEST(AlphactlTest, ErrorsAreOneLineAndANonZeroExit) {
  const CommandResult missing = Alphactl("triangulate /nonexistent/points.csv");
  ExpectError(missing, 1, "does not exist");
  ExpectError(Alphactl("classify /nonexistent/points.bin --rank 1"), 1, "does not exist");
  const std::string directory = std::filesystem::temp_directory_path();
  ExpectError(Alphactl("summary " + Quote(directory) + " --rank 0"), 1, "is a directory");
  ExpectError(Alphactl("triangulate " + Quote(directory)), 1, "is a directory");
  const std::string truncated = WriteFile("alphactl_truncated.bin", std::string("\x05\0\0\0\0\0\0\0", 8));
  ExpectError(Alphactl("spectrum " + Quote(truncated)), 1, "truncated");
  std::filesystem::remove(truncated);

  const std::string bad = WriteFile("alphactl_bad.csv", "1,2\n3,oops\n");
  ExpectError(Alphactl("triangulate " + Quote(bad)), 1, ":2:");
  ExpectError(Alphactl("summary " + Quote(bad) + " --rank 0"), 1, ":2:");
  std::filesystem::remove(bad);

  const std::string nan = WriteFile("alphactl_nan.csv", "0,0\n1,nan\n");
  ExpectError(Alphactl("triangulate " + Quote(nan) + " --backend=cpu"), 1, "point 1");
  ExpectError(Alphactl("classify " + Quote(nan) + " --rank 0"), 1, "point 1");
  std::filesystem::remove(nan);

  ExpectError(Alphactl("triangulate x.csv --backend=tpu"), 2, "tpu");
  ExpectError(Alphactl("spectrum x.csv --backend tpu"), 2, "tpu");

  const std::string square = Quote(SquareCsv());
  ExpectError(Alphactl("classify " + square), 2, "missing threshold");
  ExpectError(Alphactl("summary " + square + " --rank 1 --alpha 2"), 2, "only one threshold");
  ExpectError(Alphactl("classify " + square + " --alpha-sq 1 --alpha-sq 2"), 2, "--alpha-sq given twice");
  ExpectError(Alphactl("classify " + square + " --alpha-sq abc"), 2, "--alpha-sq 'abc'");
  ExpectError(Alphactl("classify " + square + " --alpha-sq 0.5x"), 2, "--alpha-sq '0.5x'");
  ExpectError(Alphactl("classify " + square + " --alpha-sq ''"), 2, "--alpha-sq ''");
  ExpectError(Alphactl("classify " + square + " --alpha-sq nan"), 2, "--alpha-sq 'nan'");
  ExpectError(Alphactl("classify " + square + " --alpha inf"), 2, "--alpha 'inf'");
  ExpectError(Alphactl("classify " + square + " --alpha -1"), 2, "--alpha '-1'");
  ExpectError(Alphactl("classify " + square + " --rank 1.5"), 2, "--rank '1.5'");
  ExpectError(Alphactl("classify " + square + " --rank -1"), 2, "--rank '-1'");
  ExpectError(Alphactl("classify " + square + " --rank 99999999999999999999"), 2, "--rank '99999999999999999999'");
  ExpectError(Alphactl("classify " + square + " --rank 3"), 2, "--rank 3 is outside 0..2");
  ExpectError(Alphactl("classify " + square + " --rank"), 2, "--rank needs a value");
  ExpectError(Alphactl("classify " + square + " --rank 1 --mode sideways"), 2, "--mode 'sideways'");
  ExpectError(Alphactl("classify " + square + " --rank 1 --vertex-rule x"), 2, "--vertex-rule 'x'");
  ExpectError(Alphactl("classify " + square + " --rank 1 --frobnicate 3"), 2, "unknown option '--frobnicate'");
  ExpectError(Alphactl("classify " + square + " " + square + " --rank 1"), 2, "unexpected argument");
  ExpectError(Alphactl("classify --rank 1"), 2, "missing FILE");
  ExpectError(Alphactl("shape " + square + " --rank 1"), 2, "missing --format");
  ExpectError(Alphactl("shape " + square + " --rank 1 --format pdf"), 2, "--format 'pdf'");
  ExpectError(Alphactl("shape " + square + " --rank 1 --format wkt --vertex-rule cgal"), 2, "--vertex-rule");
  ExpectError(Alphactl("spectrum " + square + " --rank 1"), 2, "unknown option '--rank'");
  ExpectError(Alphactl("frobnicate " + square), 2, "unknown command 'frobnicate'");
}

TEST(AlphactlTest, RealDataAgreesAcrossCommands) {
  const std::string file = galpha::testdata::DataDir() + "/gps_tracks_slovenia_croatia.bin";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " is missing";
  const nlohmann::json summary = nlohmann::json::parse(Succeeds("summary", file, "--rank 100"));
  const std::string classes = Succeeds("classify", file, "--rank 100");
  std::map<std::string, nlohmann::json> counts;
  std::map<std::string, std::string> group{{"v", "vertices"}, {"e", "edges"}, {"t", "triangles"}};
  for (const auto& [kind, name] : group) {
    counts[name] = {{"EXTERIOR", 0}, {"SINGULAR", 0}, {"REGULAR", 0}, {"INTERIOR", 0}};
  }
  std::string previous_kind = "v";
  std::vector<uint32_t> previous;
  for (const std::string& line : SplitLines(classes)) {
    std::istringstream fields(line);
    std::string kind, word;
    std::vector<uint32_t> indices;
    fields >> kind;
    while (fields >> word && std::isdigit(static_cast<unsigned char>(word[0]))) indices.push_back(std::stoul(word));
    ASSERT_TRUE(group.count(kind)) << line;
    ASSERT_EQ(indices.size(), kind == "v" ? 1u : kind == "e" ? 2u : 3u) << line;
    EXPECT_TRUE(std::is_sorted(indices.begin(), indices.end())) << line;
    if (kind == previous_kind) {
      EXPECT_LT(previous, indices) << line;
    } else {
      EXPECT_EQ(std::string("vet").find(previous_kind) + 1, std::string("vet").find(kind)) << line;
    }
    previous_kind = kind;
    previous = indices;
    counts[group[kind]][word] = counts[group[kind]][word].get<int>() + 1;
  }
  for (const auto& [kind, name] : group) EXPECT_EQ(counts[name], summary[name]) << name;
  EXPECT_EQ(summary["distinct_points"],
            summary["vertices"]["EXTERIOR"].get<int>() + summary["vertices"]["SINGULAR"].get<int>() +
                summary["vertices"]["REGULAR"].get<int>() + summary["vertices"]["INTERIOR"].get<int>());
  EXPECT_EQ(summary["points"], 1351);
  EXPECT_EQ(summary["level"], 100);
  EXPECT_EQ(SplitLines(Succeeds("spectrum", file, "")).size(), summary["spectrum_size"].get<size_t>());
  EXPECT_EQ(summary["alpha_sq"].get<double>(), std::stod(SplitLines(Succeeds("spectrum", file, ""))[99]));
  // The published double of rank 100, given back as --alpha-sq, is compared exactly: level 100 when
  // it rounded up, 99 when it rounded down.
  const int64_t level =
      nlohmann::json::parse(Succeeds("summary", file, "--alpha-sq " + Printed(summary["alpha_sq"].get<double>())))
          .at("level")
          .get<int64_t>();
  EXPECT_TRUE(level == 99 || level == 100) << level;

  // The summary's interior area is the shape's area (same triangles, same sums).
  const nlohmann::json shape = nlohmann::json::parse(Succeeds("shape", file, "--rank 100 --format geojson"));
  double area = 0.0;
  for (const auto& feature : shape["features"]) {
    if (feature["properties"]["kind"] == "polygons") area = feature["properties"]["area"].get<double>();
  }
  EXPECT_EQ(area, summary["interior_area"].get<double>());
}

TEST(AlphactlTest, ProgressGoesToStandardErrorForLargeInputs) {
  const std::string file = galpha::testdata::DataDir() + "/lidar_autzen.bin";  // 110000 points
  if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " is missing";
  const CommandResult run = Alphactl("summary " + Quote(file) + " --rank 10");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(nlohmann::json::parse(run.out)["points"], 110000);
  const std::vector<std::string> lines = SplitLines(run.err);
  ASSERT_EQ(lines.size(), 3u) << run.err;
  EXPECT_EQ(lines[0].rfind("alphactl: triangulation done (50%, ", 0), 0u) << lines[0];
  EXPECT_EQ(lines[1].rfind("alphactl: alpha done (90%, ", 0), 0u) << lines[1];
  EXPECT_EQ(lines[2].rfind("alphactl: components done (100%, ", 0), 0u) << lines[2];
  // Small inputs are quiet (Run checks that stderr is empty).
  Succeeds("summary", SquareCsv(), "--rank 0");
}

// Input that never ends, or is larger than a server builds, is refused with its reason. Each run
// is capped at 4 GiB of address space, so that an alphactl that did read without bound fails
// rather than take the machine's memory.
constexpr char kMemoryCap[] = "ulimit -v 4194304; ";

TEST(AlphactlTest, DevicesAndEndlessInputAreRefused) {
  ExpectError(Alphactl("triangulate /dev/zero", kMemoryCap), 1,
              "points file '/dev/zero' is a character device: alphactl reads regular files, named pipes and '-'");
  ExpectError(Alphactl("summary /dev/zero --rank 0", kMemoryCap), 1, "'/dev/zero' is a character device");
  // A pipe of zero bytes, and one line that does not end, stop at the line limit.
  const std::string zeros = std::string(kMemoryCap) + "head -c 200000000 /dev/zero | ";
  ExpectError(Alphactl("triangulate -", zeros), 1,
              "standard input: line 1 (from byte offset 0) is longer than 65536 bytes");
  ExpectError(Alphactl("spectrum /dev/stdin", zeros + "tr '\\0' 7 | "), 1,
              "/dev/stdin: line 1 (from byte offset 0) is longer than 65536 bytes");
  ExpectError(Alphactl("triangulate -", std::string(kMemoryCap) + "printf '1 2\\n3 4\\n' | cat - /dev/zero | "), 1,
              "line 3 (from byte offset 8) is longer than 65536 bytes");
  // A .bin with room for more points than a default server builds is refused from its size (a
  // sparse file: nothing is written or read).
  const std::string big = std::filesystem::temp_directory_path() / "alphactl_big.bin";
  {
    std::ofstream out(big, std::ios::binary);
    const uint64_t n = 100000001;
    out.write(reinterpret_cast<const char*>(&n), sizeof n);
  }
  std::filesystem::resize_file(big, 8 + 16 * uint64_t{100000001});
  ExpectError(Alphactl("triangulate " + Quote(big), kMemoryCap), 1,
              "room for 100000001 points: more than 100000000, the limit (--max-points raises it)");
  std::filesystem::remove(big);
}

TEST(AlphactlTest, PipesAndStandardInputCarryText) {
  const std::string square = "printf 'x,y\\n0,0\\n1,0\\n1,1\\n0,1\\n' | ";
  const CommandResult piped = Alphactl("summary - --rank 2", square);
  ASSERT_EQ(piped.exit_code, 0) << piped.err;
  nlohmann::json from_pipe = nlohmann::json::parse(piped.out);
  EXPECT_EQ(from_pipe["file"], "-");
  from_pipe.erase("file");
  nlohmann::json from_file = nlohmann::json::parse(Succeeds("summary", SquareCsv(), "--rank 2"));
  from_file.erase("file");
  EXPECT_EQ(from_pipe, from_file);
  const CommandResult dev_stdin = Alphactl("spectrum /dev/stdin", square);
  EXPECT_EQ(dev_stdin.exit_code, 0) << dev_stdin.err;
  EXPECT_EQ(dev_stdin.out, Succeeds("spectrum", SquareCsv(), ""));
  // bench builds R times from one read of the pipe.
  const CommandResult bench = Alphactl("bench - --repeat 2 --backend cpu", square);
  EXPECT_EQ(bench.exit_code, 0) << bench.err;
  EXPECT_NE(bench.out.find("# -: 4 points, 4 distinct, best of 2 builds"), std::string::npos) << bench.out;
  ExpectError(Alphactl("spectrum - < /dev/null"), 1, "standard input is a character device");
  ExpectError(Alphactl("spectrum -", "printf '1 2\\n1 oops\\n' | "), 1, "standard input:2: expected x and y");
}

TEST(AlphactlTest, MaxPointsBoundsEveryInput) {
  const std::string four = Quote(SquareCsv());
  ExpectError(Alphactl("--max-points 3 triangulate " + four), 1, "more than 3 points, the limit");
  ExpectError(Alphactl("summary " + four + " --rank 0 --max-points=3"), 1, "more than 3 points, the limit");
  EXPECT_EQ(Alphactl("--max-points 4 summary " + four + " --rank 0").exit_code, 0);
  ExpectError(Alphactl("spectrum - --max-points 3", "printf '0 0\\n1 0\\n0 1\\n1 1\\n' | "), 1,
              "standard input: more than 3 points");
  const std::string bin = WriteBin("alphactl_five.bin", {{0, 0}, {1, 0}, {0, 1}, {1, 1}, {2, 2}});
  ExpectError(Alphactl("--max-points 4 spectrum " + Quote(bin)), 1, "room for 5 points: more than 4");
  std::filesystem::remove(bin);
  ExpectError(Alphactl("spectrum " + four + " --max-points 0"), 2, "--max-points '0' is out of range");
  ExpectError(Alphactl("spectrum " + four + " --max-points 1073741825"), 2,
              "--max-points '1073741825' is more than 1073741824");
}

// Options for every command may come before it, as git's and kubectl's do.
TEST(AlphactlTest, GlobalOptionsComeBeforeOrAfterTheCommand) {
  const std::string square = Quote(SquareCsv());
  const CommandResult after = Alphactl("summary " + square + " --rank 1 --backend cpu");
  const CommandResult before = Alphactl("--backend cpu summary " + square + " --rank 1");
  const CommandResult before_equals = Alphactl("--backend=cpu --max-points=10 summary " + square + " --rank 1");
  ASSERT_EQ(after.exit_code, 0) << after.err;
  EXPECT_EQ(before.exit_code, 0) << before.err;
  EXPECT_EQ(before.out, after.out);
  EXPECT_EQ(before_equals.out, after.out);
  const CommandResult triangulate = Alphactl("--backend cpu triangulate " + square);
  ASSERT_EQ(triangulate.exit_code, 0) << triangulate.err;
  EXPECT_EQ(nlohmann::json::parse(triangulate.out)["backend"], "cpu");

  ExpectError(
      Alphactl("--rank 1 summary " + square), 2,
      "unknown option '--rank' before the command (only --backend, --server, --tls-ca, --encoding, --max-points");
  ExpectError(Alphactl("--frobnicate summary " + square), 2, "unknown option '--frobnicate' before the command");
  ExpectError(Alphactl("-x summary " + square), 2, "unknown option '-x' before the command");
  ExpectError(Alphactl("--backend cpu summary " + square + " --rank 1 --backend cpu"), 2, "--backend given twice");
  ExpectError(Alphactl("--tls-ca ca.pem summary " + square + " --rank 1"), 2, "--tls-ca needs --server");
  ExpectError(Alphactl("--backend cpu --server localhost:1 spectrum " + square), 2,
              "--backend applies to local builds");
  ExpectError(Alphactl("--backend=cpu"), 2, "missing COMMAND");
  ExpectError(Alphactl("--server"), 2, "option --server needs a value");
  ExpectError(Alphactl("--backend cpu -- summary " + square), 2, "expected a command before '--'");
  ExpectError(Alphactl("--backend cpu frobnicate " + square), 2, "unknown command 'frobnicate'");
  const CommandResult help = Alphactl("--backend cpu help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("GLOBAL OPTIONS"), std::string::npos);
}

// The same points as a LAS point cloud, a GeoPackage (with GDAL) and delimited text: the same
// spectrum and classification. The LAS doubles are computed here as offset + scale * X with the
// product stored first (never fused), and written to the text with 17 significant digits.
TEST(AlphactlTest, LasAndGeoPackageGiveWhatTheSameCsvGives) {
  galpha::testing::LasSpec spec;
  spec.format = 1;
  spec.scale[0] = 0.01;
  spec.scale[1] = 0.001;
  spec.offset[0] = 637000.0;
  spec.offset[1] = 849000.0;
  uint32_t state = 12345;
  const auto next = [&state] { return static_cast<int32_t>((state = state * 1664525u + 1013904223u) >> 12) - 500000; };
  for (int i = 0; i < 60; ++i) spec.xy.emplace_back(next(), next());
  std::vector<galpha::Point2> points;
  std::string csv = "x,y\n";
  for (const auto& [x, y] : spec.xy) {
    volatile double x_product = spec.scale[0] * x, y_product = spec.scale[1] * y;
    points.push_back({x_product + spec.offset[0], y_product + spec.offset[1]});
    char line[80];
    std::snprintf(line, sizeof line, "%.17g,%.17g\n", points.back().x, points.back().y);
    csv += line;
  }
  const std::string csv_path = WriteFile("alphactl_cloud.csv", csv);
  const std::string las_path = WriteFile("alphactl_cloud.las", galpha::testing::LasFileBytes(spec));
  const std::string spectrum = Succeeds("spectrum", csv_path, "");
  ASSERT_GT(SplitLines(spectrum).size(), 10u);
  EXPECT_EQ(Succeeds("spectrum", las_path, ""), spectrum);
  EXPECT_EQ(Succeeds("classify", las_path, "--rank 7"), Succeeds("classify", csv_path, "--rank 7"));
  ExpectError(Alphactl("--max-points 59 spectrum " + Quote(las_path)), 1,
              "has 60 points: more than 59, the limit (--max-points raises it)");
  ExpectError(Alphactl("spectrum " + Quote(las_path) + " --layer points"), 1,
              "--layer applies to Shapefiles, GeoPackages and FlatGeobuf files (.shp, .gpkg, .fgb), not to");
  const std::string laz_path = WriteFile("alphactl_cloud.laz", galpha::testing::LasFileBytes(spec));
  ExpectError(Alphactl("spectrum " + Quote(laz_path)), 1, "is compressed LAS (LAZ), which is not read");

  const std::string gpkg_path = std::filesystem::temp_directory_path() / "alphactl_cloud.gpkg";
  if (galpha::testing::VectorWriterAvailable()) {
    std::vector<galpha::testing::VectorFeature> features;
    features.reserve(points.size());
    for (const galpha::Point2& p : points) features.push_back({galpha::testing::VectorGeometry::kPoint, {p}});
    ASSERT_TRUE(
        galpha::testing::WriteVectorFile(gpkg_path, "GPKG", {{"empty", {}, ""}, {"cloud", features, "EPSG:32610"}})
            .ok());
    EXPECT_EQ(Succeeds("spectrum", gpkg_path, "--layer cloud"), spectrum);
    EXPECT_EQ(Succeeds("classify", gpkg_path, "--rank 7 --layer=cloud"), Succeeds("classify", csv_path, "--rank 7"));
    ExpectError(Alphactl("--layer nope spectrum " + Quote(gpkg_path)), 1, "has no layer 'nope' (its layers: ");
    ExpectError(Alphactl("--layer cloud --max-points 10 spectrum " + Quote(gpkg_path)), 1,
                "layer 'cloud': more than 10 points, the limit (--max-points raises it)");
  } else {
    WriteFile("alphactl_cloud.gpkg", "not read");
    ExpectError(Alphactl("spectrum " + Quote(gpkg_path)), 1, "this build has no GDAL");
  }
  for (const std::string& path : {csv_path, las_path, laz_path, gpkg_path}) std::filesystem::remove(path);
}

}  // namespace
