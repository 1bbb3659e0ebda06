// What the public engine calls (Triangulate, BuildAlphaFamily) share at their boundary: the choice
// of backend, and the one place where engine exceptions become absl::Status.
#pragma once

#include <functional>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "gpu/system/backend.hpp"

namespace galpha::detail {

/// The backend that runs a request for `requested`: Unavailable when CUDA is asked for and there
/// is none.
absl::StatusOr<Backend> ResolveBackend(Backend requested);

/// The payload that tags the ResourceExhausted status of a build stopped by its limit of exact
/// comparisons (EngineError kWorkLimit).
inline constexpr char kExactComparisonLimitPayload[] = "galpha.dev/exact-comparison-limit";

/// Runs `body`, turning what the engine throws into a status: EngineError by its kind, bad_alloc
/// as ResourceExhausted, any other exception (Thrust reports CUDA failures as system_error) as
/// Internal. `what` names the work in the messages ("triangulating 1000 points").
absl::Status RunEngine(const std::string& what, const std::function<void()>& body);

}  // namespace galpha::detail
