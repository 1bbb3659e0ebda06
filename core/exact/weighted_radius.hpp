// Weighted squared radii (the weighted alpha shape's thresholds) as exact expansions, their
// certified keys, their exact order and their nearest doubles; and the weighted attachment test.
// Host and device alike. The unweighted family keeps radius_*.hpp; a weighted family uses these,
// and the pipeline picks one or the other per family (gpu/alpha/alpha_functors.cuh).
//
// A weighted point (p, w) is the circle of squared radius w around p. The threshold of a simplex
// is the squared radius of the smallest circle orthogonal to its vertices' circles (power
// distance |c - p_i|^2 - w_i equal to rho^2 for every vertex): CGAL's
// Compute_squared_radius_smallest_orthogonal_circle_2, which CGAL's weighted Alpha_shape_2 uses.
// With every weight 0 it is the unweighted rho^2. It can be negative.
//
// Relative to the first vertex (weight w0; w'_i = w_i - w0, so w'_0 = 0) and its position (every
// difference taken from p_0):
//   edge p0 p1, v = p1 - p0, d = |v|^2:
//     rho^2 = (d - w'_1)^2 / (4 d) - w0;
//   triangle p0 p1 p2, b = p1 - p0, c = p2 - p0, D = b.x c.y - b.y c.x (twice the signed area),
//   Wb = |b|^2 - w'_1, Wc = |c|^2 - w'_2 (the centre m solves 2 b.m = Wb, 2 c.m = Wc):
//     rho^2 = ((Wb c.y - Wc b.y)^2 + (b.x Wc - c.x Wb)^2) / (4 D^2) - w0.
// So rho^2 = Num / (4 Den) with Den = d or D^2 (positive; D = 0 is a collinear triangle, an
// infinite radius) and Num the numerator above minus 4 Den w0: every quantity an exact expansion
// of differences scaled by 2^s and weights scaled by 2^(2s) (then the true value is
// Num / (4 Den) * 2^(-2s)), in the bounded buffers of radius_terms.hpp.
//
// Edge attachment (CGAL's power_side_of_bounded_power_circle_2): the third vertex r of a
// triangle of edge pq attaches the edge when its power with respect to the edge's smallest
// orthogonal circle is negative: |m - r|^2 - w_r < rho^2. Times d > 0, with r' = r - p:
//   E = d (|r'|^2 - w'_r) - (d - w'_q) (v . r')    (weights relative to w_p),
// attached when E < 0; 0 (on the circle) leaves the edge unattached, as in CGAL. With every weight
// 0, E = d (r - p).(r - q): the diametral test of attachment.hpp.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/double_double.hpp"
#include "core/exact/expansion.hpp"
#include "core/exact/order.hpp"
#include "core/exact/radius_key.hpp"
#include "core/exact/radius_refined.hpp"
#include "core/exact/radius_terms.hpp"

namespace galpha {

namespace weighted_detail {

using namespace exact;
using radius_detail::BoundedProduct;
using radius_detail::BoundedSum;
using radius_detail::Compress;
using radius_detail::ExactRadiusTerms;
using radius_detail::Finite;
using radius_detail::kBoundedCapacity;
using radius_detail::ScaledDiff;

/// The ranges a scale must respect, gathered over one or two simplices: the largest coordinate
/// difference, the largest |weight| (absolute: the terms hold w0 and differences of weights, both
/// below twice it) and the lowest set bit of any coordinate, and of any weight halved (a weight
/// scaled by 2^(2s) is a degree-2 quantity).
struct WeightedRange {
  double max_difference = 0.0;
  double max_weight = 0.0;
  int lowest_bit = 1 << 20;
  bool finite = true;
};

GALPHA_HD inline void AddToRange(const Point2* p, const double* w, int n, WeightedRange* range) {
  if (!radius_detail::DifferenceRange(p, n, &range->max_difference, &range->lowest_bit)) range->finite = false;
  for (int i = 0; i < n; ++i) {
    if (!Finite(w[i])) {
      range->finite = false;
      continue;
    }
    if (w[i] == 0.0) continue;
    const double a = Abs(w[i]);
    range->max_weight = a > range->max_weight ? a : range->max_weight;
    const int lb = LowestBitExponent(w[i]);
    const int half = lb >= 0 ? lb / 2 : -((-lb + 1) / 2);  // floor(lb / 2)
    range->lowest_bit = half < range->lowest_bit ? half : range->lowest_bit;
  }
}

/// Every degree-1 quantity (a scaled coordinate difference, the square root of a scaled weight or
/// weight difference) below 2^kWeightedScaleTop: products of degree 10 (a triangle's Num times
/// the other's Den), summed over a few dozen terms, stay below 2^930, far from Split's 2^996.
constexpr int kWeightedScaleTop = 91;

/// The scale 2^s for a range, checking that no product of degree `degree` underflows (every
/// component of a degree-k product is a multiple of 2^(k (lowest_bit + s)): keep it above 2^-960).
GALPHA_HD inline bool WeightedScaleFor(const WeightedRange& range, int degree, int* s) {
  if (!range.finite || range.max_difference == 0.0) return false;
  int e = ExactExponentOf(range.max_difference) + 1;  // differences below 2^e
  if (range.max_weight > 0.0) {
    // |w| < 2^(E + 1), twice that for a difference of weights: square roots below 2^((E + 3) / 2).
    const int ew = (ExactExponentOf(range.max_weight) + 4) >> 1;
    e = ew > e ? ew : e;
  }
  *s = kWeightedScaleTop - e;
  // ScaleByPow2 scales weights by 2^(2s) and needs 2s >= -1022 (in the input domain 2s >= -822).
  return 2 * *s >= -1022 && degree * (range.lowest_bit + *s) >= -960;
}

/// w * 2^(2s) (exact: the scale check keeps it normal), or w1 - w0 scaled, as an expansion.
GALPHA_HD inline int ScaledWeightDiff(double w1, double w0, int s, double* out) {
  double hi, lo;
  TwoDiff(w1, w0, hi, lo);
  return TwoToExpansion(ScaleByPow2(hi, 2 * s), ScaleByPow2(lo, 2 * s), out);
}

/// out = a * b - c * d for short expansions (each at most kBoundedCapacity / 2 long).
GALPHA_HD inline bool CrossDifference(int an, const double* a, int bn, const double* b, int cn, const double* c, int dn,
                                      const double* d, double* out, int* outn) {
  double left[kBoundedCapacity], right[kBoundedCapacity];
  int leftn, rightn;
  if (!BoundedProduct(an, a, bn, b, left, &leftn) || !BoundedProduct(cn, c, dn, d, right, &rightn)) return false;
  if (!BoundedSum(leftn, left, rightn, right, true, out, outn)) return false;
  *outn = Compress(*outn, out);
  return true;
}

/// |x|^2 - wrel for a difference vector (x, y) and a scaled weight difference.
GALPHA_HD inline bool LiftedLength(int xn, const double* x, int yn, const double* y, int wn, const double* wrel,
                                   double* out, int* outn) {
  double len[kBoundedCapacity];
  int lenn;
  if (!radius_detail::SquaredLength(xn, x, yn, y, len, &lenn)) return false;
  if (!BoundedSum(lenn, len, wn, wrel, true, out, outn)) return false;
  *outn = Compress(*outn, out);
  return true;
}

}  // namespace weighted_detail

/// Fills `terms` (Num and Den, module comment) for the weighted simplex p[0..n), w[0..n) (n = 2 or
/// 3) at scale 2^s (WeightedScaleFor). Den is empty (0) for a collinear triangle. Fails only when
/// a buffer would overflow.
GALPHA_HD inline bool WeightedExactTerms(const Point2* p, const double* w, int n, int s,
                                         radius_detail::ExactRadiusTerms* terms) {
  using namespace weighted_detail;
  double num[kBoundedCapacity];
  int numn;
  if (n == 2) {
    double dx[2], dy[2], w1[2];
    const int dxn = ScaledDiff(p[1].x, p[0].x, s, dx), dyn = ScaledDiff(p[1].y, p[0].y, s, dy);
    const int w1n = ScaledWeightDiff(w[1], w[0], s, w1);
    if (!radius_detail::SquaredLength(dxn, dx, dyn, dy, terms->den, &terms->denn)) return false;
    double lifted[kBoundedCapacity];
    int liftedn;
    if (!BoundedSum(terms->denn, terms->den, w1n, w1, true, lifted, &liftedn)) return false;
    if (!BoundedProduct(liftedn, lifted, liftedn, lifted, num, &numn)) return false;
  } else {
    double d[2][2][2];  // b, c; x and y
    int dn[2][2];
    double wr[2][2];
    int wrn[2];
    for (int k = 0; k < 2; ++k) {
      dn[k][0] = ScaledDiff(p[k + 1].x, p[0].x, s, d[k][0]);
      dn[k][1] = ScaledDiff(p[k + 1].y, p[0].y, s, d[k][1]);
      wrn[k] = ScaledWeightDiff(w[k + 1], w[0], s, wr[k]);
    }
    double wb[kBoundedCapacity], wc[kBoundedCapacity];
    int wbn, wcn;
    if (!LiftedLength(dn[0][0], d[0][0], dn[0][1], d[0][1], wrn[0], wr[0], wb, &wbn) ||
        !LiftedLength(dn[1][0], d[1][0], dn[1][1], d[1][1], wrn[1], wr[1], wc, &wcn)) {
      return false;
    }
    // D = b.x c.y - b.y c.x; Dx = Wb c.y - Wc b.y; Dy = Wc b.x - Wb c.x.
    double area[kBoundedCapacity], cx[kBoundedCapacity], cy[kBoundedCapacity];
    int arean, cxn, cyn;
    if (!CrossDifference(dn[0][0], d[0][0], dn[1][1], d[1][1], dn[0][1], d[0][1], dn[1][0], d[1][0], area, &arean) ||
        !CrossDifference(wbn, wb, dn[1][1], d[1][1], wcn, wc, dn[0][1], d[0][1], cx, &cxn) ||
        !CrossDifference(wcn, wc, dn[0][0], d[0][0], wbn, wb, dn[1][0], d[1][0], cy, &cyn)) {
      return false;
    }
    if (!BoundedProduct(arean, area, arean, area, terms->den, &terms->denn)) return false;
    if (terms->denn == 0) {  // collinear: infinite
      terms->numn = 0;
      return true;
    }
    double xx[kBoundedCapacity], yy[kBoundedCapacity];
    int xxn, yyn;
    if (!BoundedProduct(cxn, cx, cxn, cx, xx, &xxn) || !BoundedProduct(cyn, cy, cyn, cy, yy, &yyn)) return false;
    if (!BoundedSum(xxn, xx, yyn, yy, false, num, &numn)) return false;
  }
  // Num -= 4 Den w0 (w0 * 2^(2s) and times 4: exact, as the scale check keeps it normal).
  const double four_w0[1] = {Mul(ScaleByPow2(w[0], 2 * s), 4.0)};
  const int four_w0n = four_w0[0] != 0.0 ? 1 : 0;
  double shift[kBoundedCapacity];
  int shiftn;
  if (!BoundedProduct(terms->denn, terms->den, four_w0n, four_w0, shift, &shiftn)) return false;
  if (!BoundedSum(numn, num, shiftn, shift, true, terms->num, &terms->numn)) return false;
  terms->numn = Compress(terms->numn, terms->num);
  return true;
}

namespace weighted_detail {

/// The exact terms of one weighted simplex at its own scale (degree: what the caller multiplies).
/// `lowest_bit` (optional) receives the range's lowest bit (see WeightedRange).
GALPHA_HD inline bool OwnTerms(const Point2* p, const double* w, int n, int degree, ExactRadiusTerms* terms, int* s,
                               int* lowest_bit = nullptr) {
  WeightedRange range;
  AddToRange(p, w, n, &range);
  if (lowest_bit != nullptr) *lowest_bit = range.lowest_bit;
  return WeightedScaleFor(range, degree, s) && WeightedExactTerms(p, w, n, *s, terms);
}

/// Layout of a signed key: bit 63 set for values >= 0; below it 12 bits of biased exponent and
/// the top 51 bits of the magnitude's significand; a negative value's key is the bitwise
/// complement of its magnitude's, so that keys ascend with the values.
constexpr int kSignedKeyExponentBias = 2048;
constexpr int kSignedKeyMaxExponentField = 4094;

GALPHA_HD inline uint64_t SignedKeyOf(double m, int e, bool negative, bool* in_range) {
  const uint64_t bits = DoubleBits(m);
  const int exponent = static_cast<int>((bits >> 52) & 0x7ff) - 1023 + e;
  const int field = exponent + kSignedKeyExponentBias;
  if (field < 0 || field > kSignedKeyMaxExponentField) {
    *in_range = false;
    return 0;
  }
  const uint64_t mantissa = (bits & ((uint64_t{1} << 52) - 1)) >> (52 - radius_detail::kKeyMantissaBits);
  const uint64_t code = (static_cast<uint64_t>(field) << radius_detail::kKeyMantissaBits) | mantissa;
  return negative ? (uint64_t{1} << 63) - 1 - code : (uint64_t{1} << 63) | code;
}

}  // namespace weighted_detail

namespace weighted_detail {

/// A double with a bound on its distance to the exact value it stands for: the running error
/// analysis of the weighted floating filter. Every operation adds its own rounding (u |v|, u =
/// 2^-53, valid while results stay normal: the caller keeps magnitudes within 2^+-400) to the
/// propagated bounds. The bounds are themselves rounded: a few ulps of relative error each, which
/// the caller covers by a margin of 2^-40 on the final bound.
struct Bounded {
  double v;
  double e;
};

constexpr double kUnitRoundoff = 0x1p-53;

GALPHA_HD GALPHA_FORCEINLINE Bounded RoundedDiff(double a, double b) {
  const double v = Sub(a, b);
  return {v, Mul(Abs(v), kUnitRoundoff)};
}
GALPHA_HD GALPHA_FORCEINLINE Bounded Plus(Bounded a, Bounded b) {
  const double v = Add(a.v, b.v);
  return {v, Add(Add(a.e, b.e), Mul(Abs(v), kUnitRoundoff))};
}
GALPHA_HD GALPHA_FORCEINLINE Bounded Minus(Bounded a, Bounded b) {
  const double v = Sub(a.v, b.v);
  return {v, Add(Add(a.e, b.e), Mul(Abs(v), kUnitRoundoff))};
}
GALPHA_HD GALPHA_FORCEINLINE Bounded Times(Bounded a, Bounded b) {
  const double v = Mul(a.v, b.v);
  const double e = Add(Add(Mul(Abs(a.v), b.e), Mul(Abs(b.v), a.e)), Mul(a.e, b.e));
  return {v, Add(e, Mul(Abs(v), kUnitRoundoff))};
}
/// a / b; the caller checks b.e < |b.v| first.
GALPHA_HD GALPHA_FORCEINLINE Bounded Over(Bounded a, Bounded b) {
  const double v = a.v / b.v;
  const double e = Add(a.e, Mul(Abs(v), b.e)) / Sub(Abs(b.v), b.e);
  return {v, Add(e, Mul(Abs(v), kUnitRoundoff))};
}
/// Whether a value stays where the bounds above hold: zero, or normal well inside the range.
GALPHA_HD GALPHA_FORCEINLINE bool InFilterRange(double v) {
  return v == 0.0 || (Abs(v) >= 0x1p-400 && Abs(v) <= 0x1p400);
}

/// The floating filter of ApproxWeightedRadiusSq: rho^2 scaled by 2^(2s) with a bound on its
/// error, from the formulas of the module comment in doubles (differences scaled by 2^s so that
/// the largest difference or square root of a weight is near 1). False where the bound is not
/// valid (a value out of range) or the denominator's bound reaches its value (nearly collinear).
GALPHA_HD inline bool FilteredWeightedRadiusSq(const Point2* p, const double* w, int n, Bounded* out, int* scale) {
  double maxabs = 0.0;
  for (int i = 1; i < n; ++i) {
    const double dx = Abs(Sub(p[i].x, p[0].x)), dy = Abs(Sub(p[i].y, p[0].y));
    maxabs = dx > maxabs ? dx : maxabs;
    maxabs = dy > maxabs ? dy : maxabs;
  }
  double maxw = 0.0;
  for (int i = 0; i < n; ++i) maxw = Abs(w[i]) > maxw ? Abs(w[i]) : maxw;
  if (!(maxabs > 0.0 && maxabs <= 0x1p500) || !(maxw <= 0x1p900)) return false;  // also NaN
  int e = ExponentOf(maxabs);
  if (maxw > 0.0) {
    const int ew = (ExponentOf(maxw) + 2) >> 1;
    e = ew > e ? ew : e;
  }
  const int s = -e;
  const Bounded w0 = {ScaleByPow2(w[0], 2 * s), 0.0};
  if (!InFilterRange(w0.v)) return false;
  Bounded d[2][2], lifted_weight[2];
  for (int k = 0; k + 1 < n; ++k) {
    d[k][0] = RoundedDiff(p[k + 1].x, p[0].x);
    d[k][1] = RoundedDiff(p[k + 1].y, p[0].y);
    lifted_weight[k] = RoundedDiff(w[k + 1], w[0]);
    // Scaling by powers of two is exact in range: values and bounds alike.
    d[k][0] = {ScaleByPow2(d[k][0].v, s), ScaleByPow2(d[k][0].e, s)};
    d[k][1] = {ScaleByPow2(d[k][1].v, s), ScaleByPow2(d[k][1].e, s)};
    lifted_weight[k] = {ScaleByPow2(lifted_weight[k].v, 2 * s), ScaleByPow2(lifted_weight[k].e, 2 * s)};
    if (!InFilterRange(d[k][0].v) || !InFilterRange(d[k][1].v) || !InFilterRange(lifted_weight[k].v)) return false;
  }
  Bounded value;
  // Every intermediate must stay where the bounds hold (zero or normal, within 2^+-400): a value
  // that cancelled into the subnormal range would have lost more than its u-relative bound.
  if (n == 2) {
    const Bounded len = Plus(Times(d[0][0], d[0][0]), Times(d[0][1], d[0][1]));
    const Bounded t = Minus(len, lifted_weight[0]);
    const Bounded four_len = {Mul(len.v, 4.0), Mul(len.e, 4.0)};
    if (!InFilterRange(len.v) || !InFilterRange(t.v) || !(four_len.e < Abs(four_len.v))) return false;
    value = Minus(Over(Times(t, t), four_len), w0);
  } else {
    const Bounded wb = Minus(Plus(Times(d[0][0], d[0][0]), Times(d[0][1], d[0][1])), lifted_weight[0]);
    const Bounded wc = Minus(Plus(Times(d[1][0], d[1][0]), Times(d[1][1], d[1][1])), lifted_weight[1]);
    const Bounded area = Minus(Times(d[0][0], d[1][1]), Times(d[0][1], d[1][0]));
    const Bounded cx = Minus(Times(wb, d[1][1]), Times(wc, d[0][1]));
    const Bounded cy = Minus(Times(wc, d[0][0]), Times(wb, d[1][0]));
    const Bounded num = Plus(Times(cx, cx), Times(cy, cy));
    const Bounded square = Times(area, area);
    const Bounded den = {Mul(square.v, 4.0), Mul(square.e, 4.0)};
    const double intermediates[7] = {wb.v, wc.v, area.v, cx.v, cy.v, num.v, square.v};
    for (const double v : intermediates) {
      if (!InFilterRange(v)) return false;
    }
    if (!(den.e < Abs(den.v))) return false;
    value = Minus(Over(num, den), w0);
  }
  if (!InFilterRange(value.v) || !(value.e < 0x1p400)) return false;
  *out = value;
  *scale = s;
  return true;
}

}  // namespace weighted_detail

/// Certified key of a weighted simplex's rho^2 (the key order and kRadiusKeyGap of radius_key.hpp,
/// extended to signed values: module comment of SignedKeyOf). The approximation is the floating
/// filter's (FilteredWeightedRadiusSq) when its bound certifies 2^-42, else the quotient of the
/// exact terms' top components (each within 2^-51.99 of its compressed expansion, the quotient
/// rounded once: within 2^-49 of rho^2, relatively, as kRadiusSqRelErr demands); a collinear
/// triangle gets kInfiniteRadiusKey, and exact terms that do not fit give certified == false.
GALPHA_HD inline RadiusSqApprox ApproxWeightedRadiusSq(const Point2* p, const double* w, int n) {
  using namespace weighted_detail;
  RadiusSqApprox out;
  // The floating filter first: certified when its error bound (with a margin of 2^-40 for the
  // rounding of the bound itself) is below 2^-42 of the value.
  Bounded filtered;
  int filter_scale = 0;
  if (FilteredWeightedRadiusSq(p, w, n, &filtered, &filter_scale) && filtered.v != 0.0 &&
      Mul(filtered.e, 1.0 + 0x1p-40) <= Mul(Abs(filtered.v), 0x1p-42)) {
    bool in_range = true;
    const double m = Abs(filtered.v);
    const int m_exp = ExponentOf(m);
    out.key = SignedKeyOf(ScaleByPow2(m, -m_exp), m_exp - 2 * filter_scale, filtered.v < 0.0, &in_range);
    if (in_range) return out;
  }
  radius_detail::ExactRadiusTerms terms;
  int s = 0;
  if (!OwnTerms(p, w, n, n == 2 ? 4 : 6, &terms, &s)) {
    out.certified = false;
    return out;
  }
  if (terms.denn == 0) {
    out.key = kInfiniteRadiusKey;
    return out;
  }
  if (terms.numn == 0) {  // exactly 0
    out.key = uint64_t{1} << 63;
    return out;
  }
  const double num = terms.num[terms.numn - 1], den = terms.den[terms.denn - 1];
  const bool negative = num < 0.0;
  const int num_exp = ExponentOf(num), den_exp = ExponentOf(den);
  const double q = ScaleByPow2(Abs(num), -num_exp) / ScaleByPow2(den, -den_exp);
  bool in_range = true;
  out.key = SignedKeyOf(q, num_exp - den_exp - 2 * s - 2, negative, &in_range);
  out.certified = in_range;
  return out;
}

/// The exact order of two weighted simplices' rho^2 (a collinear triangle's is infinite, above
/// every finite value), or Order::kUndecided when the bounded buffers or the exponent range do
/// not suffice (the host's GMP comparison decides then).
GALPHA_HD inline Order CompareWeightedRadiusSqBounded(const Point2* a, const double* wa, int na, const Point2* b,
                                                      const double* wb, int nb) {
  using namespace weighted_detail;
  WeightedRange range;
  AddToRange(a, wa, na, &range);
  AddToRange(b, wb, nb, &range);
  int s = 0;
  if (!WeightedScaleFor(range, 10, &s)) return Order::kUndecided;
  ExactRadiusTerms ta, tb;
  if (!WeightedExactTerms(a, wa, na, s, &ta) || !WeightedExactTerms(b, wb, nb, s, &tb)) return Order::kUndecided;
  if (ta.denn == 0 || tb.denn == 0) return OrderOfSign((ta.denn == 0 ? 1 : 0) - (tb.denn == 0 ? 1 : 0));
  // Num_a / Den_a against Num_b / Den_b, both dens positive.
  double diff[kBoundedCapacity];
  int diffn;
  if (!CrossDifference(ta.numn, ta.num, tb.denn, tb.den, tb.numn, tb.num, ta.denn, ta.den, diff, &diffn)) {
    return Order::kUndecided;
  }
  return OrderOfSign(ExpansionSign(diffn, diff));
}

/// Whether two weighted simplices' rho^2 are equal because the simplices are congruent
/// (RadiusCongruent) and every vertex of both has one and the same weight: rho^2 is then the
/// unweighted value minus that weight. False proves nothing.
GALPHA_HD inline bool WeightedRadiusCongruent(const Point2* a, const double* wa, int na, const Point2* b,
                                              const double* wb, int nb) {
  if (na != nb) return false;
  for (int i = 0; i < na; ++i) {
    if (!(wa[i] == wa[0]) || !(wb[i] == wa[0])) return false;
  }
  return RadiusCongruent(a, na, b, nb);
}

/// The double nearest to a weighted simplex's rho^2 (ties to even; +infinity for a collinear
/// triangle), into *out; false when the bounded buffers or the exponent range do not suffice, or
/// the value is not a normal double or zero (the host rounds it exactly then).
GALPHA_HD inline bool NearestWeightedRadiusSqBounded(const Point2* p, const double* w, int n, double* out) {
  using namespace weighted_detail;
  radius_detail::ExactRadiusTerms t;
  int s = 0;
  // Degree of Num (6) plus the two of the candidate m (a value times 2^(2s)) in Num - 4 m Den.
  int lowest_bit = 0;
  if (!OwnTerms(p, w, n, 10, &t, &s, &lowest_bit)) return false;
  if (t.denn == 0) {
    *out = BitsToDouble(uint64_t{0x7ff} << 52);
    return true;
  }
  if (t.numn == 0) {
    *out = 0.0;
    return true;
  }
  const double num = t.num[t.numn - 1], den = t.den[t.denn - 1];
  const bool negative = num < 0.0;
  const int num_exp = ExponentOf(num), den_exp = ExponentOf(den);
  // Work on |v|: flip Num's sign for a negative value.
  radius_detail::ExactRadiusTerms magnitude = t;
  if (negative) {
    for (int i = 0; i < magnitude.numn; ++i) magnitude.num[i] = -magnitude.num[i];
  }
  // In scaled units |v| = |Num| / (4 Den) = c * 2^shift: m = c * 2^shift times Den must neither
  // overflow nor underflow a Two-Product (|Num| < 2^930 and Den > 2^-960 keep shift inside these
  // bounds for every value that is a normal double). The first guess is the refined quotient
  // (radius_refined.hpp, within 2^-150): almost always the answer, which the loop then only checks
  // (two exact comparisons instead of a walk of several ulps from a 2^-49 guess).
  int shift = num_exp - den_exp - 2;
  double c = ScaleByPow2(Abs(num), -num_exp) / ScaleByPow2(den, -den_exp);
  const RefinedRadiusSq refined = radius_detail::RefineTerms(magnitude, s);
  if (refined.ok) {
    c = Add(refined.hi, refined.mid);  // in [1, 2]
    shift = refined.exponent + 2 * s;
  }
  // The candidate m carries a 53-bit significand, not a lattice value: its products with Den's
  // components (multiples of 2^(4 (lowest_bit + s))) are exact only above 2^-1074.
  if (shift > 700 || shift < -700 || shift - 53 + 4 * (lowest_bit + s) < -1074) return false;
  const double scale = Pow2(shift);
  for (int iteration = 0; iteration < 8; ++iteration) {
    const double up = Mul(Sub(radius_detail::NextUp(c), c), 0.5);
    const double down = Mul(Sub(c, radius_detail::NextDown(c)), 0.5);
    const Order above = radius_detail::CompareToScaled(magnitude, Mul(c, scale), Mul(up, scale));
    const Order below = radius_detail::CompareToScaled(magnitude, Mul(c, scale), -Mul(down, scale));
    if (above == Order::kUndecided || below == Order::kUndecided) return false;
    const bool even = (DoubleBits(c) & 1) == 0;
    if (above == Order::kGreater || (above == Order::kEqual && !even)) {
      c = radius_detail::NextUp(c);
    } else if (below == Order::kLess || (below == Order::kEqual && !even)) {
      c = radius_detail::NextDown(c);
    } else {
      const int e = shift - 2 * s;
      // c * 2^e must be a normal double (rounding c is the whole rounding then).
      if (ExponentOf(c) + e < -1022 || ExponentOf(c) + e > 1023) return false;
      const double v = ldexp(c, e);
      *out = negative ? -v : v;
      return true;
    }
  }
  return false;
}

namespace weighted_detail {

/// The double-double twin of Bounded: a value hi + lo and a bound on its distance to the exact
/// value, each operation adding its own error as double_double.hpp states it (AddDd 3.01 u^2 of
/// the operands' his, MulDd 8.01 u^2 of their product, DivDd 2^-100 relative), rounded up, to the
/// propagated bounds (|operand| <= |hi| (1 + 2^-52)); the bounds' own rounding is covered by the
/// caller's margin.
struct BoundedDd {
  DoubleDouble v;
  double e;
};

constexpr double kDdSlack = 1.0 + 0x1p-50;

GALPHA_HD GALPHA_FORCEINLINE BoundedDd ExactDiffDd(double a, double b, int s) {
  double hi, lo;
  TwoDiff(a, b, hi, lo);
  return {DoubleDouble{ScaleByPow2(hi, s), ScaleByPow2(lo, s)}, 0.0};
}
GALPHA_HD GALPHA_FORCEINLINE BoundedDd PlusDd(BoundedDd a, BoundedDd b, bool negate_b = false) {
  const DoubleDouble v = AddDd(a.v, b.v, negate_b);
  return {v, Add(Add(a.e, b.e), Mul(Add(Abs(a.v.hi), Abs(b.v.hi)), 4.0 * kUnitRoundoff * kUnitRoundoff))};
}
GALPHA_HD GALPHA_FORCEINLINE BoundedDd TimesDd(BoundedDd a, BoundedDd b) {
  const DoubleDouble v = MulDd(a.v, b.v);
  const double propagated = Add(Mul(Add(Mul(Abs(a.v.hi), b.e), Mul(Abs(b.v.hi), a.e)), kDdSlack), Mul(a.e, b.e));
  return {v, Add(propagated, Mul(Abs(Mul(a.v.hi, b.v.hi)), 9.0 * kUnitRoundoff * kUnitRoundoff))};
}
/// a / b for b > 0 with b.e < b.v.hi / 2 (the caller checks).
GALPHA_HD GALPHA_FORCEINLINE BoundedDd OverDd(BoundedDd a, BoundedDd b) {
  const bool negative = a.v.hi < 0.0;
  const DoubleDouble magnitude = negative ? DoubleDouble{-a.v.hi, -a.v.lo} : a.v;
  DoubleDouble q = DivDd(magnitude, b.v);
  const double propagated =
      Mul(Add(a.e, Mul(Abs(q.hi), Mul(b.e, kDdSlack))), kDdSlack) / Sub(b.v.hi, Mul(b.e, kDdSlack));
  if (negative) q = DoubleDouble{-q.hi, -q.lo};
  return {q, Add(Mul(propagated, kDdSlack), Mul(Abs(q.hi), 0x1p-99))};
}

}  // namespace weighted_detail

/// The double nearest to a weighted simplex's rho^2 from a double-double evaluation with a running
/// error bound (about 2^-100 relative where nothing cancels): decides the rounding unless the
/// value lies within the bound of a midpoint between doubles, cancels too much, or is not a normal
/// double (false: NearestWeightedRadiusSqBounded decides). The fast path of a weighted spectrum.
GALPHA_HD inline bool NearestWeightedRadiusSqFast(const Point2* p, const double* w, int n, double* out) {
  using namespace weighted_detail;
  double maxabs = 0.0, maxw = 0.0;
  for (int i = 1; i < n; ++i) {
    const double dx = Abs(Sub(p[i].x, p[0].x)), dy = Abs(Sub(p[i].y, p[0].y));
    maxabs = dx > maxabs ? dx : maxabs;
    maxabs = dy > maxabs ? dy : maxabs;
  }
  for (int i = 0; i < n; ++i) maxw = Abs(w[i]) > maxw ? Abs(w[i]) : maxw;
  if (!(maxabs > 0.0 && maxabs <= 0x1p500) || !(maxw <= 0x1p900)) return false;
  int e = ExponentOf(maxabs);
  if (maxw > 0.0) {
    const int ew = (ExponentOf(maxw) + 2) >> 1;
    e = ew > e ? ew : e;
  }
  const int s = -e;
  // Differences and weight differences exactly (Two-Diff), scaled; tiny ones beside large ones
  // could underflow in products: the exact path takes them.
  BoundedDd d[2][2], lifted_weight[2];
  for (int k = 0; k + 1 < n; ++k) {
    d[k][0] = ExactDiffDd(p[k + 1].x, p[0].x, s);
    d[k][1] = ExactDiffDd(p[k + 1].y, p[0].y, s);
    lifted_weight[k] = ExactDiffDd(w[k + 1], w[0], 2 * s);
    if (!InFilterRange(d[k][0].v.hi) || !InFilterRange(d[k][1].v.hi) || !InFilterRange(lifted_weight[k].v.hi)) {
      return false;
    }
  }
  const BoundedDd w0 = {DoubleDouble{ScaleByPow2(w[0], 2 * s), 0.0}, 0.0};
  if (!InFilterRange(w0.v.hi)) return false;
  BoundedDd value;
  // Intermediates in range, as in FilteredWeightedRadiusSq (a tail below 2^-400 is not checked:
  // DoubleDouble's bounds are relative to the his, and his in range keep the tails' errors inside
  // them up to 2^-1074 absolute, which the 2^-1060 of the final bound covers).
  if (n == 2) {
    const BoundedDd len = PlusDd(TimesDd(d[0][0], d[0][0]), TimesDd(d[0][1], d[0][1]));
    const BoundedDd t = PlusDd(len, lifted_weight[0], true);
    const BoundedDd four_len = {DoubleDouble{Mul(len.v.hi, 4.0), Mul(len.v.lo, 4.0)}, Mul(len.e, 4.0)};
    if (!InFilterRange(len.v.hi) || !InFilterRange(t.v.hi) || !(Mul(four_len.e, 2.0) < four_len.v.hi)) return false;
    value = PlusDd(OverDd(TimesDd(t, t), four_len), w0, true);
  } else {
    const BoundedDd wb = PlusDd(PlusDd(TimesDd(d[0][0], d[0][0]), TimesDd(d[0][1], d[0][1])), lifted_weight[0], true);
    const BoundedDd wc = PlusDd(PlusDd(TimesDd(d[1][0], d[1][0]), TimesDd(d[1][1], d[1][1])), lifted_weight[1], true);
    const BoundedDd area = PlusDd(TimesDd(d[0][0], d[1][1]), TimesDd(d[0][1], d[1][0]), true);
    const BoundedDd cx = PlusDd(TimesDd(wb, d[1][1]), TimesDd(wc, d[0][1]), true);
    const BoundedDd cy = PlusDd(TimesDd(wc, d[0][0]), TimesDd(wb, d[1][0]), true);
    const BoundedDd num = PlusDd(TimesDd(cx, cx), TimesDd(cy, cy));
    const BoundedDd square = TimesDd(area, area);
    const BoundedDd den = {DoubleDouble{Mul(square.v.hi, 4.0), Mul(square.v.lo, 4.0)}, Mul(square.e, 4.0)};
    const double intermediates[7] = {wb.v.hi, wc.v.hi, area.v.hi, cx.v.hi, cy.v.hi, num.v.hi, square.v.hi};
    for (const double v : intermediates) {
      if (!InFilterRange(v)) return false;
    }
    if (!(Mul(den.e, 2.0) < den.v.hi)) return false;
    value = PlusDd(OverDd(num, den), w0, true);
  }
  if (!InFilterRange(value.v.hi) || value.v.hi == 0.0) return false;
  // Unscale: exact for h, which must be normal; l and the bound may lose bits below 2^-1074, which
  // the 2^-1060 added to the bound covers (half an ulp of h is at least 2^-953).
  const int unscaled_exponent = ExponentOf(value.v.hi) - 2 * s;
  if (unscaled_exponent < -900 || unscaled_exponent > 1000) return false;
  const double h = ldexp(value.v.hi, -2 * s);
  const double l = ldexp(value.v.lo, -2 * s);
  const double err = Add(Mul(ldexp(value.e, -2 * s), 1.0 + 0x1p-40), 0x1p-1060);
  // h is the nearest double when the enclosure stays strictly inside h's rounding interval.
  const double up = Mul(Sub(radius_detail::NextUp(Abs(h)), Abs(h)), 0.5);
  const double down = Mul(Sub(Abs(h), radius_detail::NextDown(Abs(h))), 0.5);
  const double above = h > 0.0 ? up : down, below = h > 0.0 ? down : up;  // toward +inf and -inf
  if (!(Add(l, err) < above && Sub(l, err) > -below)) return false;
  *out = h;
  return true;
}

/// The refined key (radius_refined.hpp, its certified error and its separation test extended to
/// signed values) of a weighted simplex: the three quotients are taken of |Num| and the key
/// negated for a negative value. Not ok for an exact zero (compared exactly instead), or where the
/// terms do not fit.
GALPHA_HD inline RefinedRadiusSq RefineWeightedRadiusSq(const Point2* p, const double* w, int n) {
  using namespace weighted_detail;
  RefinedRadiusSq out;
  ExactRadiusTerms terms;
  int s = 0;
  if (!OwnTerms(p, w, n, 10, &terms, &s)) return out;
  if (terms.denn == 0) {
    out.ok = true;
    out.infinite = true;
    return out;
  }
  if (terms.numn == 0) return out;
  const bool negative = terms.num[terms.numn - 1] < 0.0;
  if (negative) {
    for (int i = 0; i < terms.numn; ++i) terms.num[i] = -terms.num[i];
  }
  out = radius_detail::RefineTerms(terms, s);
  if (out.ok && negative) {
    out.hi = -out.hi;
    out.mid = -out.mid;
    out.lo = -out.lo;
  }
  return out;
}

/// E of the module comment for edge pq and the third vertex r, scaled, as an expansion into
/// out[0..*outn); false when the scale's range or the buffers do not suffice (undecided).
GALPHA_HD inline bool WeightedAttachmentExpansion(Point2 p, Point2 q, Point2 r, double wp, double wq, double wr,
                                                  double* out, int* outn) {
  using namespace weighted_detail;
  const Point2 pts[3] = {p, q, r};
  const double ws[3] = {wp, wq, wr};
  WeightedRange range;
  AddToRange(pts, ws, 3, &range);
  int s = 0;
  if (!WeightedScaleFor(range, 4, &s)) return false;
  double vx[2], vy[2], rx[2], ry[2], wq_rel[2], wr_rel[2];
  const int vxn = ScaledDiff(q.x, p.x, s, vx), vyn = ScaledDiff(q.y, p.y, s, vy);
  const int rxn = ScaledDiff(r.x, p.x, s, rx), ryn = ScaledDiff(r.y, p.y, s, ry);
  const int wqn = ScaledWeightDiff(wq, wp, s, wq_rel), wrn = ScaledWeightDiff(wr, wp, s, wr_rel);
  double d[kBoundedCapacity], lr[kBoundedCapacity], lq[kBoundedCapacity], dot[kBoundedCapacity];
  int dn, lrn, lqn, dotn;
  if (!radius_detail::SquaredLength(vxn, vx, vyn, vy, d, &dn)) return false;
  if (!LiftedLength(rxn, rx, ryn, ry, wrn, wr_rel, lr, &lrn)) return false;  // |r'|^2 - w'_r
  if (!BoundedSum(dn, d, wqn, wq_rel, true, lq, &lqn)) return false;         // d - w'_q
  double xx[kBoundedCapacity], yy[kBoundedCapacity];
  int xxn, yyn;
  if (!BoundedProduct(vxn, vx, rxn, rx, xx, &xxn) || !BoundedProduct(vyn, vy, ryn, ry, yy, &yyn) ||
      !BoundedSum(xxn, xx, yyn, yy, false, dot, &dotn)) {
    return false;
  }
  return CrossDifference(dn, d, lrn, lr, lqn, lq, dotn, dot, out, outn);
}

/// +1 when r, the third vertex of a triangle of the weighted edge pq, attaches the edge (its power
/// with respect to the edge's smallest orthogonal circle is negative), 0 on the circle, -1 outside;
/// 2 when the bounded arithmetic cannot decide (the host decides with rationals). A floating filter
/// first: every input of E is rounded once, and each of its two products of two factors, each a
/// sum of at most two products, errs by at most 16 eps of its permanent; 2^-45 leaves room.
GALPHA_HD inline int WeightedAttachedSign(Point2 p, Point2 q, Point2 r, double wp, double wq, double wr) {
  using namespace exact;
  const double vx = Sub(q.x, p.x), vy = Sub(q.y, p.y), rx = Sub(r.x, p.x), ry = Sub(r.y, p.y);
  const double wq_rel = Sub(wq, wp), wr_rel = Sub(wr, wp);
  const double d = Add(Mul(vx, vx), Mul(vy, vy));
  const double lr_abs = Add(Add(Mul(rx, rx), Mul(ry, ry)), Abs(wr_rel));
  const double lr = Sub(Add(Mul(rx, rx), Mul(ry, ry)), wr_rel);
  const double lq_abs = Add(d, Abs(wq_rel));
  const double lq = Sub(d, wq_rel);
  const double dot_abs = Add(Abs(Mul(vx, rx)), Abs(Mul(vy, ry)));
  const double dot = Add(Mul(vx, rx), Mul(vy, ry));
  const double e = Sub(Mul(d, lr), Mul(lq, dot));
  const double permanent = Add(Mul(d, lr_abs), Mul(lq_abs, dot_abs));
  const double bound = Mul(permanent, 0x1p-45);
  if (radius_detail::Finite(permanent) && permanent > 0x1p-900 && permanent < 0x1p1000 && (e > bound || -e > bound)) {
    return e < 0.0 ? 1 : -1;
  }
  double expansion[radius_detail::kBoundedCapacity];
  int n = 0;
  if (!WeightedAttachmentExpansion(p, q, r, wp, wq, wr, expansion, &n)) return 2;
  return -ExpansionSign(n, expansion);
}

}  // namespace galpha
