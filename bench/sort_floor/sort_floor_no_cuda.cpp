// Builds without nvcc have no CUDA backend: this is the sort floor's answer there.
#include <cstddef>

#include "gpu/system/backend.hpp"

namespace galpha::detail {

double SortFloorOnCuda(size_t) {
  throw EngineError(EngineError::Kind::kUnavailable, "this build of galpha has no CUDA backend");
}

}  // namespace galpha::detail
