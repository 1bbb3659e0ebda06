// Copies between host buffers on all host cores: the last leg of a download (pinned staging into
// the result's own memory) and the CPU backend's "transfers". One thread copies ~10 GB/s and
// faults fresh pages in far slower; large copies are split across the OpenMP threads.
#pragma once

#include <cstddef>

namespace galpha::detail {

/// One copy between a host buffer and a buffer in an execution system's memory.
struct HostCopy {
  void* host;
  const void* system;
  size_t bytes;
};

/// memcpy(dst, src, bytes), in parallel when `bytes` is large.
void ParallelCopy(void* dst, const void* src, size_t bytes);

/// The calling thread's parallel copies leave `cores` of the host's cores to other threads (a
/// download beside the build leaves the build's own thread room to launch and wait).
void LeaveCoresToOthers(int cores);

}  // namespace galpha::detail
