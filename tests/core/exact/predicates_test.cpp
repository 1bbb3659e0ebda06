// Tests of core/exact/expansion.hpp and core/exact/predicates.hpp against exact rational arithmetic (GMP).
//
// Every predicate is compared with the sign computed in mpq_class (doubles convert to mpq exactly)
// on families of adversarial inputs, inside the coordinate range the header guarantees. The SoS
// predicates are checked against an independent brute force: the perturbed determinant expanded
// symbolically as a polynomial in eps with rational coefficients.
#include "core/exact/predicates.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/exact/expansion.hpp"

namespace galpha {
namespace {

using Q = mpq_class;
using Rng = std::mt19937_64;
using Tri = std::array<Point2, 3>;
using Quad = std::array<Point2, 4>;

Q Exact(double v) { return Q(v); }  // mpq_set_d: exact for every finite double

Q Value(int n, const double* e) {
  Q sum = 0;
  for (int i = 0; i < n; ++i) sum += Exact(e[i]);
  return sum;
}

bool IsPowerOfTwo(const mpz_class& z) { return z > 0 && mpz_popcount(z.get_mpz_t()) == 1; }

// The exponent of the lowest set bit and of the highest set bit of a nonzero double.
int LowBit(double v) {
  int e;
  const double f = std::frexp(std::fabs(v), &e);
  auto m = static_cast<uint64_t>(std::ldexp(f, 53));
  return e - 53 + __builtin_ctzll(m);
}
int HighBit(double v) { return std::ilogb(v); }

// Sorted by increasing magnitude, nonzero, nonoverlapping (Shewchuk's definition).
::testing::AssertionResult WellFormed(int n, const double* e) {
  for (int i = 0; i < n; ++i) {
    if (e[i] == 0.0 || !std::isfinite(e[i])) return ::testing::AssertionFailure() << "component " << i;
    if (i > 0 && HighBit(e[i - 1]) >= LowBit(e[i])) {
      return ::testing::AssertionFailure() << "components " << i - 1 << " and " << i << " overlap";
    }
  }
  return ::testing::AssertionSuccess();
}

Q Det(const Tri& t) {
  const Point2 a = t[0], b = t[1], c = t[2];
  return (Exact(b.x) - Exact(a.x)) * (Exact(c.y) - Exact(a.y)) - (Exact(b.y) - Exact(a.y)) * (Exact(c.x) - Exact(a.x));
}

Q Det(const Quad& q) {
  const Point2 a = q[0], b = q[1], c = q[2], d = q[3];
  const Q adx = Exact(a.x) - Exact(d.x), ady = Exact(a.y) - Exact(d.y);
  const Q bdx = Exact(b.x) - Exact(d.x), bdy = Exact(b.y) - Exact(d.y);
  const Q cdx = Exact(c.x) - Exact(d.x), cdy = Exact(c.y) - Exact(d.y);
  return (adx * adx + ady * ady) * (bdx * cdy - cdx * bdy) + (bdx * bdx + bdy * bdy) * (cdx * ady - adx * cdy) +
         (cdx * cdx + cdy * cdy) * (adx * bdy - bdx * ady);
}

// The predicates under test, by arity.
int Sign(const Tri& t) { return Orient2dSign(t[0], t[1], t[2]); }
int Sign(const Quad& q) { return InCircleSign(q[0], q[1], q[2], q[3]); }
double Approx(const Tri& t) { return Orient2dApprox(t[0], t[1], t[2]); }
double Approx(const Quad& q) { return InCircleApprox(q[0], q[1], q[2], q[3]); }
int Expansion(const Tri& t, double* e) { return exact::Orient2dExpansion(t[0], t[1], t[2], e); }
int Expansion(const Quad& q, double* e) { return exact::InCircleExpansion(q[0], q[1], q[2], q[3], e); }

template <size_t n>
std::string Show(const std::array<Point2, n>& p) {
  std::ostringstream os;
  os << std::hexfloat;
  for (const Point2& q : p) os << "(" << q.x << ", " << q.y << ") ";
  return os.str();
}

// The value of an exact-stage expansion must be the determinant times a positive power of two.
::testing::AssertionResult ScaledCopy(const Q& value, const Q& det) {
  if (det == 0 && value == 0) return ::testing::AssertionSuccess();
  const Q ratio = det == 0 ? Q(0) : Q(value / det);
  if (ratio > 0 && IsPowerOfTwo(ratio.get_num()) && IsPowerOfTwo(ratio.get_den())) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "expansion " << value.get_d() << ", det " << det.get_d();
}

// ---- Primitives ---------------------------------------------------------------------------------

double RandomDouble(Rng& rng, int emin, int emax) {
  std::uniform_real_distribution<double> mant(1.0, 2.0);
  std::uniform_int_distribution<int> ex(emin, emax);
  const double v = std::ldexp(mant(rng), ex(rng));
  return (rng() & 1) ? v : -v;
}

TEST(Expansion, ErrorFreeTransformations) {
  // (1 + 2^-30)^2 = 1 + 2^-29 + 2^-60: the tail 2^-60 must come back exactly.
  double x, y;
  exact::TwoProduct(1.0 + 0x1p-30, 1.0 + 0x1p-30, x, y);
  EXPECT_EQ(x, 1.0 + 0x1p-29);
  EXPECT_EQ(y, 0x1p-60);
  Rng rng(1);
  for (int i = 0; i < 20000; ++i) {
    double a = RandomDouble(rng, -1074, 1000), b = RandomDouble(rng, -1074, 1000);
    exact::TwoSum(a, b, x, y);
    EXPECT_EQ(Exact(x) + Exact(y), Exact(a) + Exact(b));
    EXPECT_EQ(x, a + b);
    exact::TwoDiff(a, b, x, y);
    EXPECT_EQ(Exact(x) + Exact(y), Exact(a) - Exact(b));
    if (std::fabs(a) >= std::fabs(b)) {
      exact::FastTwoSum(a, b, x, y);
      EXPECT_EQ(Exact(x) + Exact(y), Exact(a) + Exact(b));
    }
    // Two-Product is exact while exponent(a) + exponent(b) >= -970 and fl(a * b) is finite.
    a = RandomDouble(rng, -480, 480);
    b = RandomDouble(rng, -480, 480);
    exact::TwoProduct(a, b, x, y);
    EXPECT_EQ(x, a * b);
    EXPECT_EQ(Exact(x) + Exact(y), Exact(a) * Exact(b));
    // At the edges of that range: a tail as small as it gets (exponent sum -970), and factors
    // beyond 2^996, where Dekker's split product (used before the fused one) overflowed.
    const int low = -970 + static_cast<int>(rng() % 100);
    a = RandomDouble(rng, -500, -400);
    b = std::ldexp(1.0 + std::ldexp(static_cast<double>(rng() % (uint64_t{1} << 52)), -52), low - std::ilogb(a));
    exact::TwoProduct(a, b, x, y);
    EXPECT_EQ(Exact(x) + Exact(y), Exact(a) * Exact(b));
    a = RandomDouble(rng, 996, 1010);
    b = RandomDouble(rng, -100, 0);
    exact::TwoProduct(a, b, x, y);
    EXPECT_EQ(Exact(x) + Exact(y), Exact(a) * Exact(b));
  }
}

TEST(Expansion, SumScaleProductAreExact) {
  Rng rng(3);
  for (int iter = 0; iter < 3000; ++iter) {
    double e[16], f[8], h[24];
    int el = 0, fl = 0;  // grow random values into expansions (in place, which is allowed)
    for (int i = 0; i < 8; ++i) el = exact::GrowExpansionZeroElim(el, e, RandomDouble(rng, -200, 200), e);
    for (int i = 0; i < 4; ++i) fl = exact::GrowExpansionZeroElim(fl, f, RandomDouble(rng, -200, 200), f);
    ASSERT_TRUE(WellFormed(el, e));
    ASSERT_TRUE(WellFormed(fl, f));
    const Q ev = Value(el, e), fv = Value(fl, f);
    int n = exact::ExpansionSumZeroElim(el, e, fl, f, h);
    EXPECT_EQ(Value(n, h), ev + fv);
    EXPECT_TRUE(WellFormed(n, h));
    n = exact::ExpansionDiffZeroElim(el, e, fl, f, h);
    EXPECT_EQ(Value(n, h), ev - fv);
    EXPECT_EQ(exact::ExpansionSign(n, h), sgn(ev - fv));
    EXPECT_EQ(exact::ExpansionDiffZeroElim(el, e, el, e, h), 0);
    const double b = RandomDouble(rng, -200, 200);
    n = exact::ScaleExpansionZeroElim(el, e, b, h);
    EXPECT_EQ(Value(n, h), ev * Exact(b));
    EXPECT_TRUE(WellFormed(n, h));
    double p[2 * 8 * 4];
    n = exact::ExpansionProduct<8, 4>(el, e, fl, f, p);
    EXPECT_EQ(Value(n, p), ev * fv);
    EXPECT_TRUE(WellFormed(n, p));
    n = exact::ExpansionProduct<4, 8>(fl, f, el, e, p);
    EXPECT_EQ(Value(n, p), ev * fv);
    EXPECT_NEAR(exact::Estimate(el, e), ev.get_d(), std::fabs(ev.get_d()) * 1e-15);
  }
}

TEST(Expansion, PowerOfTwoHelpers) {
  EXPECT_EQ(exact::Pow2(0), 1.0);
  EXPECT_EQ(exact::Pow2(-1022), 0x1p-1022);
  EXPECT_EQ(exact::Pow2(1023), 0x1p1023);
  EXPECT_EQ(exact::ExponentOf(1.0), 0);
  EXPECT_EQ(exact::ExponentOf(-3.5), 1);
  EXPECT_EQ(exact::ExponentOf(0x1p-1074), -1022);
  EXPECT_EQ(exact::ScaleByPow2(0x1p-1074, 1500), 0x1p426);
  EXPECT_EQ(exact::ScaleByPow2(3.0, -500), 3 * 0x1p-500);
}

// ---- Adversarial families -----------------------------------------------------------------------

struct Gen {
  Rng rng;
  explicit Gen(uint64_t seed) : rng(seed) {}
  double U(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  int I(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); }
  double Nudge(double v, int max_ulps) {  // move v by up to max_ulps ulps
    for (int k = I(-max_ulps, max_ulps); k != 0; k += (k > 0 ? -1 : 1)) {
      v = std::nextafter(v, k > 0 ? INFINITY : -INFINITY);
    }
    return v;
  }
  Point2 NudgeP(Point2 p, int max_ulps) { return {Nudge(p.x, max_ulps), Nudge(p.y, max_ulps)}; }
  double Mixed(int emin, int emax) { return RandomDouble(rng, emin, emax); }
};

// Lattice points on circles centred at 0 (x^2 + y^2 = r^2 has many integer solutions for these r).
const std::vector<Point2>& LatticeCircle(int which) {
  static const std::vector<std::vector<Point2>> circles = [] {
    std::vector<std::vector<Point2>> out;
    for (int r : {5, 25, 65, 85, 325, 1105}) {
      std::vector<Point2> pts;
      for (int x = -r; x <= r; ++x) {
        const auto y = static_cast<int>(std::lround(std::sqrt(double(r) * r - double(x) * x)));
        if (x * x + y * y == r * r) {
          pts.push_back({double(x), double(y)});
          if (y != 0) pts.push_back({double(x), double(-y)});
        }
      }
      out.push_back(pts);
    }
    return out;
  }();
  return circles[which % circles.size()];
}

// A coordinate at one end of [2^lo, 2^hi) or anywhere in it, full 53-bit significand or short.
double EdgeCoordinate(Gen& g, int lo, int hi) {
  const int pick = g.I(0, 3);
  if (pick == 2) return std::ldexp(std::floor(std::ldexp(g.Mixed(hi, hi), 10 - hi)), hi - 10);
  return pick == 0 ? g.Mixed(lo, lo) : pick == 1 ? g.Mixed(hi, hi) : g.Mixed(lo, hi);
}

// Whether every nonzero coordinate lies in [lo, hi) in magnitude.
template <size_t n>
bool InBand(const std::array<Point2, n>& p, double lo, double hi) {
  for (const auto& q : p) {
    for (double v : {q.x, q.y}) {
      if (v != 0 && (std::fabs(v) < lo || std::fabs(v) >= hi)) return false;
    }
  }
  return true;
}

// Points with coordinates spread over the whole guaranteed range; p2 often shares a coordinate
// with p0 and a rounded offset with p1 so that the determinant is small or zero.
template <size_t n>
std::array<Point2, n> RangeEdge(Gen& g, int lo, int hi) {
  std::array<Point2, n> p;
  for (auto& q : p) q = {EdgeCoordinate(g, lo, hi), EdgeCoordinate(g, lo, hi)};
  if (g.I(0, 1)) p[2] = {p[0].x + (p[1].x - p[0].x), p[0].y};
  return p;
}

Point2 Scale2(Point2 p, int k) { return {std::ldexp(p.x, k), std::ldexp(p.y, k)}; }
Point2 Shift(Point2 p, double dx, double dy) { return {p.x + dx, p.y + dy}; }

// Near-collinear triple in a unit-ish frame: c on the line ab up to rounding, then a few ulps off.
Tri NearCollinear(Gen& g, int ulps) {
  const Point2 a{g.U(-1, 1), g.U(-1, 1)}, b{g.U(-1, 1), g.U(-1, 1)};
  const double t = g.U(-2, 3);
  return {a, b, g.NudgeP({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)}, ulps)};
}

Tri ExactCollinear(Gen& g) {
  const Point2 a{double(g.I(-1000, 1000)), double(g.I(-1000, 1000))};
  const Point2 d{double(g.I(-50, 50)), double(g.I(-50, 50))};
  const double m = g.I(-100, 100), n = g.I(-100, 100);
  return {a, {a.x + m * d.x, a.y + m * d.y}, {a.x + n * d.x, a.y + n * d.y}};
}

Quad Cocircular(Gen& g) {
  const auto& c = LatticeCircle(g.I(0, 5));
  Quad q;
  for (auto& p : q) p = c[g.I(0, int(c.size()) - 1)];
  return q;
}

Quad NearCircle(Gen& g, double cx, double cy, double r, int ulps) {
  Quad q;
  for (auto& p : q) {
    const double t = g.U(0, 6.283185307179586);
    p = g.NudgeP({cx + r * std::cos(t), cy + r * std::sin(t)}, ulps);
  }
  return q;
}

std::vector<Tri> OrientCases(const std::string& kind, int n, uint64_t seed) {
  Gen g(seed);
  std::vector<Tri> out;
  while (int(out.size()) < n) {
    Tri t;
    const bool alt = g.I(0, 1) == 1;
    if (kind == "random") {
      t = {Point2{g.U(-1, 1), g.U(-1, 1)}, {g.U(-1, 1), g.U(-1, 1)}, {g.U(-1, 1), g.U(-1, 1)}};
    } else if (kind == "near_collinear") {
      t = NearCollinear(g, 3);
      const int k = g.I(-20, 20);
      for (auto& p : t) p = Scale2(p, k);
    } else if (kind == "collinear") {
      t = ExactCollinear(g);
      const int k = g.I(-40, 40);
      for (auto& p : t) p = Scale2(p, k);
      if (alt) t[2] = g.NudgeP(t[2], 1);
    } else if (kind == "grid") {
      for (auto& p : t) p = {double(g.I(-4, 4)), double(g.I(-4, 4))};
    } else if (kind == "offset1e9" || kind == "offset1e15") {
      const double base = kind == "offset1e9" ? 1e9 : 1e15, spacing = alt ? 1.0 : 1e-3;
      const double ox = base + g.I(0, 1000), oy = g.I(0, 1) ? base : -base;
      t = alt ? ExactCollinear(g) : NearCollinear(g, 2);
      for (auto& p : t) p = g.NudgeP(Shift({p.x * spacing, p.y * spacing}, ox, oy), 1);
    } else if (kind == "tiny") {
      t = alt ? ExactCollinear(g) : NearCollinear(g, 2);
      for (auto& p : t) p = alt ? Scale2(p, -1000) : Point2{p.x * 1e-300, p.y * 1e-300};
    } else if (kind == "subnormal") {  // multiples of 2^-1074 (4.9e-324)
      t = ExactCollinear(g);
      for (auto& p : t) p = Scale2(alt ? p : Point2{double(g.I(-50, 50)), double(g.I(-9, 9))}, -1074);
    } else if (kind == "mixed") {  // magnitudes 2^-420 .. 2^501: H / m < 2^930
      if (alt) {
        for (auto& p : t) p = {g.Mixed(-420, 499), g.Mixed(-420, 499)};
      } else {
        const Point2 a{g.Mixed(-420, 499), g.Mixed(-420, 499)}, b{g.Mixed(-420, 499), g.Mixed(-420, 499)};
        const double s = g.U(-2, 3);
        t = {a, b, g.NudgeP({a.x + s * (b.x - a.x), a.y + s * (b.y - a.y)}, 1)};
      }
      if (!InBand(t, 0x1p-420, 0x1p501)) continue;
    } else if (kind == "range_edge") {  // H / m' < 2^930 at both ends of the double range
      t = g.I(0, 1) ? RangeEdge<3>(g, -420, 500) : RangeEdge<3>(g, -1074, -93);
    } else if (kind == "huge") {  // up to ~2^1011 (< 2^1022)
      t = alt ? ExactCollinear(g) : NearCollinear(g, 2);
      for (auto& p : t) p = alt ? Scale2(p, 1000) : Scale2(p, 1010);
      if (g.I(0, 3) == 0) {
        for (auto& p : t) p = {g.U(-1e307, 1e307), g.U(-1e307, 1e307)};
      }
    } else {
      ADD_FAILURE() << "unknown family " << kind;
      return out;
    }
    std::shuffle(t.begin(), t.end(), g.rng);
    out.push_back(t);
  }
  return out;
}

std::vector<Quad> InCircleCases(const std::string& kind, int n, uint64_t seed) {
  Gen g(seed);
  std::vector<Quad> out;
  while (int(out.size()) < n) {
    Quad q;
    const bool alt = g.I(0, 1) == 1;
    if (kind == "random") {
      for (auto& p : q) p = {g.U(-1, 1), g.U(-1, 1)};
    } else if (kind == "cocircular") {
      q = Cocircular(g);
      const int k = g.I(-40, 40);
      const double dx = g.I(-1000, 1000), dy = g.I(-1000, 1000);
      for (auto& p : q) p = Scale2(Shift(p, dx, dy), k);
      if (g.I(0, 3) == 0) q[3] = g.NudgeP(q[3], 1);
    } else if (kind == "collinear") {  // on one line, often an axis-parallel one
      const Tri t = ExactCollinear(g);
      const Point2 d = g.I(0, 2) == 0 ? Point2{0, 1}
                       : g.I(0, 1)    ? Point2{1, 0}
                                      : Point2{t[1].x - t[0].x, t[1].y - t[0].y};
      for (auto& p : q) {
        const double k = g.I(-3, 3);
        p = Shift(t[0], k * d.x, k * d.y);
      }
      if (alt) q[3] = {t[0].x + g.I(-2, 2), t[0].y + g.I(-2, 2)};
    } else if (kind == "near_circle") {
      q = NearCircle(g, g.U(-10, 10), g.U(-10, 10), g.U(0.1, 10), 2);
    } else if (kind == "grid") {
      for (auto& p : q) p = {double(g.I(-3, 3)), double(g.I(-3, 3))};
    } else if (kind == "offset1e9" || kind == "offset1e15") {
      const double base = kind == "offset1e9" ? 1e9 : 1e15;
      const double ox = base + g.I(0, 1000), oy = g.I(0, 1) ? base : -base + g.I(0, 1000);
      q = alt ? Cocircular(g) : NearCircle(g, 0, 0, g.U(1, 100), 0);
      for (auto& p : q) p = g.NudgeP(Shift(p, ox, oy), g.I(0, 2) == 0 ? 1 : 0);
    } else if (kind == "tiny") {
      q = alt ? Cocircular(g) : NearCircle(g, g.U(-3, 3), g.U(-3, 3), g.U(0.5, 5), 1);
      for (auto& p : q) p = alt ? Scale2(p, -1000) : Point2{p.x * 1e-300, p.y * 1e-300};
    } else if (kind == "subnormal") {
      q = Cocircular(g);
      const int k = g.I(0, 1) ? -1074 : -1063;
      for (auto& p : q) p = Scale2(alt ? p : Point2{double(g.I(-20, 20)), double(g.I(-20, 20))}, k);
    } else if (kind == "mixed") {  // magnitudes 2^-215 .. 2^220: H / m < 2^437
      if (alt) {
        for (auto& p : q) p = {g.Mixed(-215, 219), g.Mixed(-215, 219)};
      } else {
        const int k = g.I(-200, 200);
        q = NearCircle(g, g.Mixed(-215, 219), g.Mixed(-215, 219), std::ldexp(g.U(1, 2), k), 1);
      }
      if (!InBand(q, 0x1p-215, 0x1p220)) continue;
    } else if (kind == "range_edge") {  // H / m' < 2^437 at both ends of the double range
      q = g.I(0, 1) ? RangeEdge<4>(g, -215, 219) : RangeEdge<4>(g, -1074, -585);
    } else if (kind == "huge") {
      q = alt ? Cocircular(g) : NearCircle(g, g.U(-3, 3), g.U(-3, 3), g.U(0.5, 5), 1);
      for (auto& p : q) p = Scale2(p, alt ? 1000 : 1015);
    } else {
      ADD_FAILURE() << "unknown family " << kind;
      return out;
    }
    std::shuffle(q.begin(), q.end(), g.rng);
    out.push_back(q);
  }
  return out;
}

const char* const kOrientFamilies[] = {"random", "near_collinear", "collinear", "grid",       "offset1e9", "offset1e15",
                                       "tiny",   "subnormal",      "mixed",     "range_edge", "huge"};
const char* const kInCircleFamilies[] = {"random",    "cocircular", "collinear",  "near_circle",
                                         "grid",      "offset1e9",  "offset1e15", "tiny",
                                         "subnormal", "mixed",      "range_edge", "huge"};

class OrientFamily : public ::testing::TestWithParam<const char*> {};
class InCircleFamily : public ::testing::TestWithParam<const char*> {};

// Each case: the sign equals GMP's, the exact expansion is well formed and equals the determinant
// up to a power of two, and cyclic / transposed argument orders give the same / opposite sign.
template <size_t n>
void CheckAgainstGmp(const std::vector<std::array<Point2, n>>& cases) {
  int zeros = 0, approx_wrong = 0;
  for (const auto& p : cases) {
    const Q det = Det(p);
    ASSERT_EQ(Sign(p), sgn(det)) << Show(p);
    double e[exact::kInCircleExpansionCapacity];
    const int len = Expansion(p, e);
    ASSERT_TRUE(WellFormed(len, e)) << Show(p);
    ASSERT_TRUE(ScaledCopy(Value(len, e), det)) << Show(p);
    auto rotated = p, swapped = p;
    std::rotate(rotated.begin(), rotated.begin() + 1, rotated.begin() + 3);
    std::swap(swapped[0], swapped[1]);
    EXPECT_EQ(Sign(rotated), sgn(det));
    EXPECT_EQ(Sign(swapped), -sgn(det));
    zeros += det == 0;
    approx_wrong += (Approx(p) > 0) - (Approx(p) < 0) != sgn(det);
  }
  ::testing::Test::RecordProperty("zeros", zeros);
  ::testing::Test::RecordProperty("approx_wrong", approx_wrong);
}

TEST_P(OrientFamily, MatchesGmp) { CheckAgainstGmp(OrientCases(GetParam(), 4000, 11)); }
TEST_P(InCircleFamily, MatchesGmp) { CheckAgainstGmp(InCircleCases(GetParam(), 3000, 12)); }

// The orientation's path after the filter (plain doubles where every operation is exact, else the
// expansion), alone, on every family: GMP's sign everywhere. The collinear and grid families are
// exact zeros in small integers, which the plain-double path decides; tiny, subnormal and huge
// ones lie outside its range and go to the expansion.
TEST_P(OrientFamily, PathBeyondTheFilterMatchesGmp) {
  int zeros = 0;
  for (const Tri& t : OrientCases(GetParam(), 4000, 17)) {
    const int exact_sign = sgn(Det(t));
    ASSERT_EQ(pred_detail::Orient2dSignBeyondFilter(t[0], t[1], t[2]), exact_sign) << Show(t);
    zeros += exact_sign == 0;
  }
  ::testing::Test::RecordProperty("zeros", zeros);
}

// Collinear points with integer coordinates (the lines of two_lines and parallel_lines) are exact
// zeros that the plain-double path proves; near them, one ulp off the line, the sign is GMP's; and
// a triple whose differences reach below 2^-480 (where a zero tail could hide an underflow) is
// still right, through the expansion.
TEST(Predicates, OrientationPathBeyondTheFilterOnLines) {
  for (int64_t v = -1000; v <= 1000; v += 7) {
    const Point2 a{3.0 * v, 2.0 * v + 5}, b{3.0 * (v + 11), 2.0 * (v + 11) + 5}, c{3.0 * (v - 29), 2.0 * (v - 29) + 5};
    EXPECT_EQ(pred_detail::Orient2dSignBeyondFilter(a, b, c), 0);
    const Point2 off{c.x, std::nextafter(c.y, 1e300)};
    EXPECT_EQ(pred_detail::Orient2dSignBeyondFilter(a, b, off), sgn(Det(Tri{a, b, off})));
  }
  const Tri tiny = {Point2{0, 0}, Point2{0x1p-490, 0x1p-491}, Point2{0x1p-489, 0x1p-490}};
  EXPECT_EQ(pred_detail::Orient2dSignBeyondFilter(tiny[0], tiny[1], tiny[2]), sgn(Det(tiny)));
  const Tri tiny_off = {Point2{0, 0}, Point2{0x1p-490, 0x1p-491}, Point2{0x1p-489, 0x1.0000000000001p-490}};
  ASSERT_NE(sgn(Det(tiny_off)), 0);
  EXPECT_EQ(pred_detail::Orient2dSignBeyondFilter(tiny_off[0], tiny_off[1], tiny_off[2]), sgn(Det(tiny_off)));
}

std::string FamilyName(const ::testing::TestParamInfo<const char*>& info) { return info.param; }
INSTANTIATE_TEST_SUITE_P(All, OrientFamily, ::testing::ValuesIn(kOrientFamilies), FamilyName);
INSTANTIATE_TEST_SUITE_P(All, InCircleFamily, ::testing::ValuesIn(kInCircleFamilies), FamilyName);

// The stages after the filters, each alone, on every family: the double-double stage wherever it
// decides (never on an exact zero), the expansion of exact differences wherever the differences
// are doubles, and the whole path after the filters (InCircleSignBeyondFilters) everywhere, all
// with GMP's sign.
TEST_P(InCircleFamily, StagesBeyondTheFiltersMatchGmp) {
  int double_double = 0, differences_expansion = 0;
  for (const Quad& q : InCircleCases(GetParam(), 3000, 13)) {
    const int exact_sign = sgn(Det(q));
    ASSERT_EQ(pred_detail::InCircleSignBeyondFilters(q[0], q[1], q[2], q[3]), exact_sign) << Show(q);
    exact::DoubleDouble x[3], y[3];
    bool exact_differences = false;
    if (!pred_detail::ScaledDifferencesToD(q[0], q[1], q[2], q[3], x, y, &exact_differences)) continue;
    int sign = 2;
    if (pred_detail::InCircleSignFromDoubleDouble(x, y, &sign)) {
      ++double_double;
      ASSERT_NE(exact_sign, 0) << Show(q);
      ASSERT_EQ(sign, exact_sign) << Show(q);
    }
    if (exact_differences) {
      ++differences_expansion;
      ASSERT_EQ(pred_detail::InCircleSignOfDifferencesExpansion(x[0].hi, x[1].hi, x[2].hi, y[0].hi, y[1].hi, y[2].hi),
                exact_sign)
          << Show(q);
    }
  }
  ::testing::Test::RecordProperty("double_double", double_double);
  ::testing::Test::RecordProperty("differences_expansion", differences_expansion);
}

// Near-co-circular points miss the plain filter by a few binary orders: the double-double stage
// decides every nonzero one, with exact differences (points within a factor 2 of each other) and
// without (around the origin, where differences round and carry tails). It declines exact zeros
// and determinants far below its error bound, which the expansions then decide; and the scaling
// refuses parts it cannot put on its grid.
TEST(Predicates, DoubleDoubleStageDecidesNearMissesAndDeclinesZerosAndExtremes) {
  Gen g(14);
  int missed_filter = 0, with_tails = 0;
  for (int i = 0; i < 4000; ++i) {
    // Around (12, 12) with radius 1 every coordinate is within a factor 2 of every other (exact
    // differences); around the origin they are not.
    const bool centred = i % 2 == 0;
    const Quad q = centred ? NearCircle(g, 0, 0, 1, 2) : NearCircle(g, 12, 12, 1, 2);
    const int exact_sign = sgn(Det(q));
    exact::DoubleDouble x[3], y[3];
    bool exact_differences = false;
    ASSERT_TRUE(pred_detail::ScaledDifferencesToD(q[0], q[1], q[2], q[3], x, y, &exact_differences)) << Show(q);
    if (!centred) {
      ASSERT_TRUE(exact_differences) << Show(q);
    }
    with_tails += !exact_differences;
    int sign = 2;
    const bool decided = pred_detail::InCircleSignFromDoubleDouble(x, y, &sign);
    EXPECT_EQ(decided, exact_sign != 0) << Show(q);
    if (decided) {
      EXPECT_EQ(sign, exact_sign) << Show(q);
    }
    EXPECT_EQ(InCircleSign(q[0], q[1], q[2], q[3]), exact_sign) << Show(q);
    const double approx = InCircleApprox(q[0], q[1], q[2], q[3]);
    missed_filter += (approx > 0) - (approx < 0) != exact_sign;
  }
  // Some were wrong in plain doubles (beyond what the filter decides); most centred ones had tails.
  EXPECT_GT(missed_filter, 0);
  EXPECT_GT(with_tails, 1000);

  exact::DoubleDouble x[3], y[3];
  bool exact_differences = false;
  int sign = 2;
  // Exactly co-circular (a rectangle of doubles in [1, 2), whose differences are exact): declined;
  // the differences' expansion finds zero.
  const double x0 = 1.2345678901, x1 = 1.9876543210, y0 = 1.1111111, y1 = 1.7777777;
  const Quad rectangle = {Point2{x0, y0}, Point2{x1, y0}, Point2{x1, y1}, Point2{x0, y1}};
  ASSERT_TRUE(pred_detail::ScaledDifferencesToD(rectangle[0], rectangle[1], rectangle[2], rectangle[3], x, y,
                                                &exact_differences));
  EXPECT_TRUE(exact_differences);
  EXPECT_FALSE(pred_detail::InCircleSignFromDoubleDouble(x, y, &sign));
  EXPECT_EQ(pred_detail::InCircleSignOfDifferencesExpansion(x[0].hi, x[1].hi, x[2].hi, y[0].hi, y[1].hi, y[2].hi), 0);
  EXPECT_EQ(InCircleSign(rectangle[0], rectangle[1], rectangle[2], rectangle[3]), 0);
  // Exactly co-circular with rounded differences (the same rectangle around the origin): declined;
  // the raw-coordinate expansion finds zero.
  const Quad centred = {Point2{-0.7, -0.3}, Point2{0.9, -0.3}, Point2{0.9, 0.6}, Point2{-0.7, 0.6}};
  ASSERT_TRUE(
      pred_detail::ScaledDifferencesToD(centred[0], centred[1], centred[2], centred[3], x, y, &exact_differences));
  EXPECT_FALSE(exact_differences);
  EXPECT_FALSE(pred_detail::InCircleSignFromDoubleDouble(x, y, &sign));
  EXPECT_EQ(pred_detail::InCircleSignBeyondFilters(centred[0], centred[1], centred[2], centred[3]), 0);
  // A rectangle of side 2^120 with one corner moved by 2^-80: the determinant is about 2^-200 of
  // the permanent, below the double-double bound, and not zero: declined there, decided by the
  // differences' expansion with GMP's sign.
  const Quad extreme = {Point2{0x1p120, 0}, Point2{0x1p120, 0x1p120}, Point2{0x1p-80, 0x1p120}, Point2{0, 0}};
  ASSERT_NE(sgn(Det(extreme)), 0);
  ASSERT_TRUE(
      pred_detail::ScaledDifferencesToD(extreme[0], extreme[1], extreme[2], extreme[3], x, y, &exact_differences));
  EXPECT_FALSE(pred_detail::InCircleSignFromDoubleDouble(x, y, &sign));
  EXPECT_EQ(pred_detail::InCircleSignBeyondFilters(extreme[0], extreme[1], extreme[2], extreme[3]), sgn(Det(extreme)));
  EXPECT_EQ(InCircleSign(extreme[0], extreme[1], extreme[2], extreme[3]), sgn(Det(extreme)));
  // Parts the grid cannot hold: differences spanning 2^10 .. 2^-200, and subnormal ones.
  EXPECT_FALSE(
      pred_detail::ScaledDifferencesToD({0x1p10, 0}, {0, 0x1p-200}, {-0x1p10, 0}, {0, 0}, x, y, &exact_differences));
  EXPECT_FALSE(pred_detail::ScaledDifferencesToD({0x1p-1060, 0}, {0, 0x1p-1060}, {0x1p-1070, 0}, {0, 0}, x, y,
                                                 &exact_differences));
  // All four points equal: zero differences, declined by the double-double stage, zero after it.
  ASSERT_TRUE(pred_detail::ScaledDifferencesToD({3, 4}, {3, 4}, {3, 4}, {3, 4}, x, y, &exact_differences));
  EXPECT_FALSE(pred_detail::InCircleSignFromDoubleDouble(x, y, &sign));
  EXPECT_EQ(pred_detail::InCircleSignBeyondFilters({3, 4}, {3, 4}, {3, 4}, {3, 4}), 0);
}

TEST(Predicates, ConventionsAndApproximations) {
  const Point2 a{0, 0}, b{1, 0}, c{0, 1};
  EXPECT_EQ(Orient2dSign(a, b, c), 1);
  EXPECT_EQ(Orient2dSign(a, c, b), -1);
  EXPECT_EQ(Orient2dSign(a, b, {2, 0}), 0);
  EXPECT_EQ(InCircleSign(a, b, c, {0.25, 0.25}), 1);
  EXPECT_EQ(InCircleSign(a, b, c, {2, 2}), -1);
  EXPECT_EQ(InCircleSign(a, b, c, {1, 1}), 0);
  EXPECT_EQ(InCircleSign(a, c, b, {0.25, 0.25}), -1);
  EXPECT_EQ(Orient2dApprox(a, b, c), 1.0);
  EXPECT_GT(InCircleApprox(a, b, c, {0.25, 0.25}), 0.0);
  EXPECT_EQ(InCircleSign(a, a, a, a), 0);
  EXPECT_EQ(Orient2dSign(a, a, a), 0);
}

TEST(Predicates, UnderflowCannotFoolTheFilter) {
  // Found by search: both products underflow to subnormals on either side of a rounding midpoint,
  // so a filter without the underflow gate (its error bound rounds to 0) would certify +1.
  const Point2 a{0x1.c089c0c4259dap-585, 0x1.b48ac652385aep-599};
  const Point2 b{0x1.a3a06f626e53cp-530, 0x1.68f160d91955cp-544};
  const Point2 c{0x1.105a747cc3b9p-530, 0x1.d487dd506ad4p-545};
  ASSERT_GT(Orient2dApprox(a, b, c), 0.0);
  ASSERT_EQ(sgn(Det(Tri{a, b, c})), -1);
  EXPECT_EQ(Orient2dSign(a, b, c), -1);
  EXPECT_EQ(Orient2dSign(b, c, a), -1);
}

// ---- Simulation of Simplicity -------------------------------------------------------------------

// Polynomials in eps: exponent -> rational coefficient.
using Poly = std::map<int64_t, Q>;

Poly Mul(const Poly& a, const Poly& b) {
  Poly r;
  for (const auto& [ea, ca] : a) {
    for (const auto& [eb, cb] : b) r[ea + eb] += ca * cb;
  }
  return r;
}

int LeadingSign(const Poly& p) {
  for (const auto& [e, c] : p) {
    if (c != 0) return sgn(c);
  }
  return 0;
}

// sign of the perturbed det of rows (1, x + d_x, y + d_y[, z + d_z]), where the point of rank r
// (1 = smallest index) moves by eps^(2^(3r - c)), c = 1 for x, 2 for y, 3 for z.
template <size_t n>
int BruteForceSoS(const std::array<Point2, n>& p, const std::array<uint32_t, n>& ids) {
  std::array<std::array<Poly, n>, n> m;
  for (size_t i = 0; i < n; ++i) {
    int rank = 1;
    for (size_t j = 0; j < n; ++j) rank += ids[j] < ids[i];
    const Q x = Exact(p[i].x), y = Exact(p[i].y);
    const Q coord[3] = {x, y, x * x + y * y};
    m[i][0] = Poly{{0, Q(1)}};
    for (size_t c = 1; c < n; ++c) {
      m[i][c][0] += coord[c - 1];
      m[i][c][int64_t(1) << (3 * rank - int(c))] += 1;
    }
  }
  std::array<size_t, n> perm;
  for (size_t i = 0; i < n; ++i) perm[i] = i;
  Poly det;
  do {
    int inversions = 0;
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = i + 1; j < n; ++j) inversions += perm[i] > perm[j];
    }
    Poly term{{0, Q(inversions % 2 ? -1 : 1)}};
    for (size_t i = 0; i < n; ++i) term = Mul(term, m[i][perm[i]]);
    for (const auto& [e, c] : term) det[e] += c;
  } while (std::next_permutation(perm.begin(), perm.end()));
  return LeadingSign(det);
}

int SoS(const Tri& t, const std::array<uint32_t, 3>& id) { return Orient2dSoS(t[0], id[0], t[1], id[1], t[2], id[2]); }
int SoS(const Quad& q, const std::array<uint32_t, 4>& id) {
  return InCircleSoS(q[0], id[0], q[1], id[1], q[2], id[2], q[3], id[3]);
}
int BruteForce(const Tri& t, const std::array<uint32_t, 3>& id) { return BruteForceSoS<3>(t, id); }
int BruteForce(const Quad& q, const std::array<uint32_t, 4>& id) { return -BruteForceSoS<4>(q, id); }

template <size_t n>
std::array<uint32_t, n> DistinctIds(Rng& rng) {
  std::array<uint32_t, n> id;
  for (size_t i = 0; i < n; ++i) {
    do {
      id[i] = (rng() & 3) == 0 ? uint32_t(rng() % 8) : uint32_t(rng());
    } while (std::find(id.begin(), id.begin() + i, id[i]) != id.begin() + i);
  }
  return id;
}

// Checks one configuration: never 0, equal to the brute force, equal to the plain sign when that
// is nonzero, and antisymmetric: value(perm) * parity(perm) is the same for every permutation.
template <size_t n>
void CheckSoS(const std::array<Point2, n>& p, const std::array<uint32_t, n>& id, int* degenerate) {
  const int s = SoS(p, id);
  ASSERT_NE(s, 0);
  ASSERT_EQ(s, BruteForce(p, id)) << Show(p);
  const int plain = Sign(p);
  if (plain != 0) {
    ASSERT_EQ(s, plain);
  }
  *degenerate += plain == 0;
  std::array<size_t, n> perm;
  for (size_t i = 0; i < n; ++i) perm[i] = i;
  do {
    std::array<Point2, n> pp;
    std::array<uint32_t, n> pid;
    int parity = 1;
    for (size_t i = 0; i < n; ++i) {
      pp[i] = p[perm[i]];
      pid[i] = id[perm[i]];
      for (size_t j = i + 1; j < n; ++j) parity *= perm[i] > perm[j] ? -1 : 1;
    }
    ASSERT_EQ(SoS(pp, pid) * parity, s);
  } while (std::next_permutation(perm.begin(), perm.end()));
}

TEST(SoS, OrientDegenerateMatchesBruteForce) {
  Gen g(21);
  int degenerate = 0;
  for (const char* kind : {"collinear", "grid", "subnormal", "offset1e15", "near_collinear", "random"}) {
    for (const Tri& t : OrientCases(kind, 600, 22)) {
      CheckSoS<3>(t, DistinctIds<3>(g.rng), &degenerate);
      if (HasFatalFailure()) return;
    }
  }
  EXPECT_GT(degenerate, 600);  // the families must actually exercise the perturbation
}

TEST(SoS, InCircleDegenerateMatchesBruteForce) {
  Gen g(23);
  int degenerate = 0;
  for (const char* kind : {"cocircular", "collinear", "grid", "subnormal", "offset1e15", "tiny", "near_circle"}) {
    for (const Quad& q : InCircleCases(kind, 400, 24)) {
      CheckSoS<4>(q, DistinctIds<4>(g.rng), &degenerate);
      if (HasFatalFailure()) return;
    }
  }
  EXPECT_GT(degenerate, 600);
}

TEST(SoS, CocircularDecidesConsistentlyUnderAllPermutations) {
  // Lifting sanity: four cocircular points (incircle exactly 0) get one perturbed answer, which
  // every ordering of the arguments reports with the sign of its permutation (checked inside).
  Gen g(25);
  int degenerate = 0;
  for (int i = 0; i < 500; ++i) {
    Quad q;
    const auto& c = LatticeCircle(i);
    std::vector<Point2> pts(c);
    std::shuffle(pts.begin(), pts.end(), g.rng);
    std::copy(pts.begin(), pts.begin() + 4, q.begin());
    for (auto& p : q) p = Shift(p, 1e9, -7);
    ASSERT_EQ(InCircleSign(q[0], q[1], q[2], q[3]), 0);
    CheckSoS<4>(q, DistinctIds<4>(g.rng), &degenerate);
    if (HasFatalFailure()) return;
  }
  EXPECT_EQ(degenerate, 500);
}

TEST(SoS, DuplicatePointsStillFollowThePerturbation) {
  // Callers promise distinct points; the full term sequence still gives the perturbed answer.
  Gen g(26);
  int degenerate = 0;
  for (int i = 0; i < 400; ++i) {
    Quad q;
    for (auto& p : q) p = {double(g.I(-2, 2)), double(g.I(-2, 2))};
    q[g.I(0, 3)] = q[g.I(0, 3)];
    if (i % 4 == 0) q[g.I(0, 3)] = q[g.I(0, 3)];
    CheckSoS<4>(q, DistinctIds<4>(g.rng), &degenerate);
    Tri t{q[0], q[1], q[2]};
    CheckSoS<3>(t, DistinctIds<3>(g.rng), &degenerate);
    if (HasFatalFailure()) return;
  }
  const Quad same{Point2{1, 1}, {1, 1}, {1, 1}, {1, 1}};
  CheckSoS<4>(same, {7, 3, 9, 1}, &degenerate);
  const Quad zero{Point2{0, 0}, {0, 0}, {0, 0}, {0, 0}};
  CheckSoS<4>(zero, {7, 3, 9, 1}, &degenerate);
}

}  // namespace
}  // namespace galpha
