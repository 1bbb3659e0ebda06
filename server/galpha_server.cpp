#include "server/galpha_server.hpp"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>

#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"

namespace galpha::server {

namespace {

absl::StatusOr<std::string> ReadTextFile(const std::string& path, const char* what) {
  std::ifstream in(path);
  if (!in) return absl::NotFoundError(absl::StrCat("cannot read the ", what, " '", path, "'"));
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> Credentials(const ServerOptions& options) {
  if (options.tls_cert_file.empty() && options.tls_key_file.empty()) return grpc::InsecureServerCredentials();
  if (options.tls_cert_file.empty() || options.tls_key_file.empty()) {
    return absl::InvalidArgumentError("TLS needs both a certificate and a key file");
  }
  auto cert = ReadTextFile(options.tls_cert_file, "TLS certificate");
  if (!cert.ok()) return cert.status();
  auto key = ReadTextFile(options.tls_key_file, "TLS key");
  if (!key.ok()) return key.status();
  grpc::SslServerCredentialsOptions ssl;
  ssl.pem_key_cert_pairs.push_back({*key, *cert});
  return grpc::SslServerCredentials(ssl);
}

}  // namespace

absl::StatusOr<std::unique_ptr<GalphaServer>> GalphaServer::Start(const ServerOptions& options) {
  std::unique_ptr<GalphaServer> server(new GalphaServer());
  server->options_ = options;
  server->metrics_ = std::make_unique<ServerMetrics>();
  auto service = AlphaService::Create(options.service, server->metrics_.get());
  if (!service.ok()) return service.status();
  server->service_ = *std::move(service);
  auto credentials = Credentials(options);
  if (!credentials.ok()) return credentials.status();
  // After the cheap checks (a bad TLS file fails at once), before listening: the first caller finds
  // the kernels loaded.
  if (options.warm_up) {
    absl::StatusOr<double> seconds = server->service_->WarmUp();
    if (!seconds.ok()) {
      return absl::Status(seconds.status().code(), absl::StrCat("the warm-up build failed (--warm_up=false skips it): ",
                                                                seconds.status().message()));
    }
    server->warm_up_seconds_ = *seconds;
    server->metrics_->SetWarmUpSeconds(*seconds);
  }

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  builder.AddListeningPort(options.listen_address, *credentials, &server->port_);
  builder.RegisterService(server->service_.get());
  builder.SetMaxReceiveMessageSize(options.max_receive_message_bytes);
  server->server_ = builder.BuildAndStart();
  if (server->server_ == nullptr || server->port_ == 0) {
    return absl::UnavailableError(absl::StrCat("cannot listen on ", options.listen_address));
  }
  grpc::HealthCheckServiceInterface* health = server->server_->GetHealthCheckService();
  health->SetServingStatus(true);
  health->SetServingStatus(kApiHealthService, true);
  health->SetServingStatus(kLivenessHealthService, true);

  if (!options.metrics_address.empty()) {
    auto port = server->metrics_->StartExporter(options.metrics_address);
    if (!port.ok()) return port.status();
    server->metrics_port_ = *port;
  }
  server->sampler_ = std::thread([s = server.get()] { s->SampleLoop(); });
  return server;
}

GalphaServer::~GalphaServer() {
  if (server_ != nullptr) {
    Drain();
  } else if (service_ != nullptr) {
    // A start that failed before listening (bad TLS files, a failed warm-up, a port that cannot be
    // bound): nothing to drain but the build workers.
    service_->StartDraining();
  }
  if (sampler_.joinable()) sampler_.join();
}

void GalphaServer::SampleLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopped_) {
    lock.unlock();
    service_->ReleaseIdleDeviceMemory();
    service_->SampleDeviceMemory();
    lock.lock();
    stopped_changed_.wait_for(lock, std::chrono::seconds(1), [&] { return stopped_; });
  }
}

void GalphaServer::Drain() {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    if (draining_) {
      stopped_changed_.wait(lock, [&] { return stopped_; });
      return;
    }
    draining_ = true;
  }
  grpc::HealthCheckServiceInterface* health = server_->GetHealthCheckService();
  // Readiness ("" and the API) goes NOT_SERVING; liveness stays SERVING, so that an orchestrator
  // lets the drain finish instead of restarting the process.
  health->SetServingStatus("", false);
  health->SetServingStatus(kApiHealthService, false);
  service_->StartDraining();
  {
    std::unique_lock<std::mutex> lock(mutex_);
    notice_over_.wait_for(lock, options_.drain_notice, [&] { return notice_cut_short_; });
  }
  // Shutdown refuses new calls at once, lets running ones finish until the deadline, then cancels
  // them (a cancelled build stops at its next phase boundary).
  server_->Shutdown(std::chrono::system_clock::now() + options_.drain_grace);
  server_->Wait();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopped_ = true;
  }
  stopped_changed_.notify_all();
}

void GalphaServer::CutNoticeShort() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    notice_cut_short_ = true;
  }
  notice_over_.notify_all();
}

void GalphaServer::Wait() {
  std::unique_lock<std::mutex> lock(mutex_);
  stopped_changed_.wait(lock, [&] { return stopped_; });
}

}  // namespace galpha::server
