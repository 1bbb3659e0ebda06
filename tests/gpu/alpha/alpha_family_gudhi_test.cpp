// The alpha family against GUDHI's seven-point example (tests/data/gudhi_alpha_seven_points.txt):
// the simplices, every birth and the spectrum, exactly.
#include <gmpxx.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/exact/radius_rational.hpp"
#include "core/family/alpha_family.hpp"
#include "gtest/gtest.h"
#include "tests/gpu/alpha/alpha_family_fixture.hpp"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::Edge;
using testing::EdgeRhoSq;
using testing::ExactThreshold;
using testing::IsOk;
using testing::SortedTri;
using testing::Tri;

struct Golden {
  std::vector<Point2> points;
  std::map<Edge, mpq_class> edges;
  std::map<Tri, mpq_class> triangles;
  int vertices = 0;
};

Golden ReadGolden(const std::string& path) {
  Golden g;
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("# Points", 0) == 0) {
      // "# Points (0-based input index: x y): 0: 1 1, 1: 7 0, ..."
      std::string list = line.substr(line.find("):") + 2);
      std::replace(list.begin(), list.end(), ',', ' ');
      std::istringstream items(list);
      std::string index;
      double x, y;
      while (items >> index >> x >> y) {
        EXPECT_EQ(index, std::to_string(g.points.size()) + ":");
        g.points.push_back({x, y});
      }
      continue;
    }
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string kind, value;
    fields >> kind;
    if (kind == "v") {
      uint32_t i;
      fields >> i >> value;
      EXPECT_EQ(value, "0");
      ++g.vertices;
    } else if (kind == "e") {
      Edge e;
      fields >> e[0] >> e[1] >> value;
      g.edges[e] = mpq_class(value);
    } else if (kind == "t") {
      Tri t;
      fields >> t[0] >> t[1] >> t[2] >> value;
      g.triangles[t] = mpq_class(value);
    } else {
      ADD_FAILURE() << "bad line: " << line;
    }
  }
  return g;
}

using GudhiTest = testing::AlphaFamilyTest;

TEST_P(GudhiTest, SevenPointsExactBirths) {
  const Golden g = ReadGolden(std::string(GALPHA_TESTS_DATA_DIR) + "/gudhi_alpha_seven_points.txt");
  ASSERT_EQ(g.points.size(), 7u);
  ASSERT_EQ(g.vertices, 7);
  ASSERT_EQ(g.edges.size(), 12u);
  ASSERT_EQ(g.triangles.size(), 6u);
  absl::StatusOr<AlphaFamily> built = Build(g.points);
  ASSERT_THAT(built, IsOk());
  const AlphaFamily& f = *built;
  const AlphaRanks& r = f.ranks();

  // The spectrum: the sorted distinct positive births, exactly and as nearest doubles.
  std::vector<mpq_class> spectrum;
  for (const auto& [e, birth] : g.edges) spectrum.push_back(birth);
  for (const auto& [t, birth] : g.triangles) spectrum.push_back(birth);
  std::sort(spectrum.begin(), spectrum.end());
  spectrum.erase(std::unique(spectrum.begin(), spectrum.end()), spectrum.end());
  ASSERT_EQ(f.max_level(), static_cast<int64_t>(spectrum.size()));
  for (int64_t rank = 1; rank <= f.max_level(); ++rank) {
    const mpq_class value = ExactThreshold(f, rank);
    EXPECT_EQ(value, spectrum[static_cast<size_t>(rank - 1)]) << "rank " << rank;
    EXPECT_EQ(f.spectrum()[static_cast<size_t>(rank - 1)], NearestDouble(value)) << "rank " << rank;
  }
  auto value_of = [&](uint32_t rank) -> mpq_class {
    if (rank == 0 || rank == kNeverRank || rank > spectrum.size()) return mpq_class(-1);
    return spectrum[rank - 1];
  };

  // The same simplices, each born at its golden value.
  std::set<Edge> edges;
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    const Edge& ed = f.edges()[e];
    edges.insert(ed);
    const auto it = g.edges.find(ed);
    ASSERT_NE(it, g.edges.end()) << "edge " << ed[0] << " " << ed[1] << " is not in the golden file";
    EXPECT_EQ(value_of(EdgeBirthRank(r, e)), it->second) << "edge " << ed[0] << " " << ed[1];
    // Attached exactly when the birth is not the edge's own rho^2 (then it is an incident
    // triangle's, which is larger).
    const bool attached = it->second != EdgeRhoSq(f, e);
    EXPECT_EQ(r.edge_rho_rank[e] == 0, attached) << "edge " << ed[0] << " " << ed[1];
  }
  EXPECT_EQ(edges.size(), g.edges.size());
  std::set<Tri> triangles;
  for (uint32_t t = 0; t < f.triangles().size(); ++t) {
    const Tri tri = SortedTri(f.triangles()[t]);
    triangles.insert(tri);
    const auto it = g.triangles.find(tri);
    ASSERT_NE(it, g.triangles.end()) << "triangle " << tri[0] << " " << tri[1] << " " << tri[2];
    EXPECT_EQ(value_of(r.tri_rank[t]), it->second) << "triangle " << tri[0] << " " << tri[1] << " " << tri[2];
  }
  EXPECT_EQ(triangles.size(), g.triangles.size());
  // The file names these two attached; everything is in at the last rank, nothing singular.
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    const bool named = f.edges()[e] == Edge{0, 4} || f.edges()[e] == Edge{4, 6};
    EXPECT_EQ(r.edge_rho_rank[e] == 0, named) << f.edges()[e][0] << " " << f.edges()[e][1];
  }
  EXPECT_EQ(f.Components(f.max_level()), 1u);
  EXPECT_EQ(f.SolidComponents(f.max_level()), 1u);
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(GudhiTest);

}  // namespace
}  // namespace galpha
