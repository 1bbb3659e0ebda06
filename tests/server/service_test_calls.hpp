// What several service_test files call: the local engine as the oracle, the whole spectrum over
// Spectrum pages, and Build streams written message by message through the raw stub.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "client/galpha_client.hpp"
#include "core/family/alpha_family.hpp"

namespace galpha::server::testing {

/// A build that takes long enough (a second or more) for a test to act while it runs.
size_t SlowBuildPoints();

/// The family of `points` built in-process on the CPU backend (a test failure when it fails).
AlphaFamily LocalFamily(const std::vector<Point2>& points);

/// The whole spectrum of `handle`, `page` values per Spectrum call.
std::vector<double> SpectrumRemote(client::AlphaClient& client, const std::string& handle, uint32_t page);

/// Streams `messages` as one Build call and returns its status.
absl::Status RawBuild(client::AlphaClient& client, const std::vector<v1::BuildRequest>& messages,
                      v1::BuildResponse* response = nullptr);

/// A Build header announcing `expected` points (0: not announced).
v1::BuildRequest Header(uint64_t expected = 0);

/// A Build chunk of interleaved x, y coordinates.
v1::BuildRequest Chunk(const std::vector<double>& coordinates);

}  // namespace galpha::server::testing
