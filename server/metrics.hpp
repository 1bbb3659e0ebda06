// The service's Prometheus metrics (server/README.md, "Metrics"), in base units, counters with `_total`,
// no handle labels (handles are unbounded). The exporter serves them on its own port.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "core/family/alpha_family.hpp"
#include "server/build_scheduler.hpp"
#include "server/family_cache.hpp"

namespace prometheus {
class Registry;
class Exposer;
}  // namespace prometheus

namespace galpha::server {

class ServerMetrics final : public CacheObserver, public SchedulerObserver {
 public:
  ServerMetrics();
  ~ServerMetrics() override;

  /// Serves GET /metrics on `address` ("host:port"; port 0 picks one). Returns the bound port.
  absl::StatusOr<int> StartExporter(const std::string& address);

  /// A finished build: every stage's latency and the radius comparisons by path.
  void RecordBuild(const BuildReport& report, double total_seconds);
  /// A finished RPC with its status code name ("OK", "NOT_FOUND", ...).
  void RecordRpc(std::string_view method, std::string_view code, double seconds);
  /// Device memory in use (total - free) on the GPU, sampled by the server.
  void SetDeviceMemoryInUse(double bytes);
  /// How long the warm-up builds took before the server listened (AlphaService::WarmUp).
  void SetWarmUpSeconds(double seconds);
  /// 1 for the backend this server runs ("cuda" or "cpu").
  void SetBackend(const std::string& backend);
  /// A Build refused or ended by a limit; `reason` is a RefusalLabel (build_refusal.hpp).
  void RecordRejectedBuild(std::string_view reason);

  // CacheObserver
  void OnHit(CacheTier tier) override;
  void OnMiss() override;
  void OnEviction(CacheTier tier) override;
  void OnDemotion() override;
  void OnPromotion() override;
  void OnSize(CacheTier tier, size_t bytes, size_t entries) override;
  void OnDeviceSize(size_t bytes) override;
  // SchedulerObserver
  void OnLoad(size_t queued, size_t running, size_t admitted_bytes) override;

 private:
  struct Families;
  std::shared_ptr<prometheus::Registry> registry_;
  std::unique_ptr<Families> families_;
  std::unique_ptr<prometheus::Exposer> exposer_;
};

}  // namespace galpha::server
