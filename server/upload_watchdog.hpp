// Ends uploads that go idle. A Build stream that stops sending keeps its points and its share of
// the bytes in flight; without an end it would keep them until the client disconnects, which a
// stalled or malicious client never does. One thread for the whole server watches every upload
// and times out those with no message for --upload_idle_timeout_ms; gRPC's callback API has no
// per-read deadline of its own.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

namespace galpha::server {

class UploadWatchdog {
 public:
  using Clock = std::chrono::steady_clock;

  /// What the watchdog watches: a Build call while it reads its stream.
  class Upload {
   public:
    virtual ~Upload() = default;
    /// When the upload last received a message (or began); nullopt once it no longer uploads
    /// (its stream ended, or it was refused). Called from the watchdog's thread.
    virtual std::optional<Clock::time_point> LastActivity() const = 0;
    /// The upload has been idle for the timeout: end it. Called once, from the watchdog's thread,
    /// with the watchdog's lock held (Unwatch waits for it); must not call Watch or Unwatch.
    virtual void TimeOut() = 0;
  };

  /// `idle_timeout` zero or less: uploads never time out (and no thread starts).
  explicit UploadWatchdog(std::chrono::milliseconds idle_timeout);
  /// Stops the thread; every upload must have been unwatched.
  ~UploadWatchdog();
  UploadWatchdog(const UploadWatchdog&) = delete;
  UploadWatchdog& operator=(const UploadWatchdog&) = delete;

  /// Watches `upload` until Unwatch (or its TimeOut).
  void Watch(Upload* upload);
  /// Stops watching `upload`; once this returns, the watchdog never calls it again (a TimeOut in
  /// progress finishes first). Safe for an upload that timed out or was never watched.
  void Unwatch(Upload* upload);

  std::chrono::milliseconds idle_timeout() const { return idle_timeout_; }

 private:
  void Loop();

  const std::chrono::milliseconds idle_timeout_;
  std::mutex mutex_;
  std::condition_variable stop_;
  bool stopping_ = false;
  std::set<Upload*> uploads_;
  std::thread thread_;
};

}  // namespace galpha::server
