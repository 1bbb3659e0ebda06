// A one-shot signal that several threads may wait on: what the concurrency tests hold a job or a
// build slot with until the test lets it go.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>

namespace galpha::testing {

class OneShotGate {
 public:
  /// Long enough never to pass on a healthy run; only a broken component waits this long.
  static constexpr std::chrono::seconds kDeadlock{20};

  void Open() {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = true;
    changed_.notify_all();
  }
  /// Whether the gate opened within `timeout`.
  template <typename Duration>
  bool WaitFor(Duration timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return open_; });
  }
  bool Wait() { return WaitFor(kDeadlock); }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  bool open_ = false;
};

}  // namespace galpha::testing
