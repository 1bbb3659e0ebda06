#include "server/chunk_codec_pool.hpp"

#include <algorithm>
#include <utility>

namespace galpha::server {

ChunkCodecPool::ChunkCodecPool(size_t threads) {
  const size_t count = std::max<size_t>(threads, 1);
  workers_.reserve(count);
  for (size_t i = 0; i < count; ++i) workers_.emplace_back([this] { Work(); });
}

ChunkCodecPool::~ChunkCodecPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

void ChunkCodecPool::Submit(Task task) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(task));
  }
  wake_.notify_one();
}

void ChunkCodecPool::Work() {
  ChunkCodecs codecs;
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    if (queue_.empty() && !stopping_) {
      // Idle: the scratch of the last chunk (its decompressed bytes) is not kept, or an idle server
      // would hold a chunk's worth per thread for good. Between the chunks of a busy stream it is
      // kept, as a stream's own decoder keeps it.
      lock.unlock();
      codecs.point_decoder.ReleaseScratch();
      codecs.simplex_encoder.ReleaseScratch();
      lock.lock();
    }
    wake_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, and nothing left to run
    Task task = std::move(queue_.front());
    queue_.pop_front();
    lock.unlock();
    task(codecs);
    task = nullptr;  // the chunk's message goes now, not under the lock
    lock.lock();
  }
}

}  // namespace galpha::server
