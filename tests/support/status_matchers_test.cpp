// The status matchers themselves: each matches what it should, fails on what it should not (checked
// with gtest-spi's failure catchers, so that a matcher that cannot fail fails here), and names the
// actual status in its failure message.
#include "tests/support/status_matchers.hpp"

#include <gtest/gtest-spi.h>

#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace galpha::testing {
namespace {

using ::testing::DescribeMatcher;
using ::testing::HasSubstr;
using ::testing::Not;

absl::StatusOr<int> Value() { return 7; }
absl::StatusOr<int> Error() { return absl::InvalidArgumentError("point 3 has a NaN y coordinate"); }

TEST(StatusMatchersTest, IsOkMatchesOkStatusesAndValues) {
  EXPECT_THAT(absl::OkStatus(), IsOk());
  EXPECT_THAT(Value(), IsOk());
  ASSERT_THAT(Value(), IsOk());
  const absl::StatusOr<std::unique_ptr<int>> move_only = std::make_unique<int>(3);
  EXPECT_THAT(move_only, IsOk());
  EXPECT_THAT(absl::NotFoundError("x"), Not(IsOk()));
  EXPECT_THAT(Error(), Not(IsOk()));
}

TEST(StatusMatchersTest, IsOkFailsOnAnErrorAndPrintsIt) {
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(absl::InternalError("disk on fire"), IsOk()), "INTERNAL: disk on fire");
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(Error(), IsOk()), "INVALID_ARGUMENT: point 3 has a NaN y coordinate");
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(Error(), IsOk()), "Expected: is OK");
  EXPECT_FATAL_FAILURE(ASSERT_THAT(Error(), IsOk()), "INVALID_ARGUMENT: point 3");
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(absl::OkStatus(), Not(IsOk())), "is not OK");
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(Value(), Not(IsOk())), "whose status is OK");
}

TEST(StatusMatchersTest, StatusIsMatchesTheCode) {
  EXPECT_THAT(Error(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_THAT(Error().status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_THAT(absl::OkStatus(), StatusIs(absl::StatusCode::kOk));
  EXPECT_THAT(Value(), StatusIs(absl::StatusCode::kOk));
  EXPECT_THAT(Error(), Not(StatusIs(absl::StatusCode::kNotFound)));
  EXPECT_THAT(Value(), Not(StatusIs(absl::StatusCode::kInvalidArgument)));
}

TEST(StatusMatchersTest, StatusIsFailsOnAnotherCodeAndPrintsTheStatus) {
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(Error(), StatusIs(absl::StatusCode::kNotFound)),
                          "INVALID_ARGUMENT: point 3 has a NaN y coordinate");
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(Error(), StatusIs(absl::StatusCode::kNotFound)), "has status code NOT_FOUND");
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(Value(), StatusIs(absl::StatusCode::kInvalidArgument)), "whose status is OK");
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(absl::OkStatus(), StatusIs(absl::StatusCode::kUnavailable)),
                          "has status code UNAVAILABLE");
  EXPECT_FATAL_FAILURE(ASSERT_THAT(absl::CancelledError("stop"), StatusIs(absl::StatusCode::kAborted)),
                       "CANCELLED: stop");
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(Error(), Not(StatusIs(absl::StatusCode::kInvalidArgument))),
                          "does not have status code INVALID_ARGUMENT");
}

TEST(StatusMatchersTest, StatusIsMatchesTheMessage) {
  EXPECT_THAT(Error(), StatusIs(absl::StatusCode::kInvalidArgument, "point 3 has a NaN y coordinate"));
  EXPECT_THAT(Error(), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("NaN y")));
  EXPECT_THAT(Error(), Not(StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("NaN x"))));
  EXPECT_THAT(Error(), Not(StatusIs(absl::StatusCode::kNotFound, HasSubstr("NaN y"))));
  EXPECT_THAT(absl::OkStatus(), StatusIs(absl::StatusCode::kOk, ""));
}

TEST(StatusMatchersTest, StatusIsFailsOnAnotherMessage) {
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(Error(), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("NaN x"))),
                          "INVALID_ARGUMENT: point 3 has a NaN y coordinate");
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(Error(), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("NaN x"))),
                          "and a message that has substring \"NaN x\"");
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(Error(), StatusIs(absl::StatusCode::kInvalidArgument, "point 3")),
                          "and a message that is equal to \"point 3\"");
  // The right message under the wrong code still fails.
  EXPECT_NONFATAL_FAILURE(EXPECT_THAT(Error(), StatusIs(absl::StatusCode::kNotFound, HasSubstr("NaN y"))),
                          "has status code NOT_FOUND");
}

TEST(StatusMatchersTest, Descriptions) {
  EXPECT_EQ(DescribeMatcher<absl::Status>(IsOk()), "is OK");
  EXPECT_EQ(DescribeMatcher<absl::StatusOr<int>>(IsOk(), /*negation=*/true), "is not OK");
  EXPECT_EQ(DescribeMatcher<absl::Status>(StatusIs(absl::StatusCode::kNotFound)), "has status code NOT_FOUND");
  EXPECT_EQ(DescribeMatcher<absl::StatusOr<int>>(StatusIs(absl::StatusCode::kNotFound, "gone")),
            "has status code NOT_FOUND and a message that is equal to \"gone\"");
}

}  // namespace
}  // namespace galpha::testing
