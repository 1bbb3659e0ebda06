// The double nearest to an exact squared radius: the alpha spectrum's published values. A fast
// double-double path with a certified error bound decides almost every rounding; the rest are
// rounded exactly on the expansion terms (radius_terms.hpp), and what the bounded buffers cannot
// hold goes to the host's GMP fallback (radius_rational.hpp). Host and device alike.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/double_double.hpp"
#include "core/exact/expansion.hpp"
#include "core/exact/order.hpp"
#include "core/exact/radius_terms.hpp"

namespace galpha {

namespace radius_detail {

/// The order of Num against 4 m Den for m = c + h (h a power of two, a half gap to a neighbour of
/// c, so that (c, h) is a nonoverlapping pair): the exact value against m. Order::kUndecided on
/// overflow.
GALPHA_HD inline Order CompareToScaled(const ExactRadiusTerms& t, double c, double h) {
  double m[2];
  const int mn = TwoToExpansion(Mul(c, 4.0), Mul(h, 4.0), m);
  double prod[kBoundedCapacity], diff[kBoundedCapacity];
  int prodn, diffn;
  if (!BoundedProduct(mn, m, t.denn, t.den, prod, &prodn)) return Order::kUndecided;
  if (!BoundedSum(t.numn, t.num, prodn, prod, true, diff, &diffn)) return Order::kUndecided;
  return OrderOfSign(ExpansionSign(diffn, diff));
}

GALPHA_HD GALPHA_FORCEINLINE double NextUp(double c) { return BitsToDouble(DoubleBits(c) + 1); }
GALPHA_HD GALPHA_FORCEINLINE double NextDown(double c) { return BitsToDouble(DoubleBits(c) - 1); }

}  // namespace radius_detail

/// The double nearest to rho^2 of the simplex p[0..n) (ties to even), into *out: exact rounding
/// whenever the result is a normal double (in the subnormal range the correctly rounded
/// significand is scaled with one more rounding). Collinear triangles give +infinity. False when
/// the bounded buffers or the exponent range do not suffice (use the CPU fallback).
GALPHA_HD inline bool NearestRadiusSqBounded(const Point2* p, int n, double* out) {
  using namespace radius_detail;
  double dmax = 0.0;
  int lowest = 1 << 20;
  int s = 0;
  ExactRadiusTerms t;
  if (!DifferenceRange(p, n, &dmax, &lowest) || !ExactScaleFor(dmax, lowest, n == 2 ? 2 : 6, &s) ||
      !ExactTerms(p, n, s, &t)) {
    return false;
  }
  if (t.denn == 0) {
    *out = BitsToDouble(uint64_t{0x7ff} << 52);
    return true;
  }
  // In scaled units v = Num / (4 Den) = q * 2^shift with q in (1/4, 4) and c its first guess. The
  // largest scaled difference is about 2^96 and rho is at least half the longest edge, so shift
  // >= 188; a shift above 700 (a triangle whose radius exceeds its edges by 2^250) goes to the
  // fallback, which keeps m * Den below and above the limits of Two-Product.
  const double num = t.num[t.numn - 1], den = t.den[t.denn - 1];
  const int num_exp = ExponentOf(num), den_exp = ExponentOf(den);
  const int shift = num_exp - den_exp - 2;
  if (shift > 700 || shift < 100) return false;
  const double scale = Pow2(shift);
  double c = ScaleByPow2(num, -num_exp) / ScaleByPow2(den, -den_exp);
  for (int iteration = 0; iteration < 8; ++iteration) {
    // Midpoints to the neighbours: c + up and c - down (up, down: half gaps, powers of two).
    const double up = Mul(Sub(NextUp(c), c), 0.5);
    const double down = Mul(Sub(c, NextDown(c)), 0.5);
    const Order above = CompareToScaled(t, Mul(c, scale), Mul(up, scale));
    const Order below = CompareToScaled(t, Mul(c, scale), -Mul(down, scale));
    if (above == Order::kUndecided || below == Order::kUndecided) return false;
    const bool even = (DoubleBits(c) & 1) == 0;
    if (above == Order::kGreater || (above == Order::kEqual && !even)) {
      c = NextUp(c);
    } else if (below == Order::kLess || (below == Order::kEqual && !even)) {
      c = NextDown(c);
    } else {
      *out = ldexp(c, shift - 2 * s);
      return true;
    }
  }
  return false;
}

namespace radius_detail {

/// Exact scaled difference (u - v) * 2^s as a double-double.
GALPHA_HD GALPHA_FORCEINLINE DoubleDouble ScaledDifferenceDd(double u, double v, int s) {
  double hi, lo;
  TwoDiff(u, v, hi, lo);
  return DoubleDouble{ScaleByPow2(hi, s), ScaleByPow2(lo, s)};
}

}  // namespace radius_detail

/// rho^2 of a simplex enclosed by double-double arithmetic: the exact value lies within `err` of
/// hi + lo (err already rounded up).
struct RadiusSqEnclosure {
  double hi;
  double lo;
  double err;
};

/// rho^2 of p[0..n) in double-double arithmetic with a certified error bound (about 2^-95
/// relative; more for thin triangles, whose cross product cancels, and none beyond 2^-66): true
/// with *out set, or false where the differences, the cancellation or the result's range are too
/// extreme for the bound (the caller then uses exact arithmetic).
GALPHA_HD inline bool EncloseRadiusSq(const Point2* p, int n, RadiusSqEnclosure* out) {
  using namespace radius_detail;
  const int from[3] = {0, 0, 1}, to[3] = {1, 2, 2};
  const int m = n == 2 ? 1 : 3;
  double maxabs = 0.0;
  for (int k = 0; k < m; ++k) {
    const double dx = Abs(Sub(p[to[k]].x, p[from[k]].x)), dy = Abs(Sub(p[to[k]].y, p[from[k]].y));
    if (!Finite(dx) || !Finite(dy)) return false;
    maxabs = dx > maxabs ? dx : maxabs;
    maxabs = dy > maxabs ? dy : maxabs;
  }
  if (maxabs == 0.0) return false;
  const int s = -ExactExponentOf(maxabs);
  DoubleDouble d[3][2];
  for (int k = 0; k < m; ++k) {
    d[k][0] = ScaledDifferenceDd(p[to[k]].x, p[from[k]].x, s);
    d[k][1] = ScaledDifferenceDd(p[to[k]].y, p[from[k]].y, s);
    for (int c = 0; c < 2; ++c) {
      // Tiny differences beside large ones could underflow in products: the exact path takes them.
      if (d[k][c].hi != 0.0 && Abs(d[k][c].hi) < 0x1p-300) return false;
    }
  }
  DoubleDouble len[3];
  for (int k = 0; k < m; ++k) len[k] = AddDd(MulDd(d[k][0], d[k][0]), MulDd(d[k][1], d[k][1]));
  DoubleDouble value;
  double bound = 0x1p-95;
  if (n == 2) {
    value = DoubleDouble{Mul(len[0].hi, 0.25), Mul(len[0].lo, 0.25)};
  } else {
    const DoubleDouble left = MulDd(d[0][0], d[1][1]), right = MulDd(d[0][1], d[1][0]);
    const DoubleDouble area = AddDd(left, right, /*negate_b=*/true);
    const double sum = Add(Abs(left.hi), Abs(right.hi));
    // |D| >= 2^-450 keeps D^2 and its tail normal (below, the tail of the product would round and
    // the bound would not hold).
    if (Abs(area.hi) < 0x1p-450 || Abs(area.hi) < Mul(sum, 0x1p-31)) return false;
    // D's relative error: 2^-101 (|left| + |right|) / |D| <= 2^-70; rho^2 gets four times that.
    bound = Add(bound, Mul(Mul(sum / Abs(area.hi), 0x1p-101), 4.0));
    const DoubleDouble num = MulDd(MulDd(len[0], len[1]), len[2]);
    const DoubleDouble den = MulDd(area, area);
    value = DivDd(num, DoubleDouble{Mul(den.hi, 4.0), Mul(den.lo, 4.0)});
  }
  // Unscale (exact while normal): the exact value lies within bound * value of h + l.
  const double h = ldexp(value.hi, -2 * s);
  const double l = ldexp(value.lo, -2 * s);
  if (!(h >= 0x1p-900 && h <= 0x1p1000)) return false;  // l and the bound stay normal
  *out = RadiusSqEnclosure{h, l, Mul(Mul(h, bound), 1.0 + 0x1p-20)};
  return true;
}

/// Whether b's exact value is certainly above a's: the enclosures do not meet. The sign of
/// (b.hi + b.lo - b.err) - (a.hi + a.lo + a.err) is taken exactly (Grow-Expansion keeps the
/// expansion nonoverlapping, Shewchuk 1997, Theorem 10, so its top component carries the sign).
GALPHA_HD inline bool EnclosuresSeparated(const RadiusSqEnclosure& a, const RadiusSqEnclosure& b) {
  using namespace exact;
  const double terms[6] = {b.lo, b.hi, -b.err, -a.lo, -a.hi, -a.err};
  double e[7];
  int en = 0;
  for (const double t : terms) en = GrowExpansionZeroElim(en, e, t, e);
  return ExpansionSign(en, e) > 0;
}

/// The double nearest to rho^2 of p[0..n) from its double-double enclosure (EncloseRadiusSq):
/// decides the rounding unless the value lies within the bound of a midpoint between two doubles
/// or outside the normal range, where it returns false and the exact NearestRadiusSqBounded
/// decides. The fast path of the published spectrum.
GALPHA_HD inline bool NearestRadiusSqFast(const Point2* p, int n, double* out) {
  using namespace radius_detail;
  RadiusSqEnclosure v;
  if (!EncloseRadiusSq(p, n, &v)) return false;
  // h is the nearest double if the enclosure stays strictly inside h's rounding interval.
  const double h = v.hi;
  const double up = Mul(Sub(NextUp(h), h), 0.5);
  const double down = Mul(Sub(h, NextDown(h)), 0.5);
  if (!(Add(v.lo, v.err) < up && Sub(v.lo, v.err) > -down)) return false;
  *out = h;
  return true;
}

}  // namespace galpha
