// Counts per kind and class of one classification, and the interior area: what `alphactl summary`
// prints and what the service's Classify sends first, computed once for both.
#pragma once

#include <array>
#include <cstdint>

#include "core/family/alpha_family.hpp"

namespace galpha {

struct ClassificationSummary {
  /// Indexed by SimplexClass. Vertices count distinct points only (duplicates share a class).
  std::array<uint64_t, 4> vertices{}, edges{}, triangles{};
  /// Sum of the interior triangles' areas, in the order AssembleShape sums them (so that it equals
  /// the area of the shape at the same threshold).
  double interior_area = 0.0;
};

ClassificationSummary SummarizeClassification(const AlphaFamily& family, const Classification& classes);
/// The same from the arrays it reads (a resident family's host arrays).
ClassificationSummary SummarizeClassification(const HostVector<Point2>& points,
                                              const HostVector<uint32_t>& representative,
                                              const HostVector<std::array<uint32_t, 3>>& triangles,
                                              const Classification& classes);

}  // namespace galpha
