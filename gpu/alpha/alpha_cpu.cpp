// The OpenMP instantiation of the family build.
#include "gpu/alpha/alpha_backend.hpp"
#include "gpu/alpha/alpha_impl.cuh"
#include "gpu/system/engine_system.cuh"

namespace galpha::detail {

void BuildFamilyOnCpu(const Point2* points, const double* weights, uint32_t n, const BuildHooks& hooks,
                      FamilyOutput* out) {
  CpuSystem system;
  RunFamilyBuild(system, points, weights, n, hooks, out);
}

}  // namespace galpha::detail
