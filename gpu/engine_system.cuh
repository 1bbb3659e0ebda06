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

#include <thrust/system/omp/execution_policy.h>

#include "gpu/delaunay_backend.hpp"

namespace galpha::detail {

/// The OpenMP backend: host memory, thrust::omp::par.
class CpuSystem {
 public:
  static constexpr const char* kName = "cpu";

  auto policy() const { return thrust::omp::par; }

  template <class T>
  T* Allocate(size_t count) {
    if (count == 0) return nullptr;
    void* p = std::malloc(count * sizeof(T));
    if (p == nullptr) {
      throw EngineError(EngineError::Kind::kResourceExhausted,
                        "host allocation of " + std::to_string(count * sizeof(T)) + " bytes failed");
    }
    return static_cast<T*>(p);
  }
  void Free(void* p) { std::free(p); }

  template <class T>
  void ToHost(T* host, const T* system, size_t count) {
    if (count != 0) std::memcpy(host, system, count * sizeof(T));
  }
  template <class T>
  void FromHost(T* system, const T* host, size_t count) {
    if (count != 0) std::memcpy(system, host, count * sizeof(T));
  }
  template <class T>
  T Read(const T* system) {
    return *system;
  }
  /// Waits for queued work; the CPU backend runs synchronously.
  void Synchronize() {}
};

/// An owning array in a system's memory. Move-only.
template <class T, class System>
class Buffer {
 public:
  Buffer(System& system, size_t count)
      : system_(&system), data_(system.template Allocate<T>(count)), size_(count) {}
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  Buffer(Buffer&& other) noexcept
      : system_(other.system_), data_(std::exchange(other.data_, nullptr)), size_(other.size_) {}
  ~Buffer() {
    if (data_ != nullptr) system_->Free(data_);
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

/// Records stage times: synchronizes the system at each stage end so a stage's time is its own.
template <class System>
class StageTimer {
 public:
  StageTimer(System& system, std::vector<StageTime>* out)
      : system_(system), out_(out), start_(std::chrono::steady_clock::now()) {}

  void EndStage(const char* name) {
    system_.Synchronize();
    const auto now = std::chrono::steady_clock::now();
    out_->push_back({name, std::chrono::duration<double>(now - start_).count()});
    start_ = now;
  }

 private:
  System& system_;
  std::vector<StageTime>* out_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace galpha::detail
