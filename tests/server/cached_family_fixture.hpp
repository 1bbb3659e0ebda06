// A served family built from points on the CPU backend, for the tests of the service's modules.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "gpu/alpha/alpha_engine.hpp"
#include "gpu/alpha/resident_family.hpp"
#include "server/cached_family.hpp"

namespace galpha::server::testing {

/// The family of `points` as the service caches it; null (and a test failure naming `name`) when
/// the build fails.
inline std::shared_ptr<const CachedFamily> MakeCachedFamily(const std::vector<Point2>& points,
                                                            const std::string& name) {
  BuildOptions options;
  options.backend = Backend::kCpu;
  absl::StatusOr<AlphaFamily> family = BuildAlphaFamily(points, options);
  if (!family.ok()) {
    ADD_FAILURE() << name << ": " << family.status();
    return nullptr;
  }
  return std::make_shared<const CachedFamily>(*std::move(family));
}

/// The same family resident (its tables in the CPU build's buffers), as a CPU server caches it.
inline std::shared_ptr<const CachedFamily> MakeResidentCachedFamily(const std::vector<Point2>& points,
                                                                    const std::string& name) {
  BuildOptions options;
  options.backend = Backend::kCpu;
  absl::StatusOr<ResidentAlphaFamily> family = BuildResidentAlphaFamily(points, options);
  if (!family.ok()) {
    ADD_FAILURE() << name << ": " << family.status();
    return nullptr;
  }
  return std::make_shared<const CachedFamily>(*std::move(family));
}

}  // namespace galpha::server::testing
