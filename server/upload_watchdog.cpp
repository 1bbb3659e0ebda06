#include "server/upload_watchdog.hpp"

#include <algorithm>
#include <vector>

namespace galpha::server {

UploadWatchdog::UploadWatchdog(std::chrono::milliseconds idle_timeout) : idle_timeout_(idle_timeout) {
  if (idle_timeout_.count() > 0) thread_ = std::thread([this] { Loop(); });
}

UploadWatchdog::~UploadWatchdog() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  stop_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void UploadWatchdog::Watch(Upload* upload) {
  if (idle_timeout_.count() <= 0) return;
  std::lock_guard<std::mutex> lock(mutex_);
  // No wake-up needed: the thread wakes at the latest one timeout from its last pass, which is no
  // later than this upload's deadline.
  uploads_.insert(upload);
}

void UploadWatchdog::Unwatch(Upload* upload) {
  if (idle_timeout_.count() <= 0) return;
  std::lock_guard<std::mutex> lock(mutex_);
  uploads_.erase(upload);
}

void UploadWatchdog::Loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    const Clock::time_point now = Clock::now();
    Clock::time_point next = now + idle_timeout_;
    std::vector<Upload*> expired;
    for (Upload* upload : uploads_) {
      const std::optional<Clock::time_point> last = upload->LastActivity();
      if (!last.has_value()) continue;  // done uploading; Unwatch comes when its call ends
      const Clock::time_point deadline = *last + idle_timeout_;
      if (deadline <= now) {
        expired.push_back(upload);
      } else {
        next = std::min(next, deadline);
      }
    }
    // Under the lock, so that an upload's Unwatch (when gRPC is done with its call, just before
    // it is deleted) waits for its TimeOut to return.
    for (Upload* upload : expired) {
      uploads_.erase(upload);
      upload->TimeOut();
    }
    stop_.wait_until(lock, next, [&] { return stopping_; });
  }
}

}  // namespace galpha::server
