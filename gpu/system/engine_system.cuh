// Execution systems for the one templated engine: where memory lives, which Thrust policy runs the
// algorithms, and how a value gets back to the host. The engine code is written once against this
// small interface (CpuSystem here, CudaSystem in cuda_system.cuh).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include <thrust/copy.h>
#include <thrust/for_each.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/remove.h>
#include <thrust/system/omp/execution_policy.h>

#include "core/base/stage_time.hpp"
#include "gpu/system/backend.hpp"
#include "gpu/system/block_lanes.hpp"
#include "gpu/system/host_copy.hpp"
#include "gpu/system/loop_condition.hpp"

namespace galpha::detail {

/// Bytes a build holds in its system's memory now and at its peak: the engine's buffers and the
/// temporaries of Thrust's algorithms. Stream-ordered frees count when they are queued, which is
/// when the memory becomes reusable by the build's later work on the same stream.
class MemoryLedger {
 public:
  void Add(size_t bytes) {
    live_ += bytes;
    if (live_ > peak_) peak_ = live_;
  }
  void Remove(size_t bytes) { live_ -= bytes; }
  size_t peak() const { return peak_; }

 private:
  size_t live_ = 0;
  size_t peak_ = 0;
};

/// Thrust's temporary storage on the host, counted in the build's ledger.
class HostTempAllocator {
 public:
  using value_type = char;
  explicit HostTempAllocator(MemoryLedger* ledger) : ledger_(ledger) {}
  char* allocate(std::ptrdiff_t bytes) {
    void* p = std::malloc(static_cast<size_t>(bytes));
    if (p == nullptr) throw std::bad_alloc();
    ledger_->Add(static_cast<size_t>(bytes));
    return static_cast<char*>(p);
  }
  void deallocate(char* p, size_t bytes) {
    std::free(p);
    ledger_->Remove(bytes);
  }

 private:
  MemoryLedger* ledger_;
};

/// The negation of a predicate (thrust::remove_if drops what its predicate accepts).
template <class Keep>
struct Rejects {
  Keep keep;
  template <class T>
  bool operator()(const T& x) const {
    return !keep(x);
  }
};

/// The OpenMP backend: host memory, thrust::omp::par.
class CpuSystem {
 public:
  static constexpr const char* kName = "cpu";
  /// Whether the system's memory is the host's (no copies needed to run host code on it).
  static constexpr bool kHostMemory = true;
  /// A parallel round of hull repair (a few parallel regions) costs about this many steps of the
  /// one-thread chain walk (~0.7 us a step here; measured on 2 cores, 2026-11-22).
  static constexpr uint32_t kRepairStepsPerRound = 64;

  CpuSystem() : temp_(&ledger_) {}
  CpuSystem(const CpuSystem&) = delete;
  CpuSystem& operator=(const CpuSystem&) = delete;

  auto policy() { return thrust::omp::par(temp_); }

  template <class T>
  T* Allocate(size_t count) {
    if (count == 0) return nullptr;
    void* p = std::malloc(count * sizeof(T));
    if (p == nullptr) {
      throw EngineError(EngineError::Kind::kResourceExhausted,
                        "host allocation of " + std::to_string(count * sizeof(T)) + " bytes failed");
    }
    ledger_.Add(count * sizeof(T));
    return static_cast<T*>(p);
  }
  void Free(void* p, size_t bytes) {
    std::free(p);
    ledger_.Remove(bytes);
  }
  /// Peak bytes of working memory held so far: the engine's buffers and Thrust's temporaries.
  size_t peak_bytes() const { return ledger_.peak(); }

  template <class T>
  void ToHost(T* host, const T* system, size_t count) {
    ParallelCopy(host, system, count * sizeof(T));
  }
  template <class T>
  void FromHost(T* system, const T* host, size_t count) {
    ParallelCopy(system, host, count * sizeof(T));
  }
  void Download(const std::vector<HostCopy>& copies) {
    for (const HostCopy& c : copies) ParallelCopy(c.host, c.system, c.bytes);
  }
  void Upload(const std::vector<HostCopy>& copies) {
    for (const HostCopy& c : copies) ParallelCopy(const_cast<void*>(c.system), c.host, c.bytes);
  }
  /// Nothing to overlap on the host: the copy is made at once.
  struct PendingDownload {
    void Wait() {}
  };
  PendingDownload DownloadAsync(const std::vector<HostCopy>& copies) {
    Download(copies);
    return {};
  }
  template <class T>
  T Read(const T* system) {
    return *system;
  }
  /// Waits for queued work; the CPU backend runs synchronously.
  void Synchronize() {}

  /// Keeps, in place and in order, the first `n` items of `data` whose flag satisfies `keep`;
  /// their number goes to `*count`.
  template <class DataIt, class FlagIt, class Keep>
  void SelectFlaggedInPlace(DataIt data, FlagIt flags, uint32_t n, Keep keep, uint32_t* count) {
    *count = static_cast<uint32_t>(thrust::remove_if(policy(), data, data + n, flags, Rejects<Keep>{keep}) - data);
  }
  /// Runs f(i) for every i below `*count` (set by earlier work).
  template <class F>
  void ForEachBelow(const uint32_t* count, F f) {
    const thrust::counting_iterator<uint32_t> first(0);
    thrust::for_each(policy(), first, first + *count, f);
  }
  /// Appends the items among the first `per_item * *count` of `in` whose flag satisfies `keep`
  /// to `out` from position `*out_count` on, in order, and adds their number to `*out_count`.
  template <class InIt, class FlagIt, class Keep, class OutIt>
  void AppendIf(const uint32_t* count, uint32_t per_item, InIt in, FlagIt flags, Keep keep, OutIt out,
                uint32_t* out_count) {
    const uint32_t n = per_item * *count;
    *out_count += static_cast<uint32_t>(thrust::copy_if(policy(), in, in + n, flags, out + *out_count, keep) -
                                        (out + *out_count));
  }
  template <class F>
  void RunSingle(F f) {
    f(0u);
  }
  /// Runs f(lanes) once, with one lane here (the CUDA system runs one block of threads).
  template <class F>
  void RunInOneBlock(F f) {
    f(BlockLanes{0, 1});
  }
  /// The CUDA system records work once and replays it; here it simply runs again.
  struct Recording {};
  template <class Body>
  void Replay(Recording&, Body&& body) {
    body();
  }
  /// Runs `body` while `condition` says so after each run (the CUDA system's loop on the device).
  template <class Body>
  void ReplayWhile(Recording&, const WhileCountNonzero& condition, Body&& body) {
    do {
      body();
    } while (condition());
  }

  using StageMark = std::chrono::steady_clock::time_point;
  StageMark MarkStage() { return std::chrono::steady_clock::now(); }
  double SecondsBetween(StageMark from, StageMark to) { return std::chrono::duration<double>(to - from).count(); }
  void ReleaseMark(StageMark) {}

 private:
  MemoryLedger ledger_;  // declared before temp_, which points at it
  HostTempAllocator temp_;
};

/// An owning array in a system's memory. Move-only.
template <class T, class System>
class Buffer {
 public:
  Buffer(System& system, size_t count) : system_(&system), data_(system.template Allocate<T>(count)), size_(count) {}
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  Buffer(Buffer&& other) noexcept
      : system_(other.system_), data_(std::exchange(other.data_, nullptr)), size_(other.size_) {}
  Buffer& operator=(Buffer&& other) noexcept {
    if (this != &other) {
      Reset();
      system_ = other.system_;
      data_ = std::exchange(other.data_, nullptr);
      size_ = std::exchange(other.size_, 0);
    }
    return *this;
  }
  ~Buffer() { Reset(); }

  /// Frees the memory now, before the end of the scope: lowers a build's peak.
  void Reset() {
    if (data_ != nullptr) system_->Free(data_, size_ * sizeof(T));
    data_ = nullptr;
    size_ = 0;
  }

  T* data() { return data_; }
  const T* data() const { return data_; }
  size_t size() const { return size_; }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }

  std::vector<T> ToHostVector(size_t count) const {
    std::vector<T> host(count);
    system_->ToHost(host.data(), data_, count);
    return host;
  }

 private:
  System* system_;
  T* data_;
  size_t size_;
};

/// Records stage times as marks in the system's own order of work (CUDA events on the stream, the
/// clock on the CPU): a stage's time is from the previous mark to its own, and no stage end waits
/// for the device. Finish() reads the marks (one wait, for the last) into the stage list.
template <class System>
class StageTimer {
 public:
  StageTimer(System& system, std::vector<StageTime>* out) : system_(system), out_(out), start_(system.MarkStage()) {}
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;
  ~StageTimer() {
    system_.ReleaseMark(start_);
    for (auto& [name, mark] : ends_) system_.ReleaseMark(mark);
  }

  void EndStage(const char* name) { ends_.emplace_back(name, system_.MarkStage()); }

  /// Appends every ended stage to the output, in order.
  void Finish() {
    typename System::StageMark from = start_;
    for (auto& [name, mark] : ends_) {
      out_->push_back({name, system_.SecondsBetween(from, mark)});
      from = mark;
    }
  }

 private:
  System& system_;
  std::vector<StageTime>* out_;
  typename System::StageMark start_;
  std::vector<std::pair<const char*, typename System::StageMark>> ends_;
};

}  // namespace galpha::detail
