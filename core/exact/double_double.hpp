// Double-double arithmetic with stated error bounds, for filters that must decide more than a
// plain-double filter can but cost far less than expansion arithmetic: a value is hi + lo, two
// doubles with |lo| <= u |hi| (u = 2^-53), as Two-Sum, Two-Diff and Two-Product leave them and as
// every operation below renormalizes its result (Two-Sum).
//
// Each operation's bound is in its comment, relative to the magnitudes of its operands (not of its
// result: additions may cancel). The bounds assume that no operation underflows or overflows;
// callers establish that (e.g. by scaling their inputs by a power of two onto a grid whose
// products stay normal). Built on the never-fused operations and the exact (fused) Two-Product of
// expansion.hpp, so host and device compute the same bits.
#pragma once

#include "core/base/hd.hpp"
#include "core/exact/expansion.hpp"

namespace galpha::exact {

struct DoubleDouble {
  double hi = 0.0;
  double lo = 0.0;
};

/// A + B (or A - B with `negate_b`). Error at most 3.01 u^2 (|A.hi| + |B.hi|): the his are added
/// exactly (Two-Sum), the los with one rounding (at most u |A.lo + B.lo| <= u^2 (|A.hi| + |B.hi|)),
/// and the two tails with one more (at most u |tail sum| <= 2.01 u^2 (|A.hi| + |B.hi|)).
GALPHA_HD GALPHA_FORCEINLINE DoubleDouble AddDd(DoubleDouble a, DoubleDouble b, bool negate_b = false) {
  const double bhi = negate_b ? -b.hi : b.hi, blo = negate_b ? -b.lo : b.lo;
  double s, se;
  TwoSum(a.hi, bhi, s, se);
  const double tail = Add(se, Add(a.lo, blo));
  DoubleDouble r;
  TwoSum(s, tail, r.hi, r.lo);
  return r;
}

/// A * B. Error at most 8.01 u^2 |A.hi B.hi|: A.hi B.hi exactly (Two-Product); the cross terms
/// A.hi B.lo and A.lo B.hi (each at most u |A.hi B.hi|) with three roundings in all; A.lo B.lo (at
/// most u^2 |A.hi B.hi|) dropped.
GALPHA_HD GALPHA_FORCEINLINE DoubleDouble MulDd(DoubleDouble a, DoubleDouble b) {
  double z, ze;
  TwoProduct(a.hi, b.hi, z, ze);
  const double tail = Add(ze, Add(Mul(a.hi, b.lo), Mul(a.lo, b.hi)));
  DoubleDouble r;
  TwoSum(z, tail, r.hi, r.lo);
  return r;
}

/// A / B for positive A and B. Relative error below 2^-100: the quotient of the his, corrected by
/// the remainder A - q B (formed with MulDd and AddDd) divided by B.hi.
GALPHA_HD GALPHA_FORCEINLINE DoubleDouble DivDd(DoubleDouble a, DoubleDouble b) {
  const double q = a.hi / b.hi;
  const DoubleDouble remainder = AddDd(a, MulDd(b, DoubleDouble{q, 0.0}), /*negate_b=*/true);
  DoubleDouble r;
  TwoSum(q, remainder.hi / b.hi, r.hi, r.lo);
  return r;
}

}  // namespace galpha::exact
