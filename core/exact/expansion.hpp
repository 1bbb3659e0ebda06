// Exact floating-point expansion arithmetic for the host and the device.
//
// Reference: J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust
// Geometric Predicates", Discrete & Computational Geometry 18(3):305-363, 1997. The algorithms
// below are reimplementations of the paper's error-free transformations (Fast-Two-Sum, Two-Sum,
// Two-Product, here with a fused multiply-add instead of Dekker's split) and expansion operations
// (Grow-Expansion, Fast-Expansion-Sum, Scale-Expansion, with zero elimination).
//
// An expansion is an array e[0..n) of doubles whose exact, unrounded sum is the value it stands
// for. The components are nonoverlapping and sorted by increasing magnitude, so the most
// significant (last) nonzero component carries the sign of the whole value. Every function here
// eliminates zero components; the value zero may therefore come back as length 0.
//
// Why the Add/Sub/Mul/Fma wrappers: the error-free transformations are only exact if every
// operation is one correctly rounded IEEE-754 binary64 operation (round to nearest, ties to
// even). A compiler that contracts x*y - z into fma(x, y, -z) on its own changes Two-Sum's and
// the filters' roundings, and the host and the device would stop agreeing bit for bit, which the
// GPU engine relies on (both sides must take the same decisions). The build passes
// -ffp-contract=off (host) and --fmad=false (nvcc); on the device we also use the
// __dadd_rn/__dsub_rn/__dmul_rn intrinsics, which the CUDA compiler never fuses, so the device code
// stays exact even in a translation unit built without --fmad=false. On the host, the code relies
// on -ffp-contract=off (GCC/Clang in ISO C++ mode do not contract by default either).
// Two-Product is the one place that fuses, explicitly (Fma: __fma_rn on the device, std::fma on
// the host, both correctly rounded): its tail a*b - fl(a*b) is exactly representable inside the
// range below, so the fused operation returns it exactly, on both sides, with the same bits as
// Dekker's 17-operation split product returned before 2026-11-29; it is 2 operations instead of
// 17, and the double-double and expansion stages of the predicates are mostly Two-Products.
//
// Range: the transformations are error-free as long as nothing overflows and no product
// underflows. Two-Product(a, b) is exact when exponent(a) + exponent(b) >= -970 (no underflow of
// its tail) and fl(a * b) is finite. Sums (Two-Sum, Two-Diff) are
// exact for all finite operands whose sum does not overflow, subnormals included. The predicates
// (core/exact/predicates.hpp) rescale their inputs by powers of two to stay inside these limits.
//
// Every function is usable from device code: no exceptions, no allocation, no std:: calls;
// callers provide fixed-size output arrays whose capacity bounds are stated per function.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/base/hd.hpp"

namespace galpha::exact {

/// Half an ulp of 1: the relative rounding error bound of one binary64 operation (Shewchuk's
/// "epsilon").
constexpr double kEpsilon = 0x1p-53;

// ---- Single correctly rounded operations that are never fused ----------------------------------

GALPHA_HD GALPHA_FORCEINLINE double Add(double a, double b) {
#if defined(__CUDA_ARCH__)
  return __dadd_rn(a, b);
#else
  return a + b;
#endif
}

GALPHA_HD GALPHA_FORCEINLINE double Sub(double a, double b) {
#if defined(__CUDA_ARCH__)
  return __dsub_rn(a, b);
#else
  return a - b;
#endif
}

GALPHA_HD GALPHA_FORCEINLINE double Mul(double a, double b) {
#if defined(__CUDA_ARCH__)
  return __dmul_rn(a, b);
#else
  return a * b;
#endif
}

/// fl(a * b + c), one rounding (never split into a product and a sum).
GALPHA_HD GALPHA_FORCEINLINE double Fma(double a, double b, double c) {
#if defined(__CUDA_ARCH__)
  return __fma_rn(a, b, c);
#else
  return std::fma(a, b, c);
#endif
}

GALPHA_HD GALPHA_FORCEINLINE double Abs(double a) { return a < 0.0 ? -a : a; }

// ---- Bit-level helpers for power-of-two scaling -------------------------------------------------

GALPHA_HD GALPHA_FORCEINLINE uint64_t DoubleBits(double v) {
#if defined(__CUDA_ARCH__)
  return static_cast<uint64_t>(__double_as_longlong(v));
#else
  uint64_t u;
  __builtin_memcpy(&u, &v, sizeof u);
  return u;
#endif
}

GALPHA_HD GALPHA_FORCEINLINE double BitsToDouble(uint64_t u) {
#if defined(__CUDA_ARCH__)
  return __longlong_as_double(static_cast<long long>(u));
#else
  double v;
  __builtin_memcpy(&v, &u, sizeof v);
  return v;
#endif
}

/// floor(log2 |v|) for a normal v; -1022 for zero and subnormals (an upper bound there, which is
/// what the scaling code needs: it must never underestimate a magnitude).
GALPHA_HD GALPHA_FORCEINLINE int ExponentOf(double v) {
  const int biased = static_cast<int>((DoubleBits(v) >> 52) & 0x7ff);
  return biased == 0 ? -1022 : biased - 1023;
}

/// 2^k, exactly, for -1022 <= k <= 1023.
GALPHA_HD GALPHA_FORCEINLINE double Pow2(int k) { return BitsToDouble(static_cast<uint64_t>(k + 1023) << 52); }

/// v * 2^s. Exact when the result is normal (or zero); s >= -1022 is assumed (one rounding at most:
/// large upward scalings go in steps of 2^1000, each exact because the value only grows).
GALPHA_HD inline double ScaleByPow2(double v, int s) {
  while (s > 1000) {
    v = Mul(v, Pow2(1000));
    s -= 1000;
  }
  return Mul(v, Pow2(s));
}

// ---- Error-free transformations (Shewchuk 1997, section 2) --------------------------------------

/// x + y = a + b exactly, x = fl(a + b); requires |a| >= |b| (or a == 0).
GALPHA_HD GALPHA_FORCEINLINE void FastTwoSum(double a, double b, double& x, double& y) {
  x = Add(a, b);
  const double bvirt = Sub(x, a);
  y = Sub(b, bvirt);
}

/// x + y = a + b exactly, x = fl(a + b); no precondition (Knuth's Two-Sum).
GALPHA_HD GALPHA_FORCEINLINE void TwoSum(double a, double b, double& x, double& y) {
  x = Add(a, b);
  const double bvirt = Sub(x, a);
  const double avirt = Sub(x, bvirt);
  const double bround = Sub(b, bvirt);
  const double around = Sub(a, avirt);
  y = Add(around, bround);
}

/// x + y = a - b exactly, x = fl(a - b).
GALPHA_HD GALPHA_FORCEINLINE void TwoDiff(double a, double b, double& x, double& y) {
  x = Sub(a, b);
  const double bvirt = Sub(a, x);
  const double avirt = Add(x, bvirt);
  const double bround = Sub(bvirt, b);
  const double around = Sub(a, avirt);
  y = Add(around, bround);
}

/// Two-Product: x + y = a * b exactly, x = fl(a * b), when exponent(a) + exponent(b) >= -970 and
/// x is finite. Why the fused tail is exact: a * b is an integer multiple of
/// q = 2^(exponent(a) + exponent(b) - 104), and so is a * b - x, whose magnitude is at most half an
/// ulp of x, below 2^53 q; with q >= 2^-1074 it is a double, and Fma returns it unrounded.
GALPHA_HD GALPHA_FORCEINLINE void TwoProduct(double a, double b, double& x, double& y) {
  x = Mul(a, b);
  y = Fma(a, b, -x);
}

// ---- Expansion arithmetic (Shewchuk 1997, section 2.8) ------------------------------------------

/// Writes the two-component expansion hi + lo (as produced by a transformation above) into h,
/// dropping zeros; returns its length (0..2).
GALPHA_HD GALPHA_FORCEINLINE int TwoToExpansion(double hi, double lo, double* h) {
  int n = 0;
  if (lo != 0.0) h[n++] = lo;
  if (hi != 0.0) h[n++] = hi;
  return n;
}

/// h = e + b (Grow-Expansion with zero elimination). h holds up to elen + 1 components and may be
/// the same array as e.
GALPHA_HD inline int GrowExpansionZeroElim(int elen, const double* e, double b, double* h) {
  double q = b;
  int hindex = 0;
  for (int i = 0; i < elen; ++i) {
    double qnew, hh;
    TwoSum(q, e[i], qnew, hh);
    q = qnew;
    if (hh != 0.0) h[hindex++] = hh;
  }
  if (q != 0.0) h[hindex++] = q;
  return hindex;
}

namespace detail {

/// Fast-Expansion-Sum with zero elimination, on e and (optionally negated) f. The inputs are
/// merged by increasing magnitude and accumulated with Two-Sum. Shewchuk's first step is a
/// Fast-Two-Sum; Two-Sum returns the same two numbers whenever Fast-Two-Sum's precondition holds
/// and stays error-free when it does not, so we use it throughout. Unlike the reference code this
/// never reads past the end of e or f.
GALPHA_HD inline int ExpansionSumImpl(int elen, const double* e, int flen, const double* f, bool negate_f, double* h) {
  int ei = 0, fi = 0, hindex = 0;
  double q = 0.0;
  bool have_q = false;
  while (ei < elen || fi < flen) {
    double g;
    if (fi >= flen) {
      g = e[ei++];
    } else {
      const double fnow = negate_f ? -f[fi] : f[fi];
      // Take e's head when |f's head| > |e's head| (Shewchuk's comparison, sign-agnostic).
      if (ei < elen && ((fnow > e[ei]) == (fnow > -e[ei]))) {
        g = e[ei++];
      } else {
        g = fnow;
        ++fi;
      }
    }
    if (!have_q) {
      q = g;
      have_q = true;
      continue;
    }
    double qnew, hh;
    TwoSum(q, g, qnew, hh);
    q = qnew;
    if (hh != 0.0) h[hindex++] = hh;
  }
  if (q != 0.0) h[hindex++] = q;
  return hindex;
}

}  // namespace detail

/// h = e + f (Fast-Expansion-Sum, zero elimination). Inputs strongly nonoverlapping (everything
/// these functions produce is); output too. h holds up to elen + flen components and must not
/// alias e or f.
GALPHA_HD inline int ExpansionSumZeroElim(int elen, const double* e, int flen, const double* f, double* h) {
  return detail::ExpansionSumImpl(elen, e, flen, f, false, h);
}

/// h = e - f; same contract as ExpansionSumZeroElim.
GALPHA_HD inline int ExpansionDiffZeroElim(int elen, const double* e, int flen, const double* f, double* h) {
  return detail::ExpansionSumImpl(elen, e, flen, f, true, h);
}

/// h = b * e (Scale-Expansion with zero elimination). h holds up to 2 * elen components and must
/// not alias e. (Shewchuk's second accumulation step is a Fast-Two-Sum; Two-Sum gives the same
/// result, see ExpansionSumImpl.)
GALPHA_HD inline int ScaleExpansionZeroElim(int elen, const double* e, double b, double* h) {
  if (elen == 0 || b == 0.0) return 0;
  double q, hh;
  TwoProduct(e[0], b, q, hh);
  int hindex = 0;
  if (hh != 0.0) h[hindex++] = hh;
  for (int i = 1; i < elen; ++i) {
    double p1, p0, sum;
    TwoProduct(e[i], b, p1, p0);
    TwoSum(q, p0, sum, hh);
    if (hh != 0.0) h[hindex++] = hh;
    TwoSum(p1, sum, q, hh);
    if (hh != 0.0) h[hindex++] = hh;
  }
  if (q != 0.0) h[hindex++] = q;
  return hindex;
}

/// h = e * f: scales the longer expansion by each component of the shorter one and sums the
/// partial products. elen <= kMaxE, flen <= kMaxF; h holds up to 2 * kMaxE * kMaxF components
/// (every partial product has at most 2 * max(elen, flen) components, and the sums at most add
/// the lengths) and must not alias e or f.
template <int kMaxE, int kMaxF>
GALPHA_HD inline int ExpansionProduct(int elen, const double* e, int flen, const double* f, double* h) {
  constexpr int kMaxLong = kMaxE > kMaxF ? kMaxE : kMaxF;  // NOLINT(bugprone-branch-clone): a max
  constexpr int kMaxOut = 2 * kMaxE * kMaxF;
  static_assert(kMaxE > 0 && kMaxF > 0, "expansion capacities must be positive");
  const double* longer = e;
  const double* shorter = f;
  int longlen = elen, shortlen = flen;
  if (flen > elen) {
    longer = f;
    shorter = e;
    longlen = flen;
    shortlen = elen;
  }
  double scaled[2 * kMaxLong];
  double other[kMaxOut];
  double* acc = h;  // holds the running sum; ping-pongs with `other`
  double* spare = other;
  int acclen = 0;
  for (int j = 0; j < shortlen; ++j) {
    const int slen = ScaleExpansionZeroElim(longlen, longer, shorter[j], scaled);
    acclen = ExpansionSumZeroElim(acclen, acc, slen, scaled, spare);
    double* t = acc;
    acc = spare;
    spare = t;
  }
  if (acc != h) {
    for (int i = 0; i < acclen; ++i) h[i] = acc[i];
  }
  return acclen;
}

/// Negates an expansion in place (exact).
GALPHA_HD inline void NegateExpansion(int elen, double* e) {
  for (int i = 0; i < elen; ++i) e[i] = -e[i];
}

/// A double approximation of the expansion's value (sum from the smallest component up).
GALPHA_HD inline double Estimate(int elen, const double* e) {
  double q = 0.0;
  for (int i = 0; i < elen; ++i) q = Add(q, e[i]);
  return q;
}

/// The exact sign of a nonoverlapping expansion: the sign of its most significant nonzero
/// component.
GALPHA_HD inline int ExpansionSign(int elen, const double* e) {
  for (int i = elen - 1; i >= 0; --i) {
    if (e[i] > 0.0) return 1;
    if (e[i] < 0.0) return -1;
  }
  return 0;
}

}  // namespace galpha::exact
