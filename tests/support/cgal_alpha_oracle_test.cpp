// The CGAL alpha-shape oracle itself, on hand-computable inputs and on GUDHI's documented example.
#include "tests/support/cgal_alpha_oracle.hpp"

#include <gmpxx.h>

#include <cstdint>
#include <fstream>
#include <initializer_list>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/base/point.hpp"
#include "gtest/gtest.h"

namespace galpha::testing {
namespace {

using Edge = std::pair<uint32_t, uint32_t>;
constexpr OracleClass kExt = OracleClass::kExterior;
constexpr OracleClass kSing = OracleClass::kSingular;
constexpr OracleClass kReg = OracleClass::kRegular;
constexpr OracleClass kInt = OracleClass::kInterior;

mpq_class Q(const char* text) { return mpq_class(text); }

std::vector<mpq_class> Qs(std::initializer_list<const char*> texts) {
  std::vector<mpq_class> out;
  for (const char* t : texts) out.push_back(Q(t));
  return out;
}

// (0,0), (4,0), (2,3): circumcenter (2, 5/6), r^2 = 169/36; every edge unattached.
const std::vector<Point2> kAcute = {{0, 0}, {4, 0}, {2, 3}};

TEST(CgalAlphaOracleTest, AcuteTriangle) {
  const CgalAlphaOracle oracle(kAcute);
  EXPECT_EQ(oracle.dimension(), 2);
  EXPECT_EQ(oracle.spectrum(), Qs({"13/4", "4", "169/36"}));

  auto c = oracle.Classify(Q("3"));
  EXPECT_EQ(c.edges, (std::map<Edge, OracleClass>{{{0, 1}, kExt}, {{0, 2}, kExt}, {{1, 2}, kExt}}));
  EXPECT_EQ(c.vertices, (std::map<uint32_t, OracleClass>{{0, kSing}, {1, kSing}, {2, kSing}}));
  EXPECT_EQ(c.interior_triangles, 0u);
  EXPECT_EQ(c.solid_components, 0u);

  // Closed at the threshold: the sides are in at exactly 13/4.
  c = oracle.Classify(Q("13/4"));
  EXPECT_EQ(c.edges, (std::map<Edge, OracleClass>{{{0, 1}, kExt}, {{0, 2}, kSing}, {{1, 2}, kSing}}));
  EXPECT_EQ(c.vertices.at(0), kSing);  // CGAL: singular until a triangle is in
  EXPECT_EQ(c.regularized_edges_regular, 0u);
  EXPECT_EQ(c.regularized_edges_singular, 2u);

  // Exact: a hair below the circumradius the triangle is still out.
  c = oracle.Classify(Q("169/36") - Q("1/1000000000000000000000000000000"));
  EXPECT_EQ(c.interior_triangles, 0u);
  EXPECT_EQ(c.edges.at({0, 1}), kSing);

  for (const char* alpha : {"169/36", "1000000"}) {
    c = oracle.Classify(Q(alpha));
    EXPECT_EQ(c.edges, (std::map<Edge, OracleClass>{{{0, 1}, kReg}, {{0, 2}, kReg}, {{1, 2}, kReg}})) << alpha;
    EXPECT_EQ(c.vertices, (std::map<uint32_t, OracleClass>{{0, kReg}, {1, kReg}, {2, kReg}}));
    EXPECT_EQ(c.interior_triangles, 1u);
    EXPECT_EQ(c.solid_components, 1u);
    EXPECT_EQ(c.regularized_edges_regular, 3u);
    EXPECT_EQ(c.regularized_edges_singular, 0u);
  }
  EXPECT_EQ(oracle.AlphaSolid(), Q("169/36"));
  EXPECT_EQ(oracle.OptimalAlpha(1), Q("169/36"));  // the last spectrum value: no "next" one
}

TEST(CgalAlphaOracleTest, ObtuseTriangleHasAnAttachedEdge) {
  // (0,0), (4,0), (2,1): circumcenter (2, -3/2), r^2 = 25/4; (2,1) is inside the base's
  // diametral circle, so the base (rho^2 = 4) is attached and 4 is not in the spectrum.
  const CgalAlphaOracle oracle(std::vector<Point2>{{0, 0}, {4, 0}, {2, 1}});
  EXPECT_EQ(oracle.spectrum(), Qs({"5/4", "25/4"}));
  auto c = oracle.Classify(Q("4"));
  EXPECT_EQ(c.edges, (std::map<Edge, OracleClass>{{{0, 1}, kExt}, {{0, 2}, kSing}, {{1, 2}, kSing}}));
  c = oracle.Classify(Q("25/4"));
  EXPECT_EQ(c.edges, (std::map<Edge, OracleClass>{{{0, 1}, kReg}, {{0, 2}, kReg}, {{1, 2}, kReg}}));
}

TEST(CgalAlphaOracleTest, SquareIsCoCircular) {
  const CgalAlphaOracle oracle(std::vector<Point2>{{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  EXPECT_EQ(oracle.spectrum(), Qs({"1/4", "1/2"}));  // sides; diagonal = both triangles (merged)

  auto c = oracle.Classify(Q("1/4"));
  ASSERT_EQ(c.edges.size(), 5u);
  const std::set<Edge> sides = {{0, 1}, {1, 2}, {2, 3}, {0, 3}};
  int diagonals = 0;
  for (const auto& [edge, cls] : c.edges) {
    if (sides.count(edge)) {
      EXPECT_EQ(cls, kSing);
    } else {
      ++diagonals;
      EXPECT_TRUE(edge == Edge(0, 2) || edge == Edge(1, 3));
      EXPECT_EQ(cls, kExt);
    }
  }
  EXPECT_EQ(diagonals, 1);
  for (const auto& [v, cls] : c.vertices) EXPECT_EQ(cls, kSing) << v;

  c = oracle.Classify(Q("1/2"));
  for (const auto& [edge, cls] : c.edges) EXPECT_EQ(cls, sides.count(edge) ? kReg : kInt);
  for (const auto& [v, cls] : c.vertices) EXPECT_EQ(cls, kReg) << v;  // hull: never interior
  EXPECT_EQ(c.interior_triangles, 2u);
  EXPECT_EQ(c.solid_components, 1u);
  EXPECT_EQ(c.regularized_edges_regular, 4u);
  EXPECT_EQ(oracle.OptimalAlpha(1), Q("1/2"));
}

TEST(CgalAlphaOracleTest, CollinearPoints) {
  // Sorted along x: (0,0)=#1, (1,0)=#3, (3,0)=#0, (6,0)=#2.
  const CgalAlphaOracle oracle(std::vector<Point2>{{3, 0}, {0, 0}, {6, 0}, {1, 0}});
  EXPECT_EQ(oracle.dimension(), 1);
  EXPECT_EQ(oracle.num_vertices(), 4u);
  EXPECT_TRUE(oracle.spectrum().empty());
  const auto c = oracle.Classify(Q("1"));  // rho^2: 1/4, 1, 9/4
  EXPECT_EQ(c.edges, (std::map<Edge, OracleClass>{{{1, 3}, kSing}, {{0, 3}, kSing}, {{0, 2}, kExt}}));
  EXPECT_EQ(c.vertices.size(), 4u);
  for (const auto& [v, cls] : c.vertices) EXPECT_EQ(cls, kSing) << v;
  EXPECT_EQ(c.interior_triangles, 0u);
  EXPECT_EQ(c.solid_components, 0u);
  EXPECT_FALSE(oracle.OptimalAlpha(1).has_value());
  EXPECT_FALSE(oracle.AlphaSolid().has_value());
}

TEST(CgalAlphaOracleTest, FewPoints) {
  const CgalAlphaOracle none(std::vector<Point2>{});
  EXPECT_EQ(none.dimension(), -1);
  EXPECT_TRUE(none.Classify(Q("1")).vertices.empty());

  const CgalAlphaOracle one(std::vector<Point2>{{2.5, -1}});
  EXPECT_EQ(one.dimension(), 0);
  EXPECT_TRUE(one.spectrum().empty());
  auto c = one.Classify(Q("0"));
  EXPECT_TRUE(c.edges.empty());
  EXPECT_EQ(c.vertices, (std::map<uint32_t, OracleClass>{{0, kSing}}));
  EXPECT_FALSE(one.OptimalAlpha(1).has_value());
  EXPECT_EQ(one.AlphaSolid(), Q("0"));

  const CgalAlphaOracle two(std::vector<Point2>{{0, 0}, {0, 3}});
  EXPECT_EQ(two.dimension(), 1);
  EXPECT_TRUE(two.spectrum().empty());
  EXPECT_EQ(two.Classify(Q("9/4")).edges, (std::map<Edge, OracleClass>{{{0, 1}, kSing}}));
  EXPECT_EQ(two.Classify(Q("2")).edges, (std::map<Edge, OracleClass>{{{0, 1}, kExt}}));
}

TEST(CgalAlphaOracleTest, DuplicatesMapToFirstOccurrence) {
  const CgalAlphaOracle oracle(std::vector<Point2>{{0, 0}, {4, 0}, {0, 0}, {2, 3}, {4, 0}, {2, 3}});
  EXPECT_EQ(oracle.num_vertices(), 3u);
  EXPECT_EQ(oracle.spectrum(), CgalAlphaOracle(kAcute).spectrum());
  const auto c = oracle.Classify(Q("4"));
  EXPECT_EQ(c.edges, (std::map<Edge, OracleClass>{{{0, 1}, kSing}, {{0, 3}, kSing}, {{1, 3}, kSing}}));
  EXPECT_EQ(c.vertices, (std::map<uint32_t, OracleClass>{{0, kSing}, {1, kSing}, {3, kSing}}));
}

TEST(CgalAlphaOracleTest, OptimalAlphaAnswersOneValuePastTheFirstQualifying) {
  // Two far-apart right triangles: r^2 = 2 and 8; legs 1 and 4; every bridge is >= 2401.
  const CgalAlphaOracle oracle(std::vector<Point2>{{0, 0}, {2, 0}, {0, 2}, {100, 0}, {104, 0}, {100, 4}});
  const auto& spectrum = oracle.spectrum();
  ASSERT_GT(spectrum.size(), 5u);
  EXPECT_EQ(std::vector<mpq_class>(spectrum.begin(), spectrum.begin() + 4), Qs({"1", "2", "4", "8"}));
  EXPECT_GE(spectrum[4], Q("2401"));
  EXPECT_EQ(oracle.AlphaSolid(), Q("8"));
  const auto at8 = oracle.Classify(Q("8"));  // already 2 solid components, every point covered
  EXPECT_EQ(at8.solid_components, 2u);
  for (const auto& [v, cls] : at8.vertices) EXPECT_EQ(cls, kReg) << v;
  EXPECT_EQ(oracle.OptimalAlpha(2), spectrum[4]);  // CGAL returns the value after 8

  // n = 1: the value after the first one (from 8 on) with a single solid component.
  size_t first = 3;
  while (first < spectrum.size() && oracle.Classify(spectrum[first]).solid_components > 1) ++first;
  ASSERT_LT(first, spectrum.size());
  EXPECT_EQ(oracle.OptimalAlpha(1), spectrum[first + 1 < spectrum.size() ? first + 1 : first]);
}

// GUDHI's documented seven points (tests/data/gudhi_alpha_seven_points.txt): CGAL's spectrum is
// the set of distinct positive births, and each simplex is in exactly from its birth on.
TEST(CgalAlphaOracleTest, AgreesWithGudhiSevenPoints) {
  std::ifstream in(std::string(GALPHA_TESTS_DATA_DIR) + "/gudhi_alpha_seven_points.txt");
  ASSERT_TRUE(in) << "missing golden file";
  std::map<Edge, mpq_class> edge_birth;
  std::vector<mpq_class> triangle_birth;
  std::set<mpq_class> births;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string kind, value;
    uint32_t i = 0, j = 0, k = 0;
    fields >> kind >> i;
    if (kind != "v") fields >> j;
    if (kind == "t") fields >> k;
    fields >> value;
    const mpq_class birth(value);
    if (kind == "e") edge_birth[{i, j}] = birth;
    if (kind == "t") triangle_birth.push_back(birth);
    if (kind != "v") births.insert(birth);
  }
  ASSERT_EQ(edge_birth.size(), 12u);
  ASSERT_EQ(triangle_birth.size(), 6u);

  const CgalAlphaOracle oracle(std::vector<Point2>{{1, 1}, {7, 0}, {4, 6}, {9, 6}, {0, 14}, {2, 19}, {9, 17}});
  EXPECT_EQ(oracle.spectrum(), std::vector<mpq_class>(births.begin(), births.end()));
  for (const mpq_class& alpha : oracle.spectrum()) {
    const auto c = oracle.Classify(alpha);
    ASSERT_EQ(c.edges.size(), edge_birth.size());
    for (const auto& [edge, birth] : edge_birth) {
      ASSERT_TRUE(c.edges.count(edge)) << edge.first << " " << edge.second;
      EXPECT_EQ(c.edges.at(edge) != kExt, birth <= alpha) << edge.first << " " << edge.second;
    }
    size_t in_triangles = 0;
    for (const mpq_class& birth : triangle_birth) in_triangles += birth <= alpha;
    EXPECT_EQ(c.interior_triangles, in_triangles) << alpha.get_str();
  }

  // Every point is covered from t(4 5 6) = 7685/338 on, with 2 solid components ({0 1 2 3} and
  // {4 5 6}); t(2 4 6) = 1825/49 makes them one. CGAL answers the spectrum value after each.
  EXPECT_EQ(oracle.AlphaSolid(), Q("7685/338"));
  EXPECT_EQ(oracle.Classify(Q("7685/338")).solid_components, 2u);
  EXPECT_EQ(oracle.Classify(Q("1825/49")).solid_components, 1u);
  EXPECT_EQ(oracle.OptimalAlpha(2), Q("121/4"));
  EXPECT_EQ(oracle.OptimalAlpha(1), Q("7225/121"));
}

}  // namespace
}  // namespace galpha::testing
