// The validation layer every point set passes before the engine sees it: the input domain within
// which every answer is exact (docs/design.md, "The input domain").
#pragma once

#include <cstdint>

#include "absl/status/status.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"

namespace galpha {

/// Largest number of input points: triangle ids are signed 32-bit and a triangulation of n points
/// has up to 2n triangles on the sphere (the vertex at infinity included).
inline constexpr uint64_t kMaxPoints = uint64_t{1} << 30;

/// Every |coordinate| must be below 2^500 (~3.27e150). The exact predicates themselves reach
/// 2^1022, but the quantities the engine reports in doubles must not overflow: areas and squared
/// lengths are products of two coordinate differences (< 2^1002 here) summed a few at a time.
inline constexpr double kMaxAbsCoordinate = 0x1p500;

/// The spread of magnitudes within one point set: with H the largest |coordinate| and m the
/// smallest nonzero one (below 2^-1022, subnormals included, counting as 2^-1022), H / m must be
/// below 2^kMaxSpreadLog2 (~3.5e131). The in-circle test and its Simulation of Simplicity evaluate
/// degree-4 polynomials exactly within one binary64 exponent range, which holds every partial
/// product only for such spreads (core/exact/predicates.hpp, "SUPPORTED COORDINATE RANGE", states
/// it for the points of one call; a whole set within it puts every call within it).
inline constexpr int kMaxSpreadLog2 = 437;
/// Magnitudes below this count as it in the spread (the predicates' own floor).
inline constexpr double kSpreadFloor = 0x1p-1022;

/// OK when the points lie in the engine's input domain: every coordinate finite, every
/// |coordinate| < kMaxAbsCoordinate, the spread of magnitudes below 2^kMaxSpreadLog2, and the
/// count within kMaxPoints. InvalidArgument names the first point outside the domain and the bound
/// it breaks; ResourceExhausted gives the count limit.
absl::Status ValidatePoints(absl::Span<const Point2> points);

/// Every |weight| must be below 2^1000 (a radius below 2^500, as coordinates).
inline constexpr double kMaxAbsWeight = 0x1p1000;

/// OK when `weights` (squared radii, one per point; negative ones are valid) may be triangulated
/// with `points` (already valid): as many as the points, every one finite, every |weight| below
/// kMaxAbsWeight, and sqrt(|weight|) counted as a coordinate magnitude in the spread of
/// ValidatePoints (the power test is exact within it: core/exact/power.hpp). InvalidArgument names
/// the first weight outside the domain and the bound it breaks.
absl::Status ValidateWeights(absl::Span<const Point2> points, absl::Span<const double> weights);

}  // namespace galpha
