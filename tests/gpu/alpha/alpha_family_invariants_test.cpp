// The alpha family on 2000-point inputs of every hard kind: the rank tables against exact radii and
// attachment, the intervals' invariants, the master list entry by entry, the exact order of the
// spectrum, the component curve.
#include <gmpxx.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <vector>

#include "absl/types/span.h"
#include "core/exact/radius_rational.hpp"
#include "core/family/alpha_family.hpp"
#include "gtest/gtest.h"
#include "tests/gpu/alpha/alpha_family_fixture.hpp"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::Case;
using testing::Edge;
using testing::EdgeRhoSq;
using testing::ExactThreshold;
using testing::IsOk;
using testing::Tri;
using testing::TriangleRhoSq;

std::vector<Case> InvariantCases() {
  using namespace gen;
  return {
      {"uniform", Uniform(2000, 31)},
      {"grid", Grid(2000, 32)},
      {"circle", Circle(2000, 33)},
      {"two_lines", TwoLines(2000, 34)},
      {"duplicates", WithDuplicates(2000, 35)},
      {"tiny", Tiny(2000, 36)},
  };
}

uint32_t MinOf(uint32_t a, uint32_t b) { return std::min(a, b); }

void CheckInvariants(const AlphaFamily& f) {
  const AlphaRanks& r = f.ranks();
  const int64_t k = f.max_level();
  const uint32_t n = static_cast<uint32_t>(f.points().size());
  const uint32_t num_tri = static_cast<uint32_t>(f.triangles().size());
  const uint32_t num_edges = static_cast<uint32_t>(f.edges().size());
  ASSERT_GT(k, 0);
  ASSERT_EQ(r.spectrum.size(), static_cast<size_t>(k));
  ASSERT_EQ(r.spectrum_simplex.size(), static_cast<size_t>(k));
  ASSERT_EQ(r.tri_rank.size(), num_tri);
  ASSERT_EQ(r.edge_rho_rank.size(), num_edges);
  ASSERT_EQ(r.edge_mu_low.size(), num_edges);
  ASSERT_EQ(r.edge_mu_high.size(), num_edges);
  ASSERT_EQ(r.edge_triangles.size(), num_edges);
  ASSERT_EQ(r.vertex_mu_low.size(), n);
  ASSERT_EQ(r.vertex_mu_high.size(), n);
  ASSERT_EQ(r.vertex_tri_low.size(), n);
  auto in_range = [k](uint32_t rank) { return rank >= 1 && static_cast<int64_t>(rank) <= k; };

  // The spectrum: strictly increasing exact values, their nearest doubles non-decreasing.
  std::vector<mpq_class> exact(static_cast<size_t>(k));
  for (int64_t rank = 1; rank <= k; ++rank) {
    exact[static_cast<size_t>(rank - 1)] = ExactThreshold(f, rank);
    ASSERT_EQ(r.spectrum[static_cast<size_t>(rank - 1)], NearestDouble(exact[static_cast<size_t>(rank - 1)]))
        << "rank " << rank;
    if (rank > 1) {
      ASSERT_LT(exact[static_cast<size_t>(rank - 2)], exact[static_cast<size_t>(rank - 1)]) << "rank " << rank;
      ASSERT_LE(r.spectrum[static_cast<size_t>(rank - 2)], r.spectrum[static_cast<size_t>(rank - 1)])
          << "rank " << rank;
    }
  }
  ASSERT_GT(exact[0], 0);

  // Triangles: the rank names their exact rho^2.
  for (uint32_t t = 0; t < num_tri; ++t) {
    ASSERT_TRUE(in_range(r.tri_rank[t])) << "triangle " << t;
    ASSERT_EQ(exact[r.tri_rank[t] - 1], TriangleRhoSq(f, t)) << "triangle " << t;
  }
  // Edges: incident triangles, attachment (exact), rho, mu-low, mu-high.
  std::map<Edge, std::vector<uint32_t>> tris_of_edge;
  for (uint32_t t = 0; t < num_tri; ++t) {
    const Tri& tr = f.triangles()[t];
    for (int k3 = 0; k3 < 3; ++k3) {
      const uint32_t a = tr[k3], b = tr[(k3 + 1) % 3];
      tris_of_edge[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  }
  ASSERT_EQ(tris_of_edge.size(), num_tri == 0 ? 0 : num_edges);
  std::vector<uint32_t> min_birth(n, kNeverRank), max_high(n, 0), min_tri(n, kNeverRank);
  std::vector<bool> has_edge(n, false);
  for (uint32_t e = 0; e < num_edges; ++e) {
    SCOPED_TRACE(::testing::Message() << "edge " << e << " (" << f.edges()[e][0] << ", " << f.edges()[e][1] << ")");
    const Edge& ed = f.edges()[e];
    std::vector<uint32_t> tris;
    for (int32_t t : r.edge_triangles[e]) {
      if (t >= 0) tris.push_back(static_cast<uint32_t>(t));
    }
    std::sort(tris.begin(), tris.end());
    if (num_tri > 0) {
      ASSERT_EQ(tris, tris_of_edge[ed]);
    }
    bool attached = false;
    const mpq_class ax(f.points()[ed[0]].x), ay(f.points()[ed[0]].y);
    const mpq_class bx(f.points()[ed[1]].x), by(f.points()[ed[1]].y);
    for (uint32_t t : tris) {
      for (uint32_t v : f.triangles()[t]) {
        if (v == ed[0] || v == ed[1]) continue;
        const mpq_class cx(f.points()[v].x), cy(f.points()[v].y);
        attached |= sgn((ax - cx) * (bx - cx) + (ay - cy) * (by - cy)) < 0;
      }
    }
    if (attached) {
      ASSERT_EQ(r.edge_rho_rank[e], 0u);
    } else {
      ASSERT_TRUE(in_range(r.edge_rho_rank[e]));
      ASSERT_EQ(exact[r.edge_rho_rank[e] - 1], EdgeRhoSq(f, e));
      ASSERT_LE(r.edge_rho_rank[e], r.edge_mu_low[e]) << "unattached: rho <= mu-low";
    }
    uint32_t low = kNeverRank, high = kNeverRank;
    if (tris.size() == 1) low = r.tri_rank[tris[0]];  // a hull edge: never interior
    if (tris.size() == 2) {
      low = std::min(r.tri_rank[tris[0]], r.tri_rank[tris[1]]);
      high = std::max(r.tri_rank[tris[0]], r.tri_rank[tris[1]]);
    }
    ASSERT_EQ(r.edge_mu_low[e], low);
    ASSERT_EQ(r.edge_mu_high[e], high);
    ASSERT_LE(r.edge_mu_low[e], r.edge_mu_high[e]);
    const uint32_t birth = EdgeBirthRank(r, e);
    ASSERT_TRUE(in_range(birth));
    for (uint32_t v : ed) {
      has_edge[v] = true;
      min_birth[v] = MinOf(min_birth[v], birth);
      max_high[v] = std::max(max_high[v], r.edge_mu_high[e]);  // kNeverRank on the hull wins
    }
  }
  for (uint32_t t = 0; t < num_tri; ++t) {
    for (uint32_t v : f.triangles()[t]) min_tri[v] = MinOf(min_tri[v], r.tri_rank[t]);
  }
  // Vertices: from their incident edges and triangles; duplicates repeat their representative's.
  for (uint32_t v = 0; v < n; ++v) {
    const uint32_t w = f.representative()[v];
    ASSERT_LE(w, v);
    ASSERT_EQ(f.representative()[w], w);
    ASSERT_EQ(r.vertex_mu_low[v], min_birth[w]) << "vertex " << v;
    ASSERT_EQ(r.vertex_mu_high[v], has_edge[w] ? max_high[w] : kNeverRank) << "vertex " << v;
    ASSERT_EQ(r.vertex_tri_low[v], min_tri[w]) << "vertex " << v;
    ASSERT_EQ(has_edge[v], w == v) << "vertex " << v << ": every distinct point and no duplicate is in an edge";
  }

  // The master list: for every rank exactly the interval end points of that rank, in the order
  // vertex < edge < triangle, then id, then end point (rho, mu-low, mu-high).
  std::vector<std::vector<MasterEntry>> want(static_cast<size_t>(k) + 1);
  auto add = [&](uint32_t rank, uint32_t id, SimplexKind kind, Endpoint end) {
    if (rank == 0 || rank == kNeverRank) return;
    want[rank].push_back({id, kind, end});
  };
  for (uint32_t v = 0; v < n; ++v) {
    if (f.representative()[v] != v) continue;
    add(r.vertex_mu_low[v], v, SimplexKind::kVertex, Endpoint::kMuLow);
    add(r.vertex_mu_high[v], v, SimplexKind::kVertex, Endpoint::kMuHigh);
  }
  for (uint32_t e = 0; e < num_edges; ++e) {
    add(r.edge_rho_rank[e], e, SimplexKind::kEdge, Endpoint::kRho);
    add(r.edge_mu_low[e], e, SimplexKind::kEdge, Endpoint::kMuLow);
    add(r.edge_mu_high[e], e, SimplexKind::kEdge, Endpoint::kMuHigh);
  }
  for (uint32_t t = 0; t < num_tri; ++t) add(r.tri_rank[t], t, SimplexKind::kTriangle, Endpoint::kRho);
  ASSERT_EQ(r.master_begin.size(), static_cast<size_t>(k) + 2);
  ASSERT_EQ(r.master_begin[0], 0u);
  ASSERT_EQ(r.master_begin[1], 0u);
  size_t total = 0;
  for (int64_t rank = 1; rank <= k; ++rank) {
    const std::vector<MasterEntry>& expected = want[static_cast<size_t>(rank)];
    ASSERT_EQ(r.master_begin[static_cast<size_t>(rank)], total) << "rank " << rank;
    total += expected.size();
    ASSERT_GE(expected.size(), 1u) << "rank " << rank << " is nobody's end point";
    const absl::Span<const MasterEntry> got = f.MasterList(rank);
    ASSERT_EQ(got.size(), expected.size()) << "rank " << rank;
    for (size_t i = 0; i < got.size(); ++i) {
      ASSERT_EQ(got[i].kind(), expected[i].kind()) << "rank " << rank << " entry " << i;
      ASSERT_EQ(got[i].id(), expected[i].id()) << "rank " << rank << " entry " << i;
      ASSERT_EQ(got[i].endpoint(), expected[i].endpoint()) << "rank " << rank << " entry " << i;
    }
  }
  ASSERT_EQ(r.master_begin.back(), total);
  ASSERT_EQ(r.master.size(), total);
  EXPECT_TRUE(f.MasterList(0).empty());
  EXPECT_TRUE(f.MasterList(k + 1).empty());

  // Components: one per distinct point at level 0, never increasing, one at the end.
  EXPECT_EQ(f.Components(-1), 0u);
  EXPECT_EQ(f.Components(0), f.num_unique());
  for (int64_t level = 1; level <= k; ++level) {
    ASSERT_LE(f.Components(level), f.Components(level - 1)) << "level " << level;
  }
  EXPECT_EQ(f.Components(k), 1u);
  EXPECT_EQ(f.SolidComponents(0), 0u);
  EXPECT_EQ(f.SolidComponents(k), num_tri > 0 ? 1u : 0u);
  EXPECT_EQ(f.report().comparisons.cpu_fallback, 0u);
}

using InvariantsTest = testing::AlphaFamilyTest;

TEST_P(InvariantsTest, MasterListAndIntervals) {
  for (const Case& c : InvariantCases()) {
    SCOPED_TRACE(c.name);
    absl::StatusOr<AlphaFamily> built = Build(c.points);
    ASSERT_THAT(built, IsOk());
    CheckInvariants(*built);
    if (HasFatalFailure()) return;
  }
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(InvariantsTest);

}  // namespace
}  // namespace galpha
