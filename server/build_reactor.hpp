// The Build RPC: a client stream of points, read through a decoder, then one build on the
// scheduler (or the cached family of the same input). Its own file because it is the one RPC with
// a life of its own: it outlives the handler, waits in the scheduler's queue and is finished by a
// build worker.
#pragma once

#include <atomic>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "galpha/v1/alpha_shapes.grpc.pb.h"
#include "server/build_scheduler.hpp"
#include "server/build_stream.hpp"
#include "server/cached_family.hpp"
#include "server/rpc_record.hpp"

namespace galpha::server {

class AlphaService;

/// One Build call: reads the stream through a decoder, then hands the build to the scheduler, whose
/// worker finishes the call. Deletes itself when gRPC is done with the call.
class BuildReactor final : public grpc::ServerReadReactor<galpha::v1::BuildRequest> {
 public:
  /// `tenant` is the caller's, or the authentication's error (the call then fails at once).
  BuildReactor(AlphaService* service, grpc::CallbackServerContext* context, galpha::v1::BuildResponse* response,
               absl::StatusOr<std::string> tenant);

  void OnReadDone(bool ok) override;
  void OnCancel() override { cancelled_ = true; }
  void OnDone() override { delete this; }

 private:
  void EndOfStream();
  void Run(const BuildSlot& slot, bool draining);
  void Succeed(const CachedFamily& family, bool was_cached);
  // The last thing any path does: after Finish, gRPC may delete this at any moment.
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
};

}  // namespace galpha::server
