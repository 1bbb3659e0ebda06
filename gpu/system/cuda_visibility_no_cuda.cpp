// Builds without nvcc have no CUDA backend: no device is ever visible.
#include "gpu/system/backend.hpp"

namespace galpha::detail {

bool CudaDeviceVisible() { return false; }

}  // namespace galpha::detail
