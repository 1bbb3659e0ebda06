// CUDA-free access to what a long-running process needs of the GPU: a pool of streams that builds
// lease (one build per stream), and the device's memory use. Builds without the CUDA backend answer
// Unavailable, so callers run the CPU backend and say so.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace galpha {

struct DeviceMemory {
  size_t free_bytes = 0;
  size_t total_bytes = 0;
  size_t used_bytes() const { return total_bytes - free_bytes; }
};

/// Free and total memory of the current device. Unavailable without a CUDA backend or GPU.
absl::StatusOr<DeviceMemory> QueryDeviceMemory();

/// Gives the device memory that CUDA's stream-ordered pool keeps for reuse (freed by builds and by
/// families that left the device) back to the device; memory still allocated stays. The engine
/// keeps that memory on purpose (mapping it again costs more than a 1M-point build), so a process
/// calls this only when it has been idle a while, with no build running or starting: it waits for
/// the whole device first. Unavailable without a CUDA backend or GPU.
absl::Status ReleaseUnusedDeviceMemory();

/// Non-blocking CUDA streams, owned for the pool's lifetime; stream(i) is a cudaStream_t.
class CudaStreamPool {
 public:
  /// Unavailable without a CUDA backend or GPU; Internal when a stream cannot be created.
  static absl::StatusOr<std::unique_ptr<CudaStreamPool>> Create(int count);
  ~CudaStreamPool();
  CudaStreamPool(const CudaStreamPool&) = delete;
  CudaStreamPool& operator=(const CudaStreamPool&) = delete;

  int size() const { return static_cast<int>(streams_.size()); }
  void* stream(int i) const { return streams_[static_cast<size_t>(i)]; }

 private:
  CudaStreamPool() = default;
  std::vector<void*> streams_;
};

}  // namespace galpha
