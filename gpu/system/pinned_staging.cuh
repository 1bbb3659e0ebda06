// Host transfers of the CUDA backend through pinned memory. A copy from pageable memory runs at a
// fraction of the link's speed (the driver stages it through small pinned buffers of its own, one
// at a time); pinning the result's memory instead costs more than the copy. So every large copy is
// pipelined through two pinned slots: the DMA of one piece overlaps the host copy of the other.
// The slots come from a process-wide pool (pinning is slow: a slot is allocated once and reused
// by every later build; concurrent builds take a pair each). Only compiled by nvcc.
#pragma once

#include <cuda_runtime.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "gpu/system/host_copy.hpp"

namespace galpha::detail {

/// Two pinned slots and their events, leased from the process-wide pool for one batch of copies.
class PinnedStaging {
 public:
  static constexpr size_t kSlotBytes = size_t{16} << 20;
  /// Largest single DMA of a download (see Download).
  static constexpr size_t kDmaBytes = size_t{1} << 20;

  PinnedStaging();
  ~PinnedStaging();
  PinnedStaging(const PinnedStaging&) = delete;
  PinnedStaging& operator=(const PinnedStaging&) = delete;

  /// Copies every `system` (device) buffer to its `host` buffer; returns when all have arrived.
  void Download(const std::vector<HostCopy>& copies, cudaStream_t stream);
  /// Copies every `host` buffer to its `system` (device) buffer; returns when the host buffers
  /// may be reused (the copies are done).
  void Upload(const std::vector<HostCopy>& copies, cudaStream_t stream);

  struct Slots;

 private:
  Slots* slots_;
};

}  // namespace galpha::detail
