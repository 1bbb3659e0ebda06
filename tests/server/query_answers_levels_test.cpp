// Thresholds resolved to the family's levels (the in-process AlphaFamily is the oracle), the
// refusal of bad thresholds, the enum conversions and the build summary.
#include "server/query_answers.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "absl/strings/str_cat.h"
#include "core/family/area_ratio.hpp"
#include "core/family/threshold.hpp"
#include "gtest/gtest.h"
#include "tests/server/query_answers_fixture.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using testing::Alpha;
using testing::AlphaSq;
using testing::Families;
using testing::NamedFamily;
using testing::Rank;
using testing::Ratio;
using testing::ResolveOn;
using testing::Thresholds;

// ---- ResolveLevel ---------------------------------------------------------------------------------

TEST(QueryAnswersTest, ResolveLevelMatchesTheFamily) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = *f.oracle;
    const int64_t k = family.max_level();
    for (int64_t rank = 0; rank <= k; rank += std::max<int64_t>(1, k / 50)) {
      const absl::StatusOr<ResolvedLevel> resolved = ResolveLevel(f.cached->reader(), Rank(rank));
      ASSERT_THAT(resolved, IsOk());
      EXPECT_EQ(resolved->level, *family.LevelForRank(rank));
      EXPECT_EQ(resolved->alpha_sq, rank == 0 ? 0.0 : family.spectrum()[static_cast<size_t>(rank - 1)]);
    }
    for (const v1::Threshold& threshold : Thresholds(family)) {
      SCOPED_TRACE(threshold.ShortDebugString());
      const absl::StatusOr<ResolvedLevel> resolved = ResolveLevel(f.cached->reader(), threshold);
      ASSERT_THAT(resolved, IsOk());
      switch (threshold.value_case()) {
        case v1::Threshold::kRank:
          EXPECT_EQ(resolved->level, *family.LevelForRank(threshold.rank()));
          break;
        case v1::Threshold::kAlphaSq:
          EXPECT_EQ(resolved->level, *family.LevelForAlphaSq(threshold.alpha_sq()));
          EXPECT_EQ(resolved->alpha_sq, threshold.alpha_sq());
          break;
        case v1::Threshold::kAlpha:
          EXPECT_EQ(resolved->level, *family.LevelForAlpha(threshold.alpha()));
          EXPECT_EQ(resolved->alpha_sq, threshold.alpha() * threshold.alpha());
          break;
        case v1::Threshold::kRatio:
          EXPECT_EQ(resolved->level, *LevelForAreaRatio(family, threshold.ratio()));
          EXPECT_EQ(resolved->alpha_sq, PublishedAlphaSq(family, resolved->level));
          break;
        case v1::Threshold::VALUE_NOT_SET:
          FAIL();
      }
    }
    // Every spectrum value, as alpha_sq, resolves to its own rank (exact comparison).
    for (int64_t rank = 1; rank <= k; rank += std::max<int64_t>(1, k / 50)) {
      const absl::StatusOr<ResolvedLevel> resolved =
          ResolveLevel(f.cached->reader(), AlphaSq(family.spectrum()[static_cast<size_t>(rank - 1)]));
      ASSERT_THAT(resolved, IsOk());
      EXPECT_EQ(resolved->level, *family.LevelForAlphaSq(family.spectrum()[static_cast<size_t>(rank - 1)]));
    }
  }
}

TEST(QueryAnswersTest, ResolveLevelRefusesBadThresholds) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = *f.oracle;
    const int64_t k = family.max_level();
    const absl::StatusOr<ResolvedLevel> none = ResolveLevel(f.cached->reader(), v1::Threshold());
    EXPECT_THAT(none.status(), StatusIs(absl::StatusCode::kInvalidArgument));
    const absl::StatusOr<ResolvedLevel> beyond = ResolveLevel(f.cached->reader(), Rank(k + 1));
    EXPECT_THAT(beyond.status(), StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_THAT(ResolveLevel(f.cached->reader(), Ratio(1.5)).status(),
                StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("outside 0..1")));
    EXPECT_NE(beyond.status().message().find(absl::StrCat(k + 1)), absl::string_view::npos) << beyond.status();
    EXPECT_THAT(ResolveLevel(f.cached->reader(), Rank(-1)).status(), StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_THAT(ResolveLevel(f.cached->reader(), AlphaSq(std::nan(""))).status(),
                StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_THAT(ResolveLevel(f.cached->reader(), Alpha(std::nan(""))).status(),
                StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_THAT(ResolveLevel(f.cached->reader(), Alpha(-1.0)).status(), StatusIs(absl::StatusCode::kInvalidArgument));
  }
}

TEST(QueryAnswersTest, EnumConversions) {
  EXPECT_EQ(*ToClassifyMode(v1::CLASSIFY_MODE_UNSPECIFIED), ClassifyMode::kGeneral);
  EXPECT_EQ(*ToClassifyMode(v1::CLASSIFY_MODE_GENERAL), ClassifyMode::kGeneral);
  EXPECT_EQ(*ToClassifyMode(v1::CLASSIFY_MODE_REGULARIZED), ClassifyMode::kRegularized);
  EXPECT_EQ(*ToVertexRule(v1::VERTEX_RULE_UNSPECIFIED), VertexRule::kReport);
  EXPECT_EQ(*ToVertexRule(v1::VERTEX_RULE_REPORT), VertexRule::kReport);
  EXPECT_EQ(*ToVertexRule(v1::VERTEX_RULE_CGAL), VertexRule::kCgal);
}

// proto3 enums are open: a number the enum does not define arrives as is, and must not silently
// mean the default.
TEST(QueryAnswersTest, UnknownEnumValuesAreRefusedByName) {
  EXPECT_THAT(ToClassifyMode(static_cast<v1::ClassifyMode>(7)).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("mode 7")));
  EXPECT_THAT(ToVertexRule(static_cast<v1::VertexRule>(-3)).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("vertex_rule -3")));
}

TEST(QueryAnswersTest, BuildSummaryDescribesTheFamily) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = *f.oracle;
    v1::BuildSummary summary;
    FillBuildSummary(*f.cached, &summary);
    EXPECT_EQ(summary.name(), "") << "a family keeps no caller's name";
    EXPECT_EQ(summary.points(), family.points().size());
    EXPECT_EQ(summary.distinct_points(), family.num_unique());
    EXPECT_EQ(summary.duplicates(), family.num_duplicates());
    EXPECT_EQ(summary.distinct_points() + summary.duplicates(), summary.points());
    EXPECT_EQ(summary.triangles(), family.triangles().size());
    EXPECT_EQ(summary.edges(), family.edges().size());
    EXPECT_EQ(summary.spectrum_size(), family.spectrum().size());
    EXPECT_EQ(summary.backend(), family.report().backend);
    EXPECT_EQ(summary.family_bytes(), f.cached->bytes());
    EXPECT_EQ(static_cast<size_t>(summary.stage_times_size()), family.report().stage_times.size());
  }
}

}  // namespace
}  // namespace galpha::server
