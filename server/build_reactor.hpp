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
#include "server/upload_reactor.hpp"

namespace galpha::server {

class AlphaService;

/// One Build call: reads the stream through a decoder (the reads, the idle watchdog and the end of
/// the stream are UploadReactor's), then hands the build to the scheduler, whose worker finishes
/// the call.
class BuildReactor final
    : public UploadReactor<grpc::ServerReadReactor<galpha::v1::BuildRequest>, galpha::v1::BuildRequest> {
 public:
  /// `tenant` is the caller's, or the authentication's error (the call then fails at once).
  BuildReactor(AlphaService* service, grpc::CallbackServerContext* context, galpha::v1::BuildResponse* response,
               absl::StatusOr<std::string> tenant);

 private:
  // UploadReactor
  absl::Status AddMessage(galpha::v1::BuildRequest message) override { return decoder_.Add(std::move(message)); }
  void DropUpload() override { decoder_.ReleasePoints(); }
  void EndOfStream() override;
  // Counts a refusal by the reason it is tagged with (build_refusal.hpp).
  void Respond(const absl::Status& status) override;

  void Run(const BuildSlot& slot, bool draining);
  void Succeed(const CachedFamily& family, bool was_cached);

  AlphaService* const service_;
  galpha::v1::BuildResponse* const response_;
  RpcRecord record_;
  std::string tenant_;
  BuildStreamDecoder decoder_;
  DecodedBuild* build_ = nullptr;
};

}  // namespace galpha::server
