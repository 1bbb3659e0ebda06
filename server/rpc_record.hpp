// Every RPC is timed and counted by method and status code (server/metrics.hpp); the Build reactor
// and the query paths share this record.
#pragma once

#include <chrono>
#include <string>

#include <grpcpp/support/status.h>

#include "absl/status/status.h"
#include "server/metrics.hpp"

namespace galpha::server {

/// Times one RPC and records its method and status code when it finishes.
class RpcRecord {
 public:
  using Clock = std::chrono::steady_clock;

  RpcRecord(ServerMetrics* metrics, const char* method) : metrics_(metrics), method_(method), start_(Clock::now()) {}
  void Done(const grpc::Status& status) const {
    const std::string code = absl::StatusCodeToString(static_cast<absl::StatusCode>(status.error_code()));
    metrics_->RecordRpc(method_, code, std::chrono::duration<double>(Clock::now() - start_).count());
  }

 private:
  ServerMetrics* metrics_;
  const char* method_;
  Clock::time_point start_;
};

}  // namespace galpha::server
