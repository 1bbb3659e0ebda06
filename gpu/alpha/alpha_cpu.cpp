// The OpenMP instantiation of the family build, of one set and of many packed.
#include <memory>

#include "gpu/alpha/alpha_backend.hpp"
#include "gpu/alpha/alpha_impl.cuh"
#include "gpu/alpha/packed_family.cuh"
#include "gpu/system/engine_system.cuh"

namespace galpha::detail {

void BuildFamilyOnCpu(const Point2* points, const double* weights, uint32_t n, const BuildHooks& hooks,
                      FamilyOutput* out) {
  if (hooks.resident) {
    auto resident = std::make_unique<ResidentTablesOn<CpuSystem>>(nullptr, std::make_unique<CpuSystem>());
    RunFamilyBuild(resident->system(), points, weights, n, hooks, out, resident.get());
    out->resident = std::move(resident);
    return;
  }
  CpuSystem system;
  RunFamilyBuild(system, points, weights, n, hooks, out);
}

void BuildFamiliesOnCpu(const Point2* points, const uint32_t* set_begin, uint32_t num_sets, uint32_t n,
                        const BuildHooks& hooks, PackedFamilyOutput* out) {
  CpuSystem system;
  RunPackedFamilyBuild(system, points, set_begin, num_sets, n, hooks, out);
}

}  // namespace galpha::detail
