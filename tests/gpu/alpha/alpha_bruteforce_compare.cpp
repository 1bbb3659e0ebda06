// The comparison of alpha_bruteforce_compare.hpp.
#include "tests/gpu/alpha/alpha_bruteforce_compare.hpp"

#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/exact/radius_rational.hpp"
#include "core/family/alpha_family.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gtest/gtest.h"
#include "tests/support/bruteforce_alpha_oracle.hpp"
#include "tests/support/persistence_consistency.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::testing {
namespace {

using ::testing::Not;

using Tri = BruteTri;
using Edge = BruteEdge;

std::string Describe(const std::vector<Point2>& points) {
  std::string out = "points {";
  char buf[96];
  for (const Point2& p : points) {
    std::snprintf(buf, sizeof buf, "{%.17g, %.17g}, ", p.x, p.y);
    out += buf;
  }
  return out + "}";
}

// ---- The comparison ------------------------------------------------------------------------------

uint32_t MinRank(const std::vector<uint32_t>& ranks) {
  return ranks.empty() ? kNeverRank : *std::min_element(ranks.begin(), ranks.end());
}

void CheckLevelResolution(const AlphaFamily& f, const BruteFamily& b) {
  const int64_t k = b.K();
  std::vector<double> probes = {
      0.0,   -1.0,  -0.0, std::numeric_limits<double>::denorm_min(), -std::numeric_limits<double>::denorm_min(),
      1e300, 1e-300};
  for (int64_t r = 1; r <= k; ++r) {
    const double d = NearestDouble(b.spectrum[static_cast<size_t>(r - 1)]);
    probes.push_back(d);
    probes.push_back(std::nextafter(d, -INFINITY));
    probes.push_back(std::nextafter(d, INFINITY));
    if (r < k)
      probes.push_back(
          NearestDouble((b.spectrum[static_cast<size_t>(r - 1)] + b.spectrum[static_cast<size_t>(r)]) / 2));
  }
  for (double x : probes) {
    if (!std::isfinite(x)) continue;
    const absl::StatusOr<int64_t> level = f.LevelForAlphaSq(x);
    ASSERT_THAT(level, IsOk());
    ASSERT_EQ(*level, b.LevelOf(mpq_class(x))) << "LevelForAlphaSq(" << x << ")";
    // CGAL's alpha_lower_bound: the first rank whose exact threshold is >= x.
    const int64_t below = std::lower_bound(b.spectrum.begin(), b.spectrum.end(), mpq_class(x)) - b.spectrum.begin();
    ASSERT_EQ(f.RankLowerBound(x), below + 1) << "RankLowerBound(" << x << ")";
    if (x < 0) continue;
    // The radius: compared through its exact square, so alpha = sqrt(x) resolves like x only when
    // the square root is exact.
    const double root = std::sqrt(x);
    for (double a : {root, std::nextafter(root, 0.0), std::nextafter(root, INFINITY)}) {
      const absl::StatusOr<int64_t> by_radius = f.LevelForAlpha(a);
      ASSERT_THAT(by_radius, IsOk());
      const mpq_class a_sq = mpq_class(a) * mpq_class(a);
      ASSERT_EQ(*by_radius, b.LevelOf(a_sq)) << "LevelForAlpha(" << a << ")";
      if (a_sq == mpq_class(x)) {
        ASSERT_EQ(*by_radius, *level) << "LevelForAlpha(" << a << ") vs LevelForAlphaSq(" << x << ")";
      }
    }
  }
  // Radii whose squares leave the double range (exact squares, compared exactly).
  for (double a :
       {1e200, std::numeric_limits<double>::max(), std::numeric_limits<double>::denorm_min(), 1e-160, 1e-300}) {
    const absl::StatusOr<int64_t> by_radius = f.LevelForAlpha(a);
    ASSERT_THAT(by_radius, IsOk());
    ASSERT_EQ(*by_radius, b.LevelOf(mpq_class(a) * mpq_class(a))) << "LevelForAlpha(" << a << ")";
  }
  EXPECT_EQ(*f.LevelForAlphaSq(std::numeric_limits<double>::max()), k);
  EXPECT_EQ(*f.LevelForAlphaSq(INFINITY), k);
  EXPECT_EQ(*f.LevelForAlphaSq(-INFINITY), -1);
  EXPECT_EQ(*f.LevelForAlpha(INFINITY), k);
  EXPECT_THAT(f.LevelForAlphaSq(std::nan("")), Not(IsOk()));
  EXPECT_THAT(f.LevelForAlpha(std::nan("")), Not(IsOk()));
  EXPECT_THAT(f.LevelForAlpha(-1.0), Not(IsOk()));
  EXPECT_EQ(f.RankLowerBound(INFINITY), k + 1);
  for (int64_t r = 0; r <= k; ++r) EXPECT_EQ(*f.LevelForRank(r), r);
  EXPECT_THAT(f.LevelForRank(-1), Not(IsOk()));
  EXPECT_THAT(f.LevelForRank(k + 1), Not(IsOk()));
}

}  // namespace

void CompareWithBruteForce(const std::vector<Point2>& points, Backend backend) {
  SCOPED_TRACE(Describe(points));
  const BruteFamily b = BruteForce(points);
  ASSERT_TRUE(b.valid_triangulation) << "test input error: the Delaunay triangulation is not unique";
  BuildOptions options;
  options.backend = backend;
  absl::StatusOr<AlphaFamily> built = BuildAlphaFamily(points, options);
  ASSERT_THAT(built, IsOk());
  const AlphaFamily& f = *built;
  const AlphaRanks& r = f.ranks();
  const uint32_t n = static_cast<uint32_t>(points.size());

  // Points and duplicates.
  ASSERT_EQ(f.points().size(), points.size());
  ASSERT_EQ(f.representative(), b.rep);
  ASSERT_EQ(f.num_unique(), b.uniq.size());
  ASSERT_EQ(f.num_duplicates(), n - b.uniq.size());

  // The same simplices: family id -> brute index.
  ASSERT_EQ(f.triangles().size(), b.tris.size());
  ASSERT_EQ(f.edges().size(), b.edges.size());
  std::map<Tri, uint32_t> brute_tri;
  for (uint32_t t = 0; t < b.tris.size(); ++t) brute_tri[b.tris[t]] = t;
  std::map<Edge, uint32_t> brute_edge;
  for (uint32_t e = 0; e < b.edges.size(); ++e) brute_edge[b.edges[e]] = e;
  std::vector<uint32_t> tri_map, edge_map;
  for (const Tri& t : f.triangles()) {
    ASSERT_EQ(Orient(b.q[t[0]], b.q[t[1]], b.q[t[2]]), 1) << "triangle not counter-clockwise";
    Tri sorted = t;
    std::sort(sorted.begin(), sorted.end());
    const auto it = brute_tri.find(sorted);
    ASSERT_NE(it, brute_tri.end()) << "not a Delaunay triangle: " << t[0] << " " << t[1] << " " << t[2];
    tri_map.push_back(it->second);
  }
  for (const Edge& e : f.edges()) {
    ASSERT_LT(e[0], e[1]);
    const auto it = brute_edge.find(e);
    ASSERT_NE(it, brute_edge.end()) << "not a Delaunay edge: " << e[0] << " " << e[1];
    edge_map.push_back(it->second);
  }
  std::vector<uint32_t> sorted_map = tri_map;
  std::sort(sorted_map.begin(), sorted_map.end());
  ASSERT_TRUE(std::adjacent_find(sorted_map.begin(), sorted_map.end()) == sorted_map.end()) << "repeated triangle";
  sorted_map = edge_map;
  std::sort(sorted_map.begin(), sorted_map.end());
  ASSERT_TRUE(std::adjacent_find(sorted_map.begin(), sorted_map.end()) == sorted_map.end()) << "repeated edge";

  // The spectrum: exact values (through the simplex the family names for each rank) and nearest
  // doubles.
  const int64_t k = b.K();
  ASSERT_EQ(f.max_level(), k);
  ASSERT_EQ(r.spectrum_simplex.size(), static_cast<size_t>(k));
  const uint32_t num_tri = static_cast<uint32_t>(f.triangles().size());
  for (int64_t rank = 1; rank <= k; ++rank) {
    const uint32_t id = r.spectrum_simplex[static_cast<size_t>(rank - 1)];
    Point2 p[3];
    int count = 2;
    if (id < num_tri) {
      for (int i = 0; i < 3; ++i) p[i] = points[f.triangles()[id][i]];
      count = 3;
    } else {
      ASSERT_LT(id - num_tri, f.edges().size());
      p[0] = points[f.edges()[id - num_tri][0]];
      p[1] = points[f.edges()[id - num_tri][1]];
    }
    const std::optional<mpq_class> value = RadiusSqRational(p, count);
    ASSERT_TRUE(value.has_value());
    const mpq_class& want = b.spectrum[static_cast<size_t>(rank - 1)];
    ASSERT_EQ(*value, want) << "rank " << rank;
    const double d = f.spectrum()[static_cast<size_t>(rank - 1)];
    ASSERT_EQ(d, NearestDouble(want)) << "rank " << rank;
    ASSERT_TRUE(IsNearestDouble(d, want)) << "rank " << rank << ": " << d;
  }

  // The rank tables (core/family/alpha_ranks.hpp), entry by entry.
  for (uint32_t t = 0; t < num_tri; ++t) {
    ASSERT_EQ(r.tri_rank[t], b.RankOf(b.tri_birth[tri_map[t]])) << "triangle " << t;
  }
  std::vector<uint32_t> brute_tri_rank(b.tris.size());
  for (uint32_t t = 0; t < num_tri; ++t) brute_tri_rank[tri_map[t]] = r.tri_rank[t];
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    const uint32_t be = edge_map[e];
    SCOPED_TRACE(::testing::Message() << "edge " << f.edges()[e][0] << "-" << f.edges()[e][1]);
    ASSERT_EQ(EdgeBirthRank(r, e), b.RankOf(b.edge_birth[be]));
    ASSERT_EQ(r.edge_rho_rank[e], b.attached[be] ? 0u : b.RankOf(b.edge_rho[be]));
    std::vector<uint32_t> ranks, ids;
    for (uint32_t t : b.edge_tris[be]) ranks.push_back(brute_tri_rank[t]);
    ASSERT_EQ(r.edge_mu_low[e], MinRank(ranks));
    ASSERT_EQ(r.edge_mu_high[e], ranks.size() == 2 ? std::max(ranks[0], ranks[1]) : kNeverRank);
    for (int32_t t : r.edge_triangles[e]) {
      if (t >= 0) ids.push_back(tri_map[static_cast<size_t>(t)]);
    }
    std::sort(ids.begin(), ids.end());
    std::vector<uint32_t> want_ids = b.edge_tris[be];
    std::sort(want_ids.begin(), want_ids.end());
    ASSERT_EQ(ids, want_ids);
  }
  std::vector<uint32_t> brute_edge_birth(b.edges.size()), brute_edge_high(b.edges.size());
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    brute_edge_birth[edge_map[e]] = EdgeBirthRank(r, e);
    brute_edge_high[edge_map[e]] = r.edge_mu_high[e];
  }
  for (uint32_t v = 0; v < n; ++v) {
    const uint32_t w = b.rep[v];
    std::vector<uint32_t> births, tri_ranks;
    uint32_t high = b.vertex_edges[w].empty() || b.on_hull[w] ? kNeverRank : 0;
    for (uint32_t e : b.vertex_edges[w]) {
      births.push_back(brute_edge_birth[e]);
      if (high != kNeverRank) high = std::max(high, brute_edge_high[e]);
    }
    for (uint32_t t : b.vertex_tris[w]) tri_ranks.push_back(brute_tri_rank[t]);
    ASSERT_EQ(r.vertex_mu_low[v], MinRank(births)) << "vertex " << v;
    ASSERT_EQ(r.vertex_mu_high[v], high) << "vertex " << v;
    ASSERT_EQ(r.vertex_tri_low[v], MinRank(tri_ranks)) << "vertex " << v;
  }

  // Every level, and a negative alpha_sq (level -1): classes in both modes under both rules,
  // components and solid components.
  for (int64_t level = -1; level <= k; ++level) {
    const mpq_class A = b.Threshold(level);
    for (ClassifyMode mode : {ClassifyMode::kGeneral, ClassifyMode::kRegularized}) {
      for (VertexRule rule : {VertexRule::kReport, VertexRule::kCgal}) {
        SCOPED_TRACE(::testing::Message()
                     << "level " << level << (mode == ClassifyMode::kGeneral ? " GENERAL" : " REGULARIZED")
                     << (rule == VertexRule::kReport ? " report rule" : " CGAL rule"));
        const BruteClasses want = ClassifyBrute(b, A, mode, rule);
        const Classification got = f.ClassifyAll(level, mode, rule);
        ASSERT_EQ(got.vertices.size(), n);
        ASSERT_EQ(got.edges.size(), b.edges.size());
        ASSERT_EQ(got.triangles.size(), b.tris.size());
        for (uint32_t v = 0; v < n; ++v) {
          ASSERT_EQ(SimplexClassName(got.vertices[v]), std::string(SimplexClassName(want.vertices[v])))
              << "vertex " << v;
          ASSERT_EQ(f.ClassifyVertex(v, level, mode, rule), got.vertices[v]) << "vertex " << v;
        }
        for (uint32_t e = 0; e < got.edges.size(); ++e) {
          ASSERT_EQ(SimplexClassName(got.edges[e]), std::string(SimplexClassName(want.edges[edge_map[e]])))
              << "edge " << f.edges()[e][0] << "-" << f.edges()[e][1];
          ASSERT_EQ(f.ClassifyEdge(e, level, mode), got.edges[e]);
        }
        for (uint32_t t = 0; t < got.triangles.size(); ++t) {
          ASSERT_EQ(SimplexClassName(got.triangles[t]), std::string(SimplexClassName(want.triangles[tri_map[t]])))
              << "triangle " << t;
          ASSERT_EQ(f.ClassifyTriangle(t, level), got.triangles[t]);
        }
      }
    }
    ASSERT_EQ(f.Components(level), BruteComponents(b, A)) << "level " << level;
    ASSERT_EQ(f.SolidComponents(level), BruteSolidComponents(b, A)) << "level " << level;
    ASSERT_EQ(f.RegularizedComponents(level), BruteRegularizedComponents(b, A)) << "level " << level;
    ASSERT_EQ(f.Holes(level, ClassifyMode::kGeneral), BruteHoles(b, A, ClassifyMode::kGeneral)) << "level " << level;
    ASSERT_EQ(f.Holes(level, ClassifyMode::kRegularized), BruteHoles(b, A, ClassifyMode::kRegularized))
        << "level " << level;
  }
  ExpectPersistenceMatchesCurves(f);
  ExpectPairsMatchMatrixReduction(f);

  // Optimal levels, by their definitions in core/family/alpha_family.hpp, over all levels 0..K.
  std::optional<int64_t> solid;
  if (!b.tris.empty()) {
    for (int64_t level = 0; level <= k && !solid; ++level) {
      if (EveryPointOnATriangle(b, b.Threshold(level))) solid = level;
    }
  }
  ASSERT_EQ(f.SolidLevel(), solid);
  for (uint32_t want_n = 1; want_n <= 4; ++want_n) {
    std::optional<int64_t> general, regularized;
    for (int64_t level = 0; level <= k; ++level) {
      const mpq_class A = b.Threshold(level);
      if (!general && BruteComponents(b, A) <= want_n) general = level;
      if (!regularized && !b.tris.empty() && EveryPointOnATriangle(b, A) && BruteSolidComponents(b, A) <= want_n) {
        regularized = level;
      }
    }
    ASSERT_EQ(f.OptimalLevelGeneral(want_n), general) << "n = " << want_n;
    ASSERT_EQ(f.OptimalLevelRegularized(want_n), regularized) << "n = " << want_n;
    // With a hole bound: the smallest level meeting both bounds, holes by GF(2) ranks.
    for (uint32_t want_holes = 0; want_holes <= 2; ++want_holes) {
      std::optional<int64_t> general_h, regularized_h;
      for (int64_t level = 0; level <= k; ++level) {
        const mpq_class A = b.Threshold(level);
        if (!general_h && BruteComponents(b, A) <= want_n && BruteHoles(b, A, ClassifyMode::kGeneral) <= want_holes) {
          general_h = level;
        }
        if (!regularized_h && !b.tris.empty() && EveryPointOnATriangle(b, A) && BruteSolidComponents(b, A) <= want_n &&
            BruteHoles(b, A, ClassifyMode::kRegularized) <= want_holes) {
          regularized_h = level;
        }
      }
      ASSERT_EQ(f.OptimalLevelGeneral(want_n, want_holes), general_h) << "n = " << want_n << ", holes " << want_holes;
      ASSERT_EQ(f.OptimalLevelRegularized(want_n, want_holes), regularized_h)
          << "n = " << want_n << ", holes " << want_holes;
    }
  }

  CheckLevelResolution(f, b);
}

}  // namespace galpha::testing
