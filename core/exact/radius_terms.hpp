// Squared radii of Delaunay simplices as exact expansions: rho^2 = Num / (4 Den), built from
// differences scaled by a power of two in buffers of bounded size. The one construction the
// certified keys (radius_key.hpp, when the floating filter fails), the exact comparison
// (radius_compare.hpp) and the nearest double (radius_nearest.hpp) share; host and device alike.
//
// rho^2 of an edge pq is |q - p|^2 / 4; of a triangle abc it is |b-a|^2 |c-a|^2 |c-b|^2 / (4 D^2)
// with D = orient2d(a, b, c) (twice the signed area). Both are exact rationals of the input, and the
// alpha spectrum needs them in exact order (docs/design.md, "Exactness"). Every construction here
// fails (returns false) rather than round when a buffer would overflow or the exponent range would
// make an error-free transformation inexact.
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/expansion.hpp"

namespace galpha {

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

using namespace exact;

GALPHA_HD GALPHA_FORCEINLINE bool Finite(double v) { return v - v == 0.0; }

/// Capacity of every bounded expansion buffer of the exact path. Inputs in one binade need far
/// fewer components; wider exponent ranges overflow it and go to the CPU fallback.
constexpr int kBoundedCapacity = 64;

/// Shewchuk's Compress: the same value in a nonoverlapping expansion with no more components (in
/// practice far fewer). In place; n is at most kCapacity (a small capacity keeps the scratch in
/// registers on the device).
template <int kCapacity = kBoundedCapacity>
GALPHA_HD inline int Compress(int n, double* e) {
  if (n <= 1) return n;
  double g[kCapacity];
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
GALPHA_HD inline bool BoundedSum(int en, const double* e, int fn, const double* f, bool negate_f, double* out,
                                 int* outn) {
  if (en + fn > kBoundedCapacity) return false;
  *outn = negate_f ? ExpansionDiffZeroElim(en, e, fn, f, out) : ExpansionSumZeroElim(en, e, fn, f, out);
  return true;
}

/// out = e * f, compressed; fails when an intermediate may not fit. out must not alias e or f.
GALPHA_HD inline bool BoundedProduct(int en, const double* e, int fn, const double* f, double* out, int* outn) {
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

}  // namespace galpha
