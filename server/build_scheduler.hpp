// The build scheduler: a fixed set of slots (one CUDA stream each on a GPU; on the CPU backend a
// slot is a turn at the host's cores), a bounded FIFO queue in front of them, and admission of
// memory: a build starts only when its estimated need fits next to the builds already running.
// Builds never wait inside the engine for memory, so an out-of-memory build is rare, and when one
// happens it fails alone.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/status.h"

namespace galpha::server {

/// What a weighted build needs on top of an unweighted one's estimate, per point: the weight
/// itself (8 bytes, uploaded and kept by the engine) and the weighted pipeline's larger peak (its
/// device buffers peaked at up to 657 B/pt on an H100 against 466-537 unweighted, bench/results/
/// h100_weighted_family_2026-11-27_ninth_final.log), with the same headroom as the unweighted
/// estimate.
inline constexpr size_t kBuildBytesPerWeight = 160;

/// What a running job gets: its slot and the slot's CUDA stream (null on the CPU backend).
struct BuildSlot {
  int index = 0;
  void* cuda_stream = nullptr;
};

/// Reports queue length, builds running and memory admitted (called with the lock held).
class SchedulerObserver {
 public:
  virtual ~SchedulerObserver() = default;
  virtual void OnLoad(size_t queued, size_t running, size_t admitted_bytes) = 0;
};

class BuildScheduler {
 public:
  /// A job runs exactly once: with `draining` false on a slot, or, when the scheduler stops before
  /// its turn, with `draining` true (it then only reports that it did not run).
  using Job = std::function<void(const BuildSlot& slot, bool draining)>;

  /// One worker thread per stream in `slot_streams` (null entries on the CPU backend). At most
  /// `max_queue` jobs wait, and at most `max_queue_per_tenant` of one tenant's, so that one
  /// tenant cannot fill the queue. `memory_budget_bytes` 0 admits everything.
  BuildScheduler(std::vector<void*> slot_streams, size_t max_queue, size_t max_queue_per_tenant,
                 size_t memory_budget_bytes, SchedulerObserver* observer);
  /// Stop(), then joins the workers.
  ~BuildScheduler();
  BuildScheduler(const BuildScheduler&) = delete;
  BuildScheduler& operator=(const BuildScheduler&) = delete;

  /// Queues `tenant`'s `job`. ResourceExhausted when the queue is full, when `tenant` already has
  /// its most jobs waiting, or when `memory_bytes` exceeds the whole budget; Unavailable after
  /// Stop(). Every refusal is tagged with its BuildRefusal.
  absl::Status Submit(const std::string& tenant, size_t memory_bytes, Job job);

  /// Refuses new jobs; queued jobs that have not started run with `draining` true. Running jobs
  /// finish. Returns at once.
  void Stop();

  /// Runs `fn` when no job has run or waited for `idle` (since the construction or the end of the
  /// last job), with the scheduler held: no job starts while it runs. Returns whether it ran.
  bool RunIfIdleFor(std::chrono::steady_clock::duration idle, const std::function<void()>& fn);

  size_t slots() const { return workers_.size(); }
  size_t max_queue() const { return max_queue_; }
  size_t max_queue_per_tenant() const { return max_queue_per_tenant_; }
  size_t memory_budget_bytes() const { return memory_budget_; }

 private:
  struct Pending {
    std::string tenant;
    size_t memory_bytes;
    Job job;
  };
  void WorkerLoop(BuildSlot slot);
  void ReportLoad();
  /// Queued jobs at the head that free slots and memory let start now (the lock held).
  size_t StartingLocked() const;
  /// Queued jobs that cannot start now (the lock held).
  size_t WaitingLocked() const { return queue_.size() - StartingLocked(); }
  /// `tenant`'s queued jobs that cannot start now (the lock held).
  size_t WaitingOfLocked(const std::string& tenant) const;

  const size_t max_queue_;
  const size_t max_queue_per_tenant_;
  const size_t memory_budget_;
  SchedulerObserver* const observer_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Pending> queue_;
  size_t running_ = 0;
  std::chrono::steady_clock::time_point idle_since_ = std::chrono::steady_clock::now();
  size_t admitted_bytes_ = 0;
  bool stopping_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace galpha::server
