// MeasureSortFloorSeconds: the OpenMP instantiation, and the entry point choosing the backend.
#include <exception>
#include <new>

#include "absl/strings/str_cat.h"
#include "bench/sort_floor/sort_floor.hpp"
#include "bench/sort_floor/sort_floor_impl.cuh"
#include "gpu/system/backend.hpp"
#include "gpu/system/engine_system.cuh"

namespace galpha {

namespace detail {
double SortFloorOnCuda(size_t pairs);  // sort_floor_cuda.cu, or the no-CUDA build's answer
}  // namespace detail

absl::StatusOr<double> MeasureSortFloorSeconds(size_t pairs, Backend backend) {
  if (backend == Backend::kAuto) backend = CudaBackendAvailable() ? Backend::kCuda : Backend::kCpu;
  try {
    if (backend == Backend::kCuda) {
      if (!CudaBackendAvailable()) return absl::UnavailableError("no CUDA backend or GPU for the sort floor");
      return detail::SortFloorOnCuda(pairs);
    }
    detail::CpuSystem system;
    return detail::SortFloorSeconds(system, pairs);
  } catch (const detail::EngineError& e) {
    if (e.kind() == detail::EngineError::Kind::kResourceExhausted) return absl::ResourceExhaustedError(e.what());
    return absl::InternalError(e.what());
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(absl::StrCat("out of memory sorting ", pairs, " pairs"));
  }
}

}  // namespace galpha
