// Exact comparison of squared radii in bounded buffers, the path the spectrum's ties take on the
// device and the host alike: one double comparison when both values are exactly doubles (grids),
// else expansion arithmetic on the exact terms (radius_terms.hpp). Order::kUndecided when a buffer
// would overflow or the operands' exponent range would make an error-free transformation inexact;
// the caller then compares with GMP rationals (radius_rational.hpp, host only).
#pragma once

#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/expansion.hpp"
#include "core/exact/order.hpp"
#include "core/exact/predicates.hpp"
#include "core/exact/radius_terms.hpp"

namespace galpha {

/// rho^2 of p[0..n) when every operation computing it in plain doubles is exact and the result is
/// a double, as for small integer coordinates (grids): then equal values are proven equal by one
/// double comparison. False otherwise (nothing is claimed). Differences are kept inside
/// [2^-100, 2^100] so that no Two-Product tail can underflow or overflow in degree 6.
GALPHA_HD inline bool ExactDoubleRadiusSq(const Point2* p, int n, double* out) {
  using namespace exact;
  pred_detail::ExactnessWitness w;
  const int from[3] = {0, 0, 1}, to[3] = {1, 2, 2};
  const int m = n == 2 ? 1 : 3;
  double dx[3], dy[3], len[3];
  for (int k = 0; k < m; ++k) {
    dx[k] = w.Diff(p[to[k]].x, p[from[k]].x);
    dy[k] = w.Diff(p[to[k]].y, p[from[k]].y);
    const double c[2] = {Abs(dx[k]), Abs(dy[k])};
    for (double v : c) {
      if (v != 0.0 && !(v >= 0x1p-100 && v <= 0x1p100)) return false;
    }
    len[k] = w.Sum(w.Product(dx[k], dx[k]), w.Product(dy[k], dy[k]));
  }
  if (!w.exact) return false;
  if (n == 2) {
    *out = Mul(len[0], 0.25);  // exact: len >= 2^-200
    return true;
  }
  const double num = w.Product(w.Product(len[0], len[1]), len[2]);
  const double area = w.Diff(w.Product(dx[0], dy[1]), w.Product(dy[0], dx[1]));
  if (!w.exact || area == 0.0) return false;
  const double den = Mul(w.Product(area, area), 4.0);
  const double q = num / den;
  double hi, lo;
  TwoProduct(q, den, hi, lo);
  if (!w.exact || hi != num || lo != 0.0) return false;
  *out = q;
  return true;
}

/// The exact order of rho^2(a) and rho^2(b) for simplices a (na = 2 or 3 points) and b, or
/// Order::kUndecided when the bounded buffers or the exponent range do not suffice.
GALPHA_HD inline Order CompareRadiusSqBounded(const Point2* a, int na, const Point2* b, int nb) {
  using namespace radius_detail;
  double va, vb;
  if (ExactDoubleRadiusSq(a, na, &va) && ExactDoubleRadiusSq(b, nb, &vb)) return OrderOfSign((va > vb) - (va < vb));
  double dmax = 0.0;
  int lowest = 1 << 20;
  if (!DifferenceRange(a, na, &dmax, &lowest) || !DifferenceRange(b, nb, &dmax, &lowest)) {
    return Order::kUndecided;
  }
  // Num_a / Den_a vs Num_b / Den_b, both of degree 2: compare Num_a Den_b with Num_b Den_a.
  const int degree = (na == 3 || nb == 3) ? (na == 3 && nb == 3 ? 10 : 6) : 2;
  int s = 0;
  if (!ExactScaleFor(dmax, lowest, degree, &s)) return Order::kUndecided;
  ExactRadiusTerms ta, tb;
  if (!ExactTerms(a, na, s, &ta) || !ExactTerms(b, nb, s, &tb)) return Order::kUndecided;
  if (ta.denn == 0 || tb.denn == 0) {  // collinear triangles: infinite radius
    return OrderOfSign((ta.denn == 0 ? 1 : 0) - (tb.denn == 0 ? 1 : 0));
  }
  double left[kBoundedCapacity], right[kBoundedCapacity], diff[kBoundedCapacity];
  int leftn, rightn, diffn;
  if (!BoundedProduct(ta.numn, ta.num, tb.denn, tb.den, left, &leftn) ||
      !BoundedProduct(tb.numn, tb.num, ta.denn, ta.den, right, &rightn) ||
      !BoundedSum(leftn, left, rightn, right, true, diff, &diffn)) {
    return Order::kUndecided;
  }
  return OrderOfSign(ExpansionSign(diffn, diff));
}

}  // namespace galpha
