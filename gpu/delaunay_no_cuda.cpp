// Builds without nvcc have no CUDA backend: these are its answers there.
#include "gpu/delaunay_backend.hpp"

namespace galpha::detail {

bool CudaDeviceVisible() { return false; }

void TriangulateOnCuda(const Point2*, uint32_t, void*, DelaunayOutput*) {
  throw EngineError(EngineError::Kind::kUnavailable, "this build of galpha has no CUDA backend");
}

}  // namespace galpha::detail
