#include "gpu/system/host_copy.hpp"

#include <omp.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

namespace galpha::detail {

void ParallelCopy(void* dst, const void* src, size_t bytes) {
  // Below a few MiB the fork/join of a parallel region costs more than it saves.
  constexpr size_t kParallelFrom = size_t{4} << 20;
  constexpr size_t kBlock = size_t{1} << 20;
  if (bytes < kParallelFrom) {
    if (bytes != 0) std::memcpy(dst, src, bytes);
    return;
  }
  auto* out = static_cast<char*>(dst);
  const auto* in = static_cast<const char*>(src);
  const int64_t blocks = static_cast<int64_t>((bytes + kBlock - 1) / kBlock);
#pragma omp parallel for schedule(static)
  for (int64_t b = 0; b < blocks; ++b) {
    const size_t begin = static_cast<size_t>(b) * kBlock;
    std::memcpy(out + begin, in + begin, std::min(kBlock, bytes - begin));
  }
}

void LeaveCoresToOthers(int cores) {
  // nthreads-var is per thread: only this thread's later parallel regions are narrower.
  omp_set_num_threads(std::max(1, omp_get_num_procs() - cores));
}

}  // namespace galpha::detail
