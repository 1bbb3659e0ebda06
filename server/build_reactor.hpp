// The Build RPC: a client stream of points, read through a decoder, then one build on the
// scheduler (or the cached family of the same input). Its own file because it is the one RPC with
// a life of its own: it outlives the handler, waits in the scheduler's queue and is finished by a
// build worker.
#pragma once

#include <atomic>
#include <mutex>
#include <optional>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "galpha/v1/alpha_shapes.grpc.pb.h"
#include "server/build_scheduler.hpp"
#include "server/build_stream.hpp"
#include "server/cached_family.hpp"
#include "server/rpc_record.hpp"
#include "server/upload_watchdog.hpp"

namespace galpha::server {

class AlphaService;

/// One Build call: reads the stream through a decoder, then hands the build to the scheduler, whose
/// worker finishes the call. While it reads, the service's UploadWatchdog may end it (idle for too
/// long). Deletes itself when gRPC is done with the call.
class BuildReactor final : public grpc::ServerReadReactor<galpha::v1::BuildRequest>, private UploadWatchdog::Upload {
 public:
  /// `tenant` is the caller's, or the authentication's error (the call then fails at once).
  BuildReactor(AlphaService* service, grpc::CallbackServerContext* context, galpha::v1::BuildResponse* response,
               absl::StatusOr<std::string> tenant);

  void OnReadDone(bool ok) override;
  void OnSendInitialMetadataDone(bool ok) override;
  void OnCancel() override { cancelled_ = true; }
  void OnDone() override;

 private:
  using Clock = UploadWatchdog::Clock;

  // UploadWatchdog::Upload
  std::optional<Clock::time_point> LastActivity() const override;
  void TimeOut() override;

  void EndOfStream();
  void Run(const BuildSlot& slot, bool draining);
  void Succeed(const CachedFamily& family, bool was_cached);
  // The last thing any path does: after Finish, gRPC may delete this at any moment. Counts a
  // refusal by the reason it is tagged with (build_refusal.hpp).
  void Respond(const absl::Status& status);

  AlphaService* const service_;
  grpc::CallbackServerContext* const context_;
  galpha::v1::BuildResponse* const response_;
  RpcRecord record_;
  std::string tenant_;
  galpha::v1::BuildRequest request_;
  BuildStreamDecoder decoder_;
  DecodedBuild* build_ = nullptr;
  std::atomic<bool> cancelled_{false};
  // The upload ends once, by whichever comes first: the next message's refusal, the end of the
  // stream, or the watchdog's timeout (on its own thread). The mutex orders the three and guards
  // the decoder until then.
  std::mutex upload_mutex_;
  bool upload_over_ = false;  // guarded by upload_mutex_
  // Read by the watchdog without the mutex: whether the upload is still reading, and when its
  // last message arrived (steady-clock ticks).
  std::atomic<bool> uploading_{false};
  std::atomic<Clock::rep> last_activity_{0};
};

}  // namespace galpha::server
