// The OpenMP instantiation of the triangulation pipeline.
#include "gpu/system/engine_system.cuh"
#include "gpu/triangulation/delaunay_backend.hpp"
#include "gpu/triangulation/delaunay_batch.cuh"
#include "gpu/triangulation/delaunay_impl.cuh"

namespace galpha::detail {

void TriangulateOnCpu(const Point2* points, const double* weights, uint32_t n, DelaunayOutput* out) {
  CpuSystem system;
  RunTriangulation(system, points, weights, n, out);
}

void TriangulateSetsOnCpu(const Point2* points, const uint32_t* set_begin, uint32_t num_sets, uint32_t n,
                          DelaunaySetsOutput* out) {
  CpuSystem system;
  RunSetsTriangulation(system, points, set_begin, num_sets, n, out);
}

}  // namespace galpha::detail
