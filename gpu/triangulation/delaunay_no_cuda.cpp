// Builds without nvcc have no CUDA backend: this is the triangulation's answer there.
#include "gpu/system/backend.hpp"
#include "gpu/triangulation/delaunay_backend.hpp"

namespace galpha::detail {

void TriangulateOnCuda(const Point2*, const double*, uint32_t, void*, DelaunayOutput*) {
  throw EngineError(EngineError::Kind::kUnavailable, "this build of galpha has no CUDA backend");
}

void TriangulateSetsOnCuda(const Point2*, const uint32_t*, uint32_t, uint32_t, void*, DelaunaySetsOutput*) {
  throw EngineError(EngineError::Kind::kUnavailable, "this build of galpha has no CUDA backend");
}

}  // namespace galpha::detail
