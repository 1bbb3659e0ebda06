// Certified keys of squared radii, for sorting the alpha spectrum: a 64-bit order-preserving key
// of a double approximation of rho^2 (radius_terms.hpp) whose relative error is certified to be
// below kRadiusSqRelErr, or flagged `certified == false`. Two keys more than kRadiusKeyGap apart
// order their exact values; closer keys may tie and need the exact comparison
// (radius_compare.hpp). Host and device alike.
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/expansion.hpp"
#include "core/exact/radius_terms.hpp"

namespace galpha {

/// Relative error bound of RadiusSqApprox's value when it is certified.
constexpr double kRadiusSqRelErr = 0x1p-40;
/// Keys whose difference exceeds this have exact values in key order (derivation at
/// RadiusKeyFromScaled); closer keys may be tied or swapped and need an exact comparison.
constexpr uint64_t kRadiusKeyGap = uint64_t{1} << 14;
/// The key of a triangle whose vertices are collinear (an infinite radius: never in any complex).
constexpr uint64_t kInfiniteRadiusKey = ~uint64_t{0};

struct RadiusSqApprox {
  uint64_t key = 0;
  /// False when the approximation's error is not certified (extreme exponent ranges inside one
  /// simplex, or overflowing differences): such a key orders nothing and must be compared exactly.
  bool certified = true;
};

namespace radius_detail {

using namespace exact;

/// Layout of a key: 13 bits of biased binary exponent, then the top 51 bits of the significand.
constexpr int kKeyMantissaBits = 51;
constexpr int kKeyExponentBias = 4096;
constexpr int kKeyMaxExponentField = 8190;  // 8191 is taken by kInfiniteRadiusKey's top bits

/// The key of the positive value m * 2^e (m a positive normal double). The key is monotone in the
/// value (truncation is monotone). Why kRadiusKeyGap suffices: for certified approximations
/// w1 <= w2 of exact values x1, x2 (relative errors below 2^-40), x2 <= x1 is possible only if
/// w2 <= w1 (1 + 2^-40) / (1 - 2^-40) < w1 (1 + 2^-38.99); with w1 in [2^E, 2^(E+1)) that is
/// w2 - w1 < 2^(E-37.99), about 8200 units of the key's last place 2^(E-51) (fewer once w2 is in
/// the next binade, where the unit doubles), plus one unit of truncation: below 2^14.
GALPHA_HD inline uint64_t RadiusKeyFromScaled(double m, int e, bool* in_range) {
  const uint64_t bits = DoubleBits(m);
  const int exponent = static_cast<int>((bits >> 52) & 0x7ff) - 1023 + e;
  const int field = exponent + kKeyExponentBias;
  if (field < 0) {
    *in_range = false;
    return 0;
  }
  if (field > kKeyMaxExponentField) {
    *in_range = false;
    return kInfiniteRadiusKey - 1;
  }
  const uint64_t mantissa = (bits & ((uint64_t{1} << 52) - 1)) >> (52 - kKeyMantissaBits);
  return (static_cast<uint64_t>(field) << kKeyMantissaBits) | mantissa;
}

/// Smallest scaled squared length the triangle approximation accepts (below it the cube of
/// lengths could underflow).
constexpr double kMinScaledLengthSq = 0x1p-900;
/// Smallest scaled |D| it accepts (D^2 must stay normal).
constexpr double kMinScaledArea = 0x1p-400;
/// Smallest nonzero scaled edge coordinate the thin-triangle stage accepts: its Two-Products are
/// then at least 2^-800 with tails on a grid of 2^-904, exactly representable.
constexpr double kMinScaledThinCoordinate = 0x1p-400;

/// Whether u - v was exact in doubles (Two-Diff's tail is zero).
GALPHA_HD inline bool ExactDifference(double u, double v) {
  double hi, lo;
  TwoDiff(u, v, hi, lo);
  return lo == 0.0;
}

/// Whether a scaled coordinate is zero or large enough for the thin-triangle stage. (A nonzero
/// difference that the scaling rounded to zero was below 2^-1073: against the stage's
/// |cross| >= 2^-400 its absence is an error below 2^-670, relatively.)
GALPHA_HD inline bool ThinStageCoordinateOk(double v) { return v == 0.0 || Abs(v) >= kMinScaledThinCoordinate; }

/// The cross product ax by - ay bx of two exact edge vectors as its exact value's top component
/// (two Two-Products, their exact difference compressed: a nonoverlapping expansion's top
/// component is within 2^-51.99 of its value, relatively), 0 exactly when the vectors are parallel.
GALPHA_HD inline double ExactCrossTop(double ax, double ay, double bx, double by) {
  double l1, l0, r1, r0;
  TwoProduct(ax, by, l1, l0);
  TwoProduct(ay, bx, r1, r0);
  double left[2], right[2], cross[4];
  const int ln = TwoToExpansion(l1, l0, left), rn = TwoToExpansion(r1, r0, right);
  const int n = Compress<4>(ExpansionDiffZeroElim(ln, left, rn, right, cross), cross);
  return n == 0 ? 0.0 : cross[n - 1];
}

}  // namespace radius_detail

/// Certified approximation of rho^2 of an edge (n = 2) or a triangle (n = 3, counter-clockwise or
/// not). Floating filter first; the exact terms when the filter cannot certify its error.
GALPHA_HD inline RadiusSqApprox ApproxRadiusSq(const Point2* p, int n) {
  using namespace radius_detail;
  RadiusSqApprox out;
  // Differences rounded once each: relative error <= 2^-53 (exact when subnormal).
  double dx[3], dy[3];
  const int from[3] = {0, 0, 1}, to[3] = {1, 2, 2};
  const int m = n == 2 ? 1 : 3;
  double maxabs = 0.0;
  bool finite = true;
  for (int k = 0; k < m; ++k) {
    dx[k] = Sub(p[to[k]].x, p[from[k]].x);
    dy[k] = Sub(p[to[k]].y, p[from[k]].y);
    finite = finite && Finite(dx[k]) && Finite(dy[k]);
    maxabs = Abs(dx[k]) > maxabs ? Abs(dx[k]) : maxabs;
    maxabs = Abs(dy[k]) > maxabs ? Abs(dy[k]) : maxabs;
  }
  if (finite && maxabs > 0.0) {
    const int s = -ExponentOf(maxabs);  // largest scaled difference in [1, 2) (or below, if subnormal)
    double len[3];
    bool lengths_ok = true;
    for (int k = 0; k < m; ++k) {
      const double sx = ScaleByPow2(dx[k], s), sy = ScaleByPow2(dy[k], s);
      len[k] = Add(Mul(sx, sx), Mul(sy, sy));  // relative error <= 4 * 2^-53 (tiny squares: absolute 2^-1074)
      lengths_ok = lengths_ok && len[k] >= kMinScaledLengthSq;
      dx[k] = sx;
      dy[k] = sy;
    }
    if (n == 2) {
      bool in_range = true;
      out.key = RadiusKeyFromScaled(len[0], -2 * s - 2, &in_range);
      out.certified = in_range;
      return out;
    }
    const double left = Mul(dx[0], dy[1]), right = Mul(dy[0], dx[1]);
    const double area = Sub(left, right);
    const double sum = Add(Abs(left), Abs(right));
    // |D - area| <= 3.01 * 2^-53 * sum + 2^-53 |area|: demand |area| >= sum * 2^-6, so that D's
    // relative error stays below 2^-45 + 2^-52; rho^2's then stays below 2^-42.
    // A thin triangle (the cross product lost more than 6 bits to cancellation: two lines of
    // points, long triangles between them) whose edge vectors were exact doubles (near
    // neighbours, integer coordinates) gets its cross product exactly, rounded once (relative
    // error 2^-51.99), instead of the exact terms in local memory below. Its lengths then err by
    // at most 3 roundings each, so rho^2 errs by under 14 * 2^-53 + 2 * 2^-51.99 + 3 * 2^-53,
    // below 2^-48: far inside kRadiusSqRelErr.
    double cross = area;
    bool cross_ok = Abs(area) >= Mul(sum, 0x1p-6);
    if (!cross_ok && lengths_ok && ExactDifference(p[1].x, p[0].x) && ExactDifference(p[1].y, p[0].y) &&
        ExactDifference(p[2].x, p[0].x) && ExactDifference(p[2].y, p[0].y) && ExactDifference(p[2].x, p[1].x) &&
        ExactDifference(p[2].y, p[1].y) && ThinStageCoordinateOk(dx[0]) && ThinStageCoordinateOk(dy[0]) &&
        ThinStageCoordinateOk(dx[1]) && ThinStageCoordinateOk(dy[1])) {
      cross = ExactCrossTop(dx[0], dy[0], dx[1], dy[1]);
      if (cross == 0.0) {  // collinear: an infinite radius
        out.key = kInfiniteRadiusKey;
        return out;
      }
      cross_ok = true;
    }
    if (lengths_ok && cross_ok && Abs(cross) >= kMinScaledArea) {
      const double num = Mul(Mul(len[0], len[1]), len[2]);
      const double den = Mul(cross, cross);
      bool in_range = true;
      // A product of lengths that left the normal range lost its relative accuracy: such
      // triangles take the exact path. The quotient is formed from the significands so that it
      // cannot overflow.
      const int num_exp = ExponentOf(num), den_exp = ExponentOf(den);
      if (num_exp > -1000 && den_exp > -1000) {
        const double q = ScaleByPow2(num, -num_exp) / ScaleByPow2(den, -den_exp);
        out.key = RadiusKeyFromScaled(q, num_exp - den_exp - 2 * s - 2, &in_range);
        out.certified = in_range;
        return out;
      }
    }
  }
  // Exact terms, each approximated by its top component (relative error < 2^-51 for a
  // nonoverlapping expansion): rho^2 within 2^-49.
  double dmax = 0.0;
  int lowest = 1 << 20;
  int s = 0;
  ExactRadiusTerms terms;
  if (!DifferenceRange(p, n, &dmax, &lowest) || !ExactScaleFor(dmax, lowest, n == 2 ? 2 : 6, &s) ||
      !ExactTerms(p, n, s, &terms)) {
    out.certified = false;
    out.key = 0;
    return out;
  }
  if (terms.denn == 0) {  // collinear triangle
    out.key = kInfiniteRadiusKey;
    return out;
  }
  const double num = terms.num[terms.numn - 1], den = terms.den[terms.denn - 1];
  const int num_exp = ExponentOf(num), den_exp = ExponentOf(den);
  const double q = ScaleByPow2(num, -num_exp) / ScaleByPow2(den, -den_exp);
  bool in_range = true;
  out.key = RadiusKeyFromScaled(q, num_exp - den_exp - 2 * s - 2, &in_range);
  out.certified = in_range;
  return out;
}

/// Whether two certified keys (lo <= hi) may stand for tied or misordered exact values.
GALPHA_HD GALPHA_FORCEINLINE bool RadiusKeysMayTie(uint64_t lo, uint64_t hi) { return hi - lo <= kRadiusKeyGap + 1; }

}  // namespace galpha
