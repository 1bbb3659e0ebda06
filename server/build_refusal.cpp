#include "server/build_refusal.hpp"

#include <string>

#include "absl/strings/cord.h"
#include "absl/types/optional.h"

namespace galpha::server {

namespace {
// A payload's type URL; only this process reads it (ToGrpcStatus sends code and message only).
constexpr char kRefusalPayload[] = "type.galpha.dev/galpha.server.BuildRefusal";
}  // namespace

std::string_view RefusalLabel(BuildRefusal reason) {
  switch (reason) {
    case BuildRefusal::kPointsPerBuild:
      return "points_per_build";
    case BuildRefusal::kInFlightBytes:
      return "in_flight_bytes";
    case BuildRefusal::kTenantInFlightBytes:
      return "tenant_in_flight_bytes";
    case BuildRefusal::kIdleTimeout:
      return "idle_timeout";
    case BuildRefusal::kQueueFull:
      return "queue_full";
    case BuildRefusal::kTenantQueuedBuilds:
      return "tenant_queued_builds";
    case BuildRefusal::kBuildMemory:
      return "build_memory";
    case BuildRefusal::kCacheBytes:
      return "cache_bytes";
    case BuildRefusal::kDraining:
      return "draining";
    case BuildRefusal::kBuildTime:
      return "build_time";
    case BuildRefusal::kExactComparisons:
      return "exact_comparisons";
  }
  return "unknown";
}

absl::Status TagRefusal(absl::Status status, BuildRefusal reason) {
  status.SetPayload(kRefusalPayload, absl::Cord(std::string(RefusalLabel(reason))));
  return status;
}

std::string RefusalLabelOf(const absl::Status& status) {
  const absl::optional<absl::Cord> payload = status.GetPayload(kRefusalPayload);
  return payload.has_value() ? std::string(*payload) : std::string();
}

}  // namespace galpha::server
