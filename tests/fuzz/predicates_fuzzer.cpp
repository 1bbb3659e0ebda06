// libFuzzer target: the exact predicates on arbitrary finite doubles of every magnitude, against
// exact rationals (GMP). Four points per input; the input domain (core/io/input_validation.hpp)
// decides which sets the engine accepts, and an independent rational check must agree with it.
// Inside the domain every sign must equal the rational one: orientation, in-circle, the
// attachment test, and the Simulation-of-Simplicity variants (equal where the exact sign is
// nonzero, never 0, and antisymmetric under a swap of two points). Any disagreement aborts.
//
// The first byte picks how the following bytes become coordinates, so that the fuzzer reaches
// every part of the range and not only sets that the domain refuses:
//   0: raw 64-bit patterns (any finite double; most sets span too many magnitudes);
//   1: one shared binary exponent plus a signed 8-bit offset per coordinate (clustered
//      magnitudes, anywhere from subnormals to the top of the domain);
//   2: a base point plus perturbations of a few ulps (near-degenerate signs, exact zeros).
#include <gmpxx.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <utility>
#include <vector>

#include "core/exact/attachment.hpp"
#include "core/exact/predicates.hpp"
#include "core/io/input_validation.hpp"
#include "tests/support/input_domain_oracle.hpp"

namespace {

using galpha::Point2;

/// Reads bytes in order, zero past the end.
class ByteReader {
 public:
  ByteReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  uint64_t Take(int bytes) {
    uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v = (v << 8) | (pos_ < size_ ? data_[pos_++] : 0);
    return v;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

/// A finite double from 64 bits: infinities and NaNs lose their top exponent bit.
double FiniteFromBits(uint64_t bits) {
  double d;
  std::memcpy(&d, &bits, sizeof d);
  if (std::isfinite(d)) return d;
  bits &= ~(uint64_t{1} << 62);
  std::memcpy(&d, &bits, sizeof d);
  return d;
}

/// The domain, decided with rationals from its definition.
bool InDomain(const Point2* p, int n) { return galpha::testing::InInputDomain(p, static_cast<size_t>(n)); }

int Sign(const mpq_class& q) { return sgn(q); }

int OrientExact(Point2 a, Point2 b, Point2 c) {
  const mpq_class ax(a.x), ay(a.y), bx(b.x), by(b.y), cx(c.x), cy(c.y);
  return Sign((bx - ax) * (cy - ay) - (by - ay) * (cx - ax));
}

int InCircleExact(Point2 a, Point2 b, Point2 c, Point2 d) {
  const mpq_class adx = mpq_class(a.x) - d.x, ady = mpq_class(a.y) - d.y;
  const mpq_class bdx = mpq_class(b.x) - d.x, bdy = mpq_class(b.y) - d.y;
  const mpq_class cdx = mpq_class(c.x) - d.x, cdy = mpq_class(c.y) - d.y;
  const mpq_class al = adx * adx + ady * ady, bl = bdx * bdx + bdy * bdy, cl = cdx * cdx + cdy * cdy;
  return Sign(al * (bdx * cdy - cdx * bdy) + bl * (cdx * ady - adx * cdy) + cl * (adx * bdy - bdx * ady));
}

/// +1 inside the circle with diameter pq, as InDiametralCircleSign.
int DiametralExact(Point2 p, Point2 q, Point2 r) {
  const mpq_class dot =
      (mpq_class(p.x) - r.x) * (mpq_class(q.x) - r.x) + (mpq_class(p.y) - r.y) * (mpq_class(q.y) - r.y);
  return -Sign(dot);
}

void Check(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  ByteReader in(data + 1, size - 1);
  Point2 p[4];
  switch (data[0] % 3) {
    case 0:
      for (Point2& q : p) {
        q.x = FiniteFromBits(in.Take(8));
        q.y = FiniteFromBits(in.Take(8));
      }
      break;
    case 1: {
      const int base = static_cast<int>(in.Take(2) % 2100) - 1080;  // 2^-1080 .. 2^1019
      for (Point2& q : p) {
        for (double* c : {&q.x, &q.y}) {
          const int offset = static_cast<int8_t>(in.Take(1));
          const uint64_t mantissa = in.Take(7) & ((uint64_t{1} << 53) - 1);
          // (+-) mantissa * 2^(base + offset - 52): exact, or rounded into a subnormal.
          *c = std::ldexp(static_cast<double>(mantissa), base + offset - 52) * (in.Take(1) & 1 ? -1.0 : 1.0);
          if (!std::isfinite(*c)) *c = 0.0;
        }
      }
      break;
    }
    default: {
      const double bx = FiniteFromBits(in.Take(8)), by = FiniteFromBits(in.Take(8));
      for (Point2& q : p) {
        q = {bx, by};
        for (double* c : {&q.x, &q.y}) {
          const int steps = static_cast<int8_t>(in.Take(1)) % 8;
          for (int s = 0; s < (steps < 0 ? -steps : steps); ++s)
            *c = std::nextafter(*c, steps < 0 ? -INFINITY : INFINITY);
          if (!std::isfinite(*c)) *c = *c > 0 ? 1.0 : -1.0;
        }
      }
      break;
    }
  }

  const bool accepted = galpha::ValidatePoints(absl::Span<const Point2>(p, 4)).ok();
  Check(accepted == InDomain(p, 4));
  if (!accepted) return 0;

  using galpha::InCircleSign;
  using galpha::InCircleSoS;
  using galpha::InDiametralCircleSign;
  using galpha::Orient2dSign;
  using galpha::Orient2dSoS;
  const Point2 a = p[0], b = p[1], c = p[2], d = p[3];
  Check(Orient2dSign(a, b, c) == OrientExact(a, b, c));
  Check(Orient2dSign(b, c, d) == OrientExact(b, c, d));
  Check(InCircleSign(a, b, c, d) == InCircleExact(a, b, c, d));
  Check(InCircleSign(d, c, b, a) == InCircleExact(d, c, b, a));
  Check(InDiametralCircleSign(a, b, c) == DiametralExact(a, b, c));
  Check(InDiametralCircleSign(c, d, a) == DiametralExact(c, d, a));

  // SoS: the exact sign where it is nonzero; never 0; a swap of two points flips it. Indices are
  // distinct, as in the engine; the points may coincide.
  const int o = Orient2dSoS(a, 0, b, 1, c, 2);
  Check(o != 0);
  const int oe = OrientExact(a, b, c);
  Check(oe == 0 || o == oe);
  Check(Orient2dSoS(b, 1, a, 0, c, 2) == -o);
  const int ic = InCircleSoS(a, 0, b, 1, c, 2, d, 3);
  Check(ic != 0);
  const int ice = InCircleExact(a, b, c, d);
  Check(ice == 0 || ic == ice);
  Check(InCircleSoS(b, 1, a, 0, c, 2, d, 3) == -ic);
  return 0;
}
