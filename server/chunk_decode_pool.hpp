// Decoding of encoded point chunks on a fixed set of threads, so that a Build stream's chunks are
// decompressed while its reactor already reads the next message. Decoded one after another on the
// reactor (zstd and the inverse transform, ~1.5 ms a 1 MiB chunk on one core), they were the
// upload's bottleneck: 24-29 ms of a 1M-point stream on the H100 host, whose client had encoded
// the chunks on eight threads. Every thread has its own wire::PointChunkDecoder (zstd context and
// scratch), so a task gets the decoder of the thread that runs it.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "proto/codec/point_chunk_codec.hpp"

namespace galpha::server {

class ChunkDecodePool {
 public:
  using Task = std::function<void(wire::PointChunkDecoder& decoder)>;

  /// `threads` workers (at least one).
  explicit ChunkDecodePool(size_t threads);
  /// Runs what is queued, then joins the workers.
  ~ChunkDecodePool();
  ChunkDecodePool(const ChunkDecodePool&) = delete;
  ChunkDecodePool& operator=(const ChunkDecodePool&) = delete;

  /// Queues `task`; tasks start in the order they were submitted.
  void Submit(Task task);

  size_t threads() const { return workers_.size(); }

 private:
  void Work();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Task> queue_;
  bool stopping_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace galpha::server
