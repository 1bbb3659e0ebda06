#include "server/build_scheduler.hpp"

#include <utility>

#include "absl/strings/str_cat.h"

namespace galpha::server {

BuildScheduler::BuildScheduler(std::vector<void*> slot_streams, size_t max_queue, size_t memory_budget_bytes,
                               SchedulerObserver* observer)
    : max_queue_(max_queue), memory_budget_(memory_budget_bytes), observer_(observer) {
  for (size_t i = 0; i < slot_streams.size(); ++i) {
    workers_.emplace_back([this, slot = BuildSlot{static_cast<int>(i), slot_streams[i]}] { WorkerLoop(slot); });
  }
}

BuildScheduler::~BuildScheduler() {
  Stop();
  for (std::thread& worker : workers_) worker.join();
}

absl::Status BuildScheduler::Submit(size_t memory_bytes, Job job) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopping_) return absl::UnavailableError("the server is shutting down and accepts no new builds");
  if (memory_budget_ != 0 && memory_bytes > memory_budget_) {
    return absl::ResourceExhaustedError(absl::StrCat("the build needs about ", memory_bytes,
                                                     " bytes of working memory; this server admits at most ",
                                                     memory_budget_, " bytes per build"));
  }
  // A job that a free slot takes at once (a slot idle and its memory admitted) is not queued; the
  // others wait, and at most max_queue_ of them may.
  queue_.push_back(Pending{memory_bytes, std::move(job)});
  if (WaitingLocked() > max_queue_) {
    queue_.pop_back();
    return absl::ResourceExhaustedError(absl::StrCat("the build queue is full (", max_queue_, " builds waiting for ",
                                                     workers_.size(), " slots); retry later"));
  }
  ReportLoad();
  changed_.notify_all();
  return absl::OkStatus();
}

void BuildScheduler::Stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  stopping_ = true;
  changed_.notify_all();
}

size_t BuildScheduler::WaitingLocked() const {
  // The jobs at the head that free slots and the memory budget admit now start at once (FIFO:
  // the first that cannot start holds back the rest).
  size_t free_slots = workers_.size() - running_;
  size_t admitted = admitted_bytes_;
  size_t starting = 0;
  for (const Pending& pending : queue_) {
    if (free_slots == 0 || (memory_budget_ != 0 && admitted + pending.memory_bytes > memory_budget_)) break;
    --free_slots;
    admitted += pending.memory_bytes;
    ++starting;
  }
  return queue_.size() - starting;
}

void BuildScheduler::ReportLoad() {
  if (observer_ != nullptr) observer_->OnLoad(WaitingLocked(), running_, admitted_bytes_);
}

void BuildScheduler::WorkerLoop(BuildSlot slot) {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    // FIFO: only the head may start, so a large build is not starved by small ones behind it.
    changed_.wait(lock, [&] {
      if (queue_.empty()) return stopping_;
      if (stopping_) return true;
      return memory_budget_ == 0 || admitted_bytes_ + queue_.front().memory_bytes <= memory_budget_;
    });
    if (queue_.empty()) return;  // stopping, nothing left
    Pending pending = std::move(queue_.front());
    queue_.pop_front();
    const bool draining = stopping_;
    if (!draining) {
      ++running_;
      admitted_bytes_ += pending.memory_bytes;
    }
    ReportLoad();
    lock.unlock();
    pending.job(slot, draining);
    pending.job = nullptr;  // release what the job captured before taking the lock
    lock.lock();
    if (!draining) {
      --running_;
      admitted_bytes_ -= pending.memory_bytes;
    }
    ReportLoad();
    changed_.notify_all();
  }
}

}  // namespace galpha::server
