// How an absl::Status reaches Python: one exception class, galpha._engine.EngineError, carrying the
// absl code number (`code`, the same numbers as gRPC's) and the message (`message`), so that the
// package maps it onto its own exceptions in one place (galpha._local, through error_for_code).
#pragma once

#include <exception>
#include <utility>

#include <pybind11/pybind11.h>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace galpha::python {

/// A non-OK status on its way out of the module: thrown anywhere (with or without the GIL) and
/// turned into EngineError by the translator RegisterEngineError installs.
class StatusError : public std::exception {
 public:
  explicit StatusError(absl::Status status) : status_(std::move(status)) {}
  const absl::Status& status() const { return status_; }
  const char* what() const noexcept override { return "galpha engine error"; }

 private:
  absl::Status status_;
};

/// Creates galpha._engine.EngineError on `module` and the translator from StatusError to it.
void RegisterEngineError(pybind11::module_& module);

/// Throws StatusError for a non-OK status; returns for OK.
void ThrowIfError(const absl::Status& status);

/// The value of `result`, or StatusError.
template <class T>
T ValueOrThrow(absl::StatusOr<T> result) {
  if (!result.ok()) throw StatusError(result.status());
  return *std::move(result);
}

}  // namespace galpha::python
