// The area curve and area-ratio thresholds against exact rational areas: every level's certified
// bound holds, and LevelForAreaRatio answers the smallest level whose exact regularized area is at
// least ratio times the hull's, for ratios on both sides of every level's own ratio (1 ulp apart,
// where only the exact fallback can decide), on inputs of every hard kind.
#include <gmpxx.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/family/alpha_family.hpp"
#include "core/family/area_ratio.hpp"
#include "core/family/threshold.hpp"
#include "gtest/gtest.h"
#include "tests/gpu/alpha/alpha_family_fixture.hpp"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::Case;
using testing::IsOk;
using testing::StatusIs;

std::vector<Case> AreaCases() {
  using namespace gen;
  return {
      {"uniform", Uniform(400, 61)},
      {"grid", Grid(400, 62)},
      {"circle", Circle(400, 63)},
      {"clustered", Clustered(400, 64)},
      {"duplicates", WithDuplicates(400, 65)},
      {"huge_offset", HugeOffset(400, 66, 1e9)},
      {"tiny", Tiny(400, 67)},
      {"two_lines", TwoLines(400, 68)},
      {"ulp_lattice", UlpLattice(400, 69)},
      {"collinear", {{0, 0}, {1, 1}, {2, 2}, {3, 3}}},
  };
}

mpq_class TriangleArea(const AlphaFamily& f, uint32_t t) {
  const Point2 a = f.points()[f.triangles()[t][0]], b = f.points()[f.triangles()[t][1]],
               c = f.points()[f.triangles()[t][2]];
  const mpq_class twice = (mpq_class(b.x) - mpq_class(a.x)) * (mpq_class(c.y) - mpq_class(a.y)) -
                          (mpq_class(b.y) - mpq_class(a.y)) * (mpq_class(c.x) - mpq_class(a.x));
  return abs(twice) / 2;
}

/// Exact regularized area at every level 0..K: the born triangles' areas summed by birth rank.
std::vector<mpq_class> ExactAreaCurve(const AlphaFamily& f) {
  std::vector<mpq_class> curve(static_cast<size_t>(f.max_level()) + 1, 0);
  for (uint32_t t = 0; t < f.triangles().size(); ++t) {
    const uint32_t rank = f.ranks().tri_rank[t];
    if (rank != kNeverRank) curve[rank] += TriangleArea(f, t);
  }
  for (size_t level = 1; level < curve.size(); ++level) curve[level] += curve[level - 1];
  return curve;
}

mpq_class Pow2(int e) {
  mpq_class p = 1;
  if (e >= 0) {
    mpz_mul_2exp(p.get_num_mpz_t(), p.get_num_mpz_t(), static_cast<mp_bitcnt_t>(e));
  } else {
    mpz_mul_2exp(p.get_den_mpz_t(), p.get_den_mpz_t(), static_cast<mp_bitcnt_t>(-e));
  }
  return p;
}

/// The smallest level whose exact area is >= ratio * hull.
int64_t ExpectedLevel(const std::vector<mpq_class>& curve, double ratio) {
  const mpq_class need = mpq_class(ratio) * curve.back();
  return std::lower_bound(curve.begin(), curve.end(), need) - curve.begin();
}

using AreaRatioTest = testing::AlphaFamilyTest;

TEST_P(AreaRatioTest, CurveIsCertifiedAndTight) {
  for (const Case& c : AreaCases()) {
    SCOPED_TRACE(c.name);
    absl::StatusOr<AlphaFamily> built = Build(c.points);
    ASSERT_THAT(built, IsOk());
    const AlphaFamily& f = *built;
    const AlphaRanks& r = f.ranks();
    const std::vector<mpq_class> exact = ExactAreaCurve(f);
    ASSERT_EQ(r.area_units.size(), exact.size());
    const mpq_class unit = Pow2(r.area_scale.unit_log2);
    const mpq_class bound = mpq_class(static_cast<unsigned long>(r.area_scale.error_units)) * unit;
    for (size_t level = 0; level < exact.size(); ++level) {
      const mpq_class curve = mpq_class(static_cast<unsigned long>(r.area_units[level])) * unit;
      ASSERT_LE(abs(curve - exact[level]), bound) << "level " << level;
    }
    EXPECT_EQ(r.area_units[0], 0u);
    if (exact.back() > 0) {
      // Not a vacuous bound: within 1e-9 of the hull's area (it is about 1e-12 here).
      EXPECT_LT(bound, exact.back() / 1000000000) << "error bound " << bound.get_d();
      EXPECT_NEAR(HullAreaApprox(f), exact.back().get_d(), 1e-9 * exact.back().get_d());
    } else {
      EXPECT_EQ(HullAreaApprox(f), 0.0);
    }
  }
}

TEST_P(AreaRatioTest, RatioLevelIsTheExactSmallest) {
  for (const Case& c : AreaCases()) {
    SCOPED_TRACE(c.name);
    absl::StatusOr<AlphaFamily> built = Build(c.points);
    ASSERT_THAT(built, IsOk());
    const AlphaFamily& f = *built;
    const std::vector<mpq_class> exact = ExactAreaCurve(f);
    std::vector<double> ratios = {0.0, 1e-300, 0.1, 0.25, 0.5, 0.75, 0.9, 0.99, 1.0};
    if (exact.back() > 0) {
      // Each level's own ratio and its neighbouring doubles: the filter cannot tell them apart.
      for (size_t level = 1; level < exact.size(); level += std::max<size_t>(1, exact.size() / 40)) {
        const double own = mpq_class(exact[level] / exact.back()).get_d();
        for (double ratio : {own, std::nextafter(own, 0.0), std::nextafter(own, 2.0)}) {
          if (ratio <= 1.0) ratios.push_back(ratio);
        }
      }
    }
    for (double ratio : ratios) {
      const absl::StatusOr<int64_t> level = LevelForAreaRatio(f, ratio);
      ASSERT_THAT(level, IsOk());
      ASSERT_EQ(*level, ExpectedLevel(exact, ratio)) << "ratio " << ratio;
    }
    // Through the shared threshold: the published alpha_sq is the level's spectrum value.
    const absl::StatusOr<ResolvedThreshold> resolved = ResolveThreshold(f, Threshold{Threshold::Kind::kRatio, 0.5, 0});
    ASSERT_THAT(resolved, IsOk());
    EXPECT_EQ(resolved->level, ExpectedLevel(exact, 0.5));
    EXPECT_EQ(resolved->alpha_sq, PublishedAlphaSq(f, resolved->level));
  }
}

TEST_P(AreaRatioTest, RatioOutsideZeroToOneIsRefused) {
  absl::StatusOr<AlphaFamily> built = Build(gen::Uniform(50, 70));
  ASSERT_THAT(built, IsOk());
  for (double ratio : {-0.1, 1.5, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    EXPECT_THAT(LevelForAreaRatio(*built, ratio),
                StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("outside 0..1")))
        << ratio;
  }
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(AreaRatioTest);

}  // namespace
}  // namespace galpha
