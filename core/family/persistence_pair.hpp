// A persistence diagram's classes (core/family/persistence.hpp computes it on the host), in a
// header of its own: the engine's pairing on its backend (gpu/alpha/persistence_pairs.cuh) and the
// family, which may carry its diagram, use them too.
#pragma once

#include <cstdint>

#include "core/base/host_vector.hpp"
#include "core/family/alpha_ranks.hpp"

namespace galpha {

/// No simplex: the killer of an essential class (one that never dies).
constexpr uint32_t kNoSimplex = 0xFFFFFFFFu;

/// One class of the diagram, by ranks (exact: rank r is the spectrum's r-th threshold, rank 0 is
/// alpha = 0) and by the simplices that create and kill it (family ids: H0 creator a vertex's input
/// index and killer an edge id; H1 creator an edge id and killer a triangle id). Trivial (no
/// member initializers), so that an array of millions of them is filled without being zeroed first.
struct PersistencePair {
  uint32_t dimension;
  uint32_t birth_rank;
  /// kNeverRank: essential (death = infinity).
  uint32_t death_rank;
  uint32_t creator;
  /// kNoSimplex when essential.
  uint32_t killer;

  bool essential() const { return death_rank == kNeverRank; }
  friend bool operator==(const PersistencePair& a, const PersistencePair& b) {
    return a.dimension == b.dimension && a.birth_rank == b.birth_rank && a.death_rank == b.death_rank &&
           a.creator == b.creator && a.killer == b.killer;
  }
  friend bool operator!=(const PersistencePair& a, const PersistencePair& b) { return !(a == b); }
};

/// Every class of positive persistence (death rank > birth rank; classes born and killed at the
/// same threshold are not listed, as in GUDHI's default), ordered by dimension, birth rank, death
/// rank (essential last), then the creator's canonical position.
struct PersistenceDiagram {
  HostVector<PersistencePair> pairs;
  /// pairs of dimension 0 are pairs[0, dimension_begin[1]), of dimension 1 the rest.
  size_t dimension_begin[3] = {0, 0, 0};
};

}  // namespace galpha
