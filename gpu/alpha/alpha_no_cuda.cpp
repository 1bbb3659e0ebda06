// Builds without nvcc have no CUDA backend: this is the family build's answer there.
#include "gpu/alpha/alpha_backend.hpp"
#include "gpu/system/backend.hpp"

namespace galpha::detail {

void BuildFamilyOnCuda(const Point2*, const double*, uint32_t, void*, const BuildHooks&, FamilyOutput*) {
  throw EngineError(EngineError::Kind::kUnavailable, "this build of galpha has no CUDA backend");
}

void BuildFamiliesOnCuda(const Point2*, const uint32_t*, uint32_t, uint32_t, void*, const BuildHooks&,
                         PackedFamilyOutput*) {
  throw EngineError(EngineError::Kind::kUnavailable, "this build of galpha has no CUDA backend");
}

}  // namespace galpha::detail
