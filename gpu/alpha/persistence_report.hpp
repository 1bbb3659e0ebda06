// What the engine reports of one persistence diagram's computation (persistence_engine.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include "core/base/stage_time.hpp"

namespace galpha {

/// How the elder rule went over one spanning forest (persistence_pairs.cuh, PairBySplicing).
struct ForestPairing {
  uint32_t forest_edges = 0;
  /// Parallel rounds of splicing.
  uint32_t rounds = 0;
  /// Forest edges left to the host's union-find in Kruskal's order.
  uint32_t host_finished_edges = 0;
};

struct PersistenceReport {
  /// persistence_upload (CUDA, from a family in host memory), persistence_orders (canonical),
  /// persistence_h0 (the primal forest and its elder rule), persistence_h1 (the dual forest, the
  /// primal's complement, and its elder rule), persistence_pairs (sorted on the backend),
  /// persistence_download.
  std::vector<StageTime> stage_times;
  /// The primal forest (H0) and the dual one (H1).
  ForestPairing forests[2];
};

}  // namespace galpha
