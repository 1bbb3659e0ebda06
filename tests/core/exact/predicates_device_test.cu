// The predicates must take the same decisions on the GPU as on the host: every result, the plain
// approximations and the exact expansions' components are compared bit for bit on adversarial
// inputs (near-degenerate, exactly degenerate, offset, tiny, subnormal, mixed magnitudes).
#include <cuda_runtime.h>
#include <gtest/gtest.h>
#include <thrust/device_vector.h>
#include <thrust/host_vector.h>
#include <thrust/transform.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "core/exact/attachment.hpp"
#include "core/exact/predicates.hpp"

namespace galpha {
namespace {

struct Case {
  Point2 p[4];
  uint32_t id[4];
};

struct Result {
  int orient, incircle, orient_sos, incircle_sos;
  int orient_len, incircle_len, diametral, diametral_len;
  double orient_approx, incircle_approx;
  double orient_exp[exact::kOrient2dExpansionCapacity];
  double incircle_exp[exact::kInCircleExpansionCapacity];
  double diametral_exp[exact::kDiametralExpansionCapacity];
};

struct Evaluate {
  GALPHA_HD Result operator()(const Case& c) const {
    Result r;
    for (int i = 0; i < exact::kOrient2dExpansionCapacity; ++i) r.orient_exp[i] = 0.0;
    for (int i = 0; i < exact::kDiametralExpansionCapacity; ++i) r.diametral_exp[i] = 0.0;
    for (int i = 0; i < exact::kInCircleExpansionCapacity; ++i) r.incircle_exp[i] = 0.0;
    const Point2 a = c.p[0], b = c.p[1], cc = c.p[2], d = c.p[3];
    r.orient = Orient2dSign(a, b, cc);
    r.incircle = InCircleSign(a, b, cc, d);
    r.orient_sos = Orient2dSoS(a, c.id[0], b, c.id[1], cc, c.id[2]);
    r.incircle_sos = InCircleSoS(a, c.id[0], b, c.id[1], cc, c.id[2], d, c.id[3]);
    r.orient_approx = Orient2dApprox(a, b, cc);
    r.incircle_approx = InCircleApprox(a, b, cc, d);
    r.orient_len = exact::Orient2dExpansion(a, b, cc, r.orient_exp);
    r.incircle_len = exact::InCircleExpansion(a, b, cc, d, r.incircle_exp);
    r.diametral = InDiametralCircleSign(a, b, cc);
    r.diametral_len = exact::DiametralDotExpansion(a, b, cc, r.diametral_exp);
    return r;
  }
};

std::vector<Case> MakeCases() {
  std::mt19937_64 rng(7);
  auto U = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  auto I = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  auto mixed = [&](int emin, int emax) {
    const double v = std::ldexp(U(1.0, 2.0), I(emin, emax));
    return I(0, 1) ? v : -v;
  };
  auto nudge = [&](double v, int ulps) {
    for (int k = I(-ulps, ulps); k != 0; k += k > 0 ? -1 : 1) v = std::nextafter(v, k > 0 ? 1e308 : -1e308);
    return v;
  };
  // Integer points on x^2 + y^2 = 25^2 (cocircular, and collinear triples among them).
  std::vector<Point2> circle;
  for (int x = -25; x <= 25; ++x) {
    for (int y = -25; y <= 25; ++y) {
      if (x * x + y * y == 625) circle.push_back({double(x), double(y)});
    }
  }
  std::vector<Case> cases;
  for (int i = 0; i < 10000; ++i) {
    Case c;
    const int family = i % 10;
    for (int k = 0; k < 4; ++k) {
      Point2& p = c.p[k];
      switch (family) {
        case 0:
          p = {U(-1, 1), U(-1, 1)};
          break;
        case 1:
          p = circle[I(0, int(circle.size()) - 1)];
          break;  // cocircular
        case 2:
          p = {double(I(-3, 3)), double(I(-3, 3))};
          break;  // grid
        case 3:
          p = {1e15 + I(-100, 100), -1e15 + I(-100, 100)};
          break;  // offset
        case 4:
          p = {std::ldexp(double(I(-40, 40)), -1074), std::ldexp(double(I(-40, 40)), -1074)};
          break;
        case 5:
          p = {mixed(-215, 219), mixed(-215, 219)};
          break;   // mixed
        case 6: {  // near a circle, then scaled far down / far up
          const double t = U(0, 6.283185307179586);
          p = {nudge(std::cos(t), 1) * 1e-300, nudge(std::sin(t), 1) * 1e-300};
          if (i % 16 == 6) p = {std::ldexp(p.x, 2000), std::ldexp(p.y, 2000)};
          break;
        }
        case 8: {  // near a unit circle around (12, 12): exact differences, the filter often fails
          const double t = U(0, 6.283185307179586);
          p = {nudge(12 + std::cos(t), 2), nudge(12 + std::sin(t), 2)};
          break;
        }
        case 9: {  // near a unit circle around the origin: rounded differences with tails, which the
                   // double-double stage decides
          const double t = U(0, 6.283185307179586);
          p = {nudge(std::cos(t), 2), nudge(std::sin(t), 2)};
          break;
        }
        default:
          p = circle[I(0, int(circle.size()) - 1)];  // shifted
          p = {std::ldexp(p.x, -1000), std::ldexp(p.y, -1000) + 0x1p-990};
      }
    }
    if (family == 0 && i % 16 == 0) {  // near-collinear first three points
      const double t = U(-2, 3);
      c.p[2] = {nudge(c.p[0].x + t * (c.p[1].x - c.p[0].x), 2), nudge(c.p[0].y + t * (c.p[1].y - c.p[0].y), 2)};
    }
    for (int k = 0; k < 4; ++k) {
      c.id[k] = static_cast<uint32_t>(rng()) & ~3u;
      c.id[k] |= static_cast<uint32_t>(k);  // distinct
    }
    cases.push_back(c);
  }
  return cases;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(PredicatesDevice, BitIdenticalToHost) {
  int devices = 0;
  if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0) {
    GTEST_SKIP() << "no CUDA device";
  }
  const std::vector<Case> cases = MakeCases();
  const thrust::device_vector<Case> d_cases(cases.begin(), cases.end());
  thrust::device_vector<Result> d_results(cases.size());
  thrust::transform(d_cases.begin(), d_cases.end(), d_results.begin(), Evaluate{});
  ASSERT_EQ(cudaDeviceSynchronize(), cudaSuccess);
  const thrust::host_vector<Result> device = d_results;
  int degenerate = 0;
  for (size_t i = 0; i < cases.size(); ++i) {
    const Result h = Evaluate{}(cases[i]);
    const Result& g = device[i];
    SCOPED_TRACE(testing::Message() << "case " << i);
    ASSERT_EQ(g.orient, h.orient);
    ASSERT_EQ(g.incircle, h.incircle);
    ASSERT_EQ(g.orient_sos, h.orient_sos);
    ASSERT_EQ(g.incircle_sos, h.incircle_sos);
    ASSERT_NE(g.orient_sos, 0);
    ASSERT_NE(g.incircle_sos, 0);
    ASSERT_TRUE(SameBits(g.orient_approx, h.orient_approx));
    ASSERT_TRUE(SameBits(g.incircle_approx, h.incircle_approx));
    ASSERT_EQ(g.orient_len, h.orient_len);
    ASSERT_EQ(g.incircle_len, h.incircle_len);
    ASSERT_EQ(std::memcmp(g.orient_exp, h.orient_exp, sizeof h.orient_exp), 0);
    ASSERT_EQ(std::memcmp(g.incircle_exp, h.incircle_exp, sizeof h.incircle_exp), 0);
    ASSERT_EQ(g.diametral, h.diametral);
    ASSERT_EQ(g.diametral_len, h.diametral_len);
    ASSERT_EQ(std::memcmp(g.diametral_exp, h.diametral_exp, sizeof h.diametral_exp), 0);
    degenerate += h.incircle == 0;
  }
  EXPECT_GT(degenerate, 500);  // the SoS paths ran on the device too
}

}  // namespace
}  // namespace galpha
