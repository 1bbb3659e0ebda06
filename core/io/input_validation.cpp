#include "core/io/input_validation.hpp"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace galpha {

absl::Status ValidatePoints(absl::Span<const Point2> points) {
  if (points.size() > kMaxPoints) {
    return absl::ResourceExhaustedError(absl::StrCat("too many points: ", points.size(), " exceeds the limit of ",
                                                     kMaxPoints, " (32-bit triangle indices)"));
  }
  // On every core (a serial pass took 24 ms at 10M points); the first bad index is the smallest.
  const int64_t n = static_cast<int64_t>(points.size());
  int64_t first_bad = n;
#pragma omp parallel for reduction(min : first_bad) schedule(static)
  for (int64_t i = 0; i < n; ++i) {
    const Point2& p = points[static_cast<size_t>(i)];
    if ((!std::isfinite(p.x) || !std::isfinite(p.y)) && i < first_bad) first_bad = i;
  }
  if (first_bad < n) {
    const Point2& p = points[static_cast<size_t>(first_bad)];
    return absl::InvalidArgumentError(absl::StrCat("point ", first_bad, " is not finite: (", p.x, ", ", p.y,
                                                   "); coordinates must be finite doubles"));
  }
  return absl::OkStatus();
}

}  // namespace galpha
