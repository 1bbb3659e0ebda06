// Why the service refused a Build (or ended its upload): one reason per limit, the `reason` label
// of galpha_builds_rejected_total. The module that hits a limit tags its status with the reason
// (an absl::Status payload, which the gRPC status does not carry); the Build reactor counts the
// tag once, where the call ends, so that a reason is counted exactly once whichever module refused.
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "absl/status/status.h"

namespace galpha::server {

enum class BuildRefusal {
  kPointsPerBuild,       // --max_points_per_build
  kInFlightBytes,        // --max_in_flight_bytes
  kTenantInFlightBytes,  // --max_tenant_in_flight_bytes
  kIdleTimeout,          // --upload_idle_timeout_ms
  kQueueFull,            // --max_queued_builds
  kTenantQueuedBuilds,   // --max_tenant_queued_builds
  kBuildMemory,          // --build_memory_bytes
  kCacheBytes,           // --cache_bytes
  kDraining,             // SIGTERM
  kBuildTime,            // --build_time_multiple, --build_time_floor_ms
  kExactComparisons,     // --max_exact_comparisons_per_point, --exact_comparisons_floor
};

/// Every reason, so that the metrics export each series from the start (at 0).
inline constexpr std::array<BuildRefusal, 11> kAllBuildRefusals = {
    BuildRefusal::kPointsPerBuild, BuildRefusal::kInFlightBytes,   BuildRefusal::kTenantInFlightBytes,
    BuildRefusal::kIdleTimeout,    BuildRefusal::kQueueFull,       BuildRefusal::kTenantQueuedBuilds,
    BuildRefusal::kBuildMemory,    BuildRefusal::kCacheBytes,      BuildRefusal::kDraining,
    BuildRefusal::kBuildTime,      BuildRefusal::kExactComparisons};

/// The metric label of `reason` ("points_per_build", "in_flight_bytes", ...).
std::string_view RefusalLabel(BuildRefusal reason);

/// `status` (an error) tagged with `reason`.
absl::Status TagRefusal(absl::Status status, BuildRefusal reason);

/// The label `status` was tagged with, or "" when it is no refusal (an input error, a failed
/// build, OK).
std::string RefusalLabelOf(const absl::Status& status);

}  // namespace galpha::server
