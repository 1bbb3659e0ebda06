// The OpenMP instantiation of the family build.
#include <memory>

#include "gpu/alpha/alpha_backend.hpp"
#include "gpu/alpha/alpha_impl.cuh"
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

}  // namespace galpha::detail
