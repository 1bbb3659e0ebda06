// The input domain (core/io/input_validation.hpp) decided from its definition with exact
// rationals, independently of the validation's floating-point test: every coordinate finite,
// every |coordinate| < 2^500, and, with magnitudes below 2^-1022 counting as 2^-1022 and zeros
// taking no part, largest / smallest nonzero magnitude < 2^437. Header-only (GMP's C++ classes),
// so that the fuzz targets, which compile only the sources they need, can include it too.
#pragma once

#include <gmpxx.h>

#include <cmath>
#include <cstddef>

#include "core/base/point.hpp"

namespace galpha::testing {

/// 2^e exactly.
inline mpq_class RationalPow2(int e) {
  mpq_class q(1);
  if (e >= 0) mpz_mul_2exp(q.get_num_mpz_t(), q.get_num_mpz_t(), static_cast<mp_bitcnt_t>(e));
  if (e < 0) mpz_mul_2exp(q.get_den_mpz_t(), q.get_den_mpz_t(), static_cast<mp_bitcnt_t>(-e));
  return q;
}

inline bool InInputDomain(const Point2* points, size_t n) {
  mpq_class largest(0), smallest(0);
  bool any = false;
  for (size_t i = 0; i < n; ++i) {
    for (const double c : {points[i].x, points[i].y}) {
      if (!std::isfinite(c)) return false;
      mpq_class m = abs(mpq_class(c));
      if (m >= RationalPow2(500)) return false;
      if (m == 0) continue;
      if (m < RationalPow2(-1022)) m = RationalPow2(-1022);
      if (!any || m > largest) largest = m;
      if (!any || m < smallest) smallest = m;
      any = true;
    }
  }
  return !any || largest / smallest < RationalPow2(437);
}

}  // namespace galpha::testing
