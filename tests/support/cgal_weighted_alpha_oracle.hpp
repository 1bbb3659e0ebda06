// CGAL's weighted Alpha_shape_2 (over Regular_triangulation_2, exact constructions) as a test
// oracle: every exact threshold, the hidden points, and the class of every edge, vertex and face
// at an exact alpha_sq, as GMP rationals. CGAL's headers stay in the .cpp (pimpl). Not thread-safe.
#pragma once

#include <gmpxx.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "absl/types/span.h"
#include "core/base/point.hpp"
#include "tests/support/cgal_alpha_oracle.hpp"

namespace galpha::testing {

class CgalWeightedAlphaOracle {
 public:
  /// Builds CGAL's weighted Alpha_shape_2 in GENERAL mode with
  /// Exact_predicates_exact_constructions_kernel over the first occurrence of every (point,
  /// weight) of the input (CGAL keeps one vertex for equal weighted points); every vertex carries
  /// that input index.
  CgalWeightedAlphaOracle(absl::Span<const Point2> points, absl::Span<const double> weights);
  ~CgalWeightedAlphaOracle();
  CgalWeightedAlphaOracle(const CgalWeightedAlphaOracle&) = delete;
  CgalWeightedAlphaOracle& operator=(const CgalWeightedAlphaOracle&) = delete;

  /// Every distinct exact threshold, ascending: the squared radii of the finite faces and of the
  /// unattached finite edges, negative ones included (CGAL's own alpha_begin()..alpha_end() keeps
  /// only the values > 0). Empty unless the dimension is 2.
  const std::vector<mpq_class>& thresholds() const;
  /// Dimension of CGAL's regular triangulation.
  int dimension() const;
  /// Input indices (first occurrences) of the points CGAL's triangulation hides, ascending.
  const std::vector<uint32_t>& hidden() const;

  struct Classes {
    /// Every finite edge of the regular triangulation, key (i, j), i < j, input indices.
    std::map<std::pair<uint32_t, uint32_t>, OracleClass> edges;
    /// Every vertex (not hidden) by input index: CGAL's rule (from incident faces; never EXTERIOR
    /// in GENERAL mode).
    std::map<uint32_t, OracleClass> vertices;
    size_t interior_triangles = 0;
  };
  /// Classes at alpha_sq exactly (GENERAL mode; dimension 2 only).
  Classes Classify(const mpq_class& alpha_sq) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace galpha::testing
