// galpha_server: flags in, a running GalphaServer out; SIGTERM or SIGINT drains it (a second one
// cuts the drain notice short). Prints one "listening" line per port on stdout so that scripts
// started with port 0 learn the ports.
#include <pthread.h>
#include <signal.h>  // NOLINT(modernize-deprecated-headers): POSIX sigwait and signal masks

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/strings/str_cat.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "grpcpp/grpcpp.h"
#include "server/galpha_server.hpp"

ABSL_FLAG(std::string, listen, "0.0.0.0:50051", "gRPC address (host:port; port 0 picks one)");
ABSL_FLAG(std::string, metrics_listen, "0.0.0.0:9464", "Prometheus exporter address; empty turns it off");
ABSL_FLAG(std::string, backend, "auto", "auto (GPU when present), cpu or cuda");
ABSL_FLAG(int, build_slots, 0, "builds running at once (CUDA streams); 0: 4 on a GPU, 1 on the CPU");
ABSL_FLAG(uint64_t, max_queued_builds, 16, "builds waiting for a slot before RESOURCE_EXHAUSTED");
ABSL_FLAG(uint64_t, max_tenant_queued_builds, 8,
          "builds of one tenant waiting for a slot before RESOURCE_EXHAUSTED (without --token_file every caller "
          "is one anonymous tenant)");
ABSL_FLAG(uint64_t, build_memory_bytes, 0,
          "working memory admitted to running builds; 0: 90% of the GPU's, or half the host's");
ABSL_FLAG(uint64_t, max_points_per_build, 100000000, "largest point set one build accepts");
ABSL_FLAG(uint64_t, max_in_flight_bytes, uint64_t{8} << 30,
          "bytes of points held by all uploads and builds at once; 0: no limit");
ABSL_FLAG(uint64_t, max_tenant_in_flight_bytes, uint64_t{4} << 30,
          "bytes of points held by one tenant's uploads and builds at once; 0: no limit per tenant");
ABSL_FLAG(int, upload_idle_timeout_ms, 30000,
          "a Build stream with no message for this long is ended with DEADLINE_EXCEEDED and its points dropped; "
          "0: never");
ABSL_FLAG(int, device_idle_release_ms, 2000,
          "after this long with no build running or queued, the GPU memory the builds' pool keeps for reuse goes "
          "back to the device (checked once a second); 0: kept for good");
ABSL_FLAG(double, build_time_multiple, 50,
          "a build may run this many times its expected time (60 ns a point on CUDA, 14 us a point over the "
          "host's cores on the CPU), then stops with DEADLINE_EXCEEDED; 0: no limit");
ABSL_FLAG(int, build_time_floor_ms, 10000, "the build time limit is never below this");
ABSL_FLAG(double, max_exact_comparisons_per_point, 64,
          "a build may make this many exact radius comparisons per point (honest inputs need a few), then stops "
          "with RESOURCE_EXHAUSTED; 0: no limit");
ABSL_FLAG(uint64_t, exact_comparisons_floor, 1000000, "the exact comparison limit is never below this");
ABSL_FLAG(uint64_t, cache_bytes, uint64_t{8} << 30,
          "byte budget of the family cache's resident tier (whole families; the least recently used move to the "
          "compact tier)");
ABSL_FLAG(uint64_t, compact_cache_bytes, uint64_t{4} << 30,
          "byte budget of the family cache's compact tier (16 B per point: families rebuilt when queried; 0: none, "
          "families pushed out of the resident tier are evicted)");
ABSL_FLAG(uint64_t, device_cache_bytes, 0,
          "GPU memory for families whose rank tables stay on the GPU after their build (no download; queries "
          "answered there), taken from the builds' default budget; 0: CUDA families are copied to host memory");
ABSL_FLAG(std::string, batch_packing, "auto",
          "how BuildBatch builds its small unweighted sets (at most 20,000 points): on (packed into one build on the "
          "service's backend), off (one set a host core, each its own build) or auto (on with the CUDA backend, off "
          "on the CPU)");
ABSL_FLAG(int, max_message_bytes, 4 << 20, "largest request message accepted");
ABSL_FLAG(std::string, tls_cert, "", "PEM certificate chain; with --tls_key turns TLS on");
ABSL_FLAG(std::string, tls_key, "", "PEM private key");
ABSL_FLAG(std::string, token_file, "", "file of 'TOKEN TENANT' lines; when set, every call needs a bearer token");
ABSL_FLAG(int, drain_notice_ms, 5000, "on SIGTERM: NOT_SERVING this long before refusing calls");
ABSL_FLAG(int, drain_grace_ms, 25000, "then: how long running calls may finish before they are cancelled");
ABSL_FLAG(bool, warm_up, true,
          "before listening, build a 16K-point lattice (half of it nudged by ulps), unweighted and weighted, so that "
          "the first "
          "caller does not pay the process's one-time costs (loading the GPU kernels, their first launches); its "
          "time is galpha_warm_up_seconds");
ABSL_FLAG(std::string, health_check, "",
          "instead of serving: ask the server at this address (plaintext) whether the API is SERVING; "
          "exit 0 if so, 1 otherwise (the container image's HEALTHCHECK)");

namespace {

int Fail(const std::string& message) {
  std::fprintf(stderr, "galpha_server: %s\n", message.c_str());
  return 1;
}

/// The --health_check mode: one grpc.health.v1 Check of the API, with a 3 s deadline.
int CheckHealth(const std::string& address) {
  auto stub = grpc::health::v1::Health::NewStub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(3));
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(galpha::server::kApiHealthService);
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = stub->Check(&context, request, &response);
  if (!status.ok()) return Fail(absl::StrCat("health check of ", address, ": ", status.error_message()));
  const std::string name = grpc::health::v1::HealthCheckResponse::ServingStatus_Name(response.status());
  std::printf("%s\n", name.c_str());
  return response.status() == grpc::health::v1::HealthCheckResponse::SERVING ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  absl::SetProgramUsageMessage("galpha_server: the galpha.v1.AlphaShapes gRPC service. Flags: --helpfull");
  absl::ParseCommandLine(argc, argv);
  if (const std::string address = absl::GetFlag(FLAGS_health_check); !address.empty()) return CheckHealth(address);
  using galpha::server::ServerOptions;
  ServerOptions options;
  options.listen_address = absl::GetFlag(FLAGS_listen);
  options.metrics_address = absl::GetFlag(FLAGS_metrics_listen);
  options.tls_cert_file = absl::GetFlag(FLAGS_tls_cert);
  options.tls_key_file = absl::GetFlag(FLAGS_tls_key);
  options.max_receive_message_bytes = absl::GetFlag(FLAGS_max_message_bytes);
  options.drain_notice = std::chrono::milliseconds(absl::GetFlag(FLAGS_drain_notice_ms));
  options.drain_grace = std::chrono::milliseconds(absl::GetFlag(FLAGS_drain_grace_ms));
  options.warm_up = absl::GetFlag(FLAGS_warm_up);
  const std::string backend = absl::GetFlag(FLAGS_backend);
  if (backend == "auto") {
    options.service.backend = galpha::Backend::kAuto;
  } else if (backend == "cpu") {
    options.service.backend = galpha::Backend::kCpu;
  } else if (backend == "cuda") {
    options.service.backend = galpha::Backend::kCuda;
  } else {
    return Fail(absl::StrCat("unknown --backend '", backend, "' (expected auto, cpu or cuda)"));
  }
  if (absl::GetFlag(FLAGS_build_slots) < 0) return Fail("--build_slots must be >= 0");
  options.service.build_slots = absl::GetFlag(FLAGS_build_slots);
  options.service.max_queued_builds = absl::GetFlag(FLAGS_max_queued_builds);
  options.service.max_tenant_queued_builds = absl::GetFlag(FLAGS_max_tenant_queued_builds);
  options.service.build_memory_bytes = absl::GetFlag(FLAGS_build_memory_bytes);
  options.service.max_points_per_build = absl::GetFlag(FLAGS_max_points_per_build);
  options.service.max_in_flight_bytes = absl::GetFlag(FLAGS_max_in_flight_bytes);
  options.service.max_tenant_in_flight_bytes = absl::GetFlag(FLAGS_max_tenant_in_flight_bytes);
  if (absl::GetFlag(FLAGS_upload_idle_timeout_ms) < 0) return Fail("--upload_idle_timeout_ms must be >= 0");
  options.service.upload_idle_timeout = std::chrono::milliseconds(absl::GetFlag(FLAGS_upload_idle_timeout_ms));
  if (absl::GetFlag(FLAGS_device_idle_release_ms) < 0) return Fail("--device_idle_release_ms must be >= 0");
  options.service.device_idle_release = std::chrono::milliseconds(absl::GetFlag(FLAGS_device_idle_release_ms));
  if (!(absl::GetFlag(FLAGS_build_time_multiple) >= 0)) return Fail("--build_time_multiple must be >= 0");
  if (absl::GetFlag(FLAGS_build_time_floor_ms) < 0) return Fail("--build_time_floor_ms must be >= 0");
  options.service.build_time.multiple = absl::GetFlag(FLAGS_build_time_multiple);
  options.service.build_time.floor = std::chrono::milliseconds(absl::GetFlag(FLAGS_build_time_floor_ms));
  if (!(absl::GetFlag(FLAGS_max_exact_comparisons_per_point) >= 0)) {
    return Fail("--max_exact_comparisons_per_point must be >= 0");
  }
  options.service.exact_comparisons.per_point = absl::GetFlag(FLAGS_max_exact_comparisons_per_point);
  options.service.exact_comparisons.floor = absl::GetFlag(FLAGS_exact_comparisons_floor);
  options.service.cache_bytes = absl::GetFlag(FLAGS_cache_bytes);
  options.service.compact_cache_bytes = absl::GetFlag(FLAGS_compact_cache_bytes);
  options.service.device_cache_bytes = absl::GetFlag(FLAGS_device_cache_bytes);
  const std::string packing = absl::GetFlag(FLAGS_batch_packing);
  if (packing == "auto") {
    options.service.batch_packing = galpha::server::BatchPacking::kAuto;
  } else if (packing == "on") {
    options.service.batch_packing = galpha::server::BatchPacking::kOn;
  } else if (packing == "off") {
    options.service.batch_packing = galpha::server::BatchPacking::kOff;
  } else {
    return Fail(absl::StrCat("unknown --batch_packing '", packing, "' (expected auto, on or off)"));
  }
  if (const std::string path = absl::GetFlag(FLAGS_token_file); !path.empty()) {
    auto tokens = galpha::server::TenantTokens::ReadFile(path);
    if (!tokens.ok()) return Fail(std::string(tokens.status().message()));
    options.service.tokens = *std::move(tokens);
  }

  // Every thread the server starts inherits this mask, so only the sigwait below sees the signals.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  auto server = galpha::server::GalphaServer::Start(options);
  if (!server.ok()) return Fail(std::string(server.status().message()));
  galpha::server::GalphaServer& s = **server;
  std::printf("galpha_server: listening on port %d (%s backend, %zu build slots, %s, %s)\n", s.port(),
              s.service().backend_name().c_str(), s.service().build_slots(),
              options.tls_cert_file.empty() ? "plaintext" : "TLS",
              options.service.tokens.enabled() ? "bearer tokens required" : "no authentication");
  if (s.metrics_port() != 0) std::printf("galpha_server: metrics on port %d\n", s.metrics_port());
  if (options.warm_up) std::printf("galpha_server: warm-up builds took %.1f ms\n", 1e3 * s.warm_up_seconds());
  std::fflush(stdout);

  int signal_number = 0;
  sigwait(&signals, &signal_number);
  std::printf("galpha_server: signal %d: draining\n", signal_number);
  std::fflush(stdout);
  std::thread second_signal([&] {
    int again = 0;
    sigwait(&signals, &again);
    s.CutNoticeShort();
  });
  second_signal.detach();  // it may wait forever; the process ends without it
  s.Drain();
  std::printf("galpha_server: stopped\n");
  std::fflush(stdout);
  return 0;
}
