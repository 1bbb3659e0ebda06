#include "client/classify_parts_merger.hpp"

#include <algorithm>
#include <utility>

#include "absl/strings/str_cat.h"

namespace galpha::client {

namespace v1 = galpha::v1;

ClassifyPartsMerger::ClassifyPartsMerger(size_t parts, size_t queued_per_part)
    : queued_per_part_(std::max<size_t>(queued_per_part, 1)), parts_(std::max<size_t>(parts, 2)) {}

bool ClassifyPartsMerger::Push(size_t part, v1::ClassifyResponse message) {
  std::unique_lock<std::mutex> lock(mutex_);
  Part& p = parts_[part];
  changed_.wait(lock, [&] { return p.dropped || p.queue.size() < queued_per_part_; });
  if (p.dropped) return false;
  p.queue.push_back(std::move(message));
  changed_.notify_all();
  return true;
}

void ClassifyPartsMerger::End(size_t part, const absl::Status& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  parts_[part].ended = true;
  parts_[part].status = status;
  changed_.notify_all();
}

bool ClassifyPartsMerger::Take(std::unique_lock<std::mutex>& lock, size_t p) {
  Part& part = parts_[p];
  changed_.wait(lock, [&] { return !part.queue.empty() || part.ended; });
  if (part.queue.empty()) return false;
  current_ = std::move(part.queue.front());
  part.queue.pop_front();
  part.first = false;
  changed_.notify_all();  // room for its reader
  return true;
}

absl::Status ClassifyPartsMerger::FinishAll(std::unique_lock<std::mutex>& lock) {
  // Whether a part holds more than it may after the answer's end. A server that does not split
  // answers sent such a part whole: only a summary, as part 0's answer had no chunk.
  const auto past_the_end = [](const Part& part) {
    if (part.dropped || part.queue.empty()) return false;
    return !(part.first && part.queue.size() == 1 && part.queue.front().has_summary());
  };
  // Not waiting for a part with chunks past the end: its reader may wait for room and never end.
  changed_.wait(lock, [&] {
    return std::all_of(parts_.begin(), parts_.end(),
                       [&](const Part& p) { return p.ended || p.dropped || past_the_end(p); });
  });
  for (size_t p = 0; p < parts_.size(); ++p) {
    const Part& part = parts_[p];
    if (past_the_end(part)) {
      return absl::InternalError(
          absl::StrCat("part ", p, " of ", parts_.size(), " of the Classify answer sent chunks past the answer's end"));
    }
    if (!part.dropped && !part.status.ok()) return part.status;
  }
  return absl::OkStatus();
}

absl::StatusOr<const v1::ClassifyResponse*> ClassifyPartsMerger::Next() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (complete_) return nullptr;
  if (!summary_taken_) {
    if (!Take(lock, 0)) {
      if (!parts_[0].status.ok()) return parts_[0].status;
      return absl::InternalError("part 0 of the Classify answer ended before its summary");
    }
    if (!current_.has_summary())
      return absl::InternalError("part 0 of the Classify answer did not start with the summary");
    summary_taken_ = true;
    return &current_;
  }
  for (;;) {
    const size_t p = whole_from_part_zero_ ? 0 : static_cast<size_t>(next_chunk_ % parts_.size());
    if (!Take(lock, p)) {
      // Part p ended at its turn: with chunk next_chunk_ not sent, no later chunk exists.
      if (!parts_[p].status.ok()) return parts_[p].status;
      absl::Status finished = FinishAll(lock);
      if (!finished.ok()) return finished;
      complete_ = true;
      return nullptr;
    }
    if (p != 0 && current_.has_summary()) {
      // The server answered this part whole: it does not know part_count. Part 0 is the answer.
      whole_from_part_zero_ = true;
      for (size_t q = 1; q < parts_.size(); ++q) {
        parts_[q].dropped = true;
        parts_[q].queue.clear();
      }
      changed_.notify_all();
      continue;
    }
    if (current_.has_summary()) {
      return absl::InternalError(absl::StrCat("part ", p, " of the Classify answer sent a second summary"));
    }
    ++next_chunk_;
    return &current_;
  }
}

bool ClassifyPartsMerger::whole_from_part_zero() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return whole_from_part_zero_;
}

void ClassifyPartsMerger::Stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (Part& part : parts_) {
    part.dropped = true;
    part.queue.clear();
  }
  complete_ = true;
  changed_.notify_all();
}

}  // namespace galpha::client
