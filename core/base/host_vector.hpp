// HostVector: a std::vector that writes nothing into its elements when it grows (plain data), for
// the large arrays a build fills in one copy (the family's tables, hundreds of bytes a point).
//
// Why: a std::vector<uint32_t>(n) zeroes its memory on one thread before the copy overwrites it,
// and touching fresh memory first is what costs (the kernel faults in and clears every 4 KiB
// page: about 2 GB/s on one core of the H100 host). Without it the parallel copy that fills the
// array is the first touch, spread over every core; large blocks are also offered
// to transparent huge pages (512x fewer faults where the kernel grants them).
#pragma once

#include <sys/mman.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace galpha {

template <class T>
class DefaultInitAllocator {
 public:
  using value_type = T;
  /// Blocks from this size on are aligned to 2 MiB and advised for huge pages.
  static constexpr size_t kHugeFrom = size_t{8} << 20;
  static constexpr size_t kHugePage = size_t{2} << 20;

  DefaultInitAllocator() noexcept = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}  // NOLINT: rebinding converts implicitly

  T* allocate(size_t count) {
    if (count > static_cast<size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    const size_t bytes = count * sizeof(T);
    if (bytes < kHugeFrom) {
      void* p = ::operator new (bytes, std::align_val_t{alignof(T)});
      return static_cast<T*>(p);
    }
    const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (p == nullptr) throw std::bad_alloc();
    // Advice only: where the kernel grants no huge pages the memory works the same.
    madvise(p, rounded, MADV_HUGEPAGE);
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t count) noexcept {
    if (count * sizeof(T) < kHugeFrom) {
      ::operator delete (p, std::align_val_t{alignof(T)});
    } else {
      std::free(p);
    }
  }

  /// Growing writes nothing for types that are trivially copyable and destructible (plain data,
  /// even with default member initialisers such as MasterEntry's): the copy that fills the array
  /// creates its objects (implicit-lifetime types, P0593). Their values are unspecified until then.
  /// Other types are default-initialised.
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    if constexpr (!(std::is_trivially_copyable_v<U> && std::is_trivially_destructible_v<U>)) {
      ::new (static_cast<void*>(p)) U;
    }
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }

  template <class U>
  bool operator==(const DefaultInitAllocator<U>&) const noexcept {
    return true;
  }
  template <class U>
  bool operator!=(const DefaultInitAllocator<U>&) const noexcept {
    return false;
  }
};

template <class T>
using HostVector = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace galpha

namespace galpha {

/// Element-wise equality with a plain std::vector (tests compare tables with expected vectors).
template <class T>
bool operator==(const HostVector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
}
template <class T>
bool operator==(const std::vector<T>& a, const HostVector<T>& b) {
  return b == a;
}

}  // namespace galpha
