// What the service tests share: a real server on loopback ports, a client for it, the metrics
// page over HTTP, and the standard health and reflection protocols.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "client/galpha_client.hpp"
#include "server/galpha_server.hpp"

namespace galpha::server::testing {

/// The backend the tests' servers run: "cpu", or "cuda" when GALPHA_SERVICE_BACKEND=cuda (the GPU
/// machine's run of bench/gpu_run.sh).
std::string TestBackend();
/// Options for a test server: loopback, ports picked by the system, a short drain.
ServerOptions TestServerOptions();
/// Starts the server; fails the test (ADD_FAILURE) and returns null when it cannot.
std::unique_ptr<GalphaServer> StartServer(const ServerOptions& options);
/// A client of `server` on 127.0.0.1 (plaintext) with an optional bearer token.
std::unique_ptr<client::AlphaClient> ClientOf(const GalphaServer& server, const std::string& token = "");

/// GET http://127.0.0.1:port/path over a plain socket; the body, or "" when it fails.
std::string HttpGet(int port, const std::string& path);
/// The value of the series `series` (name and labels exactly as exposed, e.g.
/// `galpha_rpcs_total{code="OK",method="Build"}`) in a Prometheus text page; NaN when absent.
double MetricValue(const std::string& page, const std::string& series);
/// MetricValue of the server's current metrics page.
double ScrapeMetric(const GalphaServer& server, const std::string& series);

/// grpc.health.v1 Check: "SERVING", "NOT_SERVING", ... or the call's error code name.
std::string HealthOf(const std::shared_ptr<grpc::Channel>& channel, const std::string& service);
/// grpc.reflection.v1alpha list_services.
std::vector<std::string> ReflectedServices(const std::shared_ptr<grpc::Channel>& channel);

/// Polls `condition` every 10 ms for up to `seconds`; whether it became true.
bool WaitFor(const std::function<bool()>& condition, double seconds);

}  // namespace galpha::server::testing
