// Area-ratio thresholds (PostGIS ST_ConcaveHull's target_percent, shapely's and QGIS's ratio):
// the smallest level whose regularized area is at least `ratio` times the convex hull's, decided
// exactly from the family's certified area curve (AlphaRanks::area_units), with exact rational
// arithmetic where the curve's error bound cannot decide.
#pragma once

#include <cstdint>

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

}  // namespace galpha
