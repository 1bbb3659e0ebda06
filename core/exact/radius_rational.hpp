// Exact squared radii as GMP rationals: the CPU fallback of the spectrum's exact comparisons
// (core/exact/radius_compare.hpp's bounded path answers Order::kUndecided beyond its buffers and
// exponent range) and the exact comparison of user thresholds with the spectrum. Host only; exact
// and unbounded.
#pragma once

#include <gmpxx.h>

#include <optional>

#include "core/base/point.hpp"

namespace galpha {

/// rho^2 of the edge (n = 2) or triangle (n = 3) p[0..n), exactly; nullopt for a triangle whose
/// vertices are collinear (an infinite radius).
std::optional<mpq_class> RadiusSqRational(const Point2* p, int n);

/// Exact sign of rho^2(a) - rho^2(b); an infinite radius is larger than every finite one.
int CompareRadiusSqRational(const Point2* a, int na, const Point2* b, int nb);

/// The double nearest to `value` (ties to even), +infinity beyond the double range.
double NearestDouble(const mpq_class& value);

}  // namespace galpha
