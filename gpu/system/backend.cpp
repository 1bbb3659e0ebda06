// The engine's boundary shared by Triangulate() and BuildAlphaFamily(): backend names and choice,
// and the one place where engine exceptions become absl::Status.
#include "gpu/system/engine_status.hpp"

#include <exception>
#include <new>

#include "absl/strings/cord.h"
#include "absl/strings/str_cat.h"
#include "gpu/system/backend.hpp"

namespace galpha {

const char* BackendName(Backend backend) {
  switch (backend) {
    case Backend::kAuto:
      return "auto";
    case Backend::kCpu:
      return "cpu";
    case Backend::kCuda:
      return "cuda";
  }
  return "unknown";
}

bool CudaBackendAvailable() { return detail::CudaDeviceVisible(); }

namespace detail {

absl::StatusOr<Backend> ResolveBackend(Backend requested) {
  const bool cuda = CudaBackendAvailable();
  switch (requested) {
    case Backend::kAuto:
      return cuda ? Backend::kCuda : Backend::kCpu;
    case Backend::kCpu:
      return Backend::kCpu;
    case Backend::kCuda:
      if (!cuda) return absl::UnavailableError("the CUDA backend was requested but no GPU is usable in this build");
      return Backend::kCuda;
  }
  return absl::InvalidArgumentError("unknown backend");
}

absl::Status RunEngine(const std::string& what, const std::function<void()>& body) {
  try {
    body();
  } catch (const EngineError& e) {
    switch (e.kind()) {
      case EngineError::Kind::kResourceExhausted:
        return absl::ResourceExhaustedError(absl::StrCat(what, ": ", e.what()));
      case EngineError::Kind::kUnavailable:
        return absl::UnavailableError(e.what());
      case EngineError::Kind::kCancelled:
        return absl::CancelledError(e.what());
      case EngineError::Kind::kWorkLimit: {
        absl::Status status = absl::ResourceExhaustedError(absl::StrCat(what, ": ", e.what()));
        status.SetPayload(kExactComparisonLimitPayload, absl::Cord("1"));
        return status;
      }
      case EngineError::Kind::kInternal:
        break;
    }
    return absl::InternalError(absl::StrCat(what, ": ", e.what()));
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(absl::StrCat("out of memory while ", what));
  } catch (const std::exception& e) {  // Thrust reports CUDA failures as system_error
    return absl::InternalError(absl::StrCat(what, " failed: ", e.what()));
  }
  return absl::OkStatus();
}

}  // namespace detail

}  // namespace galpha
