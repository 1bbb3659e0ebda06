// Refined keys of squared radii (core/exact/radius_refined.hpp) against exact GMP rationals: the
// certified error bound on every simplex, the soundness of the separation test on near ties (the
// ulp-perturbed lattices it exists for), and the equality proof of translated simplices.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/exact/radius_rational.hpp"
#include "core/exact/radius_refined.hpp"
#include "tests/core/exact/simplex_samples.hpp"

namespace galpha {
namespace {

using testing_support::Show;
using testing_support::Simplex;
using testing_support::Ulps;

// The exact value of a refined key: (hi + mid + lo) 2^exponent.
mpq_class RefinedValue(const RefinedRadiusSq& r) {
  mpq_class value = mpq_class(r.hi) + mpq_class(r.mid) + mpq_class(r.lo);
  if (r.exponent >= 0) {
    mpq_mul_2exp(value.get_mpq_t(), value.get_mpq_t(), static_cast<mp_bitcnt_t>(r.exponent));
  } else {
    mpq_div_2exp(value.get_mpq_t(), value.get_mpq_t(), static_cast<mp_bitcnt_t>(-r.exponent));
  }
  return value;
}

// Lattice triangles and edges, as a reprojected or unit-converted grid makes them: spacing h at an
// offset, every coordinate moved by up to `ulps` units in the last place.
std::vector<Simplex> PerturbedLattice(double offset, double h, int ulps, int count, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> cell(0, 999), nudge(-ulps, ulps), kind(0, 3);
  auto at = [&](int i, int j) { return Point2{Ulps(offset + h * i, nudge(rng)), Ulps(offset + h * j, nudge(rng))}; };
  std::vector<Simplex> out;
  for (int c = 0; c < count; ++c) {
    const int i = cell(rng), j = cell(rng);
    Simplex s;
    switch (kind(rng)) {
      case 0:
        s = {{at(i, j), at(i + 1, j), at(i, j + 1)}, 3};
        break;
      case 1:
        s = {{at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)}, 3};
        break;
      case 2:
        s = {{at(i, j), at(i + 1, j), {}}, 2};
        break;
      default:
        s = {{at(i, j), at(i + 1, j + 1), {}}, 2};
        break;
    }
    out.push_back(s);
  }
  return out;
}

// Random simplices of every scale the exact path accepts, nearly collinear ones included.
std::vector<Simplex> Assorted(int count, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> scale(-300, 300), kind(0, 2);
  std::vector<Simplex> out;
  for (int c = 0; c < count; ++c) {
    const double f = std::ldexp(1.0, scale(rng));
    Simplex s;
    s.n = kind(rng) == 0 ? 2 : 3;
    for (int i = 0; i < 3; ++i) s.p[i] = {unit(rng) * f, unit(rng) * f};
    if (kind(rng) == 1 && s.n == 3) {  // nearly collinear: the third point near the first two's midpoint
      s.p[2] = {Ulps((s.p[0].x + s.p[1].x) / 2, 3), (s.p[0].y + s.p[1].y) / 2};
    }
    out.push_back(s);
  }
  return out;
}

void ExpectWithinBound(const std::vector<Simplex>& simplices) {
  const mpq_class bound(0x1p-150);
  int checked = 0;
  for (const Simplex& s : simplices) {
    const RefinedRadiusSq r = RefineRadiusSq(s.p, s.n);
    const std::optional<mpq_class> exact = RadiusSqRational(s.p, s.n);
    if (!r.ok) continue;
    ASSERT_EQ(r.infinite, !exact.has_value()) << Show(s);
    if (r.infinite) continue;
    ASSERT_GE(r.hi, 1.0) << Show(s);
    ASSERT_LT(r.hi, 2.0) << Show(s);
    const mpq_class error = abs(RefinedValue(r) - *exact);
    ASSERT_LE(error, bound * *exact) << Show(s) << " error/value " << mpq_class(error / *exact).get_d();
    ++checked;
  }
  // Nearly all of them must take the refined path, or this test checks nothing.
  EXPECT_GT(checked, static_cast<int>(simplices.size()) * 9 / 10);
}

TEST(RefinedRadiusSqTest, ErrorWithinTheCertifiedBoundOnLattices) {
  ExpectWithinBound(PerturbedLattice(0.0, 1.0, 0, 2000, 1));
  ExpectWithinBound(PerturbedLattice(1000.0, 0.1, 2, 2000, 2));
  ExpectWithinBound(PerturbedLattice(500000.0, 0.01, 1, 2000, 3));
  ExpectWithinBound(PerturbedLattice(1e9, 1.0, 3, 2000, 4));
}

TEST(RefinedRadiusSqTest, ErrorWithinTheCertifiedBoundOnAssortedScales) { ExpectWithinBound(Assorted(4000, 5)); }

// Sorted by refined key, every pair the keys call separated must be in exact order. Near ties
// a few ulps apart are the point: they are what the 64-bit keys cannot order.
TEST(RefinedRadiusSqTest, SeparatedKeysAreInExactOrder) {
  for (const auto& [offset, h, ulps] :
       {std::tuple{1000.0, 0.1, 2}, std::tuple{500000.0, 0.01, 1}, std::tuple{0.0, 1.0, 1}, std::tuple{1e9, 1.0, 3}}) {
    SCOPED_TRACE(offset);
    std::vector<Simplex> simplices = PerturbedLattice(offset, h, ulps, 3000, 7);
    std::vector<std::pair<RefinedRadiusSq, Simplex>> keyed;
    for (const Simplex& s : simplices) {
      const RefinedRadiusSq r = RefineRadiusSq(s.p, s.n);
      // Subnormal coordinates (the lattice at offset 0 nudged by ulps) leave the exact terms'
      // exponent range: those simplices are ordered by exact comparisons instead.
      if (r.ok) keyed.emplace_back(r, s);
    }
    ASSERT_GT(keyed.size(), simplices.size() * 9 / 10);
    std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) {
      if (a.first.exponent != b.first.exponent) return a.first.exponent < b.first.exponent;
      if (a.first.hi != b.first.hi) return a.first.hi < b.first.hi;
      if (a.first.mid != b.first.mid) return a.first.mid < b.first.mid;
      return a.first.lo < b.first.lo;
    });
    int separated = 0, not_separated = 0;
    for (size_t i = 1; i < keyed.size(); ++i) {
      const Simplex& a = keyed[i - 1].second;
      const Simplex& b = keyed[i].second;
      const int exact = CompareRadiusSqRational(a.p, a.n, b.p, b.n);
      if (RefinedKeysSeparated(keyed[i - 1].first, keyed[i].first)) {
        ASSERT_LT(exact, 0) << Show(a) << "vs " << Show(b);
        ++separated;
      } else {
        ++not_separated;
      }
      // Not separated: equal, or closer than the keys' error (then they may also be swapped, which
      // the spectrum's exact check of adjacent entries repairs).
    }
    // Both outcomes occur: exact ties (congruent cells) and separated near ties.
    EXPECT_GT(separated, 100);
    EXPECT_GT(not_separated, 0);
  }
}

// Values closer than the separation threshold are never called separated, whatever their order.
TEST(RefinedRadiusSqTest, TiesAreNeverSeparated) {
  RefinedRadiusSq a;
  a.ok = true;
  a.exponent = 3;
  a.hi = 1.5;
  a.mid = 0x1p-60;
  a.lo = 0x1p-120;
  RefinedRadiusSq b = a;
  EXPECT_FALSE(RefinedKeysSeparated(a, b));
  b.lo = a.lo + 0x1p-148;
  EXPECT_FALSE(RefinedKeysSeparated(a, b));
  b.lo = a.lo + 0x1p-140;
  EXPECT_TRUE(RefinedKeysSeparated(a, b));
  EXPECT_FALSE(RefinedKeysSeparated(b, a));
  // Across a binade: (2 - 2^-53 - 2^-150) 2^3 and (1 - 2^-54) 2^4 are 2^-147 apart at exponent 3.
  const RefinedRadiusSq below{3, 2.0 - 0x1p-52, 0x1p-53, -0x1p-150, true, false};
  const RefinedRadiusSq above{4, 1.0, -0x1p-54, 0.0, true, false};
  EXPECT_FALSE(RefinedKeysSeparated(below, above));
  const RefinedRadiusSq farther{4, 1.0, -0x1p-54, 0x1p-140, true, false};
  EXPECT_TRUE(RefinedKeysSeparated(below, farther));
  RefinedRadiusSq infinite;
  infinite.ok = infinite.infinite = true;
  EXPECT_TRUE(RefinedKeysSeparated(a, infinite));
  EXPECT_FALSE(RefinedKeysSeparated(infinite, infinite));
}

TEST(RefinedRadiusSqTest, TranslatesAreProvenEqual) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> step(0, 1000);
  int identical = 0;
  for (int c = 0; c < 500; ++c) {
    // A triangle of a perturbed lattice and its translate by a whole number of lattice steps,
    // with its vertices listed in another order.
    const double h = 0.125;  // translation by multiples of it is exact at these magnitudes
    const Point2 a{Ulps(1000.0, 1), Ulps(2000.0, -1)};
    const Point2 b{Ulps(1000.0 + h, 2), Ulps(2000.0, 0)};
    const Point2 d{Ulps(1000.0, 0), Ulps(2000.0 + h, 1)};
    const double tx = h * step(rng), ty = h * step(rng);
    const Point2 first[3] = {a, b, d};
    const Point2 moved[3] = {{d.x + tx, d.y + ty}, {a.x + tx, a.y + ty}, {b.x + tx, b.y + ty}};
    // Exact translates only (the additions above may round): check it before relying on it.
    bool exact_translate = true;
    for (int i = 0; i < 3; ++i) {
      const Point2& from = first[(i + 2) % 3];
      exact_translate = exact_translate && mpq_class(moved[i].x) - mpq_class(from.x) == mpq_class(tx) &&
                        mpq_class(moved[i].y) - mpq_class(from.y) == mpq_class(ty);
    }
    const bool same = RadiusCongruent(first, 3, moved, 3);
    if (same) {
      ASSERT_EQ(CompareRadiusSqRational(first, 3, moved, 3), 0);
      ++identical;
    }
    if (exact_translate) {
      EXPECT_TRUE(same);
    }
  }
  EXPECT_GT(identical, 20);
  // Different values are never called identical.
  const Point2 t1[3] = {{0, 0}, {1, 0}, {0, 1}};
  const Point2 t2[3] = {{0, 0}, {1, 0}, {0, Ulps(1.0, 1)}};
  EXPECT_FALSE(RadiusCongruent(t1, 3, t2, 3));
  EXPECT_TRUE(RadiusCongruent(t1, 3, t1, 3));
  // A half-turn: a lattice's upper cell triangle against its lower one.
  const Point2 lower[3] = {{1000.0, 2000.0}, {Ulps(1000.125, 1), 2000.0}, {1000.0, Ulps(2000.125, -1)}};
  const Point2 upper[3] = {
      {Ulps(1000.125, 1), Ulps(2000.125, -1)}, {1000.0, Ulps(2000.125, -1)}, {Ulps(1000.125, 1), 2000.0}};
  // lower's edge vectors negated: (a + b + c) - lower, exact here, is upper's vertex list.
  EXPECT_EQ(RadiusCongruent(lower, 3, upper, 3), CompareRadiusSqRational(lower, 3, upper, 3) == 0);
  const Point2 sheared[3] = {{1000.0, 2000.0}, {Ulps(1000.125, 1), 2000.0}, {Ulps(1000.0, 1), Ulps(2000.125, -1)}};
  EXPECT_FALSE(RadiusCongruent(lower, 3, sheared, 3));
  // Edges: equal length alone is not claimed; the lattice's symmetries are.
  const Point2 e1[2] = {{0, 0}, {3, 4}}, e2[2] = {{0, 0}, {5, 0}}, e3[2] = {{7, 7}, {4, 3}}, e4[2] = {{1, 1}, {5, -2}};
  EXPECT_FALSE(RadiusCongruent(e1, 2, e2, 2));
  EXPECT_TRUE(RadiusCongruent(e1, 2, e3, 2));
  EXPECT_TRUE(RadiusCongruent(e1, 2, e4, 2));  // (4, -3): (3, 4) turned a quarter
  // The form reads each edge's coordinates with their rounding errors: differences that round to
  // the same double but are not equal (far-apart magnitudes) are not claimed equal.
  const Point2 far1[2] = {{0x1p-10, 0.0}, {0x1p53, 1.0}}, far2[2] = {{0x1p-11, 0.0}, {0x1p53, 1.0}};
  ASSERT_NE(CompareRadiusSqRational(far1, 2, far2, 2), 0);
  EXPECT_FALSE(RadiusCongruent(far1, 2, far2, 2));
  const Point2 far3[3] = {{0x1p-10, 0.0}, {0x1p53, 1.0}, {0.0, 3.0}},
               far4[3] = {{0x1p-11, 0.0}, {0x1p53, 1.0}, {0.0, 3.0}};
  ASSERT_NE(CompareRadiusSqRational(far3, 3, far4, 3), 0);
  EXPECT_FALSE(RadiusCongruent(far3, 3, far4, 3));
  // Congruent copies that no symmetry of the square lattice maps onto each other: a right
  // isosceles triangle and its mirror image in its own leg AB (direction (2, 1)). Each edge keeps
  // its coordinates up to sign and order, so the equal values are proven.
  const Point2 right1[3] = {{0, 0}, {2, 1}, {1, 3}}, right2[3] = {{0, 0}, {2, 1}, {3, -1}};
  ASSERT_EQ(CompareRadiusSqRational(right1, 3, right2, 3), 0);
  EXPECT_TRUE(RadiusCongruent(right1, 3, right2, 3));
  // Mirrors and quarter turns of a perturbed triangle, against GMP; and a shape that is no symmetry
  // of it (a shear that keeps one edge) is never claimed, equal or not.
  const Point2 tri[3] = {{Ulps(1000.0, 1), 2000.0}, {1000.125, Ulps(2000.0, -2)}, {Ulps(1000.0, -1), 2000.25}};
  for (int t = 0; t < 8; ++t) {
    Point2 image[3];
    for (int i = 0; i < 3; ++i) {
      double x = tri[i].x - 1000.0, y = tri[i].y - 2000.0;  // exact: Sterbenz
      if (t & 1) x = -x;
      if (t & 2) y = -y;
      if (t & 4) std::swap(x, y);
      image[i] = {x + 5000.0, y + 7000.0};  // may round: then the image is not an exact copy
    }
    const bool claimed = RadiusCongruent(tri, 3, image, 3);
    if (claimed) {
      EXPECT_EQ(CompareRadiusSqRational(tri, 3, image, 3), 0) << t;
    }
  }
}

// The grouping hash of the spectrum's long runs must give every pair RadiusCongruent accepts one
// hash (otherwise congruent entries would be keyed apart: slower, never wrong); over a perturbed
// lattice's cells in every orientation, and for zero differences of either sign.
TEST(RefinedRadiusSqTest, CongruentSimplicesShareTheirHash) {
  std::mt19937_64 rng(12);
  std::uniform_int_distribution<int> ulps(-2, 2), flip(0, 7), cell(0, 50);
  std::vector<std::vector<Point2>> simplices;
  for (int c = 0; c < 400; ++c) {
    const double h = 0.125;
    const double x0 = 1000.0 + h * cell(rng), y0 = 2000.0 + h * cell(rng);
    std::vector<Point2> tri = {{Ulps(x0, ulps(rng)), Ulps(y0, ulps(rng))},
                               {Ulps(x0 + h, ulps(rng)), Ulps(y0, ulps(rng))},
                               {Ulps(x0, ulps(rng)), Ulps(y0 + h, ulps(rng))}};
    const int t = flip(rng);
    for (Point2& p : tri) {
      double x = p.x - x0, y = p.y - y0;  // exact: Sterbenz
      if (t & 1) x = -x;
      if (t & 2) y = -y;
      if (t & 4) std::swap(x, y);
      p = {x + 5000.0, y + 7000.0};
    }
    simplices.push_back(tri);
    simplices.push_back({tri[0], tri[1]});
  }
  int congruent_pairs = 0, shared_without_congruence = 0;
  for (size_t i = 0; i < simplices.size(); ++i) {
    for (size_t j = i + 1; j < simplices.size(); ++j) {
      const auto& a = simplices[i];
      const auto& b = simplices[j];
      const int na = static_cast<int>(a.size()), nb = static_cast<int>(b.size());
      const bool same_hash = CongruenceHash(a.data(), na) == CongruenceHash(b.data(), nb);
      if (RadiusCongruent(a.data(), na, b.data(), nb)) {
        ++congruent_pairs;
        EXPECT_TRUE(same_hash) << "pair " << i << ", " << j;
      } else if (same_hash) {
        ++shared_without_congruence;
      }
    }
  }
  EXPECT_GT(congruent_pairs, 100);
  EXPECT_EQ(shared_without_congruence, 0);  // not required, but a 64-bit hash should not collide here
  // A zero difference of either sign: RadiusCongruent compares -0 == +0, and so must the hash.
  const Point2 plus[2] = {{0.0, 0.0}, {3.0, 0.0}}, minus[2] = {{0.0, 0.0}, {3.0, -0.0}};
  ASSERT_TRUE(RadiusCongruent(plus, 2, minus, 2));
  EXPECT_EQ(CongruenceHash(plus, 2), CongruenceHash(minus, 2));
  const Point2 flat_plus[3] = {{0.0, 0.0}, {3.0, 0.0}, {0.0, 4.0}},
               flat_minus[3] = {{0.0, -0.0}, {3.0, 0.0}, {-0.0, 4.0}};
  ASSERT_TRUE(RadiusCongruent(flat_plus, 3, flat_minus, 3));
  EXPECT_EQ(CongruenceHash(flat_plus, 3), CongruenceHash(flat_minus, 3));
}

}  // namespace
}  // namespace galpha
