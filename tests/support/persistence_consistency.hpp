// Checks of a family's persistence diagram: against its own Betti curves and simplices (at every
// level, the classes alive, born at or before it and dying after it, are exactly the components
// and holes the engine's curves count; every pair's creator and killer are born at the pair's
// ranks; the pairs are in the documented order), and, for small families, against the textbook
// algorithm: the standard reduction of the boundary matrix over GF(2) in the filtration's total
// order, which names the same creating and killing simplices (the pairing is unique for a total
// order). Header-only: used by the brute-force, GUDHI and data-set tests.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "core/family/alpha_family.hpp"
#include "core/family/canonical_order.hpp"
#include "core/family/persistence.hpp"
#include "gtest/gtest.h"

namespace galpha::testing {

inline void ExpectPersistenceMatchesCurves(const AlphaFamily& f) {
  const absl::StatusOr<PersistenceDiagram> diagram = ComputePersistence(f);
  ASSERT_TRUE(diagram.ok()) << diagram.status();
  const AlphaRanks& r = f.ranks();
  const auto levels = static_cast<size_t>(f.max_level()) + 1;
  // alive[d][L] by difference arrays over the levels.
  std::vector<int64_t> alive[2] = {std::vector<int64_t>(levels + 1, 0), std::vector<int64_t>(levels + 1, 0)};
  for (size_t i = 0; i < diagram->pairs.size(); ++i) {
    const PersistencePair& p = diagram->pairs[i];
    ASSERT_EQ(p.dimension, i < diagram->dimension_begin[1] ? 0u : 1u) << "pair " << i;
    ASSERT_LT(p.birth_rank, p.death_rank) << "pair " << i;
    ++alive[p.dimension][p.birth_rank];
    if (!p.essential()) --alive[p.dimension][p.death_rank];
    if (p.dimension == 0) {
      EXPECT_EQ(p.birth_rank, 0u);
      EXPECT_EQ(f.representative()[p.creator], p.creator) << "H0 creator " << p.creator;
      if (!p.essential()) {
        EXPECT_EQ(EdgeBirthRank(r, p.killer), p.death_rank) << "H0 killer edge " << p.killer;
      }
    } else {
      EXPECT_EQ(EdgeBirthRank(r, p.creator), p.birth_rank) << "H1 creator edge " << p.creator;
      if (!p.essential()) {
        EXPECT_EQ(r.tri_rank[p.killer], p.death_rank) << "H1 killer triangle " << p.killer;
      }
    }
  }
  // The documented order: dimension, birth, death (essential last), creator's canonical position.
  const CanonicalOrders orders = ComputeCanonicalOrders(f);
  std::vector<uint32_t> edge_position(f.edges().size());
  for (uint32_t i = 0; i < orders.edge_order.size(); ++i) edge_position[orders.edge_order[i]] = i;
  for (size_t i = 1; i < diagram->pairs.size(); ++i) {
    const PersistencePair& a = diagram->pairs[i - 1];
    const PersistencePair& b = diagram->pairs[i];
    auto key = [&](const PersistencePair& p) {
      return std::make_tuple(p.dimension, p.birth_rank, p.death_rank,
                             p.dimension == 0 ? p.creator : edge_position[p.creator]);
    };
    ASSERT_LT(key(a), key(b)) << "pairs " << i - 1 << " and " << i << " out of order";
  }
  int64_t b0 = 0, b1 = 0;
  for (size_t level = 0; level < levels; ++level) {
    b0 += alive[0][level];
    b1 += alive[1][level];
    const auto at = static_cast<int64_t>(level);
    ASSERT_EQ(b0, f.Components(at)) << "components from the diagram at level " << level;
    ASSERT_EQ(b1, f.Holes(at, ClassifyMode::kGeneral)) << "holes from the diagram at level " << level;
  }
}

/// The diagram against the standard reduction of the boundary matrix (small families: the
/// matrix is dense). Simplices never born (kNeverRank) are left out of the filtration.
inline void ExpectPairsMatchMatrixReduction(const AlphaFamily& f) {
  const absl::StatusOr<PersistenceDiagram> diagram = ComputePersistence(f);
  ASSERT_TRUE(diagram.ok()) << diagram.status();
  const AlphaRanks& r = f.ranks();
  const CanonicalOrders orders = ComputeCanonicalOrders(f);
  // Simplices as (rank, dimension, canonical position, sorted vertices).
  using Vertices = std::array<uint32_t, 3>;
  struct Simplex {
    uint32_t rank, dimension, position;
    Vertices vertices;
  };
  std::vector<Simplex> simplices;
  for (uint32_t v = 0; v < f.points().size(); ++v) {
    if (f.representative()[v] == v) simplices.push_back({0, 0, v, {v, kNoVertex, kNoVertex}});
  }
  for (uint32_t i = 0; i < orders.edge_order.size(); ++i) {
    const uint32_t e = orders.edge_order[i];
    const auto ab = SortedEdge(f.edges()[e]);
    if (EdgeBirthRank(r, e) != kNeverRank) simplices.push_back({EdgeBirthRank(r, e), 1, i, {ab[0], ab[1], kNoVertex}});
  }
  for (uint32_t i = 0; i < orders.triangle_order.size(); ++i) {
    const uint32_t t = orders.triangle_order[i];
    if (r.tri_rank[t] != kNeverRank) simplices.push_back({r.tri_rank[t], 2, i, SortedTriangle(f.triangles()[t])});
  }
  std::sort(simplices.begin(), simplices.end(), [](const Simplex& a, const Simplex& b) {
    return std::make_tuple(a.rank, a.dimension, a.position) < std::make_tuple(b.rank, b.dimension, b.position);
  });
  ASSERT_LE(simplices.size(), 4000u) << "ExpectPairsMatchMatrixReduction is for small families";
  std::map<Vertices, size_t> index;
  for (size_t i = 0; i < simplices.size(); ++i) index[simplices[i].vertices] = i;
  // Columns as sorted index sets; reduce left to right (symmetric differences over GF(2)).
  const size_t n = simplices.size();
  std::vector<std::vector<size_t>> column(n);
  for (size_t j = 0; j < n; ++j) {
    const Simplex& s = simplices[j];
    const Vertices& v = s.vertices;
    if (s.dimension == 1) {
      column[j] = {index.at({v[0], kNoVertex, kNoVertex}), index.at({v[1], kNoVertex, kNoVertex})};
    } else if (s.dimension == 2) {
      column[j] = {index.at({v[0], v[1], kNoVertex}), index.at({v[0], v[2], kNoVertex}),
                   index.at({v[1], v[2], kNoVertex})};
    }
    std::sort(column[j].begin(), column[j].end());
  }
  std::vector<size_t> owner_of_low(n, n);  // column whose lowest entry is i
  std::set<std::tuple<uint32_t, Vertices, Vertices>> expected;
  std::vector<bool> paired(n, false);
  for (size_t j = 0; j < n; ++j) {
    while (!column[j].empty() && owner_of_low[column[j].back()] != n) {
      std::vector<size_t> sum;
      std::set_symmetric_difference(column[j].begin(), column[j].end(), column[owner_of_low[column[j].back()]].begin(),
                                    column[owner_of_low[column[j].back()]].end(), std::back_inserter(sum));
      column[j] = std::move(sum);
    }
    if (column[j].empty()) continue;
    const size_t creator = column[j].back();
    owner_of_low[creator] = j;
    paired[creator] = paired[j] = true;
    if (simplices[j].rank > simplices[creator].rank) {
      expected.emplace(simplices[creator].dimension, simplices[creator].vertices, simplices[j].vertices);
    }
  }
  for (size_t i = 0; i < n; ++i) {
    if (!paired[i])
      expected.emplace(simplices[i].dimension, simplices[i].vertices, Vertices{kNoVertex, kNoVertex, kNoVertex});
  }
  std::set<std::tuple<uint32_t, Vertices, Vertices>> got;
  for (const PersistencePair& p : diagram->pairs) {
    const PairVertices v = VerticesOf(f, p);
    Vertices creator{kNoVertex, kNoVertex, kNoVertex}, killer{kNoVertex, kNoVertex, kNoVertex};
    std::copy(v.creator.begin(), v.creator.begin() + p.dimension + 1, creator.begin());
    if (!p.essential()) std::copy(v.killer.begin(), v.killer.begin() + p.dimension + 2, killer.begin());
    got.emplace(p.dimension, creator, killer);
  }
  auto show = [](const std::tuple<uint32_t, Vertices, Vertices>& t) {
    std::string text = "H" + std::to_string(std::get<0>(t)) + " (";
    for (uint32_t v : std::get<1>(t)) text += v == kNoVertex ? "" : std::to_string(v) + " ";
    text += ") killed by (";
    for (uint32_t v : std::get<2>(t)) text += v == kNoVertex ? "" : std::to_string(v) + " ";
    return text + ")";
  };
  std::string missing, extra;
  for (const auto& t : expected) {
    if (got.count(t) == 0 && missing.size() < 400) missing += show(t) + "; ";
  }
  for (const auto& t : got) {
    if (expected.count(t) == 0 && extra.size() < 400) extra += show(t) + "; ";
  }
  EXPECT_TRUE(missing.empty() && extra.empty())
      << "the diagram's simplices differ from the boundary matrix reduction's: the reduction's pairs missing: "
      << missing << " the diagram's pairs the reduction lacks: " << extra;
}

}  // namespace galpha::testing
