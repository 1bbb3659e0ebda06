// MeasureSortFloorSeconds on one engine system (sort_floor.hpp), instantiated for both backends.
#pragma once

#include <thrust/sequence.h>
#include <thrust/sort.h>
#include <thrust/tabulate.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <limits>

#include "core/base/hd.hpp"
#include "gpu/system/engine_system.cuh"

namespace galpha::detail {

/// splitmix64 of (index, round): distinct-looking 64-bit keys, like the certified radius keys.
struct RandomKey {
  uint64_t round;
  GALPHA_HD uint64_t operator()(uint64_t i) const {
    uint64_t z = i + round * 0x9E3779B97F4A7C15ull + 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
};

template <class System>
double SortFloorSeconds(System& sys, size_t pairs) {
  Buffer<uint64_t, System> keys(sys, pairs);
  Buffer<uint32_t, System> values(sys, pairs);
  auto policy = sys.policy();
  double best = std::numeric_limits<double>::infinity();
  for (uint64_t round = 0; round < 3; ++round) {
    thrust::tabulate(policy, keys.data(), keys.data() + pairs, RandomKey{round});
    thrust::sequence(policy, values.data(), values.data() + pairs);
    sys.Synchronize();
    const auto start = std::chrono::steady_clock::now();
    thrust::sort_by_key(policy, keys.data(), keys.data() + pairs, values.data());
    sys.Synchronize();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

}  // namespace galpha::detail
