// Atomic updates shared by the triangulation's and the alpha pipeline's functors: a counter
// increment, a 64-bit add and a minimum.
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"

namespace galpha::detail {

/// *p += 1, atomically; returns the value before. On the device the threads of a warp that
/// increment the same counter combine first (one atomic per distinct counter and warp): a grid's
/// millions of exactly tied radii all count into two or three ranks, and the flip loop appends
/// its next active triangles to one list; one atomic per thread on one address would serialise
/// such a pass.
GALPHA_HD inline uint32_t AtomicIncrement(uint32_t* p) {
#if defined(__CUDA_ARCH__)
  const unsigned active = __activemask();
  const unsigned peers = __match_any_sync(active, reinterpret_cast<unsigned long long>(p));
  unsigned lane;
  asm("mov.u32 %0, %%laneid;" : "=r"(lane));
  const int leader = __ffs(peers) - 1;
  uint32_t base = 0;
  if (static_cast<int>(lane) == leader) base = atomicAdd(p, static_cast<uint32_t>(__popc(peers)));
  base = __shfl_sync(peers, base, leader);
  return base + static_cast<uint32_t>(__popc(peers & ((1u << lane) - 1u)));
#else
  return __atomic_fetch_add(p, 1u, __ATOMIC_RELAXED);
#endif
}

/// *p += v, atomically, on a 64-bit counter (the area curve's units, the refine stage's count of
/// exact comparisons).
GALPHA_HD inline void AtomicAddU64(unsigned long long* p, unsigned long long v) {
#if defined(__CUDA_ARCH__)
  atomicAdd(p, v);
#else
  __atomic_fetch_add(p, v, __ATOMIC_RELAXED);
#endif
}

/// *p = min(*p, v), atomically, for words that many threads update at once. On the device the
/// threads of a warp that update the same word take their minimum first (one atomic per distinct
/// word and warp; alpha_functors.cuh's AtomicMinU32 is the plain one): a grid's exactly tied radii
/// give millions of entries one rank, and each offers its simplex as the rank's (ScatterRanks).
GALPHA_HD inline void AtomicMinU32WarpCombined(uint32_t* p, uint32_t v) {
#if defined(__CUDA_ARCH__)
  const unsigned active = __activemask();
  const unsigned peers = __match_any_sync(active, reinterpret_cast<unsigned long long>(p));
  unsigned lane;
  asm("mov.u32 %0, %%laneid;" : "=r"(lane));
  const unsigned smallest = __reduce_min_sync(peers, v);
  if (static_cast<int>(lane) == __ffs(peers) - 1) atomicMin(p, smallest);
#else
  uint32_t old = __atomic_load_n(p, __ATOMIC_RELAXED);
  while (v < old && !__atomic_compare_exchange_n(p, &old, v, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {}
#endif
}

}  // namespace galpha::detail
