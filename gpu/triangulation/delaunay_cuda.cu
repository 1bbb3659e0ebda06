// The CUDA instantiation of the triangulation pipeline: one stream, stream-ordered memory.
#include <cuda_runtime.h>

#include "gpu/system/cuda_system.cuh"
#include "gpu/triangulation/delaunay_backend.hpp"
#include "gpu/triangulation/delaunay_batch.cuh"
#include "gpu/triangulation/delaunay_impl.cuh"

namespace galpha::detail {

void TriangulateOnCuda(const Point2* points, const double* weights, uint32_t n, void* stream, DelaunayOutput* out) {
  RunOnCudaStream(stream, [&](CudaSystem& system) { RunTriangulation(system, points, weights, n, out); });
}

void TriangulateSetsOnCuda(const Point2* points, const uint32_t* set_begin, uint32_t num_sets, uint32_t n, void* stream,
                           DelaunaySetsOutput* out) {
  RunOnCudaStream(stream,
                  [&](CudaSystem& system) { RunSetsTriangulation(system, points, set_begin, num_sets, n, out); });
}

}  // namespace galpha::detail
