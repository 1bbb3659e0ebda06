// Which implementation runs the engine, and how a backend reports failure. Plain C++ and std types
// only (no CUDA, no Abseil): the public engine headers, the CUDA translation units and the
// execution systems all include it.
#pragma once

#include <stdexcept>
#include <string>

namespace galpha {

/// Which implementation runs the engine.
enum class Backend {
  kAuto,  ///< CUDA when this build has it and a GPU is visible, else the CPU.
  kCpu,   ///< OpenMP on the host cores.
  kCuda,  ///< The GPU; an error when this build or machine has none.
};

/// Human-readable backend name ("auto", "cpu", "cuda").
const char* BackendName(Backend backend);

/// Whether this build contains the CUDA backend and a GPU is visible now.
bool CudaBackendAvailable();

namespace detail {

/// Failure inside a backend. Thrown inside the engine (Thrust reports errors by exception too) and
/// turned into an absl::Status once, at the engine boundary (RunEngine, engine_status.hpp).
class EngineError : public std::runtime_error {
 public:
  /// kWorkLimit: the build passed its limit of exact comparisons (BuildOptions); ResourceExhausted
  /// at the boundary, tagged so that callers can tell it from a lack of memory.
  enum class Kind { kInternal, kResourceExhausted, kUnavailable, kCancelled, kWorkLimit };
  EngineError(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

/// Whether this build has the CUDA backend and a device is visible (cuda_visibility_cuda.cu, or
/// false in builds without nvcc).
bool CudaDeviceVisible();

}  // namespace detail
}  // namespace galpha
