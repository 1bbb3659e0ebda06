// The OpenMP instantiation of the alpha pipeline.
#include "gpu/alpha_backend.hpp"
#include "gpu/alpha_impl.cuh"
#include "gpu/engine_system.cuh"

namespace galpha::detail {

void BuildAlphaOnCpu(const AlphaInput& in, AlphaRanks* out, std::vector<StageTime>* stage_times,
                     size_t* peak_bytes) {
  CpuSystem system;
  RunAlphaPipeline(system, in, out, stage_times, peak_bytes);
}

}  // namespace galpha::detail
