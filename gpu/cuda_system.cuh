// The CUDA backend's execution system: stream-ordered allocation (cudaMallocAsync from the device's
// memory pool, also for Thrust's temporaries), Thrust's par_nosync policy on one stream, large host
// transfers through pinned staging, stage times by CUDA events, and every CUDA call checked. Only
// compiled by nvcc.
#pragma once

#include <cuda_runtime.h>

#include <cstdint>
#include <future>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <thrust/system/cuda/execution_policy.h>

#include "gpu/delaunay_backend.hpp"
#include "gpu/engine_system.cuh"
#include "gpu/host_copy.hpp"

namespace galpha::detail {

/// Turns a failed CUDA call into an EngineError and clears the sticky error state where CUDA allows.
inline void CheckCuda(cudaError_t result, const char* what) {
  if (result == cudaSuccess) return;
  cudaGetLastError();  // clear a non-sticky error so the next build starts clean
  const auto kind = result == cudaErrorMemoryAllocation ? EngineError::Kind::kResourceExhausted
                                                        : EngineError::Kind::kInternal;
  throw EngineError(kind, std::string(what) + ": " + cudaGetErrorString(result));
}

/// Thrust temporary storage taken from the stream-ordered pool instead of cudaMalloc.
class StreamOrderedAllocator {
 public:
  using value_type = char;
  StreamOrderedAllocator(cudaStream_t stream, MemoryLedger* ledger) : stream_(stream), ledger_(ledger) {}
  char* allocate(std::ptrdiff_t bytes) {
    void* p = nullptr;
    CheckCuda(cudaMallocAsync(&p, static_cast<size_t>(bytes), stream_), "cudaMallocAsync (thrust temp)");
    ledger_->Add(static_cast<size_t>(bytes));
    return static_cast<char*>(p);
  }
  void deallocate(char* p, size_t bytes) {
    cudaFreeAsync(p, stream_);
    ledger_->Remove(bytes);
  }

 private:
  cudaStream_t stream_;
  MemoryLedger* ledger_;
};

/// Keeps device memory freed by a build in the current device's pool for the next build. By
/// default the pool returns it to the driver at every synchronisation, and the next build's
/// cudaMallocAsync maps it again: at 1M points that cost more than the pipeline's own work.
/// The pool then holds the high-water mark of concurrent builds (nvidia-smi shows it as used).
void RetainFreedDeviceMemory();

/// A download running beside the build's stream (CudaSystem::DownloadAsync). Waits for the copy
/// when destroyed, so that it never outlives the buffers it reads (declare it after them).
class PendingDownload {
 public:
  PendingDownload() = default;
  explicit PendingDownload(std::future<void> done) : done_(std::move(done)) {}
  PendingDownload(PendingDownload&&) = default;
  PendingDownload& operator=(PendingDownload&& other) noexcept {
    if (done_.valid()) done_.wait();
    done_ = std::move(other.done_);
    return *this;
  }
  ~PendingDownload() {
    if (done_.valid()) done_.wait();
  }
  /// Returns once the host buffers hold the data; rethrows the copy's failure.
  void Wait() {
    if (done_.valid()) done_.get();
  }

 private:
  std::future<void> done_;
};

/// The CUDA backend on one stream.
class CudaSystem {
 public:
  static constexpr const char* kName = "cuda";
  static constexpr bool kHostMemory = false;
  /// A parallel round of hull repair (a few launches and two host syncs, ~80 us) costs about this
  /// many steps of the one-thread chain walk (~4.4 us a step at global-memory latency); measured on
  /// an H100, 2026-11-22.
  static constexpr uint32_t kRepairStepsPerRound = 16;

  /// Copies of at least this many bytes go through pinned staging (pinned_staging.cuh).
  static constexpr size_t kStagedFrom = size_t{1} << 20;

  explicit CudaSystem(cudaStream_t stream) : stream_(stream), temp_(stream, &ledger_) { RetainFreedDeviceMemory(); }
  ~CudaSystem() {
    if (copy_stream_ != nullptr) cudaStreamDestroy(copy_stream_);
  }
  CudaSystem(const CudaSystem&) = delete;
  CudaSystem& operator=(const CudaSystem&) = delete;

  auto policy() { return thrust::cuda::par_nosync(temp_).on(stream_); }

  template <class T>
  T* Allocate(size_t count) {
    if (count == 0) return nullptr;
    void* p = nullptr;
    CheckCuda(cudaMallocAsync(&p, count * sizeof(T), stream_), "cudaMallocAsync");
    ledger_.Add(count * sizeof(T));
    return static_cast<T*>(p);
  }
  void Free(void* p, size_t bytes) {
    cudaFreeAsync(p, stream_);
    ledger_.Remove(bytes);
  }
  /// Peak bytes of device memory this build has held: its buffers and Thrust's temporaries.
  size_t peak_bytes() const { return ledger_.peak(); }

  template <class T>
  void ToHost(T* host, const T* device, size_t count) {
    Download({{host, device, count * sizeof(T)}});
  }
  template <class T>
  void FromHost(T* device, const T* host, size_t count) {
    Upload({{const_cast<T*>(host), device, count * sizeof(T)}});
  }
  /// Copies device buffers to host buffers, all in one pipeline; returns when they have arrived.
  void Download(const std::vector<HostCopy>& copies);
  /// Copies host buffers to device buffers; returns when the host buffers may be reused.
  void Upload(const std::vector<HostCopy>& copies);
  /// Starts copying device buffers, as they are once the work queued so far is done, to host
  /// buffers while the build goes on: on a second stream, by a host thread of its own (the link
  /// and the host's page faults overlap the later stages). The device buffers must stay
  /// unchanged until the returned download is waited for.
  PendingDownload DownloadAsync(std::vector<HostCopy> copies);
  template <class T>
  T Read(const T* device) {
    T value;
    ToHost(&value, device, 1);
    return value;
  }
  void Synchronize() {
    CheckCuda(cudaGetLastError(), "kernel launch");
    CheckCuda(cudaStreamSynchronize(stream_), "cudaStreamSynchronize");
  }

  /// Stage marks are events on the stream: a stage's time is the stream's, with no host sync at
  /// stage ends (StageTimer reads them all once, at the end of the build).
  using StageMark = cudaEvent_t;
  StageMark MarkStage() {
    CheckCuda(cudaGetLastError(), "kernel launch");
    cudaEvent_t event = nullptr;
    CheckCuda(cudaEventCreate(&event), "cudaEventCreate");
    const cudaError_t recorded = cudaEventRecord(event, stream_);
    if (recorded != cudaSuccess) cudaEventDestroy(event);
    CheckCuda(recorded, "cudaEventRecord");
    return event;
  }
  double SecondsBetween(StageMark from, StageMark to) {
    CheckCuda(cudaEventSynchronize(to), "cudaEventSynchronize (stage mark)");
    float ms = 0;
    CheckCuda(cudaEventElapsedTime(&ms, from, to), "cudaEventElapsedTime");
    return ms * 1e-3;
  }
  void ReleaseMark(StageMark mark) { cudaEventDestroy(mark); }

 private:
  cudaStream_t stream_;
  cudaStream_t copy_stream_ = nullptr;  // DownloadAsync's, made on first use
  MemoryLedger ledger_;  // declared before temp_, which points at it
  StreamOrderedAllocator temp_;
};

/// A stream owned for the duration of one call when the caller brings none.
class OwnedStream {
 public:
  OwnedStream() { CheckCuda(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking), "cudaStreamCreate"); }
  ~OwnedStream() { cudaStreamDestroy(stream_); }
  OwnedStream(const OwnedStream&) = delete;
  OwnedStream& operator=(const OwnedStream&) = delete;
  cudaStream_t get() const { return stream_; }

 private:
  cudaStream_t stream_ = nullptr;
};

}  // namespace galpha::detail
