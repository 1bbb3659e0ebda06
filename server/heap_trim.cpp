#include "server/heap_trim.hpp"

#include <malloc.h>

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

namespace galpha::server {

namespace {

/// Requests are numbered; a pass started after request k was made covers it.
class HeapTrimmer {
 public:
  HeapTrimmer() : thread_([this] { Run(); }) {}

  void Request() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++requested_;
    }
    wake_.notify_one();
  }

  void Wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    const uint64_t ticket = requested_;
    done_.wait(lock, [&] { return trimmed_ >= ticket; });
  }

 private:
  [[noreturn]] void Run() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return requested_ > trimmed_; });
      const uint64_t covered = requested_;  // every request made before this pass starts
      lock.unlock();
#ifdef __GLIBC__
      malloc_trim(0);
#endif
      lock.lock();
      trimmed_ = covered;
      done_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  uint64_t requested_ = 0;
  uint64_t trimmed_ = 0;
  std::thread thread_;  // last: it starts once the state above exists
};

HeapTrimmer& Trimmer() {
  // Never destroyed: families are released (and trims requested) from static destructors and
  // from threads that outlive main; the thread blocks on its condition variable until the process
  // exits.
  static HeapTrimmer* const trimmer = new HeapTrimmer;
  return *trimmer;
}

}  // namespace

void ReturnFreedHeapMemory() { Trimmer().Request(); }

void WaitForHeapTrims() { Trimmer().Wait(); }

}  // namespace galpha::server
