#include "server/build_scheduler.hpp"

#include <utility>

#include "absl/strings/str_cat.h"
#include "server/build_refusal.hpp"

namespace galpha::server {

BuildScheduler::BuildScheduler(std::vector<void*> slot_streams, size_t max_queue, size_t max_queue_per_tenant,
                               size_t memory_budget_bytes, SchedulerObserver* observer)
    : max_queue_(max_queue),
      max_queue_per_tenant_(max_queue_per_tenant),
      memory_budget_(memory_budget_bytes),
      observer_(observer) {
  for (size_t i = 0; i < slot_streams.size(); ++i) {
    workers_.emplace_back([this, slot = BuildSlot{static_cast<int>(i), slot_streams[i]}] { WorkerLoop(slot); });
  }
}

BuildScheduler::~BuildScheduler() {
  Stop();
  for (std::thread& worker : workers_) worker.join();
}

absl::Status BuildScheduler::Submit(const std::string& tenant, size_t memory_bytes, Job job) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopping_) {
    return TagRefusal(absl::UnavailableError("the server is shutting down and accepts no new builds"),
                      BuildRefusal::kDraining);
  }
  if (memory_budget_ != 0 && memory_bytes > memory_budget_) {
    return TagRefusal(
        absl::ResourceExhaustedError(absl::StrCat("the build needs about ", memory_bytes,
                                                  " bytes of working memory; this server admits at most ",
                                                  memory_budget_, " bytes per build (--build_memory_bytes)")),
        BuildRefusal::kBuildMemory);
  }
  // A job that a free slot takes at once (a slot idle and its memory admitted) is not queued; the
  // others wait, at most max_queue_ of them, and at most max_queue_per_tenant_ of one tenant's.
  queue_.push_back(Pending{tenant, memory_bytes, std::move(job)});
  if (WaitingOfLocked(tenant) > max_queue_per_tenant_) {
    queue_.pop_back();
    return TagRefusal(absl::ResourceExhaustedError(absl::StrCat(
                          tenant.empty() ? std::string("the anonymous tenant") : absl::StrCat("tenant '", tenant, "'"),
                          " already has ", max_queue_per_tenant_,
                          " builds waiting, its limit (--max_tenant_queued_builds); retry when one has started")),
                      BuildRefusal::kTenantQueuedBuilds);
  }
  if (WaitingLocked() > max_queue_) {
    queue_.pop_back();
    return TagRefusal(
        absl::ResourceExhaustedError(absl::StrCat("the build queue is full (", max_queue_, " builds waiting for ",
                                                  workers_.size(), " slots, --max_queued_builds); retry later")),
        BuildRefusal::kQueueFull);
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

size_t BuildScheduler::StartingLocked() const {
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
  return starting;
}

size_t BuildScheduler::WaitingOfLocked(const std::string& tenant) const {
  const size_t starting = StartingLocked();
  size_t waiting = 0;
  for (size_t i = starting; i < queue_.size(); ++i) waiting += queue_[i].tenant == tenant ? 1 : 0;
  return waiting;
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
      if (running_ == 0) idle_since_ = std::chrono::steady_clock::now();
    }
    ReportLoad();
    changed_.notify_all();
  }
}

bool BuildScheduler::RunIfIdleFor(std::chrono::steady_clock::duration idle, const std::function<void()>& fn) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (running_ > 0 || !queue_.empty() || std::chrono::steady_clock::now() - idle_since_ < idle) return false;
  fn();
  return true;
}

}  // namespace galpha::server
