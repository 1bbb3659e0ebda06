// Tests of core/exact/power.hpp against exact rational arithmetic (GMP): the power test and its
// Simulation of Simplicity (against the perturbed determinant expanded symbolically in eps), the
// collinear power test, and the tie rule shared with CGAL's weighted triangulation.
#include "core/exact/power.hpp"

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

#include "core/exact/predicates.hpp"

namespace galpha {
namespace {

using Q = mpq_class;
using Rng = std::mt19937_64;

struct WeightedPoint {
  Point2 p;
  double w;
};
using Quad = std::array<WeightedPoint, 4>;

Q Exact(double v) { return Q(v); }
Q Lift(const WeightedPoint& a) { return Exact(a.p.x) * Exact(a.p.x) + Exact(a.p.y) * Exact(a.p.y) - Exact(a.w); }

int Sgn(const Q& v) { return sgn(v); }

// -det4 [[1, x, y, z]]: positive when d's lift lies below the plane of the ccw a, b, c.
int ExactPowerSign(const Quad& q) {
  Q m[4][3];
  for (int i = 0; i < 4; ++i) {
    m[i][0] = Exact(q[i].p.x) - Exact(q[3].p.x);
    m[i][1] = Exact(q[i].p.y) - Exact(q[3].p.y);
    m[i][2] = Lift(q[i]) - Lift(q[3]);
  }
  const Q det = m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2]) - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2]) +
                m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2]);
  return Sgn(det);
}

int Power(const Quad& q) { return PowerSign(q[0].p, q[0].w, q[1].p, q[1].w, q[2].p, q[2].w, q[3].p, q[3].w); }

std::string Show(const Quad& q) {
  std::ostringstream out;
  out.precision(17);
  for (const auto& a : q) out << "(" << a.p.x << ", " << a.p.y << "; " << a.w << ") ";
  return out.str();
}

struct Gen {
  explicit Gen(uint64_t seed) : rng(seed) {}
  Rng rng;
  double U(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  int I(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); }
};

// Four points of the circle x^2 + y^2 = 25 on the integer lattice (shuffled), or of one of a few
// such circles, as weighted points whose weights make their power circle exactly that circle
// shifted: equal weights keep exact ties.
Quad LatticeTie(Gen& g) {
  std::vector<Point2> circle = {{5, 0},  {4, 3},   {3, 4},   {0, 5},  {-3, 4}, {-4, 3},
                                {-5, 0}, {-4, -3}, {-3, -4}, {0, -5}, {3, -4}, {4, -3}};
  std::shuffle(circle.begin(), circle.end(), g.rng);
  const double w = g.I(-30, 30);
  Quad q;
  for (int i = 0; i < 4; ++i) q[i] = {circle[i], w};
  return q;
}

// Families of weighted quadruples, in the supported range.
std::vector<Quad> Cases(const std::string& kind, int count, uint64_t seed) {
  Gen g(seed);
  std::vector<Quad> out;
  for (int i = 0; i < count; ++i) {
    Quad q;
    if (kind == "random") {
      for (auto& a : q) a = {{g.U(-1, 1), g.U(-1, 1)}, g.U(-0.5, 0.5)};
    } else if (kind == "grid") {  // small integers: many exact zeros
      for (auto& a : q) a = {{double(g.I(-3, 3)), double(g.I(-3, 3))}, double(g.I(-4, 4))};
    } else if (kind == "tie") {  // exact power ties, then single-ulp nudges of one weight
      q = LatticeTie(g);
      if (i % 2 == 1) {
        auto& a = q[g.I(0, 3)];
        a.w = std::nextafter(a.w, g.I(0, 1) ? 1e300 : -1e300);
      }
    } else if (kind == "offset1e9") {
      q = LatticeTie(g);
      for (auto& a : q) a.p = {a.p.x + 1e9, a.p.y - 7e8};
      if (i % 2 == 1) q[g.I(0, 3)].p.x = std::nextafter(q[g.I(0, 3)].p.x, 2e9);
    } else if (kind == "heavy") {  // weights far above the squared coordinates, and negative ones
      for (auto& a : q) a = {{g.U(-1, 1), g.U(-1, 1)}, g.U(-1e20, 1e20)};
      if (i % 3 == 0) q[3].w = q[g.I(0, 2)].w;
    } else if (kind == "tiny") {  // tiny coordinates with weights at the squared scale
      q = LatticeTie(g);
      for (auto& a : q) a = {{std::ldexp(a.p.x, -400), std::ldexp(a.p.y, -400)}, std::ldexp(a.w, -800)};
    } else if (kind == "near") {  // near ties in rounded doubles: the filter's error bound at work
      const double cx = g.U(-3, 3), cy = g.U(-3, 3), r = g.U(0.5, 2), w = g.U(-1, 1);
      for (auto& a : q) {
        const double t = g.U(0, 6.283185307179586);
        a = {{cx + r * std::cos(t), cy + r * std::sin(t)}, w + (g.I(0, 1) ? 0.0 : g.U(-1e-15, 1e-15))};
      }
    } else if (kind == "light") {  // weights far below the squared coordinates
      for (auto& a : q) a = {{double(g.I(-9, 9)), double(g.I(-9, 9))}, std::ldexp(g.U(-1, 1), -300)};
    }
    out.push_back(q);
  }
  return out;
}

TEST(PowerSign, MatchesGmp) {
  int zeros = 0;
  for (const char* kind : {"random", "grid", "tie", "near", "offset1e9", "heavy", "tiny", "light"}) {
    for (const Quad& q : Cases(kind, 3000, 31)) {
      const int exact = ExactPowerSign(q);
      ASSERT_EQ(Power(q), exact) << kind << ": " << Show(q);
      zeros += exact == 0;
    }
  }
  EXPECT_GT(zeros, 2000);  // the families must reach the exact stage's zeros
}

TEST(PowerSign, ExactStageMatchesGmpWhereTheFilterWouldDecide) {
  for (const char* kind : {"random", "near", "heavy", "light"}) {
    for (const Quad& q : Cases(kind, 1000, 32)) {
      const Point2 p[4] = {q[0].p, q[1].p, q[2].p, q[3].p};
      const double w[4] = {q[0].w, q[1].w, q[2].w, q[3].w};
      ASSERT_EQ(power_detail::PowerSignExact(p, w), ExactPowerSign(q)) << Show(q);
    }
  }
}

TEST(PowerSign, EqualsInCircleWithoutWeights) {
  Gen g(33);
  for (int i = 0; i < 5000; ++i) {
    Quad q;
    for (auto& a : q) a = {{double(g.I(-5, 5)) + (i % 2 ? g.U(-1e-9, 1e-9) : 0.0), double(g.I(-5, 5))}, 0.0};
    ASSERT_EQ(Power(q), InCircleSign(q[0].p, q[1].p, q[2].p, q[3].p)) << Show(q);
  }
}

TEST(PowerSign, AWeightRaisesOrLowersTheLift) {
  // The unit square's corners are cocircular: a tie. A heavier fourth point sinks below the plane
  // (in conflict), a lighter one rises above it (hidden).
  const Point2 a{0, 0}, b{1, 0}, c{1, 1}, d{0, 1};
  EXPECT_EQ(PowerSign(a, 0, b, 0, c, 0, d, 0), 0);
  EXPECT_EQ(PowerSign(a, 0, b, 0, c, 0, d, 0.5), 1);
  EXPECT_EQ(PowerSign(a, 0, b, 0, c, 0, d, -0.5), -1);
  // Equal weights change nothing: the plane moves with every lift.
  EXPECT_EQ(PowerSign(a, 3, b, 3, c, 3, d, 3), 0);
  // The centre of the triangle a, b, c with a weight large enough is in conflict; with none it
  // lies inside the circumcircle (conflict too); with a very negative one it is hidden.
  const Point2 m{0.6, 0.3};
  EXPECT_EQ(PowerSign(a, 0, b, 0, c, 0, m, 0), 1);
  EXPECT_EQ(PowerSign(a, 0, b, 0, c, 0, m, -1), -1);
}

// ---- Simulation of Simplicity ----

using Poly = std::map<int64_t, Q>;  // exponent of eps -> coefficient

Poly Mul(const Poly& a, const Poly& b) {
  Poly r;
  for (const auto& [ea, ca] : a) {
    for (const auto& [eb, cb] : b) r[ea + eb] += ca * cb;
  }
  return r;
}

// The perturbed det4 [[1, x + dx, y + dy, z + dz]] (the perturbation of predicates.hpp: the point of
// rank r, 1 = smallest, moves by eps^(2^(3r - c)), c = 1 for x, 2 for y, 3 for z), its sign the
// first nonzero coefficient; negated, as PowerSign is.
int BruteForcePowerSoS(const Quad& q, const std::array<uint32_t, 4>& ranks) {
  std::array<std::array<Poly, 4>, 4> m;
  for (size_t i = 0; i < 4; ++i) {
    int rank = 1;
    for (size_t j = 0; j < 4; ++j) rank += ranks[j] < ranks[i];
    const Q coord[3] = {Exact(q[i].p.x), Exact(q[i].p.y), Lift(q[i])};
    m[i][0] = Poly{{0, Q(1)}};
    for (size_t c = 1; c < 4; ++c) {
      m[i][c][0] += coord[c - 1];
      m[i][c][int64_t(1) << (3 * rank - int(c))] += 1;
    }
  }
  std::array<size_t, 4> perm = {0, 1, 2, 3};
  Poly det;
  do {
    int inversions = 0;
    for (size_t i = 0; i < 4; ++i) {
      for (size_t j = i + 1; j < 4; ++j) inversions += perm[i] > perm[j];
    }
    Poly term{{0, Q(inversions % 2 ? -1 : 1)}};
    for (size_t i = 0; i < 4; ++i) term = Mul(term, m[i][perm[i]]);
    for (const auto& [e, c] : term) det[e] += c;
  } while (std::next_permutation(perm.begin(), perm.end()));
  for (const auto& [e, c] : det) {
    if (c != 0) return -Sgn(c);
  }
  return 0;
}

int Sos(const Quad& q, const std::array<uint32_t, 4>& r) {
  return PowerSoS(q[0].p, q[0].w, r[0], q[1].p, q[1].w, r[1], q[2].p, q[2].w, r[2], q[3].p, q[3].w, r[3]);
}

bool DistinctPositions(const Quad& q) {
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      if (q[i].p.x == q[j].p.x && q[i].p.y == q[j].p.y) return false;
    }
  }
  return true;
}

TEST(PowerSoS, MatchesTheBruteForcePerturbationAndIsAntisymmetric) {
  Gen g(34);
  int degenerate = 0;
  for (const char* kind : {"grid", "tie", "offset1e9", "tiny", "random"}) {
    for (const Quad& q : Cases(kind, 400, 35)) {
      if (!DistinctPositions(q)) continue;
      std::array<uint32_t, 4> ranks;
      for (uint32_t i = 0; i < 4; ++i) ranks[i] = i;
      std::shuffle(ranks.begin(), ranks.end(), g.rng);
      const int s = Sos(q, ranks);
      ASSERT_NE(s, 0);
      ASSERT_EQ(s, BruteForcePowerSoS(q, ranks)) << kind << ": " << Show(q);
      const int plain = Power(q);
      if (plain != 0) {
        ASSERT_EQ(s, plain);
      }
      degenerate += plain == 0;
      std::array<size_t, 4> perm = {0, 1, 2, 3};
      do {
        Quad pq;
        std::array<uint32_t, 4> pr;
        int parity = 1;
        for (size_t i = 0; i < 4; ++i) {
          pq[i] = q[perm[i]];
          pr[i] = ranks[perm[i]];
          for (size_t j = i + 1; j < 4; ++j) parity *= perm[i] > perm[j] ? -1 : 1;
        }
        ASSERT_EQ(Sos(pq, pr) * parity, s) << Show(q);
      } while (std::next_permutation(perm.begin(), perm.end()));
    }
  }
  EXPECT_GT(degenerate, 300);
}

// CGAL's perturbed power test (Regular_triangulation_2::power_test with perturb = true) on a tie:
// the points in lexicographic order, the largest first; if it is the query it is hidden (-1),
// else the orientation with the query in its place decides, and if that is collinear the next
// point does.
int CgalTieRule(const Quad& q) {
  std::array<int, 4> order = {0, 1, 2, 3};
  std::sort(order.begin(), order.end(),
            [&](int i, int j) { return q[i].p.x < q[j].p.x || (q[i].p.x == q[j].p.x && q[i].p.y < q[j].p.y); });
  for (int k = 3; k > 1; --k) {
    const int top = order[k];
    if (top == 3) return -1;
    Point2 t[3] = {q[0].p, q[1].p, q[2].p};
    t[top] = q[3].p;
    const int o = Orient2dSign(t[0], t[1], t[2]);
    if (o != 0) return o;
  }
  return 0;  // CGAL asserts this never happens
}

TEST(PowerSoS, BreaksTiesAsCgalWithLexicographicRanks) {
  // Ranks by decreasing lexicographic order (the engine's): on every exact tie of a ccw triangle
  // where CGAL's first term decides, the two agree.
  Gen g(36);
  int compared = 0;
  for (const char* kind : {"tie", "grid", "offset1e9"}) {
    for (Quad q : Cases(kind, 2000, 37)) {
      if (!DistinctPositions(q) || Power(q) != 0) continue;
      const int o = Orient2dSign(q[0].p, q[1].p, q[2].p);
      if (o == 0) continue;
      if (o < 0) std::swap(q[0], q[1]);
      std::array<uint32_t, 4> ranks;
      for (uint32_t i = 0; i < 4; ++i) {
        ranks[i] = 0;
        for (uint32_t j = 0; j < 4; ++j) {
          const bool j_larger = q[j].p.x > q[i].p.x || (q[j].p.x == q[i].p.x && q[j].p.y > q[i].p.y);
          ranks[i] += j_larger ? 1 : 0;
        }
      }
      // The first term decides unless the three points other than the largest are collinear.
      const int top = static_cast<int>(std::find(ranks.begin(), ranks.end(), 0u) - ranks.begin());
      Point2 others[3];
      for (int i = 0, k = 0; i < 4; ++i) {
        if (i != top) others[k++] = q[i].p;
      }
      if (Orient2dSign(others[0], others[1], others[2]) == 0) continue;
      ASSERT_EQ(Sos(q, ranks), CgalTieRule(q)) << Show(q);
      ++compared;
    }
  }
  EXPECT_GT(compared, 500);
}

// ---- Collinear power test ----

int ExactCollinearPowerSign(const WeightedPoint& u, const WeightedPoint& w, const WeightedPoint& p) {
  const bool along_x = u.p.x != w.p.x;
  const Q tu = Exact(along_x ? u.p.x : u.p.y), tw = Exact(along_x ? w.p.x : w.p.y), tp = Exact(along_x ? p.p.x : p.p.y);
  const Q v = Lift(u) * (tw - tp) + Lift(w) * (tp - tu) - Lift(p) * (tw - tu);
  return Sgn(v) * (tw > tu ? 1 : -1);
}

TEST(CollinearPowerSign, MatchesGmp) {
  Gen g(38);
  int zeros = 0;
  for (int i = 0; i < 20000; ++i) {
    // A line through two lattice points, three points on it by integer steps (exactly collinear),
    // sometimes offset or scaled by powers of two; weights small integers or random.
    const double dx = g.I(-3, 3), dy = g.I(-3, 3);
    if (dx == 0 && dy == 0) continue;
    const double ox = g.I(-5, 5), oy = g.I(-5, 5);
    int k[3] = {g.I(-6, 6), g.I(-6, 6), g.I(-6, 6)};
    std::sort(k, k + 3);
    if (k[0] == k[1] || k[1] == k[2]) continue;
    const int scale = i % 4 == 0 ? -300 : (i % 4 == 1 ? 200 : 0);
    // An offset only on unscaled points: 1e9 would absorb coordinates scaled by 2^-300 and make
    // the three points one.
    const double offset = i % 5 == 0 && scale == 0 ? 1e9 : 0.0;
    WeightedPoint pts[3];
    for (int j = 0; j < 3; ++j) {
      const double w = i % 3 == 0 ? g.U(-10, 10) : double(g.I(-20, 20));
      pts[j] = {{std::ldexp(ox + k[j] * dx, scale) + offset, std::ldexp(oy + k[j] * dy, scale)},
                std::ldexp(w, 2 * scale)};
    }
    if (pts[0].p == pts[1].p || pts[1].p == pts[2].p) continue;
    if (i % 4 == 3 && (k[0] + k[2]) % 2 == 0) {
      // An exact tie: the middle point's lift set on the chord (its weight |p|^2 minus the mean
      // of its neighbours' lifts, exact for these small numbers).
      const double mx = ox + ((k[0] + k[2]) / 2) * dx, my = oy + ((k[0] + k[2]) / 2) * dy;
      pts[1].p = {mx + offset, my};
      const auto lift = [](const WeightedPoint& a) { return a.p.x * a.p.x + a.p.y * a.p.y - a.w; };
      pts[1].w = pts[1].p.x * pts[1].p.x + pts[1].p.y * pts[1].p.y - 0.5 * (lift(pts[0]) + lift(pts[2]));
      if (pts[1].p == pts[0].p || pts[1].p == pts[2].p) continue;
    }
    const WeightedPoint& u = pts[i % 2 ? 0 : 2];
    const WeightedPoint& w = pts[i % 2 ? 2 : 0];
    const int exact = ExactCollinearPowerSign(u, w, pts[1]);
    ASSERT_EQ(CollinearPowerSign(u.p, u.w, w.p, w.w, pts[1].p, pts[1].w), exact) << i;
    zeros += exact == 0;
  }
  EXPECT_GT(zeros, 100);
}

TEST(CollinearPowerSign, AHeavierMiddlePointSinks) {
  // Without weights, a point between two others always lies below their lifted chord.
  EXPECT_EQ(CollinearPowerSign({0, 0}, 0, {2, 0}, 0, {1, 0}, 0), 1);
  // Its lift is 1 - w against the chord's 2 - (w_u + w_w) / 2 at the midpoint.
  EXPECT_EQ(CollinearPowerSign({0, 0}, 1, {2, 0}, 1, {1, 0}, 0), 0);
  EXPECT_EQ(CollinearPowerSign({0, 0}, 3, {2, 0}, 3, {1, 0}, 0), -1);
  EXPECT_EQ(CollinearPowerSign({0, 0}, 3, {0, 2}, 3, {0, 1}, 2.5), 1);
}

}  // namespace
}  // namespace galpha
