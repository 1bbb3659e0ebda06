// Radix-sortable words of refined keys (core/exact/refined_sort_words.hpp) against exact GMP
// rationals: the truncation stays within its stated bound of the key's value, and the words order
// every pair of keys that RefinedKeysSeparated separates, on lattice near ties, on hand-made keys
// at the renormalization edge (hi = 1 with a negative tail) and with subnormal tails.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "core/exact/radius_refined.hpp"
#include "core/exact/refined_sort_words.hpp"
#include "tests/core/exact/simplex_samples.hpp"

namespace galpha {
namespace {

using testing_support::Ulps;

mpq_class TimesPow2(mpq_class value, int64_t e) {
  if (e >= 0) {
    mpq_mul_2exp(value.get_mpq_t(), value.get_mpq_t(), static_cast<mp_bitcnt_t>(e));
  } else {
    mpq_div_2exp(value.get_mpq_t(), value.get_mpq_t(), static_cast<mp_bitcnt_t>(-e));
  }
  return value;
}

// (hi + mid + lo) 2^exponent, exactly.
mpq_class KeyValue(const RefinedRadiusSq& key) {
  return TimesPow2(mpq_class(key.hi) + mpq_class(key.mid) + mpq_class(key.lo), key.exponent);
}

// What the words say, decoded independently: the exponent E from word 0 and T = (1 + f 2^-160) 2^E.
struct Decoded {
  uint32_t run;
  int64_t exponent;
  mpq_class value;
  uint32_t id;
};

Decoded Decode(const RefinedSortWords& w) {
  Decoded d;
  d.run = static_cast<uint32_t>(w.word[0] >> 32);
  d.exponent = static_cast<int64_t>(w.word[0] & 0xffffffffu) - (int64_t{1} << 31);
  mpz_class f(std::to_string(w.word[1]));
  f = f * mpz_class("18446744073709551616") + mpz_class(std::to_string(w.word[2]));
  f = f * mpz_class(4294967296u) + mpz_class(static_cast<unsigned long>(w.word[3] >> 32));
  mpz_class one = 1;
  mpz_mul_2exp(one.get_mpz_t(), one.get_mpz_t(), 160);
  d.value = TimesPow2(mpq_class(one + f, one), d.exponent);
  d.id = static_cast<uint32_t>(w.word[3] & 0xffffffffu);
  return d;
}

bool WordsLess(const RefinedSortWords& a, const RefinedSortWords& b) {
  for (int i = 0; i < 4; ++i) {
    if (a.word[i] != b.word[i]) return a.word[i] < b.word[i];
  }
  return false;
}

// Refined keys of lattice simplices nudged by a few ulps (the inputs this sort exists for), plus
// hand-made keys at the edges of the conversion.
std::vector<RefinedRadiusSq> SampleKeys() {
  std::vector<RefinedRadiusSq> keys;
  std::mt19937_64 rng(20261125);
  std::uniform_int_distribution<int> cell(0, 99), nudge(-3, 3), kind(0, 2);
  for (int c = 0; c < 3000; ++c) {
    const int i = cell(rng), j = cell(rng);
    const double h = 0.1, offset = 1000.0;
    auto at = [&](int di, int dj) {
      return Point2{Ulps(offset + h * (i + di), nudge(rng)), Ulps(offset + h * (j + dj), nudge(rng))};
    };
    Point2 p[3];
    int n = 3;
    switch (kind(rng)) {
      case 0:
        p[0] = at(0, 0), p[1] = at(1, 0), p[2] = at(0, 1);
        break;
      case 1:
        p[0] = at(0, 0), p[1] = at(1, 1), n = 2;
        break;
      default:
        p[0] = at(0, 0), p[1] = at(1, 0), p[2] = at(1, 1);
        break;
    }
    const RefinedRadiusSq key = RefineRadiusSq(p, n);
    if (key.ok) keys.push_back(key);
  }
  // hi = 1 with a negative tail (m < 1: renormalized one bit up), subnormal and mixed-sign tails,
  // the largest mantissa, and binade neighbours.
  auto make = [](int32_t e, double hi, double mid, double lo) {
    RefinedRadiusSq key;
    key.exponent = e;
    key.hi = hi;
    key.mid = mid;
    key.lo = lo;
    key.ok = true;
    return key;
  };
  const double below_one = std::nextafter(1.0, 0.0);
  keys.push_back(make(5, 1.0, -0x1p-60, 0x1p-120));
  keys.push_back(make(5, 1.0, -0x1p-60, -0x1p-170));
  keys.push_back(make(4, std::nextafter(2.0, 0.0), 0x1p-54, 0x1p-110));
  keys.push_back(make(4, std::nextafter(2.0, 0.0), 0x1p-54, -0x1p-1074));
  keys.push_back(make(5, 1.0, 0.0, 0x1p-1074));
  keys.push_back(make(5, 1.0, 0.0, 0.0));
  keys.push_back(make(5, 1.0, -0x1p-53, 0x1p-155));
  keys.push_back(make(-3000, 1.5, 0x1p-80, -0x1p-140));
  keys.push_back(make(3000, 1.5, -0x1p-80, 0x1p-140));
  keys.push_back(make(4, below_one * 2.0, 0.0, 0.0));
  return keys;
}

TEST(RefinedSortWordsTest, TruncationIsWithinItsBound) {
  for (const RefinedRadiusSq& key : SampleKeys()) {
    const RefinedSortWords w = RefinedSortWordsOf(7, 42, key);
    const Decoded d = Decode(w);
    ASSERT_EQ(d.run, 7u);
    ASSERT_EQ(d.id, 42u);
    const mpq_class exact = KeyValue(key);
    const mpq_class error = abs(d.value - exact);
    // The stated bound: 3 units of 2^-160 at T's exponent, and T's mantissa in [1, 2).
    ASSERT_LT(error, TimesPow2(mpq_class(3), d.exponent - 160)) << key.hi << " " << key.mid << " " << key.lo;
    ASSERT_GE(d.value, TimesPow2(mpq_class(1), d.exponent));
    ASSERT_LT(d.value, TimesPow2(mpq_class(2), d.exponent));
  }
}

TEST(RefinedSortWordsTest, SeparatedKeysAreInWordOrder) {
  const std::vector<RefinedRadiusSq> keys = SampleKeys();
  std::vector<RefinedSortWords> words;
  std::vector<mpq_class> values;
  std::vector<int64_t> exponents;
  for (size_t i = 0; i < keys.size(); ++i) {
    words.push_back(RefinedSortWordsOf(3, static_cast<uint32_t>(i), keys[i]));
    values.push_back(KeyValue(keys[i]));
    exponents.push_back(Decode(words.back()).exponent);
  }
  size_t separated = 0, near = 0;
  for (size_t i = 0; i < keys.size(); ++i) {
    for (size_t j = i % 7; j < keys.size(); j += 7) {
      if (RefinedKeysSeparated(keys[i], keys[j])) {
        ++separated;
        ASSERT_TRUE(WordsLess(words[i], words[j])) << i << " " << j;
      }
      // Values farther apart than both truncations together order the words the same way.
      const mpq_class gap = values[j] - values[i];
      const int64_t e = std::max(exponents[i], exponents[j]);
      if (gap > TimesPow2(mpq_class(6), e - 160)) {
        if (gap < TimesPow2(mpq_class(1), e - 100)) ++near;
        ASSERT_TRUE(WordsLess(words[i], words[j])) << i << " " << j;
      }
    }
  }
  EXPECT_GT(separated, 100000u);
  EXPECT_GT(near, 100u);  // the lattice's near ties are in the sample, not only distant values
}

TEST(RefinedSortWordsTest, RunsComeFirstAndInfiniteKeysLast) {
  RefinedRadiusSq small;
  small.exponent = -5;
  small.hi = 1.25;
  small.ok = true;
  RefinedRadiusSq big = small;
  big.exponent = 900;
  RefinedRadiusSq infinite;
  infinite.ok = true;
  infinite.infinite = true;
  EXPECT_TRUE(WordsLess(RefinedSortWordsOf(1, 9, big), RefinedSortWordsOf(2, 0, small)));
  EXPECT_TRUE(WordsLess(RefinedSortWordsOf(1, 9, big), RefinedSortWordsOf(1, 0, infinite)));
  EXPECT_TRUE(WordsLess(RefinedSortWordsOf(1, 0, small), RefinedSortWordsOf(1, 1, small)));
  EXPECT_TRUE(WordsLess(RefinedSortWordsOf(1, 0, infinite), RefinedSortWordsOf(1, 1, infinite)));
}

}  // namespace
}  // namespace galpha
