#include "server/metrics.hpp"

#include <prometheus/counter.h>
#include <prometheus/exposer.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>

#include <array>
#include <exception>

#include "absl/strings/str_cat.h"
#include "server/build_refusal.hpp"

namespace galpha::server {

namespace {
// Stage latencies span 10 us (small inputs on a GPU) to minutes (100M points on a CPU).
prometheus::Histogram::BucketBoundaries LatencyBuckets() {
  return {1e-5, 3e-5, 1e-4, 3e-4, 1e-3, 3e-3, 0.01, 0.03, 0.1, 0.3, 1, 3, 10, 30, 100, 300};
}
}  // namespace

struct ServerMetrics::Families {
  explicit Families(prometheus::Registry& r)
      : stage_seconds(prometheus::BuildHistogram()
                          .Name("galpha_build_stage_seconds")
                          .Help("Latency of each build stage, by stage")
                          .Register(r)),
        build_seconds(prometheus::BuildHistogram()
                          .Name("galpha_build_seconds")
                          .Help("Latency of whole builds (engine only, upload excluded)")
                          .Register(r)),
        rpc_seconds(prometheus::BuildHistogram()
                        .Name("galpha_rpc_duration_seconds")
                        .Help("Latency of RPCs, by method")
                        .Register(r)),
        rpcs(prometheus::BuildCounter()
                 .Name("galpha_rpcs_total")
                 .Help("Finished RPCs by method and status code")
                 .Register(r)),
        comparisons(prometheus::BuildCounter()
                        .Name("galpha_radius_comparisons_total")
                        .Help("Exact radius comparisons by the path that decided them (filter, device_exact, "
                              "cpu_fallback); the CPU-fallback rate is cpu_fallback over the sum")
                        .Register(r)),
        rejected(prometheus::BuildCounter()
                     .Name("galpha_builds_rejected_total")
                     .Help("Builds refused or ended by a limit, by reason (the limit's name: in_flight_bytes, "
                           "idle_timeout, queue_full, ...; server/README.md)")
                     .Register(r)),
        cache_bytes(prometheus::BuildGauge()
                        .Name("galpha_cache_bytes")
                        .Help("Bytes of families in the cache, by tier (resident: whole families; compact: "
                              "their points, rebuilt on use)")
                        .Register(r)),
        cache_entries(
            prometheus::BuildGauge().Name("galpha_cache_entries").Help("Families in the cache, by tier").Register(r)),
        cache_device_bytes(prometheus::BuildGauge()
                               .Name("galpha_cache_device_bytes")
                               .Help("GPU memory held by the resident tier's families whose rank tables stayed on "
                                     "the GPU they were built on (--device_cache_bytes)")
                               .Register(r)),
        cache_hits(prometheus::BuildCounter()
                       .Name("galpha_cache_hits_total")
                       .Help("Cache lookups that found a family, by the tier it was in")
                       .Register(r)),
        cache_misses(prometheus::BuildCounter()
                         .Name("galpha_cache_misses_total")
                         .Help("Cache lookups that found nothing")
                         .Register(r)),
        cache_evictions(prometheus::BuildCounter()
                            .Name("galpha_cache_evictions_total")
                            .Help("Families that left the cache to stay within its budgets, by the tier they "
                                  "left (resident only when the compact tier cannot take them)")
                            .Register(r)),
        cache_demotions(prometheus::BuildCounter()
                            .Name("galpha_cache_demotions_total")
                            .Help("Families moved from the resident tier to the compact tier")
                            .Register(r)),
        cache_promotions(prometheus::BuildCounter()
                             .Name("galpha_cache_promotions_total")
                             .Help("Families rebuilt from the compact tier into the resident tier")
                             .Register(r)),
        builds_in_flight(
            prometheus::BuildGauge().Name("galpha_builds_in_flight").Help("Builds running on a slot").Register(r)),
        queue_length(
            prometheus::BuildGauge().Name("galpha_build_queue_length").Help("Builds waiting for a slot").Register(r)),
        admitted_bytes(prometheus::BuildGauge()
                           .Name("galpha_build_admitted_bytes")
                           .Help("Estimated working memory of the running builds")
                           .Register(r)),
        device_memory(prometheus::BuildGauge()
                          .Name("galpha_device_memory_used_bytes")
                          .Help("GPU memory in use (total - free), sampled")
                          .Register(r)),
        backend(prometheus::BuildGauge()
                    .Name("galpha_backend_info")
                    .Help("1 for the backend this server runs")
                    .Register(r)),
        warm_up(prometheus::BuildGauge()
                    .Name("galpha_warm_up_seconds")
                    .Help("Seconds the warm-up builds took before the server listened (--warm_up); 0 without them")
                    .Register(r)),
        filter(comparisons.Add({{"path", "filter"}})),
        device_exact(comparisons.Add({{"path", "device_exact"}})),
        cpu_fallback(comparisons.Add({{"path", "cpu_fallback"}})),
        build_total(build_seconds.Add({}, LatencyBuckets())),
        hits{&cache_hits.Add({{"tier", "resident"}}), &cache_hits.Add({{"tier", "compact"}})},
        misses(cache_misses.Add({})),
        evictions{&cache_evictions.Add({{"tier", "resident"}}), &cache_evictions.Add({{"tier", "compact"}})},
        demotions(cache_demotions.Add({})),
        promotions(cache_promotions.Add({})),
        bytes{&cache_bytes.Add({{"tier", "resident"}}), &cache_bytes.Add({{"tier", "compact"}})},
        entries{&cache_entries.Add({{"tier", "resident"}}), &cache_entries.Add({{"tier", "compact"}})},
        device_bytes(cache_device_bytes.Add({})),
        in_flight(builds_in_flight.Add({})),
        queued(queue_length.Add({})),
        admitted(admitted_bytes.Add({})),
        device(device_memory.Add({})),
        warm_up_seconds(warm_up.Add({})) {
    // Every reason from the start, at 0: an alert on a rate sees the series before its first refusal.
    for (const BuildRefusal reason : kAllBuildRefusals) rejected.Add({{"reason", std::string(RefusalLabel(reason))}});
  }

  prometheus::Family<prometheus::Histogram>& stage_seconds;
  prometheus::Family<prometheus::Histogram>& build_seconds;
  prometheus::Family<prometheus::Histogram>& rpc_seconds;
  prometheus::Family<prometheus::Counter>& rpcs;
  prometheus::Family<prometheus::Counter>& comparisons;
  prometheus::Family<prometheus::Counter>& rejected;
  prometheus::Family<prometheus::Gauge>& cache_bytes;
  prometheus::Family<prometheus::Gauge>& cache_entries;
  prometheus::Family<prometheus::Gauge>& cache_device_bytes;
  prometheus::Family<prometheus::Counter>& cache_hits;
  prometheus::Family<prometheus::Counter>& cache_misses;
  prometheus::Family<prometheus::Counter>& cache_evictions;
  prometheus::Family<prometheus::Counter>& cache_demotions;
  prometheus::Family<prometheus::Counter>& cache_promotions;
  prometheus::Family<prometheus::Gauge>& builds_in_flight;
  prometheus::Family<prometheus::Gauge>& queue_length;
  prometheus::Family<prometheus::Gauge>& admitted_bytes;
  prometheus::Family<prometheus::Gauge>& device_memory;
  prometheus::Family<prometheus::Gauge>& backend;
  prometheus::Family<prometheus::Gauge>& warm_up;
  prometheus::Counter& filter;
  prometheus::Counter& device_exact;
  prometheus::Counter& cpu_fallback;
  prometheus::Histogram& build_total;
  // Indexed by CacheTier.
  std::array<prometheus::Counter*, 2> hits;
  prometheus::Counter& misses;
  std::array<prometheus::Counter*, 2> evictions;
  prometheus::Counter& demotions;
  prometheus::Counter& promotions;
  std::array<prometheus::Gauge*, 2> bytes;
  std::array<prometheus::Gauge*, 2> entries;
  prometheus::Gauge& device_bytes;
  prometheus::Gauge& in_flight;
  prometheus::Gauge& queued;
  prometheus::Gauge& admitted;
  prometheus::Gauge& device;
  prometheus::Gauge& warm_up_seconds;
};

ServerMetrics::ServerMetrics()
    : registry_(std::make_shared<prometheus::Registry>()), families_(std::make_unique<Families>(*registry_)) {}

ServerMetrics::~ServerMetrics() = default;

absl::StatusOr<int> ServerMetrics::StartExporter(const std::string& address) {
  try {
    exposer_ = std::make_unique<prometheus::Exposer>(address);
  } catch (const std::exception& e) {
    return absl::UnavailableError(absl::StrCat("cannot serve metrics on ", address, ": ", e.what()));
  }
  exposer_->RegisterCollectable(registry_);
  const std::vector<int> ports = exposer_->GetListeningPorts();
  if (ports.empty()) return absl::UnavailableError(absl::StrCat("the metrics exporter on ", address, " bound no port"));
  return ports.front();
}

void ServerMetrics::RecordBuild(const BuildReport& report, double total_seconds) {
  for (const StageTime& stage : report.stage_times) {
    families_->stage_seconds.Add({{"stage", stage.stage}}, LatencyBuckets()).Observe(stage.seconds);
  }
  families_->build_total.Observe(total_seconds);
  families_->filter.Increment(static_cast<double>(report.comparisons.filter));
  families_->device_exact.Increment(static_cast<double>(report.comparisons.bounded_exact));
  families_->cpu_fallback.Increment(static_cast<double>(report.comparisons.cpu_fallback));
}

void ServerMetrics::RecordRpc(std::string_view method, std::string_view code, double seconds) {
  const std::string name(method);
  families_->rpc_seconds.Add({{"method", name}}, LatencyBuckets()).Observe(seconds);
  families_->rpcs.Add({{"method", name}, {"code", std::string(code)}}).Increment();
}

void ServerMetrics::RecordRejectedBuild(std::string_view reason) {
  families_->rejected.Add({{"reason", std::string(reason)}}).Increment();
}

void ServerMetrics::SetDeviceMemoryInUse(double bytes) { families_->device.Set(bytes); }

void ServerMetrics::SetWarmUpSeconds(double seconds) { families_->warm_up_seconds.Set(seconds); }

void ServerMetrics::SetBackend(const std::string& backend) { families_->backend.Add({{"backend", backend}}).Set(1); }

void ServerMetrics::OnHit(CacheTier tier) { families_->hits[static_cast<size_t>(tier)]->Increment(); }

void ServerMetrics::OnMiss() { families_->misses.Increment(); }

void ServerMetrics::OnEviction(CacheTier tier) { families_->evictions[static_cast<size_t>(tier)]->Increment(); }

void ServerMetrics::OnDemotion() { families_->demotions.Increment(); }

void ServerMetrics::OnPromotion() { families_->promotions.Increment(); }

void ServerMetrics::OnSize(CacheTier tier, size_t bytes, size_t entries) {
  families_->bytes[static_cast<size_t>(tier)]->Set(static_cast<double>(bytes));
  families_->entries[static_cast<size_t>(tier)]->Set(static_cast<double>(entries));
}

void ServerMetrics::OnDeviceSize(size_t bytes) { families_->device_bytes.Set(static_cast<double>(bytes)); }

void ServerMetrics::OnLoad(size_t queued, size_t running, size_t admitted_bytes) {
  families_->queued.Set(static_cast<double>(queued));
  families_->in_flight.Set(static_cast<double>(running));
  families_->admitted.Set(static_cast<double>(admitted_bytes));
}

}  // namespace galpha::server
