#include "core/io/input_validation.hpp"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/io/number_text.hpp"

namespace galpha {
namespace {

/// The magnitude a coordinate contributes to the spread: 0 for zero (it takes no part), else
/// max(|c|, kSpreadFloor).
double SpreadMagnitude(double c) {
  const double a = std::fabs(c);
  return a == 0.0 ? 0.0 : std::max(a, kSpreadFloor);
}

/// "(x, y)" with the digits that read the doubles back, and no more.
std::string Coordinates(const Point2& p) {
  return absl::StrCat("(", ShortestDouble(p.x), ", ", ShortestDouble(p.y), ")");
}

}  // namespace

absl::Status ValidatePoints(absl::Span<const Point2> points) {
  if (points.size() > kMaxPoints) {
    return absl::ResourceExhaustedError(absl::StrCat("too many points: ", points.size(), " exceeds the limit of ",
                                                     kMaxPoints, " (32-bit triangle indices)"));
  }
  // On every core (a serial pass took 24 ms at 10M points). One pass gathers what every check
  // needs; the error paths then look for the first offending index serially, as they run once.
  const int64_t n = static_cast<int64_t>(points.size());
  int64_t first_bad = n;
  double largest = 0.0;
  double smallest = kMaxAbsCoordinate;  // of the nonzero spread magnitudes
#pragma omp parallel for reduction(min : first_bad, smallest) reduction(max : largest) schedule(static)
  for (int64_t i = 0; i < n; ++i) {
    const Point2& p = points[static_cast<size_t>(i)];
    if ((!std::isfinite(p.x) || !std::isfinite(p.y)) && i < first_bad) first_bad = i;
    for (const double c : {p.x, p.y}) {
      const double m = SpreadMagnitude(c);
      largest = m > largest ? m : largest;  // NaN compares false and stays out
      if (m > 0.0 && m < smallest) smallest = m;
    }
  }
  if (first_bad < n) {
    const Point2& p = points[static_cast<size_t>(first_bad)];
    return absl::InvalidArgumentError(absl::StrCat("point ", first_bad, " is not finite: (", p.x, ", ", p.y,
                                                   "); coordinates must be finite doubles"));
  }
  if (largest >= kMaxAbsCoordinate) {
    for (int64_t i = 0; i < n; ++i) {
      const Point2& p = points[static_cast<size_t>(i)];
      if (std::fabs(p.x) >= kMaxAbsCoordinate || std::fabs(p.y) >= kMaxAbsCoordinate) {
        return absl::InvalidArgumentError(
            absl::StrCat("point ", i, " ", Coordinates(p),
                         " has a coordinate of magnitude 2^500 (~3.27e150) or more; every |coordinate| must be "
                         "below 2^500 (scale the data, e.g. to other units)"));
      }
    }
  }
  // largest / smallest < 2^kMaxSpreadLog2, decided exactly: smallest * 2^437 neither overflows
  // (smallest <= largest < 2^500) nor loses bits (smallest >= 2^-1022 is normal).
  if (largest > 0.0 && std::ldexp(smallest, kMaxSpreadLog2) <= largest) {
    int64_t largest_at = 0;
    while (SpreadMagnitude(points[static_cast<size_t>(largest_at)].x) != largest &&
           SpreadMagnitude(points[static_cast<size_t>(largest_at)].y) != largest) {
      ++largest_at;
    }
    const double floor = std::ldexp(largest, -kMaxSpreadLog2);  // exact: largest >= 2^437 * 2^-1022
    for (int64_t i = 0; i < n; ++i) {
      const Point2& p = points[static_cast<size_t>(i)];
      const double mx = SpreadMagnitude(p.x), my = SpreadMagnitude(p.y);
      if ((mx > 0.0 && mx <= floor) || (my > 0.0 && my <= floor)) {
        return absl::InvalidArgumentError(absl::StrCat(
            "point ", i, " ", Coordinates(p), " has a nonzero coordinate 2^", kMaxSpreadLog2,
            " (~3.5e131) or more times smaller than the largest magnitude in the set (point ", largest_at, " ",
            Coordinates(points[static_cast<size_t>(largest_at)]),
            "); the exact predicates need the magnitudes of one point set within a ratio of 2^", kMaxSpreadLog2,
            " (magnitudes below 2^-1022 count as 2^-1022): round such coordinates to 0 or split the set"));
      }
    }
  }
  return absl::OkStatus();
}

absl::Status ValidateWeights(absl::Span<const Point2> points, absl::Span<const double> weights) {
  if (weights.size() != points.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat(weights.size(), " weights for ", points.size(), " points: give one weight per point"));
  }
  const int64_t n = static_cast<int64_t>(points.size());
  int64_t first_bad = n;
  double largest = 0.0, smallest = kMaxAbsCoordinate;  // spread magnitudes, as in ValidatePoints
#pragma omp parallel for reduction(min : first_bad, smallest) reduction(max : largest) schedule(static)
  for (int64_t i = 0; i < n; ++i) {
    const double w = weights[static_cast<size_t>(i)];
    if (!(std::fabs(w) < kMaxAbsWeight) && i < first_bad) first_bad = i;  // NaN, inf or too large
    const Point2& p = points[static_cast<size_t>(i)];
    for (const double c : {p.x, p.y, std::sqrt(std::fabs(w))}) {
      const double m = SpreadMagnitude(c);
      largest = m > largest ? m : largest;
      if (m > 0.0 && m < smallest) smallest = m;
    }
  }
  if (first_bad < n) {
    const double w = weights[static_cast<size_t>(first_bad)];
    if (!std::isfinite(w)) {
      return absl::InvalidArgumentError(
          absl::StrCat("weight ", first_bad, " is not finite: ", w, "; weights must be finite doubles"));
    }
    return absl::InvalidArgumentError(absl::StrCat("weight ", first_bad, " (", ShortestDouble(w),
                                                   ") has a magnitude of 2^1000 (~1.07e301) or more; every |weight| "
                                                   "must be below 2^1000 (a radius below 2^500)"));
  }
  if (largest > 0.0 && std::ldexp(smallest, kMaxSpreadLog2) <= largest) {
    const double floor = std::ldexp(largest, -kMaxSpreadLog2);
    for (int64_t i = 0; i < n; ++i) {
      const double w = weights[static_cast<size_t>(i)];
      const double m = SpreadMagnitude(std::sqrt(std::fabs(w)));
      if (m > 0.0 && (m <= floor || m >= largest)) {
        return absl::InvalidArgumentError(absl::StrCat(
            "weight ", i, " (", ShortestDouble(w),
            ") is out of scale with the set: the square roots of the "
            "weights count as coordinate magnitudes, and the exact power test needs all magnitudes of one point "
            "set within a ratio of 2^",
            kMaxSpreadLog2,
            " (~3.5e131) of each other; round such weights to 0 or "
            "scale the set"));
      }
    }
    // Not reached for points that ValidatePoints accepts: some weight is then at an end.
    return absl::InvalidArgumentError("the weights and coordinates span more than 2^437 in magnitude");
  }
  return absl::OkStatus();
}

}  // namespace galpha
