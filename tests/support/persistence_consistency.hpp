// Checks that a family's persistence diagram agrees with its own Betti curves and simplices: at
// every level, the classes alive (born at or before it, dying after it) are exactly the
// components and holes the engine's curves count, and every pair's creator and killer are born at
// the pair's ranks. Header-only: used by the brute-force, GUDHI and data-set tests.
#pragma once

#include <cstdint>
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
  int64_t b0 = 0, b1 = 0;
  for (size_t level = 0; level < levels; ++level) {
    b0 += alive[0][level];
    b1 += alive[1][level];
    const auto at = static_cast<int64_t>(level);
    ASSERT_EQ(b0, f.Components(at)) << "components from the diagram at level " << level;
    ASSERT_EQ(b1, f.Holes(at, ClassifyMode::kGeneral)) << "holes from the diagram at level " << level;
  }
}

}  // namespace galpha::testing
