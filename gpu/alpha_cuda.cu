// The CUDA instantiation of the alpha pipeline: one stream, stream-ordered memory.
#include <cuda_runtime.h>

#include "gpu/alpha_backend.hpp"
#include "gpu/alpha_impl.cuh"
#include "gpu/cuda_system.cuh"

namespace galpha::detail {

void BuildAlphaOnCuda(const AlphaInput& in, void* stream, AlphaRanks* out, std::vector<StageTime>* stage_times,
                      size_t* peak_bytes) {
  if (stream != nullptr) {
    CudaSystem system(static_cast<cudaStream_t>(stream));
    RunAlphaPipeline(system, in, out, stage_times, peak_bytes);
    return;
  }
  OwnedStream owned;
  CudaSystem system(owned.get());
  RunAlphaPipeline(system, in, out, stage_times, peak_bytes);
}

}  // namespace galpha::detail
