// How long one build may run (issue "No slow inputs", item 5: a guard against abuse). A build
// costs the service a slot and its memory for as long as it runs, and some inputs cost far more
// than their size suggests; the limit is a multiple of what a build of that size is expected to
// take on this backend, with a floor, so that honest inputs never meet it.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace galpha::server {

struct BuildTimeLimitOptions {
  /// The limit is `multiple` times the expected time; 0 turns the limit off.
  double multiple = 50;
  /// It is never below this.
  std::chrono::milliseconds floor{10000};
};

/// Expected seconds of a build of `points` uniform points: measured rates of the whole engine
/// call (bench/README.md): 60 ns a point on the CUDA backend (an H100: 51 ms at 1M), 14 us a
/// point divided by the host's cores on the CPU backend (7.9 s at 1M on 2 cores).
double ExpectedBuildSeconds(size_t points, bool cuda, unsigned host_cores);

/// The limit for a build of `points`: max(floor, multiple * expected); zero when the limit is off.
std::chrono::duration<double> BuildTimeLimit(size_t points, bool cuda, unsigned host_cores,
                                             const BuildTimeLimitOptions& options);

/// The DEADLINE_EXCEEDED message of a build stopped by its limit, naming the limit and the flags.
std::string BuildTimeLimitMessage(size_t points, bool cuda, unsigned host_cores, const BuildTimeLimitOptions& options);

}  // namespace galpha::server
