// InDiametralCircleSign against the exact dot product in GMP rationals (doubles convert to mpq
// exactly), on random and adversarial inputs: right angles at r (exactly on the circle, Thales),
// points a few ulps off it, huge offsets with small spacing, tiny and subnormal coordinates.
#include "core/exact/attachment.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace galpha {
namespace {

struct Case {
  Point2 p, q, r;
};

int ExactSign(const Case& c) {
  const mpq_class dot =
      (mpq_class(c.p.x) - c.r.x) * (mpq_class(c.q.x) - c.r.x) + (mpq_class(c.p.y) - c.r.y) * (mpq_class(c.q.y) - c.r.y);
  return -sgn(dot);  // inside the diametral circle: negative dot product
}

std::string Show(const Case& c) {
  char text[256];
  std::snprintf(text, sizeof text, "p=(%.17g, %.17g) q=(%.17g, %.17g) r=(%.17g, %.17g)", c.p.x, c.p.y, c.q.x, c.q.y,
                c.r.x, c.r.y);
  return text;
}

double Ulps(double v, int n) {
  for (int i = 0; i < std::abs(n); ++i) v = std::nextafter(v, n > 0 ? INFINITY : -INFINITY);
  return v;
}

// r at a right angle: p = r + (a, b), q = r + k (-b, a) with small integers, so the dot product is
// exactly 0, then optionally nudged by a few ulps; the whole case scaled by 2^scale and offset.
Case RightAngle(std::mt19937_64& rng, double offset, int scale, int nudge) {
  std::uniform_int_distribution<int> small(-1000, 1000), k(1, 50), ulps(-3, 3);
  const double a = small(rng), b = small(rng), m = k(rng);
  const double rx = offset + std::ldexp(small(rng), scale), ry = offset + std::ldexp(small(rng), scale);
  Case c{{rx + std::ldexp(a, scale), ry + std::ldexp(b, scale)},
         {rx + std::ldexp(-b * m, scale), ry + std::ldexp(a * m, scale)},
         {rx, ry}};
  if (nudge != 0) {
    c.r.x = Ulps(c.r.x, ulps(rng));
    c.r.y = Ulps(c.r.y, ulps(rng));
  }
  return c;
}

std::vector<Case> Cases(const std::string& family, int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-60, 60);
  std::vector<Case> cases;
  for (int i = 0; i < n; ++i) {
    if (family == "random") {
      cases.push_back({{unit(rng), unit(rng)}, {unit(rng), unit(rng)}, {unit(rng), unit(rng)}});
    } else if (family == "mixed_magnitudes") {
      auto v = [&] { return std::ldexp(unit(rng), exponent(rng)); };
      cases.push_back({{v(), v()}, {v(), v()}, {v(), v()}});
    } else if (family == "on_circle") {
      cases.push_back(RightAngle(rng, 0.0, 0, 0));
    } else if (family == "near_circle") {
      cases.push_back(RightAngle(rng, 0.0, -20, 1));
    } else if (family == "offset_1e9") {
      cases.push_back(RightAngle(rng, 1e9, -20, i % 2));
    } else if (family == "offset_1e15") {
      cases.push_back(RightAngle(rng, 1e15, -2, i % 2));
    } else if (family == "tiny") {
      cases.push_back(RightAngle(rng, 0.0, -1000, i % 2));
    } else if (family == "subnormal") {
      cases.push_back(RightAngle(rng, 0.0, -1074, i % 2));
    }
  }
  return cases;
}

class DiametralFamily : public ::testing::TestWithParam<const char*> {};

TEST_P(DiametralFamily, MatchesGmp) {
  int on_circle = 0;
  for (const Case& c : Cases(GetParam(), 3000, 21)) {
    const int want = ExactSign(c);
    ASSERT_EQ(InDiametralCircleSign(c.p, c.q, c.r), want) << Show(c);
    ASSERT_EQ(InDiametralCircleSign(c.q, c.p, c.r), want) << "p and q swapped: " << Show(c);
    on_circle += want == 0;
  }
  // The exact families must really hit the circle, or the test proves little about ties.
  const std::string family = GetParam();
  if (family == "on_circle") {
    EXPECT_EQ(on_circle, 3000);
  } else if (family == "offset_1e9" || family == "tiny" || family == "subnormal") {
    EXPECT_GT(on_circle, 0);
  }
}

const char* const kFamilies[] = {"random",     "mixed_magnitudes", "on_circle", "near_circle",
                                 "offset_1e9", "offset_1e15",      "tiny",      "subnormal"};
INSTANTIATE_TEST_SUITE_P(All, DiametralFamily, ::testing::ValuesIn(kFamilies),
                         [](const ::testing::TestParamInfo<const char*>& info) { return std::string(info.param); });

TEST(InDiametralCircleSign, Conventions) {
  // Unit circle with diameter (-1, 0)-(1, 0): the centre is inside, (0, 1) on it, (0, 2) outside.
  const Point2 p{-1, 0}, q{1, 0};
  EXPECT_EQ(InDiametralCircleSign(p, q, {0, 0}), 1);
  EXPECT_EQ(InDiametralCircleSign(p, q, {0, 1}), 0);
  EXPECT_EQ(InDiametralCircleSign(p, q, {0, 2}), -1);
  EXPECT_EQ(InDiametralCircleSign(p, q, p), 0);  // an end point is on the circle
}

}  // namespace
}  // namespace galpha
