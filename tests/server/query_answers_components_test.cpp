// Component curves and optimal alpha against the in-process AlphaFamily: at a threshold and over a
// range of ranks, bad requests refused.
#include "server/query_answers.hpp"

#include <algorithm>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "tests/server/query_answers_fixture.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using testing::Families;
using testing::NamedFamily;
using testing::Rank;
using testing::ResolveOn;
using testing::Thresholds;

// ---- Components / OptimalAlpha --------------------------------------------------------------------

TEST(QueryAnswersTest, ComponentsAtAThresholdAndOverARange) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = *f.oracle;
    const int64_t k = family.max_level();
    for (const v1::Threshold& threshold : Thresholds(family)) {
      SCOPED_TRACE(threshold.ShortDebugString());
      v1::ComponentsRequest request;
      *request.mutable_threshold() = threshold;
      const absl::StatusOr<v1::ComponentsResponse> response = AnswerComponents(f.cached->reader(), request);
      ASSERT_THAT(response, IsOk());
      const int64_t level = ResolveOn(family, threshold)->level;
      EXPECT_EQ(response->first_level(), level);
      ASSERT_EQ(response->components_size(), 1);
      ASSERT_EQ(response->solid_components_size(), 1);
      EXPECT_EQ(response->components(0), family.Components(level));
      EXPECT_EQ(response->solid_components(0), family.SolidComponents(level));
    }
    const std::vector<std::pair<int64_t, int64_t>> ranges = {{0, k}, {0, 0}, {k, k}, {k / 2, std::min(k, k / 2 + 3)}};
    for (const auto& [first, last] : ranges) {
      SCOPED_TRACE(absl::StrCat(first, "..", last));
      v1::ComponentsRequest request;
      request.mutable_ranks()->set_first(first);
      request.mutable_ranks()->set_last(last);
      const absl::StatusOr<v1::ComponentsResponse> response = AnswerComponents(f.cached->reader(), request);
      ASSERT_THAT(response, IsOk());
      EXPECT_EQ(response->first_level(), first);
      ASSERT_EQ(response->components_size(), last - first + 1);
      ASSERT_EQ(response->solid_components_size(), last - first + 1);
      for (int64_t level = first; level <= last; ++level) {
        EXPECT_EQ(response->components(static_cast<int>(level - first)), family.Components(level)) << level;
        EXPECT_EQ(response->solid_components(static_cast<int>(level - first)), family.SolidComponents(level)) << level;
      }
    }
  }
}

TEST(QueryAnswersTest, ComponentsRefusesBadRequests) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = *f.oracle;
    const int64_t k = family.max_level();
    EXPECT_THAT(AnswerComponents(f.cached->reader(), v1::ComponentsRequest()).status(),
                StatusIs(absl::StatusCode::kInvalidArgument));
    const std::vector<std::pair<int64_t, int64_t>> bad = {{-1, 0}, {0, k + 1}, {1, 0}, {k + 1, k + 1}, {-5, -1}};
    for (const auto& [first, last] : bad) {
      SCOPED_TRACE(absl::StrCat(first, "..", last));
      v1::ComponentsRequest request;
      request.mutable_ranks()->set_first(first);
      request.mutable_ranks()->set_last(last);
      const auto response = AnswerComponents(f.cached->reader(), request);
      EXPECT_THAT(response.status(), StatusIs(absl::StatusCode::kInvalidArgument));
    }
    v1::ComponentsRequest beyond;
    *beyond.mutable_threshold() = Rank(k + 1);
    EXPECT_THAT(AnswerComponents(f.cached->reader(), beyond).status(), StatusIs(absl::StatusCode::kInvalidArgument));
    v1::ComponentsRequest no_value;
    no_value.mutable_threshold();  // a threshold with none of its three values
    EXPECT_THAT(AnswerComponents(f.cached->reader(), no_value).status(), StatusIs(absl::StatusCode::kInvalidArgument));
  }
}

TEST(QueryAnswersTest, OptimalAlphaMatchesTheFamily) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = *f.oracle;
    for (const uint32_t n : {1u, 2u, 3u, 5u, 10u, 100u, 1000000u}) {
      SCOPED_TRACE(n);
      v1::OptimalAlphaRequest request;
      request.set_max_components(n);
      const absl::StatusOr<v1::OptimalAlphaResponse> response = AnswerOptimalAlpha(f.cached->reader(), request);
      ASSERT_THAT(response, IsOk());
      const auto published = [&](int64_t level) {
        return level == 0 ? 0.0 : family.spectrum()[static_cast<size_t>(level - 1)];
      };
      const std::optional<int64_t> regularized = family.OptimalLevelRegularized(n);
      ASSERT_EQ(response->has_regularized(), regularized.has_value());
      if (regularized) {
        EXPECT_EQ(response->regularized().rank(), *regularized);
        EXPECT_EQ(response->regularized().alpha_sq(), published(*regularized));
        EXPECT_EQ(response->regularized().components(), family.SolidComponents(*regularized));
        EXPECT_LE(response->regularized().components(), n);
      }
      const std::optional<int64_t> general = family.OptimalLevelGeneral(n);
      ASSERT_EQ(response->has_general(), general.has_value());
      if (general) {
        EXPECT_EQ(response->general().rank(), *general);
        EXPECT_EQ(response->general().alpha_sq(), published(*general));
        EXPECT_EQ(response->general().components(), family.Components(*general));
        EXPECT_LE(response->general().components(), n);
      }
    }
    const auto refused = AnswerOptimalAlpha(f.cached->reader(), v1::OptimalAlphaRequest());
    EXPECT_THAT(refused.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  }
}

}  // namespace
}  // namespace galpha::server
