// The warm-up lattice does what server/warm_up.hpp says it is for: distinct points, half of them
// nudged by at most 3 ulps, whose build reaches the exact radius comparisons, and whose weighted
// build hides points (the engine's removal of hidden points runs too).
#include "server/warm_up.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <utility>

#include "gpu/alpha/alpha_engine.hpp"

namespace galpha::server {
namespace {

TEST(WarmUpTest, HalfTheLatticeIsNudgedByAtMostThreeUlps) {
  const WarmUpInput input = WarmUpLattice(32);
  ASSERT_EQ(input.points.size(), 32u * 32u);
  ASSERT_EQ(input.weights.size(), input.points.size());
  std::set<std::pair<double, double>> distinct;
  int nudged = 0;
  for (int i = 0; i < 32; ++i) {
    for (int j = 0; j < 32; ++j) {
      const Point2 p = input.points[static_cast<size_t>(32 * i + j)];
      const double x = 1000.0 + i, y = 1000.0 + j;
      ASSERT_GE(p.x, x);
      ASSERT_GE(p.y, y);
      // An ulp of values in [1024, 2048) is 2^-42; below 1024, 2^-43: three of them at most.
      EXPECT_LE(p.x - x, 3 * std::ldexp(1.0, p.x < 1024 ? -43 : -42));
      EXPECT_LE(p.y - y, 3 * std::ldexp(1.0, p.y < 1024 ? -43 : -42));
      nudged += (p.x != x) + (p.y != y);
      if (i >= 16) {  // the exact half
        EXPECT_EQ(p.x, x);
        EXPECT_EQ(p.y, y);
      }
      distinct.insert({p.x, p.y});
      EXPECT_EQ(input.weights[static_cast<size_t>(32 * i + j)], i % 4 == 0 && j % 4 == 0 ? 3.0 : 0.0);
    }
  }
  EXPECT_EQ(distinct.size(), input.points.size());
  EXPECT_GT(nudged, static_cast<int>(input.points.size() / 2));  // most coordinates of the nudged half moved
}

TEST(WarmUpTest, ItsBuildsReachTheExactComparisonsAndHidePoints) {
  const WarmUpInput input = WarmUpLattice(32);
  BuildOptions options;
  options.backend = Backend::kCpu;
  absl::StatusOr<AlphaFamily> plain = BuildAlphaFamily(input.points, options);
  ASSERT_TRUE(plain.ok()) << plain.status();
  EXPECT_EQ(plain->num_duplicates(), 0u);
  EXPECT_GT(plain->report().comparisons.bounded_exact, 0u);
  absl::StatusOr<AlphaFamily> weighted = BuildWeightedAlphaFamily(input.points, input.weights, options);
  ASSERT_TRUE(weighted.ok()) << weighted.status();
  EXPECT_FALSE(weighted->HiddenPoints().empty());
}

}  // namespace
}  // namespace galpha::server
