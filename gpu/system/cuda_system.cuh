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

#include <thrust/fill.h>
#include <thrust/system/cuda/execution_policy.h>
#include <cub/device/device_select.cuh>

#include "gpu/system/atomic_increment.cuh"
#include "gpu/system/backend.hpp"
#include "gpu/system/block_lanes.hpp"
#include "gpu/system/engine_system.cuh"
#include "gpu/system/host_copy.hpp"
#include "gpu/system/loop_condition.hpp"
#include "gpu/system/pinned_staging.cuh"

namespace galpha::detail {

/// Turns a failed CUDA call into an EngineError and clears the sticky error state where CUDA allows.
inline void CheckCuda(cudaError_t result, const char* what) {
  if (result == cudaSuccess) return;
  cudaGetLastError();  // clear a non-sticky error so the next build starts clean
  const auto kind =
      result == cudaErrorMemoryAllocation ? EngineError::Kind::kResourceExhausted : EngineError::Kind::kInternal;
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

/// ForEachBelow's kernel: a grid-stride loop up to a count read on the device (one item when the
/// count is null: RunSingle).
template <class F>
__global__ void ForEachBelowKernel(const uint32_t* count, F f) {
  const uint32_t n = count == nullptr ? 1u : *count;
  const uint32_t stride = gridDim.x * blockDim.x;
  for (uint32_t i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += stride) f(i);
}

/// The lanes of RunInOneBlock: a whole block of 1,024 (its functor gets at most 64 registers a
/// lane). Its one user, the flip loop's tail, waits on memory and on its slowest lane's predicates,
/// so that one item a lane beats four: measured on an H100 at 1M, insertion 0.4 to 1.6 ms faster
/// on every generator tried (uniform, two_lines, parallel_lines, circle, grid) than with 256.
constexpr unsigned kOneBlockLanes = 1024;

/// RunInOneBlock's kernel.
template <class F>
__global__ void __launch_bounds__(kOneBlockLanes) OneBlockKernel(F f) {
  f(BlockLanes{threadIdx.x, blockDim.x});
}

/// ReplayWhile's last kernel in each run of its body: sets whether the loop runs the body again.
/// (A template, so that every translation unit that includes this header may define it.)
template <class Condition>
__global__ void SetLoopConditionKernel(cudaGraphConditionalHandle handle, Condition condition) {
  cudaGraphSetConditional(handle, condition() ? 1u : 0u);
}

/// AppendIf's kernel.
template <class InIt, class FlagIt, class Keep, class OutIt>
__global__ void AppendIfKernel(const uint32_t* count, uint32_t per_item, InIt in, FlagIt flags, Keep keep, OutIt out,
                               uint32_t* out_count) {
  const uint32_t n = per_item * *count;
  const uint32_t stride = gridDim.x * blockDim.x;
  for (uint32_t i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += stride) {
    if (keep(flags[i])) out[AtomicIncrement(out_count)] = in[i];
  }
}

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

  explicit CudaSystem(cudaStream_t stream) : stream_(stream), temp_(stream, &ledger_) {
    RetainFreedDeviceMemory();
    int device = 0, sms = 0;
    CheckCuda(cudaGetDevice(&device), "cudaGetDevice");
    CheckCuda(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device), "cudaDeviceGetAttribute");
    grid_blocks_ = static_cast<unsigned>(sms) * kBlocksPerSm;
  }
  ~CudaSystem() {
    if (copy_stream_ != nullptr) cudaStreamDestroy(copy_stream_);
  }
  CudaSystem(const CudaSystem&) = delete;
  CudaSystem& operator=(const CudaSystem&) = delete;

  auto policy() { return thrust::cuda::par_nosync(temp_).on(stream_); }
  /// The stream the system's work runs on (work of another system on it follows this one's).
  cudaStream_t stream() const { return stream_; }

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

  /// Keeps, in place and in order, the first `n` items of `data` whose flag satisfies `keep`;
  /// their number goes to `*count` in device memory (no host sync).
  template <class DataIt, class FlagIt, class Keep>
  void SelectFlaggedInPlace(DataIt data, FlagIt flags, uint32_t n, Keep keep, uint32_t* count) {
    if (n == 0) {
      thrust::fill(policy(), count, count + 1, 0u);
      return;
    }
    size_t bytes = 0;
    CheckCuda(cub::DeviceSelect::FlaggedIf(nullptr, bytes, data, flags, count, n, keep, stream_),
              "cub::DeviceSelect::FlaggedIf (size)");
    TempBytes temp(temp_, bytes);
    CheckCuda(cub::DeviceSelect::FlaggedIf(temp.data, bytes, data, flags, count, n, keep, stream_),
              "cub::DeviceSelect::FlaggedIf");
  }
  /// Runs f(i) for every i below `*count`, a count in device memory set by earlier work on the
  /// stream: the launch does not wait for it (a fixed grid strides over whatever it is).
  template <class F>
  void ForEachBelow(const uint32_t* count, F f) {
    ForEachBelowKernel<<<grid_blocks_, kBlockThreads, 0, stream_>>>(count, f);
    CheckCuda(cudaGetLastError(), "kernel launch");
  }
  /// Appends the items among the first `per_item * *count` of `in` whose flag satisfies `keep`
  /// to `out` from position `*out_count` on, and adds their number to `*out_count`; both counts
  /// in device memory (no host sync, and fit for a recording). The order is that of `in` within
  /// a warp's items (the threads of a warp take consecutive slots) and roughly so across warps.
  template <class InIt, class FlagIt, class Keep, class OutIt>
  void AppendIf(const uint32_t* count, uint32_t per_item, InIt in, FlagIt flags, Keep keep, OutIt out,
                uint32_t* out_count) {
    AppendIfKernel<<<grid_blocks_, kBlockThreads, 0, stream_>>>(count, per_item, in, flags, keep, out, out_count);
    CheckCuda(cudaGetLastError(), "kernel launch");
  }
  /// Runs f(0) once, in stream order.
  template <class F>
  void RunSingle(F f) {
    ForEachBelowKernel<<<1, 1, 0, stream_>>>(nullptr, f);
    CheckCuda(cudaGetLastError(), "kernel launch");
  }
  /// Runs f(lanes) on the lanes of one block, in stream order.
  template <class F>
  void RunInOneBlock(F f) {
    OneBlockKernel<<<1, kOneBlockLanes, 0, stream_>>>(f);
    CheckCuda(cudaGetLastError(), "kernel launch");
  }

  /// Work recorded once as a CUDA graph and replayed by Replay: one launch for what was tens of
  /// kernels (the host's launch cost, ~5 us a kernel on an H100's host, bounds loops of small
  /// kernels). The stream waits for the graph's last launch before the graph is destroyed.
  class Recording {
   public:
    Recording() = default;
    ~Recording() {
      if (exec_ == nullptr) return;
      cudaStreamSynchronize(stream_);
      cudaGraphExecDestroy(exec_);
      cudaGetLastError();
    }
    Recording(const Recording&) = delete;
    Recording& operator=(const Recording&) = delete;

   private:
    friend class CudaSystem;
    cudaGraphExec_t exec_ = nullptr;
    cudaStream_t stream_ = nullptr;
  };
  /// Records `body` (stream work only: launches, no waits, no allocations) into `recording` the
  /// first time, then launches the recording on the stream.
  template <class Body>
  void Replay(Recording& recording, Body&& body) {
    if (recording.exec_ == nullptr) {
      CheckCuda(cudaStreamBeginCapture(stream_, cudaStreamCaptureModeThreadLocal), "cudaStreamBeginCapture");
      cudaGraph_t graph = nullptr;
      try {
        body();
      } catch (...) {
        cudaStreamEndCapture(stream_, &graph);
        if (graph != nullptr) cudaGraphDestroy(graph);
        cudaGetLastError();
        throw;
      }
      CheckCuda(cudaStreamEndCapture(stream_, &graph), "cudaStreamEndCapture");
      const cudaError_t instantiated = cudaGraphInstantiate(&recording.exec_, graph, 0);
      cudaGraphDestroy(graph);
      CheckCuda(instantiated, "cudaGraphInstantiate");
      recording.stream_ = stream_;
    }
    CheckCuda(cudaGraphLaunch(recording.exec_, stream_), "cudaGraphLaunch");
  }

  /// Records `body` (stream work of kernels only: no waits, allocations or CUB calls) the first
  /// time as the body of a graph's while loop, then launches the graph: the body runs at least
  /// once, and again while `condition` says so after a run, on the device, without the host (the
  /// host's wait for a count after each replay, and the replays queued while it waited, cost the
  /// flip loop tens of microseconds an insertion round).
  template <class Body>
  void ReplayWhile(Recording& recording, const WhileCountNonzero& condition, Body&& body) {
    if (recording.exec_ == nullptr) {
      cudaGraph_t graph = nullptr;
      CheckCuda(cudaGraphCreate(&graph, 0), "cudaGraphCreate");
      try {
        cudaGraphConditionalHandle handle{};
        CheckCuda(cudaGraphConditionalHandleCreate(&handle, graph, 1, cudaGraphCondAssignDefault),
                  "cudaGraphConditionalHandleCreate");
        cudaGraphNodeParams params{};
        params.type = cudaGraphNodeTypeConditional;
        params.conditional.handle = handle;
        params.conditional.type = cudaGraphCondTypeWhile;
        params.conditional.size = 1;
        cudaGraphNode_t loop = nullptr;
        CheckCuda(cudaGraphAddNode(&loop, graph, nullptr, nullptr, 0, &params), "cudaGraphAddNode (while)");
        cudaGraph_t loop_body = params.conditional.phGraph_out[0];
        CheckCuda(
            cudaStreamBeginCaptureToGraph(stream_, loop_body, nullptr, nullptr, 0, cudaStreamCaptureModeThreadLocal),
            "cudaStreamBeginCaptureToGraph");
        try {
          body();
          SetLoopConditionKernel<<<1, 1, 0, stream_>>>(handle, condition);
          CheckCuda(cudaGetLastError(), "kernel launch");
        } catch (...) {
          cudaStreamEndCapture(stream_, &loop_body);
          cudaGetLastError();
          throw;
        }
        CheckCuda(cudaStreamEndCapture(stream_, &loop_body), "cudaStreamEndCapture");
        CheckCuda(cudaGraphInstantiate(&recording.exec_, graph, 0), "cudaGraphInstantiate");
      } catch (...) {
        cudaGraphDestroy(graph);
        throw;
      }
      cudaGraphDestroy(graph);
      recording.stream_ = stream_;
    }
    CheckCuda(cudaGraphLaunch(recording.exec_, stream_), "cudaGraphLaunch");
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
  /// Temporary storage of a CUB call, from the stream-ordered pool, returned at scope end.
  struct TempBytes {
    TempBytes(StreamOrderedAllocator& allocator, size_t bytes)
        : allocator(allocator), bytes(bytes), data(allocator.allocate(static_cast<std::ptrdiff_t>(bytes))) {}
    ~TempBytes() { allocator.deallocate(data, bytes); }
    TempBytes(const TempBytes&) = delete;
    TempBytes& operator=(const TempBytes&) = delete;
    StreamOrderedAllocator& allocator;
    size_t bytes;
    char* data;
  };

  cudaStream_t stream_;
  cudaStream_t copy_stream_ = nullptr;  // DownloadAsync's, made on first use
  MemoryLedger ledger_;                 // declared before temp_, which points at it
  StreamOrderedAllocator temp_;
  // ForEachBelow's fixed grid: enough blocks to fill every multiprocessor, striding over the rest.
  static constexpr unsigned kBlockThreads = 256;
  static constexpr unsigned kBlocksPerSm = 8;
  unsigned grid_blocks_ = 0;
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

/// Calls run(system) with a CudaSystem on `stream` (a cudaStream_t), or on a stream of its own
/// when `stream` is null: how every CUDA entry point of the engine starts.
template <class F>
void RunOnCudaStream(void* stream, F&& run) {
  if (stream != nullptr) {
    CudaSystem system(static_cast<cudaStream_t>(stream));
    run(system);
    return;
  }
  OwnedStream owned;
  CudaSystem system(owned.get());  // destroyed before its stream
  run(system);
}

}  // namespace galpha::detail
