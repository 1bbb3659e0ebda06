// Squared radii of Delaunay simplices: certified approximations for sorting, and exact comparisons.
//
// rho^2 of an edge pq is |q - p|^2 / 4; of a triangle abc it is |b-a|^2 |c-a|^2 |c-b|^2 / (4 D^2)
// with D = orient2d(a, b, c) (twice the signed area). Both are exact rationals of the input. The
// alpha spectrum needs them in exact order (docs/design.md, "Exactness"), which this header provides in
// three layers, one source for host and device:
//   1. RadiusSqApprox: a 64-bit order-preserving key of a double approximation whose relative
//      error is certified to be below kRadiusSqRelErr (or flagged `certified == false`). Two keys
//      more than kRadiusKeyGap apart order their exact values; closer keys need layer 2.
//   2. CompareRadiusSqBounded: exact comparison with expansion arithmetic in bounded buffers (the
//      device's path). It answers kRadiusUndecided when a buffer would overflow or the operands'
//      exponent range would make an error-free transformation inexact; the caller then uses
//      layer 3.
//   3. core/exact/radius_rational.hpp: GMP rationals on the host, exact and unbounded (the CPU fallback).
// NearestRadiusSqBounded gives the double nearest to an exact rho^2 (the spectrum's published value).
#pragma once

#include <cmath>
#include <cstdint>

#include "core/exact/expansion.hpp"
#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/predicates.hpp"

namespace galpha {

/// Relative error bound of RadiusSqApprox's value when it is certified.
constexpr double kRadiusSqRelErr = 0x1p-40;
/// Keys whose difference exceeds this have exact values in key order (derivation at
/// RadiusKeyFromScaled); closer keys may be tied or swapped and need an exact comparison.
constexpr uint64_t kRadiusKeyGap = uint64_t{1} << 14;
/// The key of a triangle whose vertices are collinear (an infinite radius: never in any complex).
constexpr uint64_t kInfiniteRadiusKey = ~uint64_t{0};
/// CompareRadiusSqBounded's answer when it cannot decide within its buffers.
constexpr int kRadiusUndecided = 2;

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

GALPHA_HD GALPHA_FORCEINLINE bool Finite(double v) { return v - v == 0.0; }

}  // namespace radius_detail

/// Exponent of the lowest set bit of a nonzero finite double (2^-1074 for the smallest subnormal).
GALPHA_HD inline int LowestBitExponent(double v) {
  const uint64_t bits = exact::DoubleBits(v);
  uint64_t mantissa = bits & ((uint64_t{1} << 52) - 1);
  const int biased = static_cast<int>((bits >> 52) & 0x7ff);
  int exponent = biased == 0 ? -1074 : biased - 1075;
  if (biased != 0) mantissa |= uint64_t{1} << 52;
  while ((mantissa & 1) == 0) {
    mantissa >>= 1;
    ++exponent;
  }
  return exponent;
}

/// floor(log2 |v|) for a nonzero finite double, subnormals included.
GALPHA_HD inline int ExactExponentOf(double v) {
  const uint64_t bits = exact::DoubleBits(v);
  const int biased = static_cast<int>((bits >> 52) & 0x7ff);
  if (biased != 0) return biased - 1023;
  uint64_t mantissa = bits & ((uint64_t{1} << 52) - 1);
  int exponent = -1075;
  while (mantissa != 0) {
    mantissa >>= 1;
    ++exponent;
  }
  return exponent;
}

namespace radius_detail {

/// Capacity of every bounded expansion buffer of the exact path. Inputs in one binade need far
/// fewer components; wider exponent ranges overflow it and go to the CPU fallback.
constexpr int kBoundedCapacity = 64;

/// Shewchuk's Compress: the same value in a nonoverlapping expansion with no more components (in
/// practice far fewer). In place.
GALPHA_HD inline int Compress(int n, double* e) {
  if (n <= 1) return n;
  double g[kBoundedCapacity];
  double q = e[n - 1];
  int bottom = n - 1;
  for (int i = n - 2; i >= 0; --i) {
    double sum, err;
    FastTwoSum(q, e[i], sum, err);
    if (err != 0.0) {
      g[bottom--] = sum;
      q = err;
    } else {
      q = sum;
    }
  }
  g[bottom] = q;
  int top = 0;
  for (int i = bottom + 1; i < n; ++i) {
    double sum, err;
    FastTwoSum(g[i], q, sum, err);
    if (err != 0.0) e[top++] = err;
    q = sum;
  }
  e[top++] = q;
  return top;
}

/// out = e + f (or e - f with negate_f), failing when the result may not fit the buffer.
GALPHA_HD inline bool BoundedSum(int en, const double* e, int fn, const double* f, bool negate_f,
                                 double* out, int* outn) {
  if (en + fn > kBoundedCapacity) return false;
  *outn = negate_f ? ExpansionDiffZeroElim(en, e, fn, f, out) : ExpansionSumZeroElim(en, e, fn, f, out);
  return true;
}

/// out = e * f, compressed; fails when an intermediate may not fit. out must not alias e or f.
GALPHA_HD inline bool BoundedProduct(int en, const double* e, int fn, const double* f, double* out,
                                     int* outn) {
  if (en == 0 || fn == 0) {
    *outn = 0;
    return true;
  }
  const double* longer = en >= fn ? e : f;
  const double* shorter = en >= fn ? f : e;
  const int longn = en >= fn ? en : fn;
  const int shortn = en >= fn ? fn : en;
  if (2 * longn > kBoundedCapacity) return false;
  double scaled[kBoundedCapacity];
  double acc[kBoundedCapacity];
  int accn = 0;
  for (int j = 0; j < shortn; ++j) {
    const int sn = ScaleExpansionZeroElim(longn, longer, shorter[j], scaled);
    if (accn + sn > kBoundedCapacity) {
      accn = Compress(accn, acc);
      if (accn + sn > kBoundedCapacity) return false;
    }
    accn = ExpansionSumZeroElim(accn, acc, sn, scaled, out);
    for (int i = 0; i < accn; ++i) acc[i] = out[i];
  }
  accn = Compress(accn, acc);
  for (int i = 0; i < accn; ++i) out[i] = acc[i];
  *outn = accn;
  return true;
}

/// A simplex's rho^2 as Num / (4 Den), exact, over differences scaled by 2^s: for an edge
/// Num = |q-p|^2 and Den = 1 (degree 2 and 0), for a triangle Num = |b-a|^2 |c-a|^2 |c-b|^2 and
/// Den = D^2 (degree 6 and 4). The true value is Num / (4 Den) * 2^(-2s).
struct ExactRadiusTerms {
  double num[kBoundedCapacity];
  double den[kBoundedCapacity];
  int numn = 0;
  int denn = 0;
};

/// Scaled exact difference u - v as an expansion of at most 2 components.
GALPHA_HD inline int ScaledDiff(double u, double v, int s, double* out) {
  double hi, lo;
  TwoDiff(u, v, hi, lo);
  return TwoToExpansion(ScaleByPow2(hi, s), ScaleByPow2(lo, s), out);
}

/// |d|^2 for a difference vector given as two expansions of at most 2 components.
GALPHA_HD inline bool SquaredLength(int xn, const double* x, int yn, const double* y, double* out, int* outn) {
  double xx[kBoundedCapacity], yy[kBoundedCapacity];
  int xxn, yyn;
  if (!BoundedProduct(xn, x, xn, x, xx, &xxn) || !BoundedProduct(yn, y, yn, y, yy, &yyn)) return false;
  if (!BoundedSum(xxn, xx, yyn, yy, false, out, outn)) return false;
  *outn = Compress(*outn, out);
  return true;
}

/// Fills `terms` for the simplex p[0..n) (n = 2 or 3) at scale 2^s. The caller has checked the
/// exponent range (ExactScaleFor). Fails only when a buffer would overflow.
GALPHA_HD inline bool ExactTerms(const Point2* p, int n, int s, ExactRadiusTerms* terms) {
  if (n == 2) {
    double dx[2], dy[2];
    const int dxn = ScaledDiff(p[1].x, p[0].x, s, dx);
    const int dyn = ScaledDiff(p[1].y, p[0].y, s, dy);
    if (!SquaredLength(dxn, dx, dyn, dy, terms->num, &terms->numn)) return false;
    terms->den[0] = 1.0;
    terms->denn = 1;
    return true;
  }
  double d[3][2][2];  // ab, ac, bc; x and y
  int dn[3][2];
  const int from[3] = {0, 0, 1}, to[3] = {1, 2, 2};
  for (int k = 0; k < 3; ++k) {
    dn[k][0] = ScaledDiff(p[to[k]].x, p[from[k]].x, s, d[k][0]);
    dn[k][1] = ScaledDiff(p[to[k]].y, p[from[k]].y, s, d[k][1]);
  }
  double len[3][kBoundedCapacity];
  int lenn[3];
  for (int k = 0; k < 3; ++k) {
    if (!SquaredLength(dn[k][0], d[k][0], dn[k][1], d[k][1], len[k], &lenn[k])) return false;
  }
  double two[kBoundedCapacity];
  int twon;
  if (!BoundedProduct(lenn[0], len[0], lenn[1], len[1], two, &twon)) return false;
  if (!BoundedProduct(twon, two, lenn[2], len[2], terms->num, &terms->numn)) return false;
  // D = abx * acy - aby * acx
  double left[kBoundedCapacity], right[kBoundedCapacity], area[kBoundedCapacity];
  int leftn, rightn, arean;
  if (!BoundedProduct(dn[0][0], d[0][0], dn[1][1], d[1][1], left, &leftn)) return false;
  if (!BoundedProduct(dn[0][1], d[0][1], dn[1][0], d[1][0], right, &rightn)) return false;
  if (!BoundedSum(leftn, left, rightn, right, true, area, &arean)) return false;
  arean = Compress(arean, area);
  return BoundedProduct(arean, area, arean, area, terms->den, &terms->denn);
}

/// Largest |difference head| and lowest set bit over the coordinates of a simplex.
GALPHA_HD inline bool DifferenceRange(const Point2* p, int n, double* maxabs, int* lowest_bit) {
  for (int i = 0; i < n; ++i) {
    const double c[2] = {p[i].x, p[i].y};
    for (double v : c) {
      if (!Finite(v)) return false;
      if (v != 0.0) {
        const int lb = LowestBitExponent(v);
        if (lb < *lowest_bit) *lowest_bit = lb;
      }
    }
    for (int j = i + 1; j < n; ++j) {
      const double dx = Abs(Sub(p[j].x, p[i].x)), dy = Abs(Sub(p[j].y, p[i].y));
      if (!Finite(dx) || !Finite(dy)) return false;
      if (dx > *maxabs) *maxabs = dx;
      if (dy > *maxabs) *maxabs = dy;
    }
  }
  return true;
}

/// Scale exponent that brings the largest difference to [2^96, 2^97): products of degree 10
/// stay below 2^1000 and Split's 2^996 limit. Checks that every product of degree `degree` keeps
/// its exponent above -960, so that no Two-Product underflows (every component of a degree-k
/// intermediate is a nonzero multiple of 2^(k (lowest_bit + s))). False when out of range.
GALPHA_HD inline bool ExactScaleFor(double maxabs, int lowest_bit, int degree, int* s) {
  if (maxabs == 0.0) return false;
  *s = 96 - ExactExponentOf(maxabs);
  return degree * (lowest_bit + *s) >= -960;
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
    if (lengths_ok && Abs(area) >= Mul(sum, 0x1p-6) && Abs(area) >= kMinScaledArea) {
      const double num = Mul(Mul(len[0], len[1]), len[2]);
      const double den = Mul(area, area);
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
GALPHA_HD GALPHA_FORCEINLINE bool RadiusKeysMayTie(uint64_t lo, uint64_t hi) {
  return hi - lo <= kRadiusKeyGap + 1;
}

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

/// Exact sign of rho^2(a) - rho^2(b) for simplices a (na = 2 or 3 points) and b, or
/// kRadiusUndecided when the bounded buffers or the exponent range do not suffice.
GALPHA_HD inline int CompareRadiusSqBounded(const Point2* a, int na, const Point2* b, int nb) {
  using namespace radius_detail;
  double va, vb;
  if (ExactDoubleRadiusSq(a, na, &va) && ExactDoubleRadiusSq(b, nb, &vb)) return (va > vb) - (va < vb);
  double dmax = 0.0;
  int lowest = 1 << 20;
  if (!DifferenceRange(a, na, &dmax, &lowest) || !DifferenceRange(b, nb, &dmax, &lowest)) {
    return kRadiusUndecided;
  }
  // Num_a / Den_a vs Num_b / Den_b, both of degree 2: compare Num_a Den_b with Num_b Den_a.
  const int degree = (na == 3 || nb == 3) ? (na == 3 && nb == 3 ? 10 : 6) : 2;
  int s = 0;
  if (!ExactScaleFor(dmax, lowest, degree, &s)) return kRadiusUndecided;
  ExactRadiusTerms ta, tb;
  if (!ExactTerms(a, na, s, &ta) || !ExactTerms(b, nb, s, &tb)) return kRadiusUndecided;
  if (ta.denn == 0 || tb.denn == 0) {  // collinear triangles: infinite radius
    return (ta.denn == 0 ? 1 : 0) - (tb.denn == 0 ? 1 : 0);
  }
  double left[kBoundedCapacity], right[kBoundedCapacity], diff[kBoundedCapacity];
  int leftn, rightn, diffn;
  if (!BoundedProduct(ta.numn, ta.num, tb.denn, tb.den, left, &leftn) ||
      !BoundedProduct(tb.numn, tb.num, ta.denn, ta.den, right, &rightn) ||
      !BoundedSum(leftn, left, rightn, right, true, diff, &diffn)) {
    return kRadiusUndecided;
  }
  return ExpansionSign(diffn, diff);
}

namespace radius_detail {

/// sign(Num - 4 m Den) for m = c + h (h a power of two, a half gap to a neighbour of c, so that
/// (c, h) is a nonoverlapping pair): the exact value against m. kRadiusUndecided on overflow.
GALPHA_HD inline int CompareToScaled(const ExactRadiusTerms& t, double c, double h) {
  double m[2];
  const int mn = TwoToExpansion(Mul(c, 4.0), Mul(h, 4.0), m);
  double prod[kBoundedCapacity], diff[kBoundedCapacity];
  int prodn, diffn;
  if (!BoundedProduct(mn, m, t.denn, t.den, prod, &prodn)) return kRadiusUndecided;
  if (!BoundedSum(t.numn, t.num, prodn, prod, true, diff, &diffn)) return kRadiusUndecided;
  return ExpansionSign(diffn, diff);
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
    const int above = CompareToScaled(t, Mul(c, scale), Mul(up, scale));
    const int below = CompareToScaled(t, Mul(c, scale), -Mul(down, scale));
    if (above == kRadiusUndecided || below == kRadiusUndecided) return false;
    const bool even = (DoubleBits(c) & 1) == 0;
    if (above > 0 || (above == 0 && !even)) {
      c = NextUp(c);
    } else if (below < 0 || (below == 0 && !even)) {
      c = NextDown(c);
    } else {
      *out = ldexp(c, shift - 2 * s);
      return true;
    }
  }
  return false;
}

namespace radius_detail {

/// Double-double value h + l (|l| <= half an ulp of h after TwoSum).
struct DoubleDouble {
  double h, l;
};

GALPHA_HD GALPHA_FORCEINLINE DoubleDouble Normalize(double h, double l) {
  DoubleDouble r;
  TwoSum(h, l, r.h, r.l);
  return r;
}
/// Relative error below 2^-102 (the dropped l*l term and three roundings of the tail).
GALPHA_HD GALPHA_FORCEINLINE DoubleDouble DDMul(DoubleDouble a, DoubleDouble b) {
  double p, e;
  TwoProduct(a.h, b.h, p, e);
  return Normalize(p, Add(e, Add(Mul(a.h, b.l), Mul(a.l, b.h))));
}
/// Absolute error below 2^-102 (|a| + |b|).
GALPHA_HD GALPHA_FORCEINLINE DoubleDouble DDAdd(DoubleDouble a, DoubleDouble b) {
  double s, e;
  TwoSum(a.h, b.h, s, e);
  return Normalize(s, Add(e, Add(a.l, b.l)));
}
/// Relative error below 2^-100 for positive operands.
GALPHA_HD GALPHA_FORCEINLINE DoubleDouble DDDiv(DoubleDouble a, DoubleDouble b) {
  const double q1 = a.h / b.h;
  const DoubleDouble qb = DDMul(b, DoubleDouble{q1, 0.0});
  const DoubleDouble r = DDAdd(a, DoubleDouble{-qb.h, -qb.l});
  return Normalize(q1, r.h / b.h);
}
/// Exact scaled difference as a double-double.
GALPHA_HD GALPHA_FORCEINLINE DoubleDouble DDDiff(double u, double v, int s) {
  double hi, lo;
  TwoDiff(u, v, hi, lo);
  return DoubleDouble{ScaleByPow2(hi, s), ScaleByPow2(lo, s)};
}

}  // namespace radius_detail

/// The double nearest to rho^2 of p[0..n) by double-double arithmetic with a certified error
/// bound (about 2^-95 relative): decides the rounding unless the value lies within that bound of a
/// midpoint between two doubles or outside the normal range, where it returns false and the
/// exact NearestRadiusSqBounded decides. The fast path of the published spectrum.
GALPHA_HD inline bool NearestRadiusSqFast(const Point2* p, int n, double* out) {
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
    d[k][0] = DDDiff(p[to[k]].x, p[from[k]].x, s);
    d[k][1] = DDDiff(p[to[k]].y, p[from[k]].y, s);
    for (int c = 0; c < 2; ++c) {
      // Tiny differences beside large ones could underflow in products: the exact path takes them.
      if (d[k][c].h != 0.0 && Abs(d[k][c].h) < 0x1p-300) return false;
    }
  }
  DoubleDouble len[3];
  for (int k = 0; k < m; ++k) len[k] = DDAdd(DDMul(d[k][0], d[k][0]), DDMul(d[k][1], d[k][1]));
  DoubleDouble value;
  double bound = 0x1p-95;
  if (n == 2) {
    value = DoubleDouble{Mul(len[0].h, 0.25), Mul(len[0].l, 0.25)};
  } else {
    const DoubleDouble left = DDMul(d[0][0], d[1][1]), right = DDMul(d[0][1], d[1][0]);
    const DoubleDouble area = DDAdd(left, DoubleDouble{-right.h, -right.l});
    const double sum = Add(Abs(left.h), Abs(right.h));
    if (Abs(area.h) < 0x1p-500 || Abs(area.h) < Mul(sum, 0x1p-31)) return false;
    // D's relative error: 2^-101 (|left| + |right|) / |D| <= 2^-70; rho^2 gets four times that.
    bound = Add(bound, Mul(Mul(sum / Abs(area.h), 0x1p-101), 4.0));
    const DoubleDouble num = DDMul(DDMul(len[0], len[1]), len[2]);
    const DoubleDouble den = DDMul(area, area);
    value = DDDiv(num, DoubleDouble{Mul(den.h, 4.0), Mul(den.l, 4.0)});
  }
  // Unscale (exact while normal), then decide the rounding: the exact value lies within
  // bound * value of h + l; h is its nearest double if that interval stays strictly inside
  // h's rounding interval.
  const double h = ldexp(value.h, -2 * s);
  const double l = ldexp(value.l, -2 * s);
  if (!(h >= 0x1p-900 && h <= 0x1p1000)) return false;  // l and the bound stay normal
  const double err = Mul(Mul(h, bound), 1.0 + 0x1p-20);
  const double up = Mul(Sub(NextUp(h), h), 0.5);
  const double down = Mul(Sub(h, NextDown(h)), 0.5);
  if (!(Add(l, err) < up && Sub(l, err) > -down)) return false;
  *out = h;
  return true;
}

}  // namespace galpha
