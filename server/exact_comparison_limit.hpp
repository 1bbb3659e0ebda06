// How many exact radius comparisons one build may make (issue "No slow inputs", item 5: a guard
// against abuse, beside the time limit). Honest inputs need at most a few per point (a grid five,
// a lattice nudged by single ulps under one, co-circular points almost none); an input built to defeat the
// certified keys needs many more, and the host's sequential repair of what the device cannot
// decide has no bound in the input's size. Unlike the time limit, this one does not depend on
// the machine or its load: the same input is refused everywhere.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace galpha::server {

struct ExactComparisonLimitOptions {
  /// The limit is this many comparisons per input point; 0 turns the limit off.
  double per_point = 64;
  /// It is never below this (small inputs may sort all their few simplices exactly).
  uint64_t floor = 1000000;
};

/// The limit for a build of `points`: max(floor, per_point * points); zero when the limit is off.
uint64_t ExactComparisonLimit(size_t points, const ExactComparisonLimitOptions& options);

/// The RESOURCE_EXHAUSTED message of a build stopped by its limit, naming the limit and the flags.
std::string ExactComparisonLimitMessage(size_t points, const ExactComparisonLimitOptions& options);

}  // namespace galpha::server
