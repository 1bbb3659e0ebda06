// The service's replies carry absl statuses (the engine's, the decoder's, the queries'); gRPC wants
// its own. One conversion for every RPC, so that a code means the same on every path.
#pragma once

#include <grpcpp/support/status.h>

#include "absl/status/status.h"

namespace galpha::server {

/// The gRPC status of `status`: the same code (absl's canonical codes are gRPC's, number for
/// number) and the same message. OK carries no message.
grpc::Status ToGrpcStatus(const absl::Status& status);

}  // namespace galpha::server
