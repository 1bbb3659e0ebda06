// Deterministic weights for weighted (regular) triangulations and weighted alpha shapes: one per
// point, a pure function of (kind, points, seed), scaled to the points' spacing so that every
// generator of point_generators.hpp gets comparable behaviour (some points hidden, some not).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/base/point.hpp"

namespace galpha::gen {

/// The kinds, by name:
///  "zero"        every weight 0 (the unweighted triangulation);
///  "equal"       every weight the same positive value (the unweighted triangulation again);
///  "uniform"     uniform in [0, s^2], s the typical spacing (bounding box / sqrt(n));
///  "signed"      uniform in [-s^2, s^2] (negative weights are valid);
///  "one_huge"    0 everywhere but one point, whose disk's radius is a quarter of the box's side
///                (about a fifth of a square box's area): it hides every point near it;
///  "many_hidden" every other point (by index) 4 s^2, the rest 0: many light points hidden;
///  "integers"    small integers times s^2 rounded to a power of two: with integer coordinates
///                (grids, lines) exact power ties everywhere.
std::vector<double> Weights(const std::string& kind, const std::vector<Point2>& points, uint64_t seed);

/// Every kind above.
std::vector<std::string> WeightKinds();

}  // namespace galpha::gen
