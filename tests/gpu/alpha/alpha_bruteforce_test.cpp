// The alpha family against its definitions (docs/design.md, "Semantics"), computed by brute force
// with GMP rationals, independently of CGAL and of the engine (tests/support's
// bruteforce_alpha_oracle; the comparison is alpha_bruteforce_compare.cpp), on small inputs whose
// Delaunay triangulation is unique: random sets in general position at every scale, small integers
// (exact ties, right angles, collinear runs), duplicates, 0 to 3 points, collinear chains and
// hand-made degenerate sets.
#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

#include "core/base/point.hpp"
#include "gtest/gtest.h"
#include "tests/gpu/alpha/alpha_bruteforce_compare.hpp"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/bruteforce_alpha_oracle.hpp"

namespace galpha {
namespace {

using testing::BruteForce;
using testing::CompareWithBruteForce;
using testing::InGeneralPosition;

enum class Scale {
  kUnit,
  kOffset1e9,
  kTiny,
  kMixedSigns,
  kSmallIntegers,
  // The edges of the input domain (core/io/input_validation.hpp): magnitudes just below 2^500;
  // every coordinate subnormal; magnitudes spread over almost 2^437 in one set.
  kDomainTop,
  kSubnormal,
  kWidestSpread,
};

std::vector<Point2> RandomSet(std::mt19937_64& rng, size_t n, Scale scale) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (;;) {
    std::vector<Point2> points;
    for (size_t i = 0; i < n; ++i) {
      double x = unit(rng), y = unit(rng);
      switch (scale) {
        case Scale::kUnit:
          break;
        case Scale::kOffset1e9:
          x = 1e9 + 1000 * x;
          y = 1e9 + 1000 * y;
          break;
        case Scale::kTiny:
          x *= 1e-300;
          y *= 1e-300;
          break;
        case Scale::kMixedSigns:
          x = 2 * x - 1;
          y = (2 * y - 1) * 1e-3;  // flat: many obtuse triangles and attached edges
          break;
        case Scale::kDomainTop:
          x = std::ldexp(2 * x - 1, 500);  // |x| < 2^500
          y = std::ldexp(2 * y - 1, 500);
          break;
        case Scale::kSubnormal:
          // Multiples of 2^-1074 below 2^-1040: coarse enough to collide, hence the retry below.
          x = std::ldexp(std::floor(x * 0x1p34), -1074);
          y = std::ldexp(std::floor(y * 0x1p34), -1074);
          break;
        case Scale::kWidestSpread:
          // Most coordinates near 2^200; the first point's y just above 2^(200-437); one zero.
          x = std::ldexp(0.5 + x / 2, 200);
          y = i == 0 ? std::ldexp(1.0 + y, 200 - 437) : (i == 3 ? 0.0 : std::ldexp(0.5 + y / 2, 200));
          break;
        case Scale::kSmallIntegers:
          // Exact ties of lengths and radii, right angles (third vertices on diametral circles),
          // collinear runs and duplicates; kept only where the triangulation is still unique.
          x = std::floor(24 * x);
          y = std::floor(24 * y);
          break;
      }
      points.push_back({x, y});
    }
    if (scale == Scale::kSmallIntegers ? BruteForce(points).valid_triangulation : InGeneralPosition(points)) {
      return points;
    }
  }
}

using AlphaBruteForceTest = testing::BackendTest;

TEST_P(AlphaBruteForceTest, RandomGeneralPosition) {
  std::mt19937_64 rng(20240607);
  for (Scale scale : {Scale::kUnit, Scale::kOffset1e9, Scale::kTiny, Scale::kMixedSigns, Scale::kDomainTop,
                      Scale::kSubnormal, Scale::kWidestSpread}) {
    const int sets = scale == Scale::kUnit || scale == Scale::kOffset1e9 || scale == Scale::kMixedSigns ? 80 : 40;
    for (int s = 0; s < sets; ++s) {
      const size_t n = 4 + static_cast<size_t>(rng() % 11);  // 4..14
      SCOPED_TRACE(::testing::Message() << "scale " << static_cast<int>(scale) << " set " << s);
      CompareWithBruteForce(RandomSet(rng, n, scale), GetParam());
      if (HasFatalFailure()) return;
    }
  }
}

TEST_P(AlphaBruteForceTest, RandomSmallIntegersWithUniqueTriangulation) {
  std::mt19937_64 rng(4242);
  for (int s = 0; s < 150; ++s) {
    const size_t n = 4 + static_cast<size_t>(rng() % 9);  // 4..12
    SCOPED_TRACE(::testing::Message() << "set " << s);
    CompareWithBruteForce(RandomSet(rng, n, Scale::kSmallIntegers), GetParam());
    if (HasFatalFailure()) return;
  }
}

TEST_P(AlphaBruteForceTest, RandomWithDuplicates) {
  std::mt19937_64 rng(77);
  for (int s = 0; s < 60; ++s) {
    std::vector<Point2> points = RandomSet(rng, 3 + rng() % 8, Scale::kUnit);
    const size_t copies = 1 + rng() % 4;
    for (size_t c = 0; c < copies; ++c) {
      const Point2 p = points[rng() % points.size()];
      points.insert(points.begin() + static_cast<std::ptrdiff_t>(rng() % (points.size() + 1)), p);
    }
    CompareWithBruteForce(points, GetParam());
    if (HasFatalFailure()) return;
  }
}

TEST_P(AlphaBruteForceTest, SmallAndCollinear) {
  const std::vector<std::vector<Point2>> cases = {
      {},
      {{1.5, -2}},
      {{1.5, -2}, {1.5, -2}, {1.5, -2}},
      {{0, 0}, {3, 4}},
      {{3, 4}, {0, 0}, {3, 4}},
      // Collinear chains, with repeated gap lengths (ties in the spectrum) and shuffled order.
      {{0, 1}, {3, 7}, {1, 3}, {2, 5}, {5, 11}},
      {{2, 0}, {2, -1}, {2, 5}, {2, 4}, {2, 2}, {2, -1}},
      {{-1e9, 1e9}, {1e9, -1e9}, {0, 0}, {0.5, -0.5}},
      {{1e-300, 2e-300}, {3e-300, 6e-300}, {2e-300, 4e-300}},
      {{0.1, 0.1}, {0.3, 0.3}, {0.2, 0.2}, {0.7, 0.7}},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(::testing::Message() << "case " << i);
    CompareWithBruteForce(cases[i], GetParam());
    if (HasFatalFailure()) return;
  }
}

TEST_P(AlphaBruteForceTest, DegenerateButUnique) {
  const std::vector<std::vector<Point2>> cases = {
      // Three collinear and one off the line; and longer runs with points on either side.
      {{0, 0}, {1, 0}, {3, 0}, {0.7, 2.3}},
      {{3, 0}, {0.7, 2.3}, {1, 0}, {0, 0}},
      {{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}, {5, 0}, {2.5, 1.7}},
      {{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}, {1.3, 2.1}, {2.9, -1.7}},
      {{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}, {2, 0.25}},
      // A right triangle: the hypotenuse's third vertex lies on its diametral circle (unattached,
      // born together with the triangle: an exact tie).
      {{0, 0}, {2, 0}, {0, 2}},
      {{0, 0}, {2, 0}, {0, 2}, {3.1, 2.9}},
      // Isosceles (two equal edges) and obtuse (an attached edge).
      {{0, 0}, {4, 0}, {2, 3}},
      {{0, 0}, {10, 0}, {5, 1}},
      {{0, 0}, {10, 0}, {5, 1}, {5, -1.5}},
      // Exact duplicates of a degenerate set.
      {{0, 0}, {1, 0}, {3, 0}, {0.7, 2.3}, {1, 0}, {0.7, 2.3}},
      // Huge offset and tiny scale, 3 collinear and 1 off.
      {{1e9, 1e9}, {1e9 + 1, 1e9}, {1e9 + 3, 1e9}, {1e9 + 0.7, 1e9 + 2.3}},
      {{0, 0}, {1e-300, 0}, {3e-300, 0}, {7e-301, 2.3e-300}},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(::testing::Message() << "case " << i);
    CompareWithBruteForce(cases[i], GetParam());
    if (HasFatalFailure()) return;
  }
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(AlphaBruteForceTest);

}  // namespace
}  // namespace galpha
