// The galpha server process's core, without flags or signals (main.cpp owns those): the gRPC
// server with the AlphaShapes service, the standard health service, reflection, optional TLS, and
// the Prometheus exporter. Tests start it in-process on loopback ports.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "absl/status/statusor.h"
#include "server/alpha_service.hpp"
#include "server/metrics.hpp"

namespace grpc {
class Server;
}

namespace galpha::server {

/// Health service names: readiness (NOT_SERVING while draining) and liveness (SERVING until exit).
inline constexpr char kApiHealthService[] = "galpha.v1.AlphaShapes";
inline constexpr char kLivenessHealthService[] = "galpha.liveness";

struct ServerOptions {
  /// gRPC listening address; port 0 picks a free port (see GalphaServer::port()).
  std::string listen_address = "0.0.0.0:50051";
  /// Prometheus exporter address; empty: no exporter.
  std::string metrics_address = "0.0.0.0:9464";
  /// PEM files: both set turns TLS on; neither leaves the port in plaintext.
  std::string tls_cert_file;
  std::string tls_key_file;
  /// Largest message the server accepts (a Build chunk); larger ones fail RESOURCE_EXHAUSTED.
  int max_receive_message_bytes = 4 << 20;
  /// How long a drain keeps answering (health NOT_SERVING, new builds refused, queries answered)
  /// before it stops accepting calls, so that load balancers move traffic away first.
  std::chrono::milliseconds drain_notice{5000};
  /// How long a drain then waits for running calls before cancelling them.
  std::chrono::milliseconds drain_grace{25000};  // the flag's default (main.cpp)
  /// Before listening, build the warm-up lattice once, unweighted and weighted
  /// (AlphaService::WarmUp), so that the first caller's build does not pay the process's one-time
  /// costs; a failure stops the start.
  bool warm_up = true;
  ServiceOptions service;
};

class GalphaServer {
 public:
  /// Builds the service and starts listening. Errors: a port that cannot be bound, unreadable TLS
  /// files, no GPU when one is required.
  static absl::StatusOr<std::unique_ptr<GalphaServer>> Start(const ServerOptions& options);
  /// Drains if still serving, then stops.
  ~GalphaServer();

  int port() const { return port_; }
  /// Seconds the warm-up builds took (ServerOptions::warm_up); 0 without them.
  double warm_up_seconds() const { return warm_up_seconds_; }
  int metrics_port() const { return metrics_port_; }
  AlphaService& service() { return *service_; }
  ServerMetrics& metrics() { return *metrics_; }

  /// Health goes NOT_SERVING and new builds are refused; after the notice period the server stops
  /// accepting calls, and calls still running after the grace period are cancelled. Returns when the server has
  /// stopped. Safe to call more than once and from any thread.
  void Drain();
  /// Ends a running drain's notice period now (a second SIGTERM).
  void CutNoticeShort();
  /// Blocks until Drain() has finished.
  void Wait();

 private:
  GalphaServer() = default;
  void SampleLoop();

  ServerOptions options_;
  std::unique_ptr<ServerMetrics> metrics_;
  std::unique_ptr<AlphaService> service_;
  std::unique_ptr<grpc::Server> server_;
  int port_ = 0;
  int metrics_port_ = 0;
  double warm_up_seconds_ = 0;
  std::mutex mutex_;
  std::condition_variable stopped_changed_;
  std::condition_variable notice_over_;
  bool notice_cut_short_ = false;
  bool draining_ = false;
  bool stopped_ = false;
  std::thread sampler_;
};

}  // namespace galpha::server
