// One class of a persistence diagram (core/family/persistence.hpp), in a header of its own: the
// engine's device pairing (gpu/alpha/persistence_pairs.cuh) writes these too.
#pragma once

#include <cstdint>

#include "core/family/alpha_ranks.hpp"

namespace galpha {

/// No simplex: the killer of an essential class (one that never dies).
constexpr uint32_t kNoSimplex = 0xFFFFFFFFu;

/// One class of the diagram, by ranks (exact: rank r is the spectrum's r-th threshold, rank 0 is
/// alpha = 0) and by the simplices that create and kill it (family ids: H0 creator a vertex's input
/// index and killer an edge id; H1 creator an edge id and killer a triangle id).
struct PersistencePair {
  uint32_t dimension = 0;
  uint32_t birth_rank = 0;
  /// kNeverRank: essential (death = infinity).
  uint32_t death_rank = kNeverRank;
  uint32_t creator = 0;
  /// kNoSimplex when essential.
  uint32_t killer = kNoSimplex;

  bool essential() const { return death_rank == kNeverRank; }
};

}  // namespace galpha
