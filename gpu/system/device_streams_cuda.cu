#include <cuda_runtime.h>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "gpu/system/device_streams.hpp"

namespace galpha {

absl::StatusOr<DeviceMemory> QueryDeviceMemory() {
  int count = 0;
  if (cudaGetDeviceCount(&count) != cudaSuccess || count == 0) {
    cudaGetLastError();
    return absl::UnavailableError("no CUDA device is visible");
  }
  DeviceMemory memory;
  const cudaError_t result = cudaMemGetInfo(&memory.free_bytes, &memory.total_bytes);
  if (result != cudaSuccess) {
    cudaGetLastError();
    return absl::InternalError(absl::StrCat("cudaMemGetInfo: ", cudaGetErrorString(result)));
  }
  return memory;
}

absl::Status ReleaseUnusedDeviceMemory() {
  int device = 0;
  if (cudaGetDevice(&device) != cudaSuccess) {
    cudaGetLastError();
    return absl::UnavailableError("no CUDA device is visible");
  }
  // Memory freed on a stream after the host last waited on it still counts as in use for the pool
  // (a build's buffers are freed after its last wait, a resident family's when its stream goes),
  // so the host waits for the device first. The caller holds builds off; a query capturing a
  // graph on another thread meanwhile is unaffected (captures are thread-local).
  cudaError_t result = cudaDeviceSynchronize();
  // The pool the engine allocates from (gpu/system/cuda_system.cu configures it).
  cudaMemPool_t pool = nullptr;
  if (result == cudaSuccess) result = cudaDeviceGetDefaultMemPool(&pool, device);
  if (result == cudaSuccess) result = cudaMemPoolTrimTo(pool, 0);
  if (result != cudaSuccess) {
    cudaGetLastError();
    return absl::InternalError(absl::StrCat("releasing the memory pool's unused memory: ", cudaGetErrorString(result)));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<CudaStreamPool>> CudaStreamPool::Create(int count) {
  int devices = 0;
  if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0) {
    cudaGetLastError();
    return absl::UnavailableError("no CUDA device is visible");
  }
  std::unique_ptr<CudaStreamPool> pool(new CudaStreamPool());
  for (int i = 0; i < count; ++i) {
    cudaStream_t stream = nullptr;
    const cudaError_t result = cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking);
    if (result != cudaSuccess) {
      cudaGetLastError();
      return absl::InternalError(absl::StrCat("cudaStreamCreateWithFlags: ", cudaGetErrorString(result)));
    }
    pool->streams_.push_back(stream);
  }
  return pool;
}

CudaStreamPool::~CudaStreamPool() {
  for (void* stream : streams_) {
    // Best effort at shutdown: a failure here has no one left to report to.
    cudaStreamSynchronize(static_cast<cudaStream_t>(stream));
    cudaStreamDestroy(static_cast<cudaStream_t>(stream));
  }
}

}  // namespace galpha
