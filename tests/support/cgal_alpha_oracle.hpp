// CGAL's Alpha_shape_2 as a test oracle: exact spectrum, exact classification of every Delaunay
// edge and vertex, solid components and CGAL's "optimal alpha", all as GMP rationals.
//
// CGAL's headers stay in the .cpp (pimpl); see the comment block there for what exactly CGAL 5.5
// computes (spectrum contents, closed thresholds, its vertex rule, find_optimal_alpha's quirks).
// Not thread-safe: Classify switches the underlying alpha shape's mode and alpha internally.
#pragma once

#include <gmpxx.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <utility>
#include <vector>

#include "absl/types/span.h"
#include "core/base/point.hpp"

namespace galpha::testing {

/// CGAL's Classification_type, in the same order.
enum class OracleClass { kExterior, kSingular, kRegular, kInterior };
/// "EXTERIOR", "SINGULAR", ... (also what gtest prints).
std::ostream& operator<<(std::ostream& os, OracleClass c);

class CgalAlphaOracle {
 public:
  /// Builds CGAL's Alpha_shape_2 in GENERAL mode with Exact_predicates_exact_constructions_kernel
  /// over the distinct points of `points` (exact duplicates removed first; every vertex carries the
  /// input index of the first occurrence of its point). Any input is accepted, including an empty
  /// one, a single point, two points and collinear sets.
  explicit CgalAlphaOracle(absl::Span<const galpha::Point2> points);
  ~CgalAlphaOracle();
  CgalAlphaOracle(const CgalAlphaOracle&) = delete;
  CgalAlphaOracle& operator=(const CgalAlphaOracle&) = delete;

  /// CGAL's alpha spectrum (alpha_begin()..alpha_end(); squared radii), ascending, distinct, exact.
  /// Empty when the triangulation is not 2-dimensional (CGAL builds no intervals then).
  const std::vector<mpq_class>& spectrum() const;

  /// Dimension of CGAL's Delaunay triangulation: -1 (no point), 0 (one), 1 (collinear), 2.
  int dimension() const;
  /// Number of distinct points (= CGAL's finite vertices).
  size_t num_vertices() const;

  struct Classes {
    /// Every finite Delaunay edge, key (i, j), i < j, input indices (first occurrences).
    std::map<std::pair<uint32_t, uint32_t>, OracleClass> edges;
    /// CGAL's vertex classification (from incident triangles, not edges; see the .cpp).
    std::map<uint32_t, OracleClass> vertices;
    /// Finite faces classified INTERIOR.
    size_t interior_triangles = 0;
    /// CGAL's number_of_solid_components(alpha).
    size_t solid_components = 0;
    /// Size of CGAL's alpha_shape_edges list in REGULARIZED mode (its regular edges).
    size_t regularized_edges_regular = 0;
    /// Edges CGAL's GENERAL-mode alpha_shape_edges list has on top of the REGULARIZED one (the
    /// singular edges that regularization drops).
    size_t regularized_edges_singular = 0;
  };

  /// Classification of every Delaunay edge and vertex at alpha_sq = `alpha_sq` exactly (GENERAL
  /// mode). In dimension < 2 CGAL has no intervals and its answers are meaningless; the oracle then
  /// reports the natural extension instead: edges EXTERIOR below their squared half length and
  /// SINGULAR from it on (counted in regularized_edges_singular), vertices SINGULAR, no triangles,
  /// 0 components.
  Classes Classify(const mpq_class& alpha_sq) const;

  /// CGAL's find_optimal_alpha(num_components), exactly (see the .cpp for what it really returns);
  /// nullopt when CGAL returns alpha_end() and whenever the dimension is < 2 (where CGAL would read
  /// an empty map).
  std::optional<mpq_class> OptimalAlpha(int num_components) const;

  /// CGAL's find_alpha_solid(): the smallest alpha at which every vertex has an incident interior
  /// triangle (max over vertices of their smallest incident circumradius^2); 0 with < 3 vertices,
  /// nullopt in dimension < 2 with >= 3 vertices (CGAL would read an empty map).
  std::optional<mpq_class> AlphaSolid() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace galpha::testing
