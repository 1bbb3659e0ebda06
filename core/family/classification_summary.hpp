// Counts per kind and class of one classification, and the interior area: what `alphactl summary`
// prints and what the service's Classify sends first, computed once for both.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

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
/// Each triangle's term of the interior area, 0.5 * Orient2dApprox of its vertices, in triangle
/// order (on every core). A service that summarizes many classifications of one family computes
/// them once: reading three points at random per triangle is most of a summary's time.
std::vector<double> TriangleAreaTerms(const HostVector<Point2>& points,
                                      const HostVector<std::array<uint32_t, 3>>& triangles);
/// The same summary from those terms (area_terms.size() == classes.triangles.size()): the interior
/// area adds the interior triangles' terms in triangle order, the same double as the others give.
ClassificationSummary SummarizeClassification(const HostVector<uint32_t>& representative,
                                              const std::vector<double>& area_terms, const Classification& classes);
/// The same from the arrays it reads (a resident family's host arrays).
ClassificationSummary SummarizeClassification(const HostVector<Point2>& points,
                                              const HostVector<uint32_t>& representative,
                                              const HostVector<std::array<uint32_t, 3>>& triangles,
                                              const Classification& classes);

/// The same interior area from per-triangle flags (1: in the complex), in triangle order: what a
/// resident family's shape adds (gpu/alpha/resident_family.hpp, ShapeAt), so that its area is
/// AssembleShape's double.
double InteriorAreaOfFlagged(const HostVector<Point2>& points, const HostVector<std::array<uint32_t, 3>>& triangles,
                             const std::vector<uint8_t>& in_complex);

}  // namespace galpha
