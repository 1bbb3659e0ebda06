#include "server/build_time_limit.hpp"

#include <algorithm>

#include "absl/strings/str_format.h"

namespace galpha::server {

double ExpectedBuildSeconds(size_t points, bool cuda, unsigned host_cores) {
  const double n = static_cast<double>(points);
  if (cuda) return n * 60e-9;
  return n * 14e-6 / std::max(1u, host_cores);
}

std::chrono::duration<double> BuildTimeLimit(size_t points, bool cuda, unsigned host_cores,
                                             const BuildTimeLimitOptions& options) {
  if (options.multiple <= 0) return std::chrono::duration<double>(0);
  const double floor = std::chrono::duration<double>(options.floor).count();
  return std::chrono::duration<double>(
      std::max(floor, options.multiple * ExpectedBuildSeconds(points, cuda, host_cores)));
}

std::string BuildTimeLimitMessage(size_t points, bool cuda, unsigned host_cores, const BuildTimeLimitOptions& options) {
  return absl::StrFormat(
      "the build ran past its time limit of %.3g s and was stopped: %g times the %.3g s a build of %d points is "
      "expected to take on the %s backend%s, at least %d ms (--build_time_multiple, --build_time_floor_ms)",
      BuildTimeLimit(points, cuda, host_cores, options).count(), options.multiple,
      ExpectedBuildSeconds(points, cuda, host_cores), points, cuda ? "cuda" : "cpu",
      cuda ? "" : absl::StrFormat(" with %u cores", host_cores), options.floor.count());
}

}  // namespace galpha::server
