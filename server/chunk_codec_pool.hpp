// Encoding and decoding of wire chunks on a fixed set of threads, one a core, shared by every
// stream of the server:
// - a Build stream's encoded point chunks are decompressed while its reactor already reads the
//   next message. Decoded one after another on the reactor (zstd and the inverse transform, ~1.5 ms
//   a 1 MiB chunk on one core), they were the upload's bottleneck: 24-29 ms of a 1M-point stream
//   on the H100 host, whose client had encoded the chunks on eight threads;
// - a compact Classify answer's chunks are encoded ahead of the writes (server/encoded_answer).
// Every thread has its own codecs (zstd contexts and scratch), so a task gets those of the thread
// that runs it.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "proto/codec/point_chunk_codec.hpp"
#include "proto/codec/simplex_chunk_codec.hpp"

namespace galpha::server {

/// The codecs of one pool thread.
struct ChunkCodecs {
  wire::PointChunkDecoder point_decoder;
  wire::SimplexChunkEncoder simplex_encoder;
};

class ChunkCodecPool {
 public:
  using Task = std::function<void(ChunkCodecs& codecs)>;

  /// `threads` workers (at least one).
  explicit ChunkCodecPool(size_t threads);
  /// Runs what is queued, then joins the workers.
  ~ChunkCodecPool();
  ChunkCodecPool(const ChunkCodecPool&) = delete;
  ChunkCodecPool& operator=(const ChunkCodecPool&) = delete;

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
