// Refined keys of squared radii: rho^2 to about 150 bits with a certified error, for ordering the
// spectrum's long runs of near ties (the 64-bit keys of radius_key.hpp separate values only
// 2^-38 apart, and a lattice perturbed by single ulps puts millions of radii closer than that;
// their first- and second-order differences are 2^-40 to 2^-120 of the value). Sorting by these
// keys orders every pair of values more than 2^-146 apart exactly, so that the exact comparisons
// left are those of adjacent entries whose keys cannot separate them: O(n) of them, most of them
// exact ties, which RadiusCongruent proves without arithmetic when the two simplices are
// congruent with the same edge coordinates up to sign and order (a lattice's translated, turned
// and mirrored cells). Host and device alike.
//
// Why the error is certified (rho^2 = Num / (4 Den) * 2^(-2s), exact expansions from
// radius_terms.hpp, both positive, each compressed; Q = Num / Den):
//  1. The top component of a compressed (nonoverlapping) expansion is within 2^-51.99 of its
//     value, relatively: the rest is below one unit in its last place.
//  2. q0 = fl(num_top / den_top) is Q (1 + z) with |z| <= 2^-50.4 (two inputs within 2^-51.99 and
//     one rounding of 2^-53).
//  3. R1 = Num - q0 Den is exact (a scaled expansion and a difference, no rounding), so
//     Q = q0 + R1/Den with |R1/Den| = |z| Q <= 2^-50.4 Q. q1 = fl(R1_top / den_top) is
//     R1/Den (1 + y1) with |y1| <= 2^-50.4, as in 2.
//  4. R2 = R1 - q1 Den is exact, Q = q0 + q1 + R2/Den, |R2/Den| = |y1| |R1/Den| <= 2^-100.8 Q, and
//     q2 = fl(R2_top / den_top) errs by |y2| |R2/Den| <= 2^-151.2 Q.
//  5. q0 + q1 + q2 is carried exactly into (hi, mid, lo) by error-free sums; scaling by powers of
//     two is exact, except that mid or lo may underflow to a subnormal when hi is scaled to
//     [1, 2): an absolute error below 2^-1073, nothing against the 2^-151.2 above.
// So a refined key (hi + mid + lo) 2^e is within kRefinedRelErr = 2^-150 of rho^2, relatively. The
// components need not be normalized for that: the separation test subtracts the keys exactly.
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/expansion.hpp"
#include "core/exact/radius_terms.hpp"

namespace galpha {

/// Relative error bound of a refined key (derivation above).
constexpr double kRefinedRelErr = 0x1p-150;
/// Refined values closer than this (at a common exponent where both are below 4) are not
/// separated by their keys; farther ones are (RefinedKeysSeparated).
constexpr double kRefinedSeparation = 0x1p-146;

/// rho^2 ~ (hi + mid + lo) 2^exponent with hi in [1, 2) and |mid| + |lo| below 2^-50, certified
/// within kRefinedRelErr; `ok` is false when the exact terms do not fit the bounded buffers or their
/// exponent range (the caller then orders the simplex by exact comparisons), and `infinite` marks
/// a collinear triangle.
struct RefinedRadiusSq {
  int32_t exponent = 0;
  double hi = 0.0;
  double mid = 0.0;
  double lo = 0.0;
  bool ok = false;
  bool infinite = false;
};

namespace radius_detail {

/// Puts the vertices of a simplex in lexicographic order (x, then y). The order is translation
/// invariant, so two simplices that are exact translates of each other list corresponding
/// vertices in the same places, and their refined keys come out bit for bit the same (the sort's
/// cheapest tie).
GALPHA_HD inline void LexOrderVertices(Point2* p, int n) {
  for (int i = 1; i < n; ++i) {
    const Point2 x = p[i];
    int j = i;
    while (j > 0 && LexLess(x, p[j - 1])) {
      p[j] = p[j - 1];
      --j;
    }
    p[j] = x;
  }
}

/// The exact terms of a simplex in canonical vertex order, and the scale they were built at.
/// False when they do not fit (bounded buffers, exponent range).
GALPHA_HD inline bool CanonicalExactTerms(const Point2* points, int n, ExactRadiusTerms* terms, int* scale) {
  Point2 p[3];
  for (int i = 0; i < n; ++i) p[i] = points[i];
  LexOrderVertices(p, n);
  double dmax = 0.0;
  int lowest = 1 << 20;
  return DifferenceRange(p, n, &dmax, &lowest) && ExactScaleFor(dmax, lowest, n == 2 ? 2 : 6, scale) &&
         ExactTerms(p, n, *scale, terms);
}

}  // namespace radius_detail

namespace radius_detail {

/// The refined key of Num / (4 Den) * 2^(-2s) for exact terms with Num > 0 and Den > 0 (the
/// derivation above); not ok when the quotient's range or the buffers do not suffice.
GALPHA_HD inline RefinedRadiusSq RefineTerms(const ExactRadiusTerms& terms, int s) {
  RefinedRadiusSq out;
  const double num_top = terms.num[terms.numn - 1], den_top = terms.den[terms.denn - 1];
  // Num and Den are positive, so are their top components. Their quotient must stay well inside
  // the double range, and q0 * Den must be splittable (below 2^996).
  const int quotient_exponent = ExponentOf(num_top) - ExponentOf(den_top);
  if (quotient_exponent > 900 || quotient_exponent < -900) return out;
  const double q0 = num_top / den_top;
  // R1 = Num - q0 Den, then R2 = R1 - q1 Den, exactly.
  double product[kBoundedCapacity], residual[kBoundedCapacity], next[kBoundedCapacity];
  if (terms.numn + 2 * terms.denn > kBoundedCapacity) return out;
  int productn = ScaleExpansionZeroElim(terms.denn, terms.den, q0, product);
  int residualn = Compress(ExpansionDiffZeroElim(terms.numn, terms.num, productn, product, residual), residual);
  const double q1 = residualn == 0 ? 0.0 : residual[residualn - 1] / den_top;
  double q2 = 0.0;
  if (q1 != 0.0) {
    if (residualn + 2 * terms.denn > kBoundedCapacity) return out;
    productn = ScaleExpansionZeroElim(terms.denn, terms.den, q1, product);
    const int nextn = Compress(ExpansionDiffZeroElim(residualn, residual, productn, product, next), next);
    q2 = nextn == 0 ? 0.0 : next[nextn - 1] / den_top;
  }
  // q0 + q1 + q2 into (hi, mid, lo) without rounding: |q2| << |q1| << |q0|.
  double s12, e12, hi, e0;
  TwoSum(q1, q2, s12, e12);
  FastTwoSum(q0, s12, hi, e0);
  double mid, lo;
  TwoSum(e0, e12, mid, lo);
  const int k = ExponentOf(hi);
  out.hi = ScaleByPow2(hi, -k);
  out.mid = ScaleByPow2(mid, -k);
  out.lo = ScaleByPow2(lo, -k);
  out.exponent = k - 2 * s - 2;  // rho^2 = Num / (4 Den) at scale 2^s
  out.ok = true;
  return out;
}

}  // namespace radius_detail

/// The refined key of the edge (n = 2) or triangle (n = 3) p[0..n).
GALPHA_HD inline RefinedRadiusSq RefineRadiusSq(const Point2* p, int n) {
  using namespace radius_detail;
  RefinedRadiusSq out;
  ExactRadiusTerms terms;
  int s = 0;
  if (!CanonicalExactTerms(p, n, &terms, &s) || terms.numn == 0) return out;
  if (terms.denn == 0) {  // collinear triangle
    out.ok = true;
    out.infinite = true;
    return out;
  }
  return RefineTerms(terms, s);
}

/// Whether b's exact value is certainly above a's, given refined keys with a before b in key
/// order: at a common exponent (where both are below 4) the exact difference of the keys exceeds
/// kRefinedSeparation = 2^-146, and their certified errors sum to under 6 * 2^-150 < 2^-147, so
/// the exact values differ by more than 2^-147 in b's favour.
GALPHA_HD inline bool RefinedKeysSeparated(const RefinedRadiusSq& a, const RefinedRadiusSq& b) {
  using namespace exact;
  if (a.infinite || b.infinite) return !a.infinite && b.infinite;  // only an infinite b is above a finite a
  // Signed keys (weighted radii, core/exact/weighted_radius.hpp): a key's sign is its value's (hi
  // carries it, and |mid| + |lo| < |hi|). Two negative keys are mirrored positive ones: b is above
  // a when |a| is above |b|, so the larger magnitude is a's and the common exponent b's.
  const bool a_negative = a.hi < 0.0, b_negative = b.hi < 0.0;
  if (a_negative != b_negative) return a_negative;
  const RefinedRadiusSq& upper = a_negative ? a : b;  // the larger magnitude if separated
  const RefinedRadiusSq& lower = a_negative ? b : a;
  const int64_t gap = static_cast<int64_t>(upper.exponent) - lower.exponent;
  if (gap >= 2) return true;  // |upper| >= 4 (1 - 2^-50) > 2 (1 + 2^-50) > |lower|, errors included
  if (gap < 0) return false;
  const double scale = gap == 1 ? 2.0 : 1.0;  // exact
  const double sa = a_negative ? scale : 1.0, sb = a_negative ? 1.0 : scale;
  // b - a - 2^-146 by Grow-Expansion only, which keeps an expansion nonoverlapping (Shewchuk 1997,
  // Theorem 10) so that its most significant component carries the sign; every step is exact.
  const double terms[7] = {Mul(b.lo, sb),   Mul(b.mid, sb), Mul(b.hi, sb),      -Mul(a.lo, sa),
                           -Mul(a.mid, sa), -Mul(a.hi, sa), -kRefinedSeparation};
  double e[8];
  int en = 0;
  for (const double t : terms) en = GrowExpansionZeroElim(en, e, t, e);
  return ExpansionSign(en, e) > 0;
}

namespace radius_detail {

/// An edge vector's two coordinates in error-free form (Two-Diff heads and tails: unique for a
/// real number, and ordered as the numbers are) up to their signs and their order, the larger
/// magnitude first. The edge's squared length is a function of these alone.
struct EdgeLengthForm {
  double major_head, major_tail, minor_head, minor_tail;
};

GALPHA_HD inline bool HeadTailLess(double a_head, double a_tail, double b_head, double b_tail) {
  return a_head != b_head ? a_head < b_head : a_tail < b_tail;
}

GALPHA_HD inline EdgeLengthForm EdgeLengthFormOf(const Point2& from, const Point2& to) {
  using namespace exact;
  double xh, xt, yh, yt;
  TwoDiff(to.x, from.x, xh, xt);
  TwoDiff(to.y, from.y, yh, yt);
  // A head has its difference's sign and is zero only when the difference is.
  if (xh < 0.0) {
    xh = -xh;
    xt = -xt;
  }
  if (yh < 0.0) {
    yh = -yh;
    yt = -yt;
  }
  if (HeadTailLess(xh, xt, yh, yt)) return {yh, yt, xh, xt};
  return {xh, xt, yh, yt};
}

GALPHA_HD inline bool EdgeLengthFormLess(const EdgeLengthForm& a, const EdgeLengthForm& b) {
  if (a.major_head != b.major_head || a.major_tail != b.major_tail) {
    return HeadTailLess(a.major_head, a.major_tail, b.major_head, b.major_tail);
  }
  return HeadTailLess(a.minor_head, a.minor_tail, b.minor_head, b.minor_tail);
}

GALPHA_HD inline bool EdgeLengthFormEqual(const EdgeLengthForm& a, const EdgeLengthForm& b) {
  return a.major_head == b.major_head && a.major_tail == b.major_tail && a.minor_head == b.minor_head &&
         a.minor_tail == b.minor_tail;
}

/// A simplex's edges in EdgeLengthForm, sorted (one for an edge, three for a triangle): what
/// RadiusCongruent compares.
struct CongruenceForm {
  EdgeLengthForm edge[3] = {};
};

GALPHA_HD inline CongruenceForm CongruenceFormOf(const Point2* p, int n) {
  CongruenceForm form;
  form.edge[0] = EdgeLengthFormOf(p[0], p[1]);
  if (n == 3) {
    form.edge[1] = EdgeLengthFormOf(p[0], p[2]);
    form.edge[2] = EdgeLengthFormOf(p[1], p[2]);
    for (int i = 1; i < 3; ++i) {
      const EdgeLengthForm x = form.edge[i];
      int j = i;
      while (j > 0 && EdgeLengthFormLess(x, form.edge[j - 1])) {
        form.edge[j] = form.edge[j - 1];
        --j;
      }
      form.edge[j] = x;
    }
  }
  return form;
}

}  // namespace radius_detail

/// Whether rho^2(a) and rho^2(b) are equal because the simplices have the same squared edge
/// lengths, each read from its edge vector's coordinates up to their signs and order (so
/// translations, half-turns, quarter-turns and mirrors in the axes and diagonals, the copies a
/// lattice's cells come in, and more). A triangle's rho^2 is a symmetric function of its three
/// squared edge lengths (abc / 4A with Heron's formula for A: equal side lengths, congruent
/// triangles), an edge's is its squared length / 4; so equal forms mean equal values. The
/// coordinates are compared exactly in error-free form; an overflowing difference compares unequal
/// (NaN). False proves nothing (equal lengths from other coordinates, (3, 4) and (5, 0), are not
/// seen).
GALPHA_HD inline bool RadiusCongruent(const Point2* a, int na, const Point2* b, int nb) {
  using namespace radius_detail;
  if (na != nb) return false;
  const CongruenceForm fa = CongruenceFormOf(a, na), fb = CongruenceFormOf(b, nb);
  const int m = na == 2 ? 1 : 3;
  for (int k = 0; k < m; ++k) {
    if (!EdgeLengthFormEqual(fa.edge[k], fb.edge[k])) return false;
  }
  return true;
}

/// A hash of the congruence form RadiusCongruent compares (zeros of either sign alike): two
/// simplices it calls congruent get equal hashes, so sorting by the hash puts each class of
/// congruent simplices together. Equal hashes prove nothing (a collision): whoever groups by them
/// confirms each neighbour with RadiusCongruent.
GALPHA_HD inline uint64_t CongruenceHash(const Point2* p, int n) {
  using namespace radius_detail;
  const CongruenceForm form = CongruenceFormOf(p, n);
  uint64_t h = static_cast<uint64_t>(n) * 0x9e3779b97f4a7c15ULL;
  const int m = n == 2 ? 1 : 3;
  for (int k = 0; k < m; ++k) {
    const EdgeLengthForm& e = form.edge[k];
    const double parts[4] = {e.major_head, e.major_tail, e.minor_head, e.minor_tail};
    for (const double d : parts) {
      h ^= exact::DoubleBits(d == 0.0 ? 0.0 : d);  // -0 == +0 in the form's comparison
      h *= 0xbf58476d1ce4e5b9ULL;
      h ^= h >> 31;
    }
  }
  return h;
}

}  // namespace galpha
