// The threads of one block, for work that loops over dependent steps too short to fill the GPU:
// one block iterates on its own, with a barrier between steps, instead of one grid launch a step.
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"

namespace galpha::detail {

/// Lane `id` of `count` lanes; Sync() is the barrier between steps (a no-op with one lane, as on
/// the CPU system, which runs such work on one thread).
struct BlockLanes {
  uint32_t id;
  uint32_t count;
  GALPHA_HD void Sync() const {
#if defined(__CUDA_ARCH__)
    __syncthreads();
#endif
  }
};

}  // namespace galpha::detail
