// Builds without nvcc have no CUDA backend: these are its answers there.
#include "gpu/alpha_backend.hpp"
#include "gpu/delaunay_backend.hpp"

namespace galpha::detail {

bool CudaDeviceVisible() { return false; }

double SortFloorOnCuda(size_t) {
  throw EngineError(EngineError::Kind::kUnavailable, "this build of galpha has no CUDA backend");
}

void TriangulateOnCuda(const Point2*, uint32_t, void*, DelaunayOutput*) {
  throw EngineError(EngineError::Kind::kUnavailable, "this build of galpha has no CUDA backend");
}

void BuildFamilyOnCuda(const Point2*, uint32_t, void*, const BuildHooks&, FamilyOutput*) {
  throw EngineError(EngineError::Kind::kUnavailable, "this build of galpha has no CUDA backend");
}

}  // namespace galpha::detail
