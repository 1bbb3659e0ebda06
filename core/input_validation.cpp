#include "core/input_validation.hpp"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace galpha {

absl::Status ValidatePoints(absl::Span<const Point2> points) {
  if (points.size() > kMaxPoints) {
    return absl::ResourceExhaustedError(absl::StrCat("too many points: ", points.size(),
                                                     " exceeds the limit of ", kMaxPoints,
                                                     " (32-bit triangle indices)"));
  }
  for (size_t i = 0; i < points.size(); ++i) {
    const Point2& p = points[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      return absl::InvalidArgumentError(absl::StrCat("point ", i, " is not finite: (", p.x, ", ", p.y,
                                                     "); coordinates must be finite doubles"));
    }
  }
  return absl::OkStatus();
}

}  // namespace galpha
