// Whether a CUDA device is visible, in builds with the CUDA backend.
#include <cuda_runtime.h>

#include "gpu/system/backend.hpp"

namespace galpha::detail {

bool CudaDeviceVisible() {
  int count = 0;
  if (cudaGetDeviceCount(&count) != cudaSuccess) {
    cudaGetLastError();  // clear the sticky error: no device is an answer, not a failure
    return false;
  }
  return count > 0;
}

}  // namespace galpha::detail
