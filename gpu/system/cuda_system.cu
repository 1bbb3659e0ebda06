// The out-of-line parts of the CUDA execution system: host transfers and the pool's policy.
#include "gpu/system/cuda_system.cuh"

#include <limits>
#include <set>

#include "gpu/system/pinned_staging.cuh"

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

/// Small copies (a count, a few values): straight to or from pageable memory, one wait for all
/// (the host buffers may be short-lived).
void CopyDirectly(const std::vector<HostCopy>& copies, cudaMemcpyKind kind, cudaStream_t stream) {
  bool any = false;
  for (const HostCopy& c : copies) {
    if (c.bytes == 0) continue;
    void* system = const_cast<void*>(c.system);
    const bool to_host = kind == cudaMemcpyDeviceToHost;
    CheckCuda(cudaMemcpyAsync(to_host ? c.host : system, to_host ? system : c.host, c.bytes, kind, stream),
              to_host ? "cudaMemcpyAsync to host" : "cudaMemcpyAsync to device");
    any = true;
  }
  if (any) CheckCuda(cudaStreamSynchronize(stream), "cudaStreamSynchronize");
}

}  // namespace

void CudaSystem::Download(const std::vector<HostCopy>& copies) {
  if (AnyLarge(copies)) {
    PinnedStaging staging;
    staging.Download(copies, stream_);
    return;
  }
  CopyDirectly(copies, cudaMemcpyDeviceToHost, stream_);
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
    // Copy threads on every core would compete with the build's own thread (its launches and its
    // waits for counts), so three cores are left to it. (On the H100 host this changed nothing
    // measurable; what slowed the pipeline beside a download was the shared copy engine, see
    // PinnedStaging::Download.)
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
  CopyDirectly(copies, cudaMemcpyHostToDevice, stream_);
}

}  // namespace galpha::detail
