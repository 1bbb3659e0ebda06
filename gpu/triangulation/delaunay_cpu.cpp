// The OpenMP instantiation of the triangulation pipeline.
#include "gpu/system/engine_system.cuh"
#include "gpu/triangulation/delaunay_backend.hpp"
#include "gpu/triangulation/delaunay_impl.cuh"

namespace galpha::detail {

void TriangulateOnCpu(const Point2* points, const double* weights, uint32_t n, DelaunayOutput* out) {
  CpuSystem system;
  RunTriangulation(system, points, weights, n, out);
}

}  // namespace galpha::detail
