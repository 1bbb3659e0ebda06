// Radix-sortable words for refined keys (radius_refined.hpp): the spectrum's long runs of near ties
// are sorted by these words, 64 bits at a time, instead of by exact comparisons of the keys.
//
// Why the order they give is good enough (gpu/alpha/spectrum_refine.cuh relies on it): the words
// order entries by run, then by T, a truncation of the key's value to 160 fractional bits of its
// mantissa, then by simplex id. |T - key| < 3 * 2^-160 * 2^E, where 2^E <= 2 at any common exponent
// where both values of a pair are below 4; the key is within 2^-150 * 4 = 2^-148 of rho^2 there.
// So every sorted entry's T is within eta = 2^-148 + 3 * 2^-159 of its rho^2, and for adjacent a, b
// whose keys are separated (kb - ka > 2^-146): every entry x before a has
// rho^2(x) <= T(x) + eta <= T(a) + eta <= ka + 3 * 2^-159 + eta, every y after b has
// rho^2(y) >= kb - 3 * 2^-159 - eta, and 2 eta + 6 * 2^-159 = 2^-147 + 12 * 2^-159 < 2^-146: the pair is
// a certified boundary, exactly as with a sort by the keys' exact values. Pairs the truncation
// puts out of key order are closer than 6 * 2^-159 and never separated: the exact comparison sees
// them.
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"
#include "core/exact/expansion.hpp"
#include "core/exact/radius_refined.hpp"

namespace galpha {

/// A spectrum entry (run, simplex id, refined key) as four 64-bit words whose lexicographic order is its sort order, so
/// that radix sorts order the entries (a merge sort comparing keys exactly took most of this stage):
///  word 0: the run (high half), then the key's exponent E, biased (low half);
///  words 1, 2 and the high half of word 3: the fraction of the key's mantissa m, m = 1.f with
///    f to 160 bits, E and m renormalized so that m is in [1, 2);
///  low half of word 3: the simplex id, the last tie-break.
/// The fraction is a truncation: each of the key's three components is truncated to a multiple of
/// 2^-160 before they are added, so the sort key T is within 3 * 2^-160 * 2^E of the key's value.
/// An infinite key (a collinear triangle) sorts above every finite one of its run.
struct RefinedSortWords {
  uint64_t word[4];
};

namespace refined_detail {

/// t += d * 2^160, truncated toward zero, modulo 2^192 (limbs least significant first). |d| < 2^32.
GALPHA_HD inline void AddFixedPoint160(double d, uint64_t t[3]) {
  const uint64_t bits = exact::DoubleBits(d);
  const int biased = static_cast<int>((bits >> 52) & 0x7ff);
  if (biased == 0 && (bits << 1) == 0) return;  // a zero
  const uint64_t mantissa = (bits & ((uint64_t{1} << 52) - 1)) | (biased != 0 ? uint64_t{1} << 52 : 0);
  const int shift = (biased != 0 ? biased - 1075 : -1074) + 160;  // d = mantissa * 2^(shift - 160)
  uint64_t v[3] = {0, 0, 0};
  if (shift >= 0) {  // below 192 for |d| < 2^32: mantissa spans at most two limbs after the shift
    const int limb = shift / 64, bit = shift % 64;
    v[limb] = mantissa << bit;
    if (bit != 0 && limb + 1 < 3) v[limb + 1] = mantissa >> (64 - bit);
  } else if (shift > -64) {
    v[0] = mantissa >> -shift;
  }
  if (bits >> 63) {  // negative: two's complement of v
    v[0] = ~v[0];
    v[1] = ~v[1];
    v[2] = ~v[2];
    if (++v[0] == 0 && ++v[1] == 0) ++v[2];
  }
  uint64_t carry = 0;
  for (int i = 0; i < 3; ++i) {
    const uint64_t sum = t[i] + v[i];
    const uint64_t next = sum < t[i] ? 1 : 0;
    t[i] = sum + carry;
    carry = next + (t[i] < sum ? 1 : 0);
  }
}

}  // namespace refined_detail

/// The sort words of an entry (see RefinedSortWords).
GALPHA_HD inline RefinedSortWords RefinedSortWordsOf(uint32_t run_index, uint32_t id, const RefinedRadiusSq& key) {
  RefinedSortWords out;
  const uint64_t run = uint64_t{run_index} << 32;
  if (key.infinite) {
    out.word[0] = run | 0xffffffffu;
    out.word[1] = out.word[2] = ~uint64_t{0};
    out.word[3] = (uint64_t{0xffffffffu} << 32) | id;
    return out;
  }
  // A negative key (a weighted radius, core/exact/weighted_radius.hpp) is encoded from its
  // magnitude, then mirrored below every nonnegative one (below).
  const bool negative = key.hi < 0.0;
  const double sign = negative ? -1.0 : 1.0;
  // m * 2^160 with m = hi + mid + lo in (1 - 2^-52, 2): hi is in [1, 2) and |mid| + |lo| is below
  // half an ulp of hi. The sum is positive and below 2^161, so the arithmetic modulo 2^192 is exact.
  uint64_t t[3] = {0, 0, 0};
  refined_detail::AddFixedPoint160(sign * key.hi, t);
  refined_detail::AddFixedPoint160(sign * key.mid, t);
  refined_detail::AddFixedPoint160(sign * key.lo, t);
  int64_t exponent = key.exponent;
  if ((t[2] >> 32) == 0) {  // m < 1: one bit up (m > 1/2, so the doubled value is in [1, 2))
    t[2] = (t[2] << 1) | (t[1] >> 63);
    t[1] = (t[1] << 1) | (t[0] >> 63);
    t[0] <<= 1;
    --exponent;
  }
  // Now t = 2^160 + f: bit 160 is bit 32 of t[2]; f's top 64 bits, next 64, last 32.
  out.word[1] = (t[2] << 32) | (t[1] >> 32);
  out.word[2] = (t[1] << 32) | (t[0] >> 32);
  out.word[3] = (t[0] << 32) | id;
  if (!negative) {
    out.word[0] = run | static_cast<uint32_t>(exponent + (int64_t{1} << 31));
    return out;
  }
  // Exponents stay within +-2^12 of 0, so nonnegative keys' low halves lie near 2^31 and negative
  // ones' near 2^30, larger magnitudes lower; the fraction bits are complemented likewise (the
  // truncation is then toward zero for negative keys too, and the bounds above hold).
  out.word[0] = run | static_cast<uint32_t>((int64_t{1} << 30) - exponent);
  out.word[1] = ~out.word[1];
  out.word[2] = ~out.word[2];
  out.word[3] = (~out.word[3] & (~uint64_t{0} << 32)) | id;
  return out;
}

}  // namespace galpha
