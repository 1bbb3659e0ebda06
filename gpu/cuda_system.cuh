// The CUDA backend's execution system: stream-ordered allocation (cudaMallocAsync from the device's
// memory pool, also for Thrust's temporaries), Thrust's par_nosync policy on one stream, and every
// CUDA call checked. Only compiled by nvcc.
#pragma once

#include <cuda_runtime.h>

#include <string>

#include <thrust/system/cuda/execution_policy.h>

#include "gpu/delaunay_backend.hpp"
#include "gpu/engine_system.cuh"

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

/// The CUDA backend on one stream.
class CudaSystem {
 public:
  static constexpr const char* kName = "cuda";
  static constexpr bool kHostMemory = false;
  /// A parallel round of hull repair (a few launches and two host syncs, ~80 us) costs about this
  /// many steps of the one-thread chain walk (~4.4 us a step at global-memory latency); measured on
  /// an H100, 2026-11-22.
  static constexpr uint32_t kRepairStepsPerRound = 16;

  explicit CudaSystem(cudaStream_t stream) : stream_(stream), temp_(stream, &ledger_) {}
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
    if (count == 0) return;
    CheckCuda(cudaMemcpyAsync(host, device, count * sizeof(T), cudaMemcpyDeviceToHost, stream_),
              "cudaMemcpyAsync to host");
    CheckCuda(cudaStreamSynchronize(stream_), "cudaStreamSynchronize");
  }
  template <class T>
  void FromHost(T* device, const T* host, size_t count) {
    if (count == 0) return;
    CheckCuda(cudaMemcpyAsync(device, host, count * sizeof(T), cudaMemcpyHostToDevice, stream_),
              "cudaMemcpyAsync to device");
    // The host buffer may be pageable and short-lived: wait until the copy has consumed it.
    CheckCuda(cudaStreamSynchronize(stream_), "cudaStreamSynchronize");
  }
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

 private:
  cudaStream_t stream_;
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
