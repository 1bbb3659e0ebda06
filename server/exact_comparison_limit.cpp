#include "server/exact_comparison_limit.hpp"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"

namespace galpha::server {

uint64_t ExactComparisonLimit(size_t points, const ExactComparisonLimitOptions& options) {
  if (!(options.per_point > 0)) return 0;
  const double scaled = std::ceil(options.per_point * static_cast<double>(points));
  // Beyond 2^63 the limit is no limit in practice; the cast below must stay in range.
  const uint64_t per_points = scaled >= 0x1p63 ? uint64_t{1} << 63 : static_cast<uint64_t>(scaled);
  return std::max(options.floor, per_points);
}

std::string ExactComparisonLimitMessage(size_t points, const ExactComparisonLimitOptions& options) {
  return absl::StrFormat(
      "the build needed more than its limit of %d exact radius comparisons and was stopped: %g a point for %d "
      "points, at least %d (--max_exact_comparisons_per_point, --exact_comparisons_floor); honest inputs need a "
      "few a point, so this input's radii are adversarially close",
      ExactComparisonLimit(points, options), options.per_point, points, options.floor);
}

}  // namespace galpha::server
