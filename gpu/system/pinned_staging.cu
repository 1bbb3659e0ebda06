#include "gpu/system/pinned_staging.cuh"

#include <algorithm>
#include <mutex>

#include "gpu/system/cuda_system.cuh"

namespace galpha::detail {

struct PinnedStaging::Slots {
  char* memory[2] = {nullptr, nullptr};
  cudaEvent_t done[2] = {nullptr, nullptr};  // recorded after the DMA that used the slot
};

namespace {

std::mutex pool_mutex;

/// Pinned blocks of one kind not leased now. Kept for the life of the process: pinning costs
/// milliseconds.
template <class Block>
class IdleBlocks {
 public:
  /// An idle block, or a new one from `make`.
  template <class Make>
  static Block* Take(Make make) {
    {
      std::lock_guard<std::mutex> lock(pool_mutex);
      if (!Idle().empty()) {
        Block* block = Idle().back();
        Idle().pop_back();
        return block;
      }
    }
    return make();
  }
  static void Give(Block* block) {
    std::lock_guard<std::mutex> lock(pool_mutex);
    Idle().push_back(block);
  }

 private:
  static std::vector<Block*>& Idle() {
    static auto* idle = new std::vector<Block*>();
    return *idle;
  }
};

PinnedStaging::Slots* NewSlots() {
  auto* slots = new PinnedStaging::Slots();
  try {
    for (int i = 0; i < 2; ++i) {
      CheckCuda(
          cudaHostAlloc(reinterpret_cast<void**>(&slots->memory[i]), PinnedStaging::kSlotBytes, cudaHostAllocDefault),
          "cudaHostAlloc (pinned staging)");
      CheckCuda(cudaEventCreateWithFlags(&slots->done[i], cudaEventDisableTiming), "cudaEventCreate");
    }
  } catch (...) {
    for (int i = 0; i < 2; ++i) {
      if (slots->memory[i] != nullptr) cudaFreeHost(slots->memory[i]);
      if (slots->done[i] != nullptr) cudaEventDestroy(slots->done[i]);
    }
    delete slots;
    throw;
  }
  return slots;
}

/// A copy cut into pieces of at most one slot.
struct Piece {
  char* host;
  char* device;
  size_t bytes;
};

std::vector<Piece> CutIntoPieces(const std::vector<HostCopy>& copies) {
  std::vector<Piece> pieces;
  for (const HostCopy& c : copies) {
    for (size_t at = 0; at < c.bytes; at += PinnedStaging::kSlotBytes) {
      pieces.push_back({static_cast<char*>(c.host) + at, const_cast<char*>(static_cast<const char*>(c.system)) + at,
                        std::min(PinnedStaging::kSlotBytes, c.bytes - at)});
    }
  }
  return pieces;
}

}  // namespace

PinnedStaging::PinnedStaging() : slots_(IdleBlocks<Slots>::Take(NewSlots)) {}

PinnedStaging::~PinnedStaging() {
  // A copy may still be in flight when an exception unwinds: the slots return only once idle.
  for (int i = 0; i < 2; ++i) cudaEventSynchronize(slots_->done[i]);
  cudaGetLastError();
  IdleBlocks<Slots>::Give(slots_);
}

void PinnedStaging::Download(const std::vector<HostCopy>& copies, cudaStream_t stream) {
  const std::vector<Piece> pieces = CutIntoPieces(copies);
  auto issue = [&](size_t i) {
    const int slot = static_cast<int>(i % 2);
    // In DMAs of at most kDmaBytes: a download beside the build shares the device-to-host copy
    // engine with the build's own small reads (counts it waits for), which would otherwise queue
    // behind a whole slot.
    for (size_t at = 0; at < pieces[i].bytes; at += kDmaBytes) {
      CheckCuda(cudaMemcpyAsync(slots_->memory[slot] + at, pieces[i].device + at,
                                std::min(kDmaBytes, pieces[i].bytes - at), cudaMemcpyDeviceToHost, stream),
                "cudaMemcpyAsync to pinned staging");
    }
    CheckCuda(cudaEventRecord(slots_->done[slot], stream), "cudaEventRecord");
  };
  if (!pieces.empty()) issue(0);
  for (size_t i = 0; i < pieces.size(); ++i) {
    // The next piece's DMA runs while this one is copied out (its slot was emptied last turn).
    if (i + 1 < pieces.size()) issue(i + 1);
    const int slot = static_cast<int>(i % 2);
    CheckCuda(cudaEventSynchronize(slots_->done[slot]), "cudaEventSynchronize (download)");
    ParallelCopy(pieces[i].host, slots_->memory[slot], pieces[i].bytes);
  }
}

void PinnedStaging::Upload(const std::vector<HostCopy>& copies, cudaStream_t stream) {
  const std::vector<Piece> pieces = CutIntoPieces(copies);
  for (size_t i = 0; i < pieces.size(); ++i) {
    const int slot = static_cast<int>(i % 2);
    // The slot's previous piece must have left before it is overwritten.
    if (i >= 2) CheckCuda(cudaEventSynchronize(slots_->done[slot]), "cudaEventSynchronize (upload)");
    ParallelCopy(slots_->memory[slot], pieces[i].host, pieces[i].bytes);
    CheckCuda(cudaMemcpyAsync(pieces[i].device, slots_->memory[slot], pieces[i].bytes, cudaMemcpyHostToDevice, stream),
              "cudaMemcpyAsync from pinned staging");
    CheckCuda(cudaEventRecord(slots_->done[slot], stream), "cudaEventRecord");
  }
  for (size_t i = pieces.size() >= 2 ? pieces.size() - 2 : 0; i < pieces.size(); ++i) {
    CheckCuda(cudaEventSynchronize(slots_->done[i % 2]), "cudaEventSynchronize (upload)");
  }
}

}  // namespace galpha::detail
