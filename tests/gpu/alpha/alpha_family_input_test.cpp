// The alpha family of bad and degenerate input: NaN and infinity name their index; 0, 1, 2 points
// and collinear sets give families with edges only (a chain, the spectrum of its squared half
// lengths). A build past its limit of exact comparisons stops with a tagged ResourceExhausted.
#include <gmpxx.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/exact/radius_rational.hpp"
#include "core/family/alpha_family.hpp"
#include "core/geometry/shape.hpp"
#include "gtest/gtest.h"
#include "tests/gpu/alpha/alpha_family_fixture.hpp"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::Edge;
using testing::ExactThreshold;
using ::testing::HasSubstr;
using testing::IsOk;
using ::testing::Not;
using testing::StatusIs;

using InputTest = testing::AlphaFamilyTest;

TEST_P(InputTest, NonFiniteCoordinatesNameTheirIndex) {
  const double nan = std::nan(""), inf = INFINITY;
  const std::vector<std::pair<std::vector<Point2>, size_t>> cases = {
      {{{nan, 0}}, 0},
      {{{0, 0}, {1, 0}, {0, 1}, {2, nan}, {5, 5}}, 3},
      {{{0, 0}, {1, 0}, {nan, nan}, {inf, 1}}, 2},
      {{{0, 0}, {1, 0}, {0, 1}, {1, 1}, {-inf, 1}}, 4},
      {{{0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {3, -inf}}, 11},
  };
  for (const auto& [points, bad] : cases) {
    const absl::StatusOr<AlphaFamily> built = Build(points);
    ASSERT_THAT(built, Not(IsOk())) << "bad index " << bad;
    EXPECT_THAT(built.status(), StatusIs(absl::StatusCode::kInvalidArgument));
    const std::string message(built.status().message());
    EXPECT_NE(message.find("point " + std::to_string(bad) + " "), std::string::npos) << message;
  }
}

// Outside the input domain (core/io/input_validation.hpp) the build is refused, naming the point
// and the bound, on every backend: near the largest double the predicates overflowed and the
// issue's five points came out collinear (0 triangles) with an OK status.
TEST_P(InputTest, OutsideTheInputDomainIsRefusedNamingThePointAndTheBound) {
  const std::vector<std::tuple<std::vector<Point2>, size_t, std::string>> cases = {
      {{{1e308, 1e308}, {-1e308, 1e308}, {0, -1e308}, {1e308, -1e308}, {0, 0}}, 0, "2^500"},
      {{{0, 0}, {1, 0}, {0, 1}, {0x1p500, 1}}, 3, "2^500"},
      {{{1, 1}, {2, 0}, {0, 1e-140}, {3, 3}}, 2, "2^437"},
      {{{0x1p-585, 0}, {0x1p-1074, 0x1p-1070}, {0, 0x1p-600}}, 1, "2^437"},
  };
  for (const auto& [points, bad, bound] : cases) {
    const absl::StatusOr<AlphaFamily> built = Build(points);
    ASSERT_THAT(built, Not(IsOk())) << "bad index " << bad;
    EXPECT_THAT(built.status(), StatusIs(absl::StatusCode::kInvalidArgument));
    const std::string message(built.status().message());
    EXPECT_EQ(message.rfind("point " + std::to_string(bad) + " ", 0), 0u) << message;
    EXPECT_NE(message.find(bound), std::string::npos) << message;
  }
}

// A family with no triangles: the edges of a chain, the spectrum of their squared half lengths.
void CheckChainFamily(const AlphaFamily& f, const std::vector<Point2>& points) {
  // The chain: the distinct points in their order along the line (lexicographic on a line).
  std::vector<uint32_t> order;
  for (uint32_t i = 0; i < points.size(); ++i) {
    bool first = true;
    for (uint32_t j = 0; j < i && first; ++j) first = !(points[j] == points[i]);
    if (first) order.push_back(i);
  }
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return LexLess(points[a], points[b]); });
  std::set<Edge> want_edges;
  std::vector<mpq_class> spectrum;
  for (size_t i = 0; i + 1 < order.size(); ++i) {
    want_edges.insert({std::min(order[i], order[i + 1]), std::max(order[i], order[i + 1])});
    const mpq_class dx = mpq_class(points[order[i + 1]].x) - points[order[i]].x;
    const mpq_class dy = mpq_class(points[order[i + 1]].y) - points[order[i]].y;
    spectrum.emplace_back((dx * dx + dy * dy) / 4);
  }
  std::sort(spectrum.begin(), spectrum.end());
  spectrum.erase(std::unique(spectrum.begin(), spectrum.end()), spectrum.end());

  EXPECT_EQ(f.num_unique(), order.size());
  EXPECT_TRUE(f.triangles().empty());
  EXPECT_EQ(std::set<Edge>(f.edges().begin(), f.edges().end()), want_edges);
  EXPECT_EQ(f.edges().size(), want_edges.size());
  ASSERT_EQ(f.max_level(), static_cast<int64_t>(spectrum.size()));
  for (int64_t rank = 1; rank <= f.max_level(); ++rank) {
    EXPECT_EQ(ExactThreshold(f, rank), spectrum[static_cast<size_t>(rank - 1)]) << "rank " << rank;
    EXPECT_EQ(f.spectrum()[static_cast<size_t>(rank - 1)], NearestDouble(spectrum[static_cast<size_t>(rank - 1)]));
  }
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    EXPECT_NE(f.ranks().edge_rho_rank[e], 0u) << "an edge without triangles is unattached";
    EXPECT_EQ(f.ranks().edge_mu_low[e], kNeverRank);
    EXPECT_EQ(f.ranks().edge_mu_high[e], kNeverRank);
  }
  EXPECT_EQ(f.SolidLevel(), std::nullopt);
  EXPECT_EQ(f.OptimalLevelRegularized(1), std::nullopt);
  EXPECT_EQ(f.Components(0), order.size());
  EXPECT_EQ(f.Components(f.max_level()), order.empty() ? 0u : 1u);
  EXPECT_EQ(f.OptimalLevelGeneral(1),
            order.empty() ? std::optional<int64_t>(0) : std::optional<int64_t>(order.size() <= 1 ? 0 : f.max_level()));
  // Everything is singular at the end (no triangle ever), and nothing is in REGULARIZED mode.
  const Classification general = f.ClassifyAll(f.max_level(), ClassifyMode::kGeneral, VertexRule::kReport);
  for (SimplexClass c : general.edges) EXPECT_EQ(c, SimplexClass::kSingular);
  for (uint32_t v = 0; v < points.size(); ++v) {
    EXPECT_EQ(general.vertices[v], order.size() == 1 ? SimplexClass::kSingular : SimplexClass::kRegular) << v;
  }
  const Classification regularized = f.ClassifyAll(f.max_level(), ClassifyMode::kRegularized, VertexRule::kCgal);
  for (SimplexClass c : regularized.edges) EXPECT_EQ(c, SimplexClass::kExterior);
  for (SimplexClass c : regularized.vertices) EXPECT_EQ(c, SimplexClass::kExterior);
  const absl::StatusOr<ShapeGeometry> shape = AssembleShape(f.ComplexAt(f.max_level(), ClassifyMode::kGeneral));
  ASSERT_THAT(shape, IsOk());
  EXPECT_TRUE(shape->polygons.empty());
  EXPECT_EQ(shape->singular_edges.size(), want_edges.size());
}

TEST_P(InputTest, FewPointsAndCollinearSetsAreValid) {
  auto tiny = [](int m) { return std::ldexp(static_cast<double>(m), -1000); };  // m * 2^-1000, exact
  const std::vector<std::vector<Point2>> cases = {
      {},
      {{2, 3}},
      {{2, 3}, {2, 3}},
      {{2, 3}, {5, -1}},
      {{5, -1}, {2, 3}, {5, -1}},
      // Collinear chains: repeated gaps (exact ties), unsorted input, duplicates, a vertical line,
      // a diagonal through huge coordinates, tiny coordinates.
      {{0, 1}, {3, 7}, {1, 3}, {2, 5}, {5, 11}, {4, 9}, {9, 19}},
      {{7, 0}, {7, -3}, {7, 10}, {7, -3}, {7, 1}, {7, 4}},
      {{1e15, -1e15}, {-1e15, 1e15}, {0.5, -0.5}, {0, 0}, {3, -3}},
      {{tiny(1), tiny(3)}, {tiny(4), tiny(12)}, {tiny(2), tiny(6)}, {tiny(8), tiny(24)}, {tiny(5), tiny(15)}},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(::testing::Message() << "case " << i);
    const absl::StatusOr<AlphaFamily> built = Build(cases[i]);
    ASSERT_THAT(built, IsOk());
    CheckChainFamily(*built, cases[i]);
  }
  // A long chain of integers on one line (many exact ties).
  std::vector<Point2> line;
  line.reserve(500);
  for (int i = 0; i < 500; ++i)
    line.push_back({static_cast<double>((i * 37) % 500), static_cast<double>(2 * ((i * 37) % 500) + 1)});
  const absl::StatusOr<AlphaFamily> built = Build(line);
  ASSERT_THAT(built, IsOk());
  CheckChainFamily(*built, line);
  EXPECT_EQ(built->max_level(), 1);
}

TEST_P(InputTest, ExactComparisonLimitStopsTheBuild) {
  // A lattice nudged by single ulps: its certified keys tie by the thousand, so its spectrum needs
  // exact comparisons (on the device, in refined-key clusters and short runs).
  const std::vector<Point2> points = gen::UlpLattice(2500, 13);
  BuildOptions options;
  options.backend = GetParam();
  const absl::StatusOr<AlphaFamily> unlimited = BuildAlphaFamily(points, options);
  ASSERT_THAT(unlimited, IsOk());
  const ComparisonCounts& counts = unlimited->report().comparisons;
  const uint64_t used = counts.bounded_exact + counts.cpu_fallback;
  ASSERT_GT(used, 250u);  // the service test limits this input to 250

  options.max_exact_comparisons = used;  // exactly enough: the same family
  const absl::StatusOr<AlphaFamily> enough = BuildAlphaFamily(points, options);
  ASSERT_THAT(enough, IsOk());
  EXPECT_EQ(enough->spectrum(), unlimited->spectrum());
  EXPECT_EQ(enough->ranks().spectrum_simplex, unlimited->ranks().spectrum_simplex);

  options.max_exact_comparisons = used - 1;
  const absl::StatusOr<AlphaFamily> stopped = BuildAlphaFamily(points, options);
  EXPECT_THAT(stopped, StatusIs(absl::StatusCode::kResourceExhausted,
                                HasSubstr("limit of " + std::to_string(used - 1) + " exact radius comparisons")));
  EXPECT_TRUE(IsExactComparisonLimit(stopped.status()));
  // Only the limit is tagged: other refusals of the same code are not.
  EXPECT_FALSE(IsExactComparisonLimit(absl::ResourceExhaustedError("out of memory")));
  EXPECT_FALSE(IsExactComparisonLimit(absl::OkStatus()));
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(InputTest);

}  // namespace
}  // namespace galpha
