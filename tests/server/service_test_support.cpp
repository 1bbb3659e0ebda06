#include "service_test_support.hpp"

#include <arpa/inet.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <thread>

#include "galpha_testing/reflection.pb.h"
#include "grpc/health/v1/health.grpc.pb.h"

namespace galpha::server::testing {

std::string TestBackend() {
  const char* backend = std::getenv("GALPHA_SERVICE_BACKEND");
  return backend != nullptr && std::string(backend) == "cuda" ? "cuda" : "cpu";
}

ServerOptions TestServerOptions() {
  ServerOptions options;
  options.listen_address = "127.0.0.1:0";
  options.metrics_address = "127.0.0.1:0";
  options.drain_notice = std::chrono::milliseconds(0);
  options.drain_grace = std::chrono::milliseconds(5000);
  options.service.backend = TestBackend() == "cuda" ? Backend::kCuda : Backend::kCpu;
  // Most tests start servers by the dozen: without the warm-up builds (a test of its own turns
  // them on).
  options.warm_up = false;
  // GALPHA_SERVICE_DEVICE_CACHE_BYTES: on CUDA, every test's families resident on the GPU (a GPU
  // run sets it for a second pass of the suite; bench/gpu_run.sh service).
  if (const char* bytes = std::getenv("GALPHA_SERVICE_DEVICE_CACHE_BYTES"); bytes != nullptr) {
    options.service.device_cache_bytes = std::strtoull(bytes, nullptr, 10);
  }
  return options;
}

std::unique_ptr<GalphaServer> StartServer(const ServerOptions& options) {
  auto server = GalphaServer::Start(options);
  if (!server.ok()) {
    ADD_FAILURE() << "the server did not start: " << server.status();
    return nullptr;
  }
  return *std::move(server);
}

std::unique_ptr<client::AlphaClient> ClientOf(const GalphaServer& server, const std::string& token) {
  client::ClientOptions options;
  options.target = "127.0.0.1:" + std::to_string(server.port());
  options.bearer_token = token;
  auto client = client::AlphaClient::Connect(options);
  if (!client.ok()) {
    ADD_FAILURE() << client.status();
    return nullptr;
  }
  return *std::move(client);
}

std::string HttpGet(int port, const std::string& path) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return "";
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string response;
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0) {
    const std::string request = "GET " + path + " HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n";
    if (send(fd, request.data(), request.size(), 0) == static_cast<ssize_t>(request.size())) {
      char buffer[65536];
      ssize_t got;
      while ((got = recv(fd, buffer, sizeof buffer, 0)) > 0) response.append(buffer, static_cast<size_t>(got));
    }
  }
  close(fd);
  const size_t body = response.find("\r\n\r\n");
  return body == std::string::npos ? "" : response.substr(body + 4);
}

double MetricValue(const std::string& page, const std::string& series) {
  std::istringstream lines(page);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.size() > series.size() && line.compare(0, series.size(), series) == 0 && line[series.size()] == ' ') {
      return std::strtod(line.c_str() + series.size() + 1, nullptr);
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

double ScrapeMetric(const GalphaServer& server, const std::string& series) {
  return MetricValue(HttpGet(server.metrics_port(), "/metrics"), series);
}

std::string HealthOf(const std::shared_ptr<grpc::Channel>& channel, const std::string& service) {
  auto stub = grpc::health::v1::Health::NewStub(channel);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = stub->Check(&context, request, &response);
  if (!status.ok()) return "error " + std::to_string(status.error_code());
  return grpc::health::v1::HealthCheckResponse::ServingStatus_Name(response.status());
}

std::vector<std::string> ReflectedServices(const std::shared_ptr<grpc::Channel>& channel) {
  namespace reflection = galpha_testing::reflection;
  const grpc::internal::RpcMethod method("/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo",
                                         grpc::internal::RpcMethod::BIDI_STREAMING, channel);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
  std::unique_ptr<grpc::ClientReaderWriter<reflection::ServerReflectionRequest, reflection::ServerReflectionResponse>>
      stream(grpc::internal::ClientReaderWriterFactory<reflection::ServerReflectionRequest,
                                                       reflection::ServerReflectionResponse>::Create(channel.get(),
                                                                                                     method, &context));
  reflection::ServerReflectionRequest request;
  request.set_list_services("*");
  std::vector<std::string> names;
  if (!stream->Write(request)) return names;
  stream->WritesDone();
  reflection::ServerReflectionResponse response;
  while (stream->Read(&response)) {
    for (const auto& service : response.list_services_response().service()) names.push_back(service.name());
  }
  stream->Finish();
  return names;
}

bool WaitFor(const std::function<bool()>& condition, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return condition();
}

}  // namespace galpha::server::testing
