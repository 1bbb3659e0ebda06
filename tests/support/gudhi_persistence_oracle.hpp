// GUDHI's alpha-complex persistence (exact constructions) behind a GUDHI-free interface: the test
// oracle of galpha's persistence diagrams and the competitor of its benchmark. GUDHI builds the
// alpha complex of the points with CGAL's exact kernel (Alpha_complex<Epeck_d>, exact = true: its
// filtration values are the exact squared radii converted to double) and computes persistent
// cohomology over Z/2Z.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "absl/types/span.h"
#include "core/base/point.hpp"

namespace galpha::testing {

struct GudhiDiagram {
  /// (birth, death) of every interval of positive length, per dimension (0 and 1); death is
  /// +infinity for an essential class. GUDHI's order.
  std::vector<std::pair<double, double>> intervals[2];
  /// Simplices of the alpha complex GUDHI built (vertices, edges and triangles).
  size_t num_simplices = 0;
};

/// The diagram of `points` (duplicates are one vertex, as in CGAL's triangulation). Needs at least
/// two distinct points (GUDHI refuses a zero-dimensional triangulation).
GudhiDiagram GudhiAlphaPersistence(absl::Span<const Point2> points);

}  // namespace galpha::testing
