// The build scheduler: jobs run on the given slots with their streams, the bounded queue refuses
// what does not fit, memory admission keeps the admitted builds within the budget (FIFO, so a large
// build is not overtaken), Stop drains what has not started and refuses new jobs, and the observer
// ends at an idle load. Jobs block on promises the tests open; a bounded wait is used only where a
// test checks that something does *not* happen while a job is held.
#include "server/build_scheduler.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include "gtest/gtest.h"
#include "server/build_refusal.hpp"
#include "tests/support/one_shot_gate.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

using galpha::testing::IsOk;
using galpha::testing::StatusIs;

// Long enough never to fire on a healthy run; only a broken scheduler waits this long.
constexpr std::chrono::seconds kDeadlock{20};
// How long a test watches for something that must not happen while a job is held.
constexpr std::chrono::milliseconds kWatch{150};

// A per-tenant queue limit that the tests of the shared queue never reach.
constexpr size_t kNoTenantCap = 1000;

void* FakeStream(uintptr_t value) { return reinterpret_cast<void*>(value); }

using Gate = galpha::testing::OneShotGate;

struct Load {
  size_t queued = 0;
  size_t running = 0;
  size_t admitted_bytes = 0;
};

// Keeps every load report, and the largest values seen.
class LoadRecorder : public SchedulerObserver {
 public:
  void OnLoad(size_t queued, size_t running, size_t admitted_bytes) override {
    std::lock_guard<std::mutex> lock(mutex_);
    loads_.push_back(Load{queued, running, admitted_bytes});
    max_running_ = std::max(max_running_, running);
    max_admitted_ = std::max(max_admitted_, admitted_bytes);
    changed_.notify_all();
  }
  // Waits until the latest report satisfies `predicate`; false after kDeadlock.
  bool WaitFor(const std::function<bool(const Load&)>& predicate) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, kDeadlock, [&] { return !loads_.empty() && predicate(loads_.back()); });
  }
  Load last() {
    std::lock_guard<std::mutex> lock(mutex_);
    return loads_.empty() ? Load{} : loads_.back();
  }
  size_t reports() {
    std::lock_guard<std::mutex> lock(mutex_);
    return loads_.size();
  }
  size_t max_running() {
    std::lock_guard<std::mutex> lock(mutex_);
    return max_running_;
  }
  size_t max_admitted() {
    std::lock_guard<std::mutex> lock(mutex_);
    return max_admitted_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<Load> loads_;
  size_t max_running_ = 0;
  size_t max_admitted_ = 0;
};

void ExpectIdle(LoadRecorder& recorder) {
  const Load last = recorder.last();
  EXPECT_EQ(last.queued, 0u);
  EXPECT_EQ(last.running, 0u);
  EXPECT_EQ(last.admitted_bytes, 0u);
}

// What one job saw.
struct JobRun {
  BuildSlot slot;
  bool draining = false;
  int calls = 0;
};

TEST(BuildSchedulerTest, JobsRunOnTheSlotsWithTheirStreams) {
  const std::vector<void*> streams = {FakeStream(0x10), FakeStream(0x20), FakeStream(0x30)};
  LoadRecorder recorder;
  std::vector<JobRun> runs(3);
  {
    BuildScheduler scheduler(streams, /*max_queue=*/0, kNoTenantCap, /*memory_budget_bytes=*/0, &recorder);
    EXPECT_EQ(scheduler.slots(), 3u);
    EXPECT_EQ(scheduler.max_queue(), 0u);
    EXPECT_EQ(scheduler.memory_budget_bytes(), 0u);
    // Every job waits until all three run: they must be on three different slots at once. With
    // max_queue 0, jobs that idle slots take at once are still accepted.
    std::atomic<int> started{0};
    Gate all_started, release;
    for (size_t i = 0; i < runs.size(); ++i) {
      ASSERT_THAT(scheduler.Submit("", 1,
                                   [&, i](const BuildSlot& slot, bool draining) {
                                     runs[i].slot = slot;
                                     runs[i].draining = draining;
                                     ++runs[i].calls;
                                     if (++started == 3) all_started.Open();
                                     release.Wait();
                                   }),
                  IsOk());
    }
    ASSERT_TRUE(all_started.Wait());
    EXPECT_THAT(scheduler.Submit("", 1, [](const BuildSlot&, bool) {}), StatusIs(absl::StatusCode::kResourceExhausted))
        << "every slot busy and no queue";
    release.Open();
  }
  std::set<int> indices;
  for (const JobRun& run : runs) {
    EXPECT_EQ(run.calls, 1);
    EXPECT_FALSE(run.draining);
    ASSERT_GE(run.slot.index, 0);
    ASSERT_LT(run.slot.index, 3);
    EXPECT_EQ(run.slot.cuda_stream, streams[static_cast<size_t>(run.slot.index)]);
    indices.insert(run.slot.index);
  }
  EXPECT_EQ(indices.size(), 3u) << "three jobs at once take three slots";
  EXPECT_EQ(recorder.max_running(), 3u);
  ExpectIdle(recorder);
}

TEST(BuildSchedulerTest, FullQueueRefusesWithResourceExhausted) {
  LoadRecorder recorder;
  Gate first_started, release_first, second_done;
  std::atomic<int> third_calls{0};
  JobRun second;
  {
    BuildScheduler scheduler({FakeStream(0x10)}, /*max_queue=*/1, kNoTenantCap, /*memory_budget_bytes=*/0, &recorder);
    ASSERT_THAT(scheduler.Submit("", 0,
                                 [&](const BuildSlot&, bool) {
                                   first_started.Open();
                                   release_first.Wait();
                                 }),
                IsOk());
    ASSERT_TRUE(first_started.Wait());
    ASSERT_THAT(scheduler.Submit("", 0,
                                 [&](const BuildSlot& slot, bool draining) {
                                   second = JobRun{slot, draining, second.calls + 1};
                                   second_done.Open();
                                 }),
                IsOk());
    ASSERT_TRUE(recorder.WaitFor([](const Load& l) { return l.queued == 1 && l.running == 1; }));
    const absl::Status refused = scheduler.Submit("", 0, [&](const BuildSlot&, bool) { ++third_calls; });
    EXPECT_THAT(refused, StatusIs(absl::StatusCode::kResourceExhausted));
    EXPECT_NE(refused.message().find("queue"), absl::string_view::npos) << refused;

    release_first.Open();
    ASSERT_TRUE(second_done.Wait());
    EXPECT_EQ(second.calls, 1);
    EXPECT_FALSE(second.draining);
    EXPECT_EQ(second.slot.index, 0);
    EXPECT_EQ(second.slot.cuda_stream, FakeStream(0x10));
    // The queue has room again once the second job left it.
    Gate fourth_done;
    ASSERT_TRUE(recorder.WaitFor([](const Load& l) { return l.running == 0; }));
    ASSERT_THAT(scheduler.Submit("", 0, [&](const BuildSlot&, bool) { fourth_done.Open(); }), IsOk());
    ASSERT_TRUE(fourth_done.Wait());
  }
  EXPECT_EQ(third_calls.load(), 0) << "a refused job never runs";
  EXPECT_EQ(recorder.max_running(), 1u);
  ExpectIdle(recorder);
}

TEST(BuildSchedulerTest, JobsRunInSubmissionOrder) {
  Gate first_started, release_first, all_done;
  std::mutex mutex;
  std::vector<int> order;
  {
    BuildScheduler scheduler({nullptr}, /*max_queue=*/8, kNoTenantCap, /*memory_budget_bytes=*/0, nullptr);
    ASSERT_THAT(scheduler.Submit("", 0,
                                 [&](const BuildSlot&, bool) {
                                   first_started.Open();
                                   release_first.Wait();
                                 }),
                IsOk());
    ASSERT_TRUE(first_started.Wait());
    for (int i = 1; i <= 5; ++i) {
      ASSERT_THAT(scheduler.Submit("", 0,
                                   [&, i](const BuildSlot& slot, bool draining) {
                                     EXPECT_FALSE(draining);
                                     EXPECT_EQ(slot.cuda_stream, nullptr);
                                     std::lock_guard<std::mutex> lock(mutex);
                                     order.push_back(i);
                                     if (order.size() == 5) all_done.Open();
                                   }),
                  IsOk());
    }
    release_first.Open();
    ASSERT_TRUE(all_done.Wait());  // before the destructor's Stop would drain what is left
  }
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(order, (std::vector<int>{1, 2, 3, 4, 5}));
}

TEST(BuildSchedulerTest, MemoryAdmissionKeepsBuildsWithinTheBudget) {
  LoadRecorder recorder;
  std::atomic<int> current{0}, max_concurrent{0};
  Gate first_started, release_first, later_started, both_later_started, all_done;
  std::atomic<int> done{0}, later{0};
  auto track = [&] {
    const int now = ++current;
    int seen = max_concurrent.load();
    while (now > seen && !max_concurrent.compare_exchange_weak(seen, now)) {}
  };
  auto finish = [&] {
    --current;
    if (++done == 3) all_done.Open();
  };
  {
    BuildScheduler scheduler({FakeStream(0x10), FakeStream(0x20)}, /*max_queue=*/4, kNoTenantCap,
                             /*memory_budget_bytes=*/100, &recorder);
    const absl::Status too_big = scheduler.Submit("", 101, [](const BuildSlot&, bool) { ADD_FAILURE() << "ran"; });
    EXPECT_THAT(too_big, StatusIs(absl::StatusCode::kResourceExhausted));
    EXPECT_NE(too_big.message().find("101"), absl::string_view::npos) << too_big;

    ASSERT_THAT(scheduler.Submit("", 60,
                                 [&](const BuildSlot&, bool draining) {
                                   EXPECT_FALSE(draining);
                                   track();
                                   first_started.Open();
                                   release_first.Wait();
                                   finish();
                                 }),
                IsOk());
    ASSERT_TRUE(first_started.Wait());
    // The second needs 60 (60 + 60 > 100); the third needs only 10 but queues behind the second.
    for (const size_t need : {size_t{60}, size_t{10}}) {
      ASSERT_THAT(scheduler.Submit("", need,
                                   [&](const BuildSlot&, bool draining) {
                                     EXPECT_FALSE(draining);
                                     track();
                                     later_started.Open();
                                     // 60 + 10 fit in 100: the two must be able to run side by side.
                                     if (++later == 2) both_later_started.Open();
                                     EXPECT_TRUE(both_later_started.Wait()) << "the 60 and the 10 never ran together";
                                     finish();
                                   }),
                  IsOk());
    }
    EXPECT_FALSE(later_started.WaitFor(kWatch)) << "a job started while the first held 60 of 100 bytes";
    EXPECT_EQ(recorder.last().admitted_bytes, 60u);
    EXPECT_EQ(recorder.last().running, 1u);
    release_first.Open();
    ASSERT_TRUE(all_done.Wait());
  }
  EXPECT_EQ(max_concurrent.load(), 2) << "the 60 and the 10 fit together";
  EXPECT_LE(recorder.max_admitted(), 100u);
  EXPECT_EQ(recorder.max_running(), 2u);
  ExpectIdle(recorder);
}

TEST(BuildSchedulerTest, TwoBuildsOfSixtyNeverOverlap) {
  LoadRecorder recorder;
  std::atomic<int> current{0}, max_concurrent{0}, done{0};
  Gate all_done;
  {
    BuildScheduler scheduler({FakeStream(0x10), FakeStream(0x20)}, /*max_queue=*/8, kNoTenantCap,
                             /*memory_budget_bytes=*/100, &recorder);
    constexpr int kJobs = 6;
    for (int i = 0; i < kJobs; ++i) {
      ASSERT_THAT(scheduler.Submit("", 60,
                                   [&](const BuildSlot&, bool) {
                                     const int now = ++current;
                                     int seen = max_concurrent.load();
                                     while (now > seen && !max_concurrent.compare_exchange_weak(seen, now)) {}
                                     // Give a second job every chance to start now, if admission let it.
                                     all_done.WaitFor(std::chrono::milliseconds(10));
                                     --current;
                                     if (++done == kJobs) all_done.Open();
                                   }),
                  IsOk());
    }
    ASSERT_TRUE(all_done.Wait());
  }
  EXPECT_EQ(max_concurrent.load(), 1);
  EXPECT_EQ(recorder.max_running(), 1u);
  EXPECT_EQ(recorder.max_admitted(), 60u);
  ExpectIdle(recorder);
}

// A slot that is idle only because the head of the queue waits for memory is not free capacity:
// the second job waits (for memory, on an idle slot), so it is queued, and with max_queue 1 a
// third job is refused.
TEST(BuildSchedulerTest, JobsWaitingForMemoryCountAsQueued) {
  LoadRecorder recorder;
  Gate first_started, release_first;
  std::atomic<int> later_calls{0};
  {
    BuildScheduler scheduler({FakeStream(0x10), FakeStream(0x20)}, /*max_queue=*/1, kNoTenantCap,
                             /*memory_budget_bytes=*/100, &recorder);
    ASSERT_THAT(scheduler.Submit("", 60,
                                 [&](const BuildSlot&, bool) {
                                   first_started.Open();
                                   release_first.Wait();
                                 }),
                IsOk());
    ASSERT_TRUE(first_started.Wait());
    ASSERT_TRUE(recorder.WaitFor([](const Load& l) { return l.running == 1; }));
    ASSERT_THAT(scheduler.Submit("", 60, [&](const BuildSlot&, bool) { ++later_calls; }), IsOk());
    EXPECT_EQ(recorder.last().queued, 1u) << "the second job waits for memory, so it is queued";
    const absl::Status third = scheduler.Submit("", 60, [&](const BuildSlot&, bool) { ++later_calls; });
    EXPECT_THAT(third, StatusIs(absl::StatusCode::kResourceExhausted)) << "max_queue 1, one job already waiting";
    release_first.Open();
  }
  ExpectIdle(recorder);
}

TEST(BuildSchedulerTest, ZeroBudgetAdmitsEverything) {
  Gate both_started;
  std::atomic<int> started{0};
  BuildScheduler scheduler({nullptr, nullptr}, /*max_queue=*/0, kNoTenantCap, /*memory_budget_bytes=*/0, nullptr);
  for (int i = 0; i < 2; ++i) {
    ASSERT_THAT(scheduler.Submit("", size_t{1} << 50,
                                 [&](const BuildSlot&, bool) {
                                   if (++started == 2) both_started.Open();
                                   both_started.Wait();
                                 }),
                IsOk());
  }
  EXPECT_TRUE(both_started.Wait()) << "with no budget, two huge builds run side by side";
}

TEST(BuildSchedulerTest, StopDrainsQueuedJobsAndRefusesNewOnes) {
  LoadRecorder recorder;
  Gate first_started, release_first;
  JobRun first, second, third;
  std::promise<void> third_done;
  std::future<void> third_done_future = third_done.get_future();
  std::atomic<int> late_calls{0};
  {
    BuildScheduler scheduler({FakeStream(0x10)}, /*max_queue=*/2, kNoTenantCap, /*memory_budget_bytes=*/0, &recorder);
    ASSERT_THAT(scheduler.Submit("", 0,
                                 [&](const BuildSlot& slot, bool draining) {
                                   first = JobRun{slot, draining, first.calls + 1};
                                   first_started.Open();
                                   release_first.Wait();
                                 }),
                IsOk());
    ASSERT_TRUE(first_started.Wait());
    ASSERT_THAT(scheduler.Submit("", 0,
                                 [&](const BuildSlot& slot, bool draining) {
                                   second = JobRun{slot, draining, second.calls + 1};
                                 }),
                IsOk());
    ASSERT_THAT(scheduler.Submit("", 0,
                                 [&](const BuildSlot& slot, bool draining) {
                                   third = JobRun{slot, draining, third.calls + 1};
                                   third_done.set_value();
                                 }),
                IsOk());
    ASSERT_TRUE(recorder.WaitFor([](const Load& l) { return l.queued == 2 && l.running == 1; }));

    scheduler.Stop();  // returns at once, with the first job still running
    const absl::Status refused = scheduler.Submit("", 0, [&](const BuildSlot&, bool) { ++late_calls; });
    EXPECT_THAT(refused, StatusIs(absl::StatusCode::kUnavailable));
    EXPECT_EQ(first.calls, 1);

    release_first.Open();
    ASSERT_EQ(third_done_future.wait_for(kDeadlock), std::future_status::ready);
    EXPECT_THAT(scheduler.Submit("", 0, [&](const BuildSlot&, bool) { ++late_calls; }),
                StatusIs(absl::StatusCode::kUnavailable));
  }
  EXPECT_EQ(first.calls, 1);
  EXPECT_FALSE(first.draining) << "the running job finishes normally";
  EXPECT_EQ(second.calls, 1);
  EXPECT_TRUE(second.draining);
  EXPECT_EQ(third.calls, 1);
  EXPECT_TRUE(third.draining);
  EXPECT_EQ(late_calls.load(), 0);
  EXPECT_EQ(recorder.max_running(), 1u) << "draining jobs do not count as running";
  ExpectIdle(recorder);
}

TEST(BuildSchedulerTest, StopWakesJobsWaitingForMemory) {
  // The second job waits for memory on an idle slot; Stop must drain it while the first still runs.
  LoadRecorder recorder;
  Gate first_started, release_first;
  std::promise<bool> second_draining;
  std::future<bool> second_future = second_draining.get_future();
  {
    BuildScheduler scheduler({FakeStream(0x10), FakeStream(0x20)}, /*max_queue=*/2, kNoTenantCap,
                             /*memory_budget_bytes=*/100, &recorder);
    ASSERT_THAT(scheduler.Submit("", 60,
                                 [&](const BuildSlot&, bool draining) {
                                   EXPECT_FALSE(draining);
                                   first_started.Open();
                                   release_first.Wait();
                                 }),
                IsOk());
    ASSERT_TRUE(first_started.Wait());
    ASSERT_THAT(scheduler.Submit("", 60,
                                 [&](const BuildSlot& slot, bool draining) {
                                   EXPECT_NE(slot.cuda_stream, nullptr);
                                   second_draining.set_value(draining);
                                 }),
                IsOk());
    scheduler.Stop();
    ASSERT_EQ(second_future.wait_for(kDeadlock), std::future_status::ready)
        << "a queued job must be drained without waiting for the running one";
    EXPECT_TRUE(second_future.get());
    release_first.Open();
  }
  EXPECT_LE(recorder.max_admitted(), 100u);
  ExpectIdle(recorder);
}

TEST(BuildSchedulerTest, DestructorRunsEveryAcceptedJobOnce) {
  LoadRecorder recorder;
  constexpr int kJobs = 4;
  std::vector<std::atomic<int>> calls(kJobs);
  Gate first_started, release_first;
  {
    BuildScheduler scheduler({nullptr}, /*max_queue=*/kJobs, kNoTenantCap, /*memory_budget_bytes=*/0, &recorder);
    ASSERT_THAT(scheduler.Submit("", 0,
                                 [&](const BuildSlot&, bool) {
                                   ++calls[0];
                                   first_started.Open();
                                   release_first.Wait();
                                 }),
                IsOk());
    ASSERT_TRUE(first_started.Wait());
    for (int i = 1; i < kJobs; ++i) {
      ASSERT_THAT(scheduler.Submit("", 0, [&, i](const BuildSlot&, bool) { ++calls[static_cast<size_t>(i)]; }), IsOk());
    }
    release_first.Open();
  }
  for (int i = 0; i < kJobs; ++i) EXPECT_EQ(calls[static_cast<size_t>(i)].load(), 1) << "job " << i;
  ExpectIdle(recorder);
}

TEST(BuildSchedulerTest, ObserverSeesTheLoadRiseAndFall) {
  LoadRecorder recorder;
  Gate first_started, release_first, second_done;
  {
    BuildScheduler scheduler({nullptr}, /*max_queue=*/1, kNoTenantCap, /*memory_budget_bytes=*/1000, &recorder);
    ASSERT_THAT(scheduler.Submit("", 300,
                                 [&](const BuildSlot&, bool) {
                                   first_started.Open();
                                   release_first.Wait();
                                 }),
                IsOk());
    ASSERT_TRUE(first_started.Wait());
    ASSERT_TRUE(recorder.WaitFor([](const Load& l) { return l.running == 1 && l.admitted_bytes == 300; }));
    ASSERT_THAT(scheduler.Submit("", 200, [&](const BuildSlot&, bool) { second_done.Open(); }), IsOk());
    ASSERT_TRUE(
        recorder.WaitFor([](const Load& l) { return l.queued == 1 && l.running == 1 && l.admitted_bytes == 300; }));
    release_first.Open();
    ASSERT_TRUE(second_done.Wait());
    ASSERT_TRUE(recorder.WaitFor([](const Load& l) { return l.queued == 0 && l.running == 0; }));
    ExpectIdle(recorder);
  }
  EXPECT_EQ(recorder.max_running(), 1u);
  EXPECT_EQ(recorder.max_admitted(), 300u);
  ExpectIdle(recorder);
}

TEST(BuildSchedulerTest, OneTenantCannotFillTheQueue) {
  LoadRecorder recorder;
  Gate first_started, release_first;
  std::atomic<int> ran{0};
  {
    BuildScheduler scheduler({FakeStream(0x10)}, /*max_queue=*/4, /*max_queue_per_tenant=*/2,
                             /*memory_budget_bytes=*/0, &recorder);
    ASSERT_THAT(scheduler.Submit("a", 0,
                                 [&](const BuildSlot&, bool) {
                                   ++ran;
                                   first_started.Open();
                                   release_first.Wait();
                                 }),
                IsOk());
    ASSERT_TRUE(first_started.Wait());
    // The running job is not waiting: tenant a may still queue two.
    ASSERT_THAT(scheduler.Submit("a", 0, [&](const BuildSlot&, bool) { ++ran; }), IsOk());
    ASSERT_THAT(scheduler.Submit("a", 0, [&](const BuildSlot&, bool) { ++ran; }), IsOk());
    const absl::Status refused = scheduler.Submit("a", 0, [&](const BuildSlot&, bool) { ADD_FAILURE() << "ran"; });
    EXPECT_THAT(refused, StatusIs(absl::StatusCode::kResourceExhausted,
                                  ::testing::HasSubstr("tenant 'a' already has 2 builds waiting")));
    EXPECT_THAT(refused.message(), ::testing::HasSubstr("--max_tenant_queued_builds"));
    EXPECT_EQ(RefusalLabelOf(refused), "tenant_queued_builds");
    // Another tenant still has room in the shared queue, up to its size.
    ASSERT_THAT(scheduler.Submit("b", 0, [&](const BuildSlot&, bool) { ++ran; }), IsOk());
    ASSERT_THAT(scheduler.Submit("", 0, [&](const BuildSlot&, bool) { ++ran; }), IsOk());
    const absl::Status full = scheduler.Submit("b", 0, [&](const BuildSlot&, bool) { ADD_FAILURE() << "ran"; });
    EXPECT_THAT(full, StatusIs(absl::StatusCode::kResourceExhausted, ::testing::HasSubstr("--max_queued_builds")));
    EXPECT_EQ(RefusalLabelOf(full), "queue_full");
    EXPECT_EQ(recorder.last().queued, 4u);
    release_first.Open();
    ASSERT_TRUE(recorder.WaitFor([](const Load& l) { return l.queued == 0 && l.running == 0; }));
  }
  EXPECT_EQ(ran.load(), 5);
}

TEST(BuildSchedulerTest, RefusalsAreTaggedWithTheirReason) {
  BuildScheduler scheduler({nullptr}, /*max_queue=*/1, kNoTenantCap, /*memory_budget_bytes=*/100, nullptr);
  const absl::Status too_big = scheduler.Submit("", 101, [](const BuildSlot&, bool) { ADD_FAILURE() << "ran"; });
  EXPECT_THAT(too_big, StatusIs(absl::StatusCode::kResourceExhausted, ::testing::HasSubstr("--build_memory_bytes")));
  EXPECT_EQ(RefusalLabelOf(too_big), "build_memory");
  scheduler.Stop();
  const absl::Status stopped = scheduler.Submit("", 1, [](const BuildSlot&, bool) { ADD_FAILURE() << "ran"; });
  EXPECT_THAT(stopped, StatusIs(absl::StatusCode::kUnavailable));
  EXPECT_EQ(RefusalLabelOf(stopped), "draining");
}

// RunIfIdleFor (what the service gives the device's pooled memory back under): only after the
// given idleness since the start or the last job's end, never while a job runs or waits, and with
// the scheduler held (a job submitted meanwhile starts after it).
TEST(BuildSchedulerTest, RunIfIdleForWaitsForIdlenessAndHoldsTheScheduler) {
  using namespace std::chrono_literals;
  BuildScheduler scheduler({nullptr}, /*max_queue=*/4, kNoTenantCap, /*memory_budget_bytes=*/0, nullptr);
  int runs = 0;
  EXPECT_TRUE(scheduler.RunIfIdleFor(0s, [&] { ++runs; })) << "idle from the start";
  EXPECT_FALSE(scheduler.RunIfIdleFor(1h, [&] { ++runs; })) << "not idle for an hour yet";
  EXPECT_EQ(runs, 1);
  Gate started, release, finished;
  ASSERT_THAT(scheduler.Submit("", 1,
                               [&](const BuildSlot&, bool) {
                                 started.Open();
                                 release.Wait();
                               }),
              IsOk());
  ASSERT_THAT(scheduler.Submit("", 1, [&](const BuildSlot&, bool) { finished.Open(); }), IsOk());
  ASSERT_TRUE(started.Wait());
  EXPECT_FALSE(scheduler.RunIfIdleFor(0s, [&] { ++runs; })) << "a job runs and one waits";
  release.Open();
  ASSERT_TRUE(finished.Wait());
  // The last job's end restarts the idleness.
  bool ran = false;
  for (int i = 0; i < 2000 && !(ran = scheduler.RunIfIdleFor(0s, [&] { ++runs; })); ++i) {
    std::this_thread::sleep_for(1ms);
  }
  EXPECT_TRUE(ran);
  EXPECT_FALSE(scheduler.RunIfIdleFor(10s, [&] { ++runs; })) << "a job ended moments ago";
  EXPECT_EQ(runs, 2);
  // Held: a job submitted while `fn` runs starts only after it.
  std::atomic<bool> job_ran{false};
  bool ran_before_fn_returned = true;
  std::thread submitter;
  EXPECT_TRUE(scheduler.RunIfIdleFor(0s, [&] {
    submitter = std::thread(
        [&] { EXPECT_THAT(scheduler.Submit("", 1, [&](const BuildSlot&, bool) { job_ran = true; }), IsOk()); });
    std::this_thread::sleep_for(100ms);
    ran_before_fn_returned = job_ran.load();
  }));
  submitter.join();  // its Submit returned once the scheduler was free again
  EXPECT_FALSE(ran_before_fn_returned);
  for (int i = 0; i < 2000 && !job_ran; ++i) std::this_thread::sleep_for(1ms);
  EXPECT_TRUE(job_ran.load());
}

}  // namespace
}  // namespace galpha::server
