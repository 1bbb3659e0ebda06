// The out-of-line parts of the CUDA execution system: host transfers and the pool's policy.
#include "gpu/cuda_system.cuh"

#include <limits>
#include <set>

#include "gpu/pinned_staging.cuh"

namespace galpha::detail {

void RetainFreedDeviceMemory() {
  static std::mutex mutex;
  static std::set<int> configured;
  int device = 0;
  CheckCuda(cudaGetDevice(&device), "cudaGetDevice");
  std::lock_guard<std::mutex> lock(mutex);
  if (configured.count(device) != 0) return;
  cudaMemPool_t pool = nullptr;
  CheckCuda(cudaDeviceGetDefaultMemPool(&pool, device), "cudaDeviceGetDefaultMemPool");
  uint64_t keep_all = std::numeric_limits<uint64_t>::max();
  CheckCuda(cudaMemPoolSetAttribute(pool, cudaMemPoolAttrReleaseThreshold, &keep_all),
            "cudaMemPoolSetAttribute (release threshold)");
  configured.insert(device);
}

namespace {

bool AnyLarge(const std::vector<HostCopy>& copies) {
  for (const HostCopy& c : copies) {
    if (c.bytes >= CudaSystem::kStagedFrom) return true;
  }
  return false;
}

}  // namespace

void CudaSystem::Download(const std::vector<HostCopy>& copies) {
  if (AnyLarge(copies)) {
    PinnedStaging staging;
    staging.Download(copies, stream_);
    return;
  }
  // Small copies (a count, a few values): straight from pageable memory, one sync for all.
  bool any = false;
  for (const HostCopy& c : copies) {
    if (c.bytes == 0) continue;
    CheckCuda(cudaMemcpyAsync(c.host, c.system, c.bytes, cudaMemcpyDeviceToHost, stream_), "cudaMemcpyAsync to host");
    any = true;
  }
  if (any) CheckCuda(cudaStreamSynchronize(stream_), "cudaStreamSynchronize");
}

PendingDownload CudaSystem::DownloadAsync(std::vector<HostCopy> copies) {
  if (copy_stream_ == nullptr) {
    CheckCuda(cudaStreamCreateWithFlags(&copy_stream_, cudaStreamNonBlocking), "cudaStreamCreate (copies)");
  }
  CheckCuda(cudaGetLastError(), "kernel launch");
  cudaEvent_t ready = nullptr;
  CheckCuda(cudaEventCreateWithFlags(&ready, cudaEventDisableTiming), "cudaEventCreate");
  const cudaError_t recorded = cudaEventRecord(ready, stream_);
  if (recorded == cudaSuccess) {
    // The copy stream starts only once the build's stream has produced the data.
    const cudaError_t waited = cudaStreamWaitEvent(copy_stream_, ready, 0);
    cudaEventDestroy(ready);  // released once the wait is done
    CheckCuda(waited, "cudaStreamWaitEvent");
  } else {
    cudaEventDestroy(ready);
    CheckCuda(recorded, "cudaEventRecord");
  }
  int device = 0;
  CheckCuda(cudaGetDevice(&device), "cudaGetDevice");
  cudaStream_t copy_stream = copy_stream_;
  return PendingDownload(std::async(std::launch::async, [copies = std::move(copies), copy_stream, device] {
    CheckCuda(cudaSetDevice(device), "cudaSetDevice (download thread)");
    // Spinning copy threads on every core would delay the build's own thread (its launches and
    // its waits for counts): measured +3 ms on the 1M pipeline when the copy took all 16 cores.
    LeaveCoresToOthers(3);
    PinnedStaging staging;
    staging.Download(copies, copy_stream);
  }));
}

void CudaSystem::Upload(const std::vector<HostCopy>& copies) {
  if (AnyLarge(copies)) {
    PinnedStaging staging;
    staging.Upload(copies, stream_);
    return;
  }
  bool any = false;
  for (const HostCopy& c : copies) {
    if (c.bytes == 0) continue;
    CheckCuda(cudaMemcpyAsync(const_cast<void*>(c.system), c.host, c.bytes, cudaMemcpyHostToDevice, stream_),
              "cudaMemcpyAsync to device");
    any = true;
  }
  // The host buffers may be pageable and short-lived: wait until the copies have consumed them.
  if (any) CheckCuda(cudaStreamSynchronize(stream_), "cudaStreamSynchronize");
}

}  // namespace galpha::detail
