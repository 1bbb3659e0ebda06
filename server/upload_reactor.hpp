// The upload half of the RPCs whose client streams points to build (Build, BuildBatch): the reads,
// the service's idle watchdog, and the end of the stream told apart from a broken call. The
// derived reactor decodes each message (AddMessage), frees what it holds when the watchdog ends
// the upload (DropUpload), and goes on at EndOfStream; every answer goes through its Respond.
#pragma once

#include <atomic>
#include <chrono>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include <grpcpp/grpcpp.h>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "server/build_refusal.hpp"
#include "server/upload_watchdog.hpp"

namespace galpha::server {

/// `GrpcReactor`: the gRPC reactor whose reads carry `Request`s (a ServerReadReactor or a
/// ServerBidiReactor). Deletes itself when gRPC is done with the call.
template <class GrpcReactor, class Request>
class UploadReactor : public GrpcReactor, private UploadWatchdog::Upload {
 public:
  void OnReadDone(bool ok) override {
    absl::Status refused;
    {
      std::lock_guard<std::mutex> lock(upload_mutex_);
      if (upload_over_) return;  // the watchdog ended the call
      if (ok) {
        last_activity_ = Clock::now().time_since_epoch().count();
        refused = AddMessage(std::move(request_));
        if (refused.ok()) {
          this->StartRead(&request_);
          return;
        }
      }
      upload_over_ = true;
      uploading_ = false;
    }
    if (ok) {
      Respond(refused);
    } else {
      // A read fails both at the end of the stream and when the call broke (the client went away,
      // gRPC refused a message over --max_message_bytes), and gRPC may report the failed read
      // before it marks the call cancelled: a cut stream would then be built as if it were whole.
      // A send on a broken call fails, so the initial metadata decides (OnSendInitialMetadataDone).
      this->StartSendInitialMetadata();
    }
  }

  void OnSendInitialMetadataDone(bool ok) override {
    if (!ok || cancelled_) {
      Respond(absl::CancelledError("the upload was cut: the client went away or gRPC refused one of its messages"));
      return;
    }
    EndOfStream();
  }

  void OnCancel() override { cancelled_ = true; }

  void OnDone() override {
    // After this the watchdog never calls this reactor again.
    watchdog_->Unwatch(this);
    delete this;
  }

 protected:
  using Clock = UploadWatchdog::Clock;

  /// The idle timeout's message says "`upload_name` sent nothing ...: `dropped_name` was dropped".
  UploadReactor(UploadWatchdog* watchdog, grpc::CallbackServerContext* context, const char* upload_name,
                const char* dropped_name)
      : context_(context), watchdog_(watchdog), upload_name_(upload_name), dropped_name_(dropped_name) {}
  ~UploadReactor() override = default;

  /// The derived constructor's last step: answers `refusal` (the authentication's or the drain's)
  /// when it is an error, else starts reading under the watchdog.
  void BeginUpload(const absl::Status& refusal) {
    if (!refusal.ok()) {
      Respond(refusal);
      return;
    }
    last_activity_ = Clock::now().time_since_epoch().count();
    uploading_ = true;
    watchdog_->Watch(this);
    std::lock_guard<std::mutex> lock(upload_mutex_);
    if (!upload_over_) this->StartRead(&request_);  // else the watchdog already ended the call
  }

  /// Whether the call was cancelled: the client went away, or gRPC refused one of its messages.
  bool CallerGone() const { return cancelled_ || context_->IsCancelled(); }

  /// One message, with the upload's mutex held; an error ends the upload and is answered.
  virtual absl::Status AddMessage(Request message) = 0;
  /// Frees what the upload holds (its points and their reservation), with the mutex held, when the
  /// watchdog ends it: now, not when gRPC is done with the call.
  virtual void DropUpload() = 0;
  /// The stream ended whole.
  virtual void EndOfStream() = 0;
  /// The last thing any path does: after Finish, gRPC may delete this at any moment.
  virtual void Respond(const absl::Status& status) = 0;

  grpc::CallbackServerContext* const context_;
  std::atomic<bool> cancelled_{false};

 private:
  // UploadWatchdog::Upload
  std::optional<Clock::time_point> LastActivity() const override {
    if (!uploading_) return std::nullopt;
    return Clock::time_point(Clock::duration(last_activity_.load()));
  }

  void TimeOut() override {
    {
      std::lock_guard<std::mutex> lock(upload_mutex_);
      if (upload_over_) return;
      upload_over_ = true;
      uploading_ = false;
      DropUpload();
    }
    // The read still pending completes (not ok) after Finish; OnReadDone then sees upload_over_.
    Respond(TagRefusal(absl::DeadlineExceededError(absl::StrCat(
                           upload_name_, " sent nothing for ", watchdog_->idle_timeout().count(),
                           " ms, the server's idle limit (--upload_idle_timeout_ms): ", dropped_name_, " was dropped")),
                       BuildRefusal::kIdleTimeout));
  }

  UploadWatchdog* const watchdog_;
  const char* const upload_name_;
  const char* const dropped_name_;
  Request request_;
  // The upload ends once, by whichever comes first: the next message's refusal, the end of the
  // stream, or the watchdog's timeout (on its own thread). The mutex orders the three and guards
  // the derived reactor's decoding until then.
  std::mutex upload_mutex_;
  bool upload_over_ = false;  // guarded by upload_mutex_
  // Read by the watchdog without the mutex: whether the upload is still reading, and when its
  // last message arrived (steady-clock ticks).
  std::atomic<bool> uploading_{false};
  std::atomic<Clock::rep> last_activity_{0};
};

}  // namespace galpha::server
