// The CUDA instantiation of the family build, of one set and of many packed: one stream,
// stream-ordered memory.
#include <cuda_runtime.h>

#include <memory>

#include "gpu/alpha/alpha_backend.hpp"
#include "gpu/alpha/alpha_impl.cuh"
#include "gpu/alpha/packed_family.cuh"
#include "gpu/system/cuda_system.cuh"

namespace galpha::detail {

void BuildFamilyOnCuda(const Point2* points, const double* weights, uint32_t n, void* stream, const BuildHooks& hooks,
                       FamilyOutput* out) {
  if (hooks.resident) {
    // The tables own the stream they were built on; later queries run on it too.
    auto owned = std::make_shared<OwnedStream>();
    auto resident = std::make_unique<ResidentTablesOn<CudaSystem>>(owned, std::make_unique<CudaSystem>(owned->get()));
    RunFamilyBuild(resident->system(), points, weights, n, hooks, out, resident.get());
    out->resident = std::move(resident);
    return;
  }
  RunOnCudaStream(stream, [&](CudaSystem& system) { RunFamilyBuild(system, points, weights, n, hooks, out); });
}

void BuildFamiliesOnCuda(const Point2* points, const uint32_t* set_begin, uint32_t num_sets, uint32_t n, void* stream,
                         const BuildHooks& hooks, PackedFamilyOutput* out) {
  RunOnCudaStream(
      stream, [&](CudaSystem& system) { RunPackedFamilyBuild(system, points, set_begin, num_sets, n, hooks, out); });
}

}  // namespace galpha::detail
