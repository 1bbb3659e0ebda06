// Builds without nvcc have no GPU: every device query answers Unavailable.
#include "absl/status/status.h"
#include "gpu/system/device_streams.hpp"

namespace galpha {

absl::StatusOr<DeviceMemory> QueryDeviceMemory() {
  return absl::UnavailableError("this build of galpha has no CUDA backend");
}

absl::Status ReleaseUnusedDeviceMemory() { return absl::UnavailableError("this build of galpha has no CUDA backend"); }

absl::StatusOr<std::unique_ptr<CudaStreamPool>> CudaStreamPool::Create(int) {
  return absl::UnavailableError("this build of galpha has no CUDA backend");
}

CudaStreamPool::~CudaStreamPool() = default;

}  // namespace galpha
