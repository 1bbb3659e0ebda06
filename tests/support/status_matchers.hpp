// gMock matchers for absl::Status and absl::StatusOr<T> (Debian 12's Abseil 20220623 ships none):
//
//   ASSERT_THAT(built, IsOk());
//   EXPECT_THAT(s, StatusIs(absl::StatusCode::kInvalidArgument));
//   EXPECT_THAT(s, StatusIs(absl::StatusCode::kNotFound, ::testing::HasSubstr("unknown handle")));
//   EXPECT_THAT(s, ::testing::Not(IsOk()));
//
// A failure prints the status (code and message) whatever the argument's type: gtest prints an
// absl::Status itself but an absl::StatusOr<T> as raw bytes, so for the latter the matchers name
// the status in their explanation.
#pragma once

#include <gmock/gmock.h>

#include <optional>
#include <ostream>
#include <string>
#include <type_traits>
#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace galpha::testing {
namespace status_internal {

inline const absl::Status& GetStatus(const absl::Status& status) { return status; }
template <typename T>
const absl::Status& GetStatus(const absl::StatusOr<T>& status_or) {
  return status_or.status();
}

// gtest prints an absl::Status itself, an absl::StatusOr<T> only as bytes: name the latter's status.
template <typename StatusType>
void ExplainStatus(const StatusType& actual, ::testing::MatchResultListener* listener) {
  if constexpr (!std::is_same_v<StatusType, absl::Status>) *listener << "whose status is " << GetStatus(actual);
}

class IsOkMatcher {
 public:
  template <typename StatusType>
  bool MatchAndExplain(const StatusType& actual, ::testing::MatchResultListener* listener) const {
    ExplainStatus(actual, listener);
    return GetStatus(actual).ok();
  }
  void DescribeTo(std::ostream* os) const { *os << "is OK"; }
  void DescribeNegationTo(std::ostream* os) const { *os << "is not OK"; }
};

class StatusIsMatcher {
 public:
  StatusIsMatcher(absl::StatusCode code, std::optional<::testing::Matcher<const std::string&>> message)
      : code_(code), message_(std::move(message)) {}

  template <typename StatusType>
  bool MatchAndExplain(const StatusType& actual, ::testing::MatchResultListener* listener) const {
    ExplainStatus(actual, listener);
    const absl::Status& status = GetStatus(actual);
    if (status.code() != code_) return false;
    if (!message_) return true;
    ::testing::StringMatchResultListener message_listener;
    const bool matches = message_->MatchAndExplain(std::string(status.message()), &message_listener);
    if (!matches && !message_listener.str().empty()) {
      *listener << (std::is_same_v<StatusType, absl::Status> ? "whose message " : ", whose message ")
                << message_listener.str();
    }
    return matches;
  }
  void DescribeTo(std::ostream* os) const {
    *os << "has status code " << code_;
    if (message_) {
      *os << " and a message that ";
      message_->DescribeTo(os);
    }
  }
  void DescribeNegationTo(std::ostream* os) const {
    *os << "does not have status code " << code_;
    if (message_) {
      *os << " or has a message that ";
      message_->DescribeNegationTo(os);
    }
  }

 private:
  absl::StatusCode code_;
  std::optional<::testing::Matcher<const std::string&>> message_;
};

}  // namespace status_internal

/// Matches an OK absl::Status, or an absl::StatusOr<T> that holds a value.
inline ::testing::PolymorphicMatcher<status_internal::IsOkMatcher> IsOk() {
  return ::testing::MakePolymorphicMatcher(status_internal::IsOkMatcher());
}

/// Matches an absl::Status or absl::StatusOr<T> whose status code is `code`.
inline ::testing::PolymorphicMatcher<status_internal::StatusIsMatcher> StatusIs(absl::StatusCode code) {
  return ::testing::MakePolymorphicMatcher(status_internal::StatusIsMatcher(code, std::nullopt));
}

/// ... and whose message matches `message` (a string, or a matcher such as ::testing::HasSubstr).
inline ::testing::PolymorphicMatcher<status_internal::StatusIsMatcher> StatusIs(
    absl::StatusCode code, ::testing::Matcher<const std::string&> message) {
  return ::testing::MakePolymorphicMatcher(status_internal::StatusIsMatcher(code, std::move(message)));
}

}  // namespace galpha::testing
