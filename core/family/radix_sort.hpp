// A stable least-significant-digit radix sort on the host's cores, for the family's large host-side
// sorts (the persistence diagram's filtration order, the canonical orders), where a comparison sort
// of millions of items was the larger part of the query.
#pragma once

#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace galpha::detail {

/// The number of bits that hold every value in [0, max_value].
inline int BitWidth(uint64_t max_value) {
  int bits = 0;
  while (bits < 64 && (max_value >> bits) != 0) ++bits;
  return bits;
}

/// Sorts `items` stably by `key_of(item)`, an unsigned key below 2^bits: 11 bits a pass (none when
/// `bits` is 0), each pass a count per thread over its own contiguous slice, one prefix sum (digit
/// major, thread minor) and a scatter, so that equal keys keep their order whatever the number of
/// threads. `scratch` is working space; both keep their sizes.
template <class Vector, class KeyOf>
void StableRadixSort(Vector& items, Vector& scratch, int bits, KeyOf key_of) {
  constexpr int kDigitBits = 11;
  constexpr size_t kDigits = size_t{1} << kDigitBits;
  const size_t n = items.size();
  scratch.resize(n);
  std::vector<size_t> offsets(static_cast<size_t>(omp_get_max_threads()) * kDigits);
  for (int shift = 0; shift < bits; shift += kDigitBits) {
    std::fill(offsets.begin(), offsets.end(), 0);
    auto digit = [&](const auto& item) { return static_cast<size_t>(key_of(item) >> shift) & (kDigits - 1); };
#pragma omp parallel
    {
      const auto threads = static_cast<size_t>(omp_get_num_threads());
      const auto thread = static_cast<size_t>(omp_get_thread_num());
      const size_t begin = n * thread / threads, end = n * (thread + 1) / threads;
      size_t* mine = &offsets[thread * kDigits];
      for (size_t i = begin; i < end; ++i) ++mine[digit(items[i])];
#pragma omp barrier
#pragma omp single
      {
        size_t next = 0;
        for (size_t d = 0; d < kDigits; ++d) {
          for (size_t t = 0; t < threads; ++t) {
            const size_t count = offsets[t * kDigits + d];
            offsets[t * kDigits + d] = next;
            next += count;
          }
        }
      }
      for (size_t i = begin; i < end; ++i) scratch[mine[digit(items[i])]++] = items[i];
    }
    std::swap(items, scratch);
  }
}

}  // namespace galpha::detail
