// Area-ratio thresholds (PostGIS ST_ConcaveHull's target_percent, shapely's and QGIS's ratio):
// the smallest level whose regularized area is at least `ratio` times the convex hull's, decided
// exactly from the family's certified area curve (AlphaRanks::area_units), with exact rational
// arithmetic where the curve's error bound cannot decide.
#pragma once

#include <cstdint>
#include <functional>

#include "absl/status/statusor.h"
#include "core/family/alpha_family.hpp"

namespace galpha {

/// The area of the regularized complex (the triangles that are in) at `level`, from the area
/// curve: within the curve's certified bound of the exact area (relative error about 1e-12 of
/// the hull's area, far below a double's printing precision for most shapes), identical on both
/// backends. For display and ratios printed to users; decisions use LevelForAreaRatio.
double RegularizedAreaApprox(const AlphaFamily& family, int64_t level);

/// The convex hull's area (the regularized area at the last level), as RegularizedAreaApprox.
double HullAreaApprox(const AlphaFamily& family);

/// The smallest level L in 0..K whose exact regularized area is >= ratio * the exact hull area
/// (ratio = 1: the convex hull's level, the first at which every triangle is in; ratio = 0 and
/// input without a triangle: level 0). InvalidArgument for a NaN or a ratio outside 0..1.
absl::StatusOr<int64_t> LevelForAreaRatio(const AlphaFamily& family, double ratio);

// The same decision in two steps, for a family whose curve lives elsewhere (a resident family's,
// in device memory): the certified curve brackets the answer from a few of its values, and only
// a bracket it leaves open needs the exact areas, which read every edge's triangles.

/// A family's area curve as the filter reads it.
struct AreaCurveReader {
  int64_t max_level = 0;
  /// Whether the curve has a value for every level 0..K (a family without one is decided by exact
  /// areas alone).
  bool complete = false;
  uint64_t error_units = 0;
  /// The curve's value at a level in 0..K (AlphaRanks::area_units).
  std::function<absl::StatusOr<uint64_t>(int64_t level)> units_at;
};

/// Levels (low, high] that hold the answer (high always qualifies); it is high when
/// high == low + 1.
struct AreaRatioBracket {
  int64_t low = -1;
  int64_t high = 0;
  bool decided() const { return high == low + 1; }
};

/// The bracket the certified curve proves for `ratio` (O(log K) values read). InvalidArgument as
/// LevelForAreaRatio; a failed read's status is returned.
absl::StatusOr<AreaRatioBracket> BracketAreaRatio(const AreaCurveReader& curve, double ratio);

/// The answer within `bracket` (from BracketAreaRatio for the same family and ratio) by exact
/// areas of `family`'s regularized complexes.
int64_t LevelForAreaRatioWithin(const AlphaFamily& family, double ratio, AreaRatioBracket bracket);

}  // namespace galpha
