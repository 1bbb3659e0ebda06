// The comparison of alpha_bruteforce_test: the family the engine builds on a backend against the
// brute-force family of tests/support/bruteforce_alpha_oracle.hpp.
#pragma once

#include <vector>

#include "core/base/point.hpp"
#include "gpu/system/backend.hpp"

namespace galpha::testing {

/// Builds the family of `points` (whose Delaunay triangulation must be unique) on `backend` and
/// checks it against the brute-force family: the simplices, the spectrum (exact values and nearest
/// doubles), the rank tables, the classes in both modes under both vertex rules at every level, the
/// component curves, the optimal levels and the resolution of user thresholds (alpha_sq and alpha)
/// to levels. Fatal failures end the comparison; use with HasFatalFailure().
void CompareWithBruteForce(const std::vector<Point2>& points, Backend backend);

}  // namespace galpha::testing
