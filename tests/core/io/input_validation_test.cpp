// The input domain (core/io/input_validation.hpp) at its edges, against an independent oracle that
// decides membership with exact rationals: every |coordinate| < 2^500 and, with magnitudes below
// 2^-1022 counting as 2^-1022, largest / smallest nonzero < 2^437.
#include "core/io/input_validation.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "tests/support/input_domain_oracle.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::IsOk;
using testing::StatusIs;

bool InDomainOracle(const std::vector<Point2>& points) { return testing::InInputDomain(points.data(), points.size()); }

void ExpectRefusedNaming(const std::vector<Point2>& points, size_t index, const std::string& bound) {
  const absl::Status status = ValidatePoints(points);
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
  const std::string message(status.message());
  EXPECT_EQ(message.rfind("point " + std::to_string(index) + " ", 0), 0u) << message;
  EXPECT_NE(message.find(bound), std::string::npos) << message;
}

TEST(InputDomain, TheReportedOverflowIsRefused) {
  // Overflowed inside the predicates and came out collinear (0 triangles) with an OK status.
  const std::vector<Point2> big = {{1e308, 1e308}, {-1e308, 1e308}, {0, -1e308}, {1e308, -1e308}, {0, 0}};
  ExpectRefusedNaming(big, 0, "2^500");
  ASSERT_FALSE(InDomainOracle(big));
}

TEST(InputDomain, LargestMagnitudeEdge) {
  const double below = std::nextafter(kMaxAbsCoordinate, 0.0);
  EXPECT_THAT(ValidatePoints({{below, -below}, {0, 0x1p100}, {-below, 1e40}}), IsOk());
  ExpectRefusedNaming({{0, 1}, {1, 2}, {3, kMaxAbsCoordinate}}, 2, "2^500");
  ExpectRefusedNaming({{0, 1}, {-kMaxAbsCoordinate, 2}, {1e308, 1}}, 1, "2^500");
  ExpectRefusedNaming({{0, 1}, {1, std::numeric_limits<double>::max()}}, 1, "2^500");
}

TEST(InputDomain, SpreadEdge) {
  // 1 and 2^-437: a spread of exactly 2^437 is out; one ulp less is in.
  ExpectRefusedNaming({{1, 0}, {0.5, 0.25}, {0x1p-437, 1}}, 2, "2^437");
  EXPECT_THAT(ValidatePoints({{1, 0}, {0.5, 0.25}, {std::nextafter(0x1p-437, 1.0), 1}}), IsOk());
  // The message names the largest magnitude's point as well.
  const absl::Status status = ValidatePoints({{1e-140, 0}, {0.5, 0.25}, {3, 1}});
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(std::string(status.message()).find("(point 2 "), std::string::npos) << status.message();
  // Zeros take no part: exact zeros beside any magnitude are fine.
  EXPECT_THAT(ValidatePoints({{0, 0}, {0, 1e150}, {-1e150, 0}, {0, 0}}), IsOk());
}

TEST(InputDomain, SubnormalsCountAsTheSmallestNormal) {
  const double denorm = std::numeric_limits<double>::denorm_min();
  // All subnormal: any mix is in (the spread is at most 1).
  EXPECT_THAT(ValidatePoints({{denorm, 0}, {0, 3 * denorm}, {0x1p-1030, -denorm}}), IsOk());
  // Subnormals beside magnitudes up to 2^-585 (exclusive) are in, at 2^-585 out.
  EXPECT_THAT(ValidatePoints({{denorm, 0}, {std::nextafter(0x1p-585, 0.0), 1e-320}}), IsOk());
  ExpectRefusedNaming({{0x1p-585, 0}, {denorm, 1e-320}}, 1, "2^437");
  // Smallest normal and the largest allowed: far out.
  ExpectRefusedNaming({{0x1p-1022, 1}, {1, 1e150}}, 0, "2^437");
}

TEST(InputDomain, NonFiniteIsNamedFirst) {
  ExpectRefusedNaming({{0, 0}, {1e308, 0}, {std::nan(""), 1}}, 2, "not finite");
  ExpectRefusedNaming({{0, 0}, {-INFINITY, 0}}, 1, "not finite");
}

// Random sets over the whole double range, biased towards the edges, against the oracle.
TEST(InputDomain, MatchesTheExactOracleOnRandomSets) {
  std::mt19937_64 rng(20261125);
  std::uniform_int_distribution<int> exponent(-1080, 1030), count(1, 6), pick(0, 9);
  std::uniform_real_distribution<double> mantissa(0.5, 1.0);
  int refused = 0, accepted = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    // Each trial draws its exponents from a window, so that many sets sit near the bounds.
    const int center = exponent(rng);
    const int width = std::uniform_int_distribution<int>(0, 480)(rng);
    std::vector<Point2> points(static_cast<size_t>(count(rng)));
    for (Point2& p : points) {
      for (double* c : {&p.x, &p.y}) {
        const int k = pick(rng);
        if (k == 0) {
          *c = 0.0;
        } else {
          const int e = center + std::uniform_int_distribution<int>(-width / 2, width / 2)(rng);
          *c = std::ldexp(mantissa(rng), e) * (k % 2 == 0 ? 1.0 : -1.0);  // may round to 0 or inf
          if (!std::isfinite(*c)) *c = std::numeric_limits<double>::max();
        }
      }
    }
    const bool in = InDomainOracle(points);
    const absl::Status status = ValidatePoints(points);
    ASSERT_EQ(status.ok(), in) << status << " trial " << trial;
    if (!in) {
      ASSERT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
    }
    (in ? accepted : refused)++;
  }
  // Both outcomes occur often, or the test would not test the edge.
  EXPECT_GT(accepted, 2000);
  EXPECT_GT(refused, 2000);
}

}  // namespace
}  // namespace galpha
