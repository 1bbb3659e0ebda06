#include "server/encoded_answer.hpp"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <new>
#include <utility>

#include "absl/strings/str_cat.h"

namespace galpha::server {

namespace v1 = galpha::v1;

namespace {

// One message of the answer: ready at once (the summary) or once its chunk is encoded.
struct PendingMessage {
  std::mutex mutex;
  std::condition_variable encoded;
  bool ready = false;
  bool summary = false;  // set when queued, never changed: readable without the lock
  absl::Status status;
  v1::ClassifyResponse message;
};

class EncodedClassifySource final : public ChunkSource<v1::ClassifyResponse> {
 public:
  EncodedClassifySource(std::unique_ptr<ChunkSource<v1::ClassifyResponse>> raw, v1::SimplexEncoding encoding,
                        ChunkCodecPool* pool)
      : raw_(std::move(raw)), encoding_(encoding), pool_(pool), window_(std::clamp<size_t>(pool->threads(), 1, 8)) {}

  // Tasks still queued or running hold their own PendingMessage and chunk: nothing to wait for.
  ~EncodedClassifySource() override = default;

  bool Next(v1::ClassifyResponse* message) override {
    if (!status_.ok()) return false;
    // The summary goes out at once: the chunks after it are taken from the raw answer (copies of
    // a few megabytes) and sent to the pool on the next call, while it is written. Other messages
    // wait for their encoding with the window full behind them.
    if (ahead_.empty()) Refill(1);
    if (!ahead_.empty() && !ahead_.front()->summary) Refill(window_);
    if (ahead_.empty()) {
      status_ = raw_->status();
      return false;
    }
    std::shared_ptr<PendingMessage> front = std::move(ahead_.front());
    ahead_.pop_front();
    {
      std::unique_lock<std::mutex> lock(front->mutex);
      front->encoded.wait(lock, [&] { return front->ready; });
    }
    if (!front->status.ok()) {
      status_ = UnsharedCopy(front->status);
      ahead_.clear();  // their tasks finish on their own
      return false;
    }
    message->Swap(&front->message);
    if (!front->summary) Refill(window_);  // the next chunks encode while this one is written
    return true;
  }

  absl::Status status() const override { return status_; }

 private:
  // Takes raw messages until `count` are ahead (or the raw answer ends), sending each simplex
  // chunk to the pool.
  void Refill(size_t count) {
    while (ahead_.size() < count && !raw_done_) {
      auto pending = std::make_shared<PendingMessage>();
      if (!raw_->Next(&pending->message)) {
        raw_done_ = true;
        break;
      }
      ahead_.push_back(pending);
      if (!pending->message.has_chunk()) {
        pending->summary = true;
        pending->ready = true;
        continue;
      }
      const uint64_t index = chunk_index_++;
      try {
        pool_->Submit([pending, encoding = encoding_, index](ChunkCodecs& codecs) {
          absl::Status status;
          v1::ClassifyResponse encoded;
          try {
            status = codecs.simplex_encoder.Encode(pending->message.chunk(), encoding, encoded.mutable_encoded_chunk());
            if (!status.ok()) {
              // The raw chunks come from the family's own tables: an encoder refusal is our defect.
              status = absl::InternalError(absl::StrCat("encoding simplex chunk ", index, ": ", status.message()));
            }
          } catch (const std::bad_alloc&) {
            status = OutOfMemory(index);
          }
          Finish(*pending, std::move(status), &encoded);
        });
      } catch (const std::bad_alloc&) {
        Finish(*pending, OutOfMemory(index), nullptr);  // never queued: Next must not wait for it
      }
    }
  }

  // A copy of a pool task's status that shares nothing with it. absl::Status copies share one
  // counted message, and the task's copy may be released last on the pool's thread; the count's
  // atomics live in Debian's uninstrumented libabsl_status, so ThreadSanitizer cannot see that
  // release order and reported the message's delete as racing with this thread's reads (a CI run
  // on 2026-11-28, in encoded_answer_test). The code and the message are what the answer needs.
  static absl::Status UnsharedCopy(const absl::Status& status) { return absl::Status(status.code(), status.message()); }

  static absl::Status OutOfMemory(uint64_t index) {
    return absl::ResourceExhaustedError(
        absl::StrCat("the server ran out of memory encoding simplex chunk ", index, " of the answer"));
  }

  // Marks `pending` done with `status` and, when given, its encoded message.
  static void Finish(PendingMessage& pending, absl::Status status, v1::ClassifyResponse* encoded) {
    std::lock_guard<std::mutex> lock(pending.mutex);
    pending.status = std::move(status);
    if (encoded != nullptr) pending.message.Swap(encoded);
    pending.ready = true;
    pending.encoded.notify_one();
  }

  std::unique_ptr<ChunkSource<v1::ClassifyResponse>> raw_;
  v1::SimplexEncoding encoding_;
  ChunkCodecPool* pool_;
  size_t window_;
  std::deque<std::shared_ptr<PendingMessage>> ahead_;
  bool raw_done_ = false;
  uint64_t chunk_index_ = 0;
  absl::Status status_;
};

}  // namespace

std::unique_ptr<ChunkSource<v1::ClassifyResponse>> EncodeSimplexChunks(
    std::unique_ptr<ChunkSource<v1::ClassifyResponse>> raw, v1::SimplexEncoding encoding, ChunkCodecPool* pool) {
  if (encoding != v1::SIMPLEX_ENCODING_DELTA && encoding != v1::SIMPLEX_ENCODING_DELTA_ZSTD) return raw;
  return std::make_unique<EncodedClassifySource>(std::move(raw), encoding, pool);
}

}  // namespace galpha::server
