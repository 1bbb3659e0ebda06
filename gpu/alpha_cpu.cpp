// The OpenMP instantiation of the family build.
#include "gpu/alpha_backend.hpp"
#include "gpu/alpha_impl.cuh"
#include "gpu/engine_system.cuh"

namespace galpha::detail {

void BuildFamilyOnCpu(const Point2* points, uint32_t n, const BuildHooks& hooks, FamilyOutput* out) {
  CpuSystem system;
  RunFamilyBuild(system, points, n, hooks, out);
}

}  // namespace galpha::detail
