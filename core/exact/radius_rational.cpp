#include "core/exact/radius_rational.hpp"

#include <cmath>
#include <limits>

namespace galpha {

std::optional<mpq_class> RadiusSqRational(const Point2* p, int n) {
  auto q = [](double v) { return mpq_class(v); };  // exact: every double is a dyadic rational
  if (n == 2) {
    const mpq_class dx = q(p[1].x) - q(p[0].x), dy = q(p[1].y) - q(p[0].y);
    return mpq_class((dx * dx + dy * dy) / 4);
  }
  const mpq_class abx = q(p[1].x) - q(p[0].x), aby = q(p[1].y) - q(p[0].y);
  const mpq_class acx = q(p[2].x) - q(p[0].x), acy = q(p[2].y) - q(p[0].y);
  const mpq_class bcx = q(p[2].x) - q(p[1].x), bcy = q(p[2].y) - q(p[1].y);
  const mpq_class area = abx * acy - aby * acx;
  if (sgn(area) == 0) return std::nullopt;
  const mpq_class num = (abx * abx + aby * aby) * (acx * acx + acy * acy) * (bcx * bcx + bcy * bcy);
  mpq_class value = num / (4 * area * area);
  value.canonicalize();
  return value;
}

int CompareRadiusSqRational(const Point2* a, int na, const Point2* b, int nb) {
  const std::optional<mpq_class> ra = RadiusSqRational(a, na), rb = RadiusSqRational(b, nb);
  if (!ra || !rb) return (ra ? 0 : 1) - (rb ? 0 : 1);
  return cmp(*ra, *rb) > 0 ? 1 : (cmp(*ra, *rb) < 0 ? -1 : 0);
}

double NearestDouble(const mpq_class& value) {
  if (sgn(value) == 0) return 0.0;
  if (sgn(value) < 0) return -NearestDouble(-value);
  // mpq_get_d truncates; the nearest double is then the truncation or the next one up: compare
  // the value with their midpoint exactly.
  const double down = value.get_d();
  if (std::isinf(down)) return down;
  const double up = std::nextafter(down, std::numeric_limits<double>::infinity());
  if (std::isinf(up)) {
    // Above the midpoint between DBL_MAX and 2^1024 rounds to infinity.
    mpq_class limit(std::numeric_limits<double>::max());
    mpq_class half_gap(std::ldexp(1.0, 970));
    return cmp(value, limit + half_gap) >= 0 ? up : down;
  }
  const mpq_class mid = (mpq_class(down) + mpq_class(up)) / 2;
  const int c = cmp(value, mid);
  if (c < 0) return down;
  if (c > 0) return up;
  uint64_t bits;
  __builtin_memcpy(&bits, &down, sizeof bits);
  return (bits & 1) == 0 ? down : up;
}

}  // namespace galpha
