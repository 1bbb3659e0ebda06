#include "client/classify_answer_decoder.hpp"

#include <algorithm>
#include <utility>

#include "proto/codec/simplex_chunk_codec.hpp"

namespace galpha::client {

namespace v1 = galpha::v1;

ClassifyAnswerDecoder::ClassifyAnswerDecoder(size_t threads, size_t max_waiting)
    : max_waiting_(std::max<size_t>(max_waiting, 1)) {
  const size_t count = std::max<size_t>(threads, 1);
  workers_.reserve(count);
  for (size_t i = 0; i < count; ++i) workers_.emplace_back([this] { Work(); });
}

ClassifyAnswerDecoder::~ClassifyAnswerDecoder() {
  Stop();
  for (std::thread& worker : workers_) worker.join();
}

bool ClassifyAnswerDecoder::Push(v1::ClassifyResponse message) {
  auto item = std::make_shared<Item>();
  item->message = std::move(message);
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return waiting_.size() < max_waiting_ || stopped_; });
  if (stopped_) return false;
  if (item->message.has_summary()) {
    item->done = true;
  } else {
    item->chunk_index = chunks_++;
    item->encoded = item->message.has_encoded_chunk();
    item->done = !item->encoded;
    if (item->encoded) undecoded_.push_back(item);
  }
  waiting_.push_back(std::move(item));
  changed_.notify_all();
  return true;
}

void ClassifyAnswerDecoder::End() {
  std::lock_guard<std::mutex> lock(mutex_);
  ended_ = true;
  changed_.notify_all();
}

void ClassifyAnswerDecoder::Stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  stopped_ = true;
  waiting_.clear();
  undecoded_.clear();
  changed_.notify_all();
}

absl::StatusOr<const v1::ClassifyResponse*> ClassifyAnswerDecoder::Next() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return stopped_ || (waiting_.empty() ? ended_ : waiting_.front()->done); });
  if (stopped_ || waiting_.empty()) return nullptr;
  current_ = std::move(waiting_.front());
  waiting_.pop_front();
  changed_.notify_all();  // room for the producer
  lock.unlock();
  if (!current_->status.ok()) return current_->status;
  return current_->encoded ? &current_->decoded : &current_->message;
}

void ClassifyAnswerDecoder::Work() {
  wire::SimplexChunkDecoder decoder;
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return stopped_ || ended_ || !undecoded_.empty(); });
    if (stopped_ || undecoded_.empty()) return;  // stopped, or ended with nothing left to decode
    std::shared_ptr<Item> item = std::move(undecoded_.front());
    undecoded_.pop_front();
    lock.unlock();
    absl::Status status =
        decoder.Decode(item->message.encoded_chunk(), item->chunk_index, item->decoded.mutable_chunk());
    item->message.Clear();  // the encoded bytes are not needed any more
    lock.lock();
    item->status = std::move(status);
    item->done = true;
    changed_.notify_all();
  }
}

}  // namespace galpha::client
