// A served family built from points on the CPU backend, for the tests of the service's modules.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "gpu/alpha/alpha_engine.hpp"
#include "server/cached_family.hpp"

namespace galpha::server::testing {

/// The family of `points` built on the CPU backend as the service builds it (BuildCachedFamily):
/// in host memory, or with `resident` its tables kept in the build's buffers (the form a GPU
/// server with a device budget caches, here on the CPU so that CI reads it through the same
/// code); null (and a test failure naming `name`) when the build fails.
inline std::shared_ptr<const CachedFamily> MakeCachedFamily(const std::vector<Point2>& points, const std::string& name,
                                                            bool resident = false) {
  BuildOptions options;
  options.backend = Backend::kCpu;
  absl::StatusOr<std::shared_ptr<const CachedFamily>> family =
      BuildCachedFamily(points, {}, /*weighted=*/false, options, resident, nullptr);
  if (!family.ok()) {
    ADD_FAILURE() << name << ": " << family.status();
    return nullptr;
  }
  return *std::move(family);
}

}  // namespace galpha::server::testing
