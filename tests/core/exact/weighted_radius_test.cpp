// Weighted squared radii and weighted attachment (core/exact/weighted_radius.hpp) against exact
// GMP rationals solved directly from the orthogonal circle's centre (weighted_radius_rational.cpp):
// the certified key order, the bounded exact comparison, the nearest double, the refined keys and
// their sort words, and the attachment sign, on random and adversarial weighted simplices: exact
// ties (congruent cells with equal weights, power ties on small integers), near ties a few ulps
// apart, negative values, weights far above and below the squared spacing, 1e9 offsets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/exact/order.hpp"
#include "core/exact/radius_compare.hpp"
#include "core/exact/radius_rational.hpp"
#include "core/exact/refined_sort_words.hpp"
#include "core/exact/simplex_radius.hpp"
#include "core/exact/weighted_radius.hpp"
#include "core/exact/weighted_radius_rational.hpp"

namespace galpha {
namespace {

struct WeightedSimplex {
  Point2 p[3];
  double w[3];
  int n;
};

std::string Show(const WeightedSimplex& s) {
  std::string out;
  char text[160];
  for (int i = 0; i < s.n; ++i) {
    std::snprintf(text, sizeof text, "(%.17g, %.17g; w %.17g) ", s.p[i].x, s.p[i].y, s.w[i]);
    out += text;
  }
  return out;
}

/// Weighted simplices of one family. "grid": small integer coordinates and weights (exact power
/// ties everywhere); "equal": grid cells with one weight; "nudged": grid with coordinates or
/// weights moved by an ulp; "random": uniform coordinates and weights up to the squared spacing;
/// "heavy": weights 1e6 times the squared spacing, nearly equal; "light": weights 1e-9 of it;
/// "offset": coordinates near 1e9 with unit spacing; "negative": weights well below zero; "tiny":
/// coordinates near 2^-900 (squared radii below the smallest double).
std::vector<WeightedSimplex> Family(const std::string& name, int count, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> small(-4, 4), weight(-3, 3), coin(0, 1), ulps(-2, 2);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<WeightedSimplex> out;
  while (static_cast<int>(out.size()) < count) {
    WeightedSimplex s;
    s.n = coin(rng) ? 3 : 2;
    for (int i = 0; i < s.n; ++i) {
      if (name == "grid" || name == "equal" || name == "nudged") {
        s.p[i] = {static_cast<double>(small(rng)), static_cast<double>(small(rng))};
        s.w[i] = name == "equal" ? 2.0 : static_cast<double>(weight(rng)) * 0.5;
        if (name == "nudged") {  // nonzero values only: a nudged zero is subnormal, outside the domain
          if (s.p[i].x != 0.0) {
            for (int k = 0; k < ulps(rng) + 2; ++k) s.p[i].x = std::nextafter(s.p[i].x, 10.0);
          }
          if (s.w[i] != 0.0 && coin(rng)) s.w[i] = std::nextafter(s.w[i], 10.0);
        }
      } else if (name == "tiny") {  // rho^2 far below the smallest double: it rounds to 0
        s.p[i] = {std::ldexp(unit(rng), -900), std::ldexp(unit(rng), -900)};
        s.w[i] = 0.0;
      } else if (name == "offset") {
        s.p[i] = {1e9 + static_cast<double>(small(rng)) + unit(rng), 1e9 + static_cast<double>(small(rng))};
        s.w[i] = unit(rng);
      } else {
        s.p[i] = {unit(rng), unit(rng)};
        const double base = name == "heavy" ? 1e6 : name == "light" ? 1e-9 : name == "negative" ? -5.0 : 0.0;
        s.w[i] = base + unit(rng) * (name == "light" ? 1e-9 : 0.5);
      }
    }
    bool distinct = true;
    for (int i = 0; i < s.n; ++i) {
      for (int j = i + 1; j < s.n; ++j) distinct = distinct && !(s.p[i] == s.p[j]);
    }
    if (distinct) out.push_back(s);
  }
  return out;
}

const std::vector<std::string>& FamilyNames() {
  static const std::vector<std::string> names = {"grid",  "equal",  "nudged",   "random", "heavy",
                                                 "light", "offset", "negative", "tiny"};
  return names;
}

std::optional<mpq_class> Exact(const WeightedSimplex& s) { return SimplexRadiusSqRational(s.p, s.w, s.n); }

TEST(WeightedRadius, ZeroWeightsGiveTheUnweightedValue) {
  for (const WeightedSimplex& base : Family("random", 200, 1)) {
    WeightedSimplex s = base;
    for (double& w : s.w) w = 0.0;
    const std::optional<mpq_class> weighted = Exact(s), plain = RadiusSqRational(s.p, s.n);
    ASSERT_EQ(weighted.has_value(), plain.has_value());
    if (weighted) {
      EXPECT_EQ(*weighted, *plain) << Show(s);
      // The weighted expansions and keys give the unweighted answers: the same nearest double,
      // and the same order against an unweighted simplex's value (compared through its own
      // zero-weight terms with a weight-free path: the unweighted bounded comparison).
      double nearest = 0.0;
      ASSERT_TRUE(NearestWeightedRadiusSqBounded(s.p, s.w, s.n, &nearest)) << Show(s);
      EXPECT_EQ(nearest, NearestDouble(*plain)) << Show(s);
      const Point2 unit_edge[2] = {{0.0, 0.0}, {0.5, 0.25}};
      const double zero[2] = {0.0, 0.0};
      EXPECT_EQ(CompareWeightedRadiusSqBounded(s.p, s.w, s.n, unit_edge, zero, 2),
                CompareRadiusSqBounded(s.p, s.n, unit_edge, 2))
          << Show(s);
    }
  }
}

TEST(WeightedRadius, KnownValues) {
  // Edge of length 2 between weights 1 and 1: the circle through... orthogonal to both unit
  // circles centred 2 apart has its centre midway and rho^2 = 1 - 1 = 0.
  const Point2 edge[2] = {{0, 0}, {2, 0}};
  const double unit_weights[2] = {1.0, 1.0};
  EXPECT_EQ(*SimplexRadiusSqRational(edge, unit_weights, 2), 0);
  double v = -1.0;
  ASSERT_TRUE(NearestWeightedRadiusSqBounded(edge, unit_weights, 2, &v));
  EXPECT_EQ(v, 0.0);
  // Weights 4 and 0 on an edge of length 2: centre where |m|^2 - 4 = |m - 2|^2, m = 2: rho^2 = 0.
  const double heavy_first[2] = {4.0, 0.0};
  EXPECT_EQ(*SimplexRadiusSqRational(edge, heavy_first, 2), 0);
  // Overlapping disks: weights 4 and 4 at distance 2: rho^2 = 1 - 4 = -3.
  const double overlapping[2] = {4.0, 4.0};
  ASSERT_TRUE(NearestWeightedRadiusSqBounded(edge, overlapping, 2, &v));
  EXPECT_EQ(v, -3.0);
  // The right triangle (0,0), (2,0), (0,2) with weights 1: circumradius^2 2, minus 1.
  const Point2 tri[3] = {{0, 0}, {2, 0}, {0, 2}};
  const double ones[3] = {1.0, 1.0, 1.0};
  ASSERT_TRUE(NearestWeightedRadiusSqBounded(tri, ones, 3, &v));
  EXPECT_EQ(v, 1.0);
  // Collinear: infinite.
  const Point2 flat[3] = {{0, 0}, {1, 0}, {2, 0}};
  EXPECT_FALSE(SimplexRadiusSqRational(flat, ones, 3).has_value());
  EXPECT_EQ(ApproxWeightedRadiusSq(flat, ones, 3).key, kInfiniteRadiusKey);
}

TEST(WeightedRadius, KeysOrderCertifiedValues) {
  for (const std::string& name : FamilyNames()) {
    const std::vector<WeightedSimplex> simplices = Family(name, 180, 11);
    std::vector<RadiusSqApprox> keys;
    keys.reserve(simplices.size());
    for (const WeightedSimplex& s : simplices) keys.push_back(ApproxWeightedRadiusSq(s.p, s.w, s.n));
    for (size_t i = 0; i < simplices.size(); ++i) {
      if (!keys[i].certified) continue;
      if (!Exact(simplices[i])) {
        EXPECT_EQ(keys[i].key, kInfiniteRadiusKey) << name << " " << Show(simplices[i]);
        continue;
      }
      for (size_t j = 0; j < simplices.size(); ++j) {
        if (!keys[j].certified || keys[j].key <= keys[i].key || !Exact(simplices[j])) continue;
        if (RadiusKeysMayTie(keys[i].key, keys[j].key)) continue;
        ASSERT_LT(*Exact(simplices[i]), *Exact(simplices[j])) << name << "\n"
                                                              << Show(simplices[i]) << "\n"
                                                              << Show(simplices[j]);
      }
    }
  }
}

TEST(WeightedRadius, FloatingFilterBoundsItsError) {
  int filtered = 0, certified = 0;
  for (const std::string& name : FamilyNames()) {
    for (const WeightedSimplex& s : Family(name, 600, 17)) {
      weighted_detail::Bounded value;
      int scale = 0;
      if (!weighted_detail::FilteredWeightedRadiusSq(s.p, s.w, s.n, &value, &scale)) continue;
      ++filtered;
      const std::optional<mpq_class> exact = Exact(s);
      ASSERT_TRUE(exact.has_value()) << "a collinear triangle passed the filter: " << Show(s);
      // |exact * 2^(2s) - v| <= e, in rationals.
      mpq_class scaled = *exact;
      mpz_class power = 1;
      mpz_mul_2exp(power.get_mpz_t(), power.get_mpz_t(), static_cast<unsigned long>(std::abs(2 * scale)));
      if (scale >= 0) {
        scaled *= mpq_class(power);
      } else {
        scaled /= mpq_class(power);
      }
      const mpq_class error = abs(scaled - mpq_class(value.v));
      ASSERT_LE(error, mpq_class(value.e) * mpq_class(1.0 + 0x1p-40)) << name << " " << Show(s);
      certified += value.v != 0.0 && value.e <= std::abs(value.v) * 0x1p-42 ? 1 : 0;
    }
  }
  EXPECT_GT(filtered, 3000);
  EXPECT_GT(certified, 2500);  // the filter decides most keys
}

TEST(WeightedRadius, BoundedComparisonIsExact) {
  int decided = 0, ties = 0;
  for (const std::string& name : FamilyNames()) {
    const std::vector<WeightedSimplex> simplices = Family(name, 160, 23);
    for (const WeightedSimplex& a : simplices) {
      for (const WeightedSimplex& b : simplices) {
        const Order got = CompareWeightedRadiusSqBounded(a.p, a.w, a.n, b.p, b.w, b.n);
        // Every family here is well inside the bounded path's range: it decides them all.
        ASSERT_NE(got, Order::kUndecided) << name << "\n" << Show(a) << "\n" << Show(b);
        ++decided;
        const int expected = CompareSimplexRadiusSqRational(a.p, a.w, a.n, b.p, b.w, b.n);
        ties += expected == 0 && &a != &b ? 1 : 0;
        ASSERT_EQ(SignOf(got), expected) << name << "\n" << Show(a) << "\n" << Show(b);
        if (WeightedRadiusCongruent(a.p, a.w, a.n, b.p, b.w, b.n)) {
          ASSERT_EQ(expected, 0) << "congruence claimed for unequal values\n" << Show(a) << "\n" << Show(b);
        }
      }
    }
  }
  EXPECT_GT(decided, 150000);
  EXPECT_GT(ties, 200);  // the grid families' exact ties were exercised
}

TEST(WeightedRadius, NearestDoubleIsCorrectlyRounded) {
  int rounded = 0;
  for (const std::string& name : FamilyNames()) {
    for (const WeightedSimplex& s : Family(name, 400, 37)) {
      double got = 0.0;
      if (!NearestWeightedRadiusSqBounded(s.p, s.w, s.n, &got)) {
        // Only values that are not normal doubles (tiny ones next to large weights) go to the host.
        const std::optional<mpq_class> exact = Exact(s);
        ASSERT_TRUE(exact.has_value()) << Show(s);
        EXPECT_LT(std::abs(NearestDouble(*exact)), 0x1p-1000) << name << " " << Show(s);
        continue;
      }
      ++rounded;
      const std::optional<mpq_class> exact = Exact(s);
      if (!exact) {
        EXPECT_TRUE(std::isinf(got)) << Show(s);
        continue;
      }
      ASSERT_EQ(got, NearestDouble(*exact)) << name << " " << Show(s);
    }
  }
  EXPECT_GT(rounded, 3000);
}

TEST(WeightedRadius, FastNearestDoubleIsCorrectlyRoundedWhereItDecides) {
  int decided = 0, total = 0;
  for (const std::string& name : FamilyNames()) {
    for (const WeightedSimplex& s : Family(name, 1500, 71)) {
      ++total;
      double got = 0.0;
      if (!NearestWeightedRadiusSqFast(s.p, s.w, s.n, &got)) continue;
      ++decided;
      const std::optional<mpq_class> exact = Exact(s);
      ASSERT_TRUE(exact.has_value()) << Show(s);
      ASSERT_EQ(got, NearestDouble(*exact)) << name << " " << Show(s);
    }
  }
  EXPECT_GT(decided, total * 3 / 4);  // most values: the exact loop is the exception
}

TEST(WeightedRadius, RefinedKeysAndSortWordsOrderSeparatedValues) {
  for (const std::string& name : FamilyNames()) {
    const std::vector<WeightedSimplex> simplices = Family(name, 140, 41);
    std::vector<RefinedRadiusSq> keys;
    keys.reserve(simplices.size());
    for (const WeightedSimplex& s : simplices) keys.push_back(RefineWeightedRadiusSq(s.p, s.w, s.n));
    for (size_t i = 0; i < simplices.size(); ++i) {
      for (size_t j = 0; j < simplices.size(); ++j) {
        if (!keys[i].ok || !keys[j].ok) continue;
        const int exact = CompareSimplexRadiusSqRational(simplices[i].p, simplices[i].w, simplices[i].n, simplices[j].p,
                                                         simplices[j].w, simplices[j].n);
        if (RefinedKeysSeparated(keys[i], keys[j])) {
          ASSERT_LT(exact, 0) << name << "\n" << Show(simplices[i]) << "\n" << Show(simplices[j]);
        }
        // Sort words (one run) put clearly smaller values first.
        const RefinedSortWords wi = RefinedSortWordsOf(0, static_cast<uint32_t>(i), keys[i]);
        const RefinedSortWords wj = RefinedSortWordsOf(0, static_cast<uint32_t>(j), keys[j]);
        const bool words_less = std::lexicographical_compare(wi.word, wi.word + 4, wj.word, wj.word + 4);
        if (RefinedKeysSeparated(keys[i], keys[j])) {
          ASSERT_TRUE(words_less) << name << "\n" << Show(simplices[i]) << "\n" << Show(simplices[j]);
        }
      }
    }
  }
}

TEST(WeightedRadius, AttachmentIsExact) {
  int attached = 0, on_circle = 0, decided = 0;
  for (const std::string& name : FamilyNames()) {
    const std::vector<WeightedSimplex> simplices = Family(name, 3000, 53);
    for (const WeightedSimplex& s : simplices) {
      if (s.n != 3) continue;
      for (int k = 0; k < 3; ++k) {
        const int a = k, b = (k + 1) % 3, c = (k + 2) % 3;
        const int got = WeightedAttachedSign(s.p[a], s.p[b], s.p[c], s.w[a], s.w[b], s.w[c]);
        ASSERT_NE(got, 2) << name << " " << Show(s);  // undecided only far outside these ranges
        ++decided;
        const int expected = WeightedAttachedSignRational(s.p[a], s.p[b], s.p[c], s.w[a], s.w[b], s.w[c]);
        ASSERT_EQ(got, expected) << name << " edge " << a << b << " " << Show(s);
        attached += got > 0;
        on_circle += got == 0;
        const double w3[3] = {s.w[a], s.w[b], s.w[c]};
        ASSERT_EQ(SimplexAttachedSign(s.p[a], s.p[b], s.p[c], w3), got);
      }
    }
  }
  EXPECT_GT(decided, 10000);
  EXPECT_GT(attached, 500);
  EXPECT_GT(on_circle, 10);  // grid power ties: the third vertex on the orthogonal circle
}

TEST(WeightedRadius, ZeroWeightAttachmentIsTheDiametralTest) {
  for (const WeightedSimplex& s : Family("grid", 2000, 61)) {
    if (s.n != 3) continue;
    EXPECT_EQ(WeightedAttachedSign(s.p[0], s.p[1], s.p[2], 0.0, 0.0, 0.0),
              InDiametralCircleSign(s.p[0], s.p[1], s.p[2]))
        << Show(s);
  }
}

}  // namespace
}  // namespace galpha
