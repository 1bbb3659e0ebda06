// Weighted squared radii and the weighted attachment test as exact GMP rationals: the host's
// fallback where bounded arithmetic cannot decide (core/exact/weighted_radius.hpp), the exact
// comparison of user thresholds with a weighted spectrum, and the tests' oracle. Host only.
#pragma once

#include <gmpxx.h>

#include <optional>

#include "core/base/point.hpp"

namespace galpha {

/// rho^2 of the weighted edge (n = 2) or triangle (n = 3) p[0..n), w[0..n): the squared radius of
/// the smallest circle orthogonal to the vertices' circles; nullopt for a collinear triangle. With
/// w == nullptr, the unweighted rho^2 (RadiusSqRational).
std::optional<mpq_class> SimplexRadiusSqRational(const Point2* p, const double* w, int n);

/// Exact sign of rho^2(a) - rho^2(b) (an infinite radius above every finite one); wa and wb both
/// weights or both nullptr.
int CompareSimplexRadiusSqRational(const Point2* a, const double* wa, int na, const Point2* b, const double* wb,
                                   int nb);

/// +1 when r attaches the weighted edge pq (weighted_radius.hpp, WeightedAttachedSign), 0 on the
/// circle, -1 outside; exactly.
int WeightedAttachedSignRational(Point2 p, Point2 q, Point2 r, double wp, double wq, double wr);

}  // namespace galpha
