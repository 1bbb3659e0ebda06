// The point set a server builds before it listens (AlphaService::WarmUp), so that its first caller
// does not pay the process's one-time costs of the engine: on a GPU, loading the kernels (CUDA loads
// each on its first launch), the first launch of the exact comparisons' kernels (their deep stacks
// grow the device's local-memory reservation, measured at about 9 ms: bench/README.md), and the
// stream-ordered pool's first mappings (until the server's idle release gives them back).
#pragma once

#include <vector>

#include "core/base/point.hpp"

namespace galpha::server {

/// Points and their weights (squared radii), one per point.
struct WarmUpInput {
  std::vector<Point2> points;
  std::vector<double> weights;
};

/// A `side` x `side` lattice of spacing 1 whose first `side` / 2 rows have their coordinates nudged
/// by 0 to 3 ulps in a fixed pattern: there its co-circular quadruples, broken by ulps, reach the
/// exact radius comparisons of near ties, and in the exact rows those of exact ties, besides the
/// degenerate predicates and the common path. Weighted, one point in 16 has weight 3 (it hides its
/// nearest neighbours), the others 0, so that a weighted build also removes hidden points.
WarmUpInput WarmUpLattice(int side);

}  // namespace galpha::server
