// Early-return helpers for absl::Status / absl::StatusOr.
//
// Debian's Abseil (20220623) ships neither RETURN_IF_ERROR nor ASSIGN_OR_RETURN, so we keep two
// small macros of our own, prefixed so that they never clash with a later Abseil's.
#pragma once

#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace galpha::status_macros_internal {

// Lets GALPHA_RETURN_IF_ERROR take either a Status or a StatusOr.
inline const absl::Status& AsStatus(const absl::Status& status) { return status; }
template <typename T>
const absl::Status& AsStatus(const absl::StatusOr<T>& status_or) {
  return status_or.status();
}

}  // namespace galpha::status_macros_internal

#define GALPHA_STATUS_MACROS_CONCAT_INNER_(a, b) a##b
#define GALPHA_STATUS_MACROS_CONCAT_(a, b) GALPHA_STATUS_MACROS_CONCAT_INNER_(a, b)

/// Evaluates `expr` (an absl::Status or absl::StatusOr) once; returns its status from the
/// enclosing function when it is not OK.
#define GALPHA_RETURN_IF_ERROR(expr)                                                                  \
  do {                                                                                                \
    ::absl::Status galpha_return_if_error_status_ = ::galpha::status_macros_internal::AsStatus(expr); \
    if (!galpha_return_if_error_status_.ok()) return galpha_return_if_error_status_;                  \
  } while (false)

/// `GALPHA_ASSIGN_OR_RETURN(lhs, expr)`: evaluates `expr` (an absl::StatusOr<T>); on error returns
/// its status from the enclosing function, else moves the value into `lhs`, which may be a
/// declaration (`auto points`). A `lhs` containing a top-level comma must be parenthesised as a
/// type alias first: the preprocessor splits macro arguments on commas.
#define GALPHA_ASSIGN_OR_RETURN(lhs, expr) \
  GALPHA_ASSIGN_OR_RETURN_IMPL_(GALPHA_STATUS_MACROS_CONCAT_(galpha_status_or_, __LINE__), lhs, expr)

#define GALPHA_ASSIGN_OR_RETURN_IMPL_(status_or, lhs, expr)  \
  auto status_or = (expr);                                   \
  if (!status_or.ok()) return std::move(status_or).status(); \
  lhs = std::move(status_or).value()
