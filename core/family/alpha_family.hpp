// AlphaFamily: the immutable, exact family of alpha shapes of one point set, and every query over
// it (classification, spectrum, master list, components, optimal alpha, the shape as geometry).
// Built by BuildAlphaFamily (gpu/alpha/alpha_engine.hpp); semantics in docs/design.md, "Semantics".
//
// Thresholds are resolved to a *level*: the number of spectrum values <= the threshold, compared
// exactly (level 0: alpha_sq in [min_alpha_sq, spectrum[0]); level -1: alpha_sq below
// min_alpha_sq, where nothing is in). min_alpha_sq is 0 unweighted, minus the largest weight
// weighted (below it every disk of squared radius alpha_sq + w is empty). The complex at level L is
// the complex at every alpha_sq in [spectrum[L-1], spectrum[L]).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"
#include "core/base/stage_time.hpp"
#include "core/family/alpha_ranks.hpp"
#include "core/family/persistence_pair.hpp"
#include "core/family/simplex_class.hpp"
#include "core/geometry/shape.hpp"

namespace galpha {

/// What a build measured.
struct BuildReport {
  std::string backend;
  std::vector<StageTime> stage_times;
  ComparisonCounts comparisons;
  size_t peak_memory_bytes = 0;
};

/// The raw parts a family is assembled from (moved in by the builder).
struct AlphaFamilyParts {
  HostVector<Point2> points;
  HostVector<uint32_t> representative;
  uint32_t num_unique = 0;
  HostVector<std::array<uint32_t, 3>> triangles;  // counter-clockwise, input indices
  HostVector<std::array<uint32_t, 2>> edges;      // (smaller, larger) input index
  /// Weighted families (issue 18): every input point's weight (the squared radius of its disk),
  /// and 1 for every input index whose point is hidden (no vertex of the regular triangulation:
  /// EXTERIOR at every level). Both empty for an unweighted family.
  HostVector<double> weights;
  HostVector<uint8_t> hidden;
  AlphaRanks ranks;
  BuildReport report;
  /// The persistence diagram, when the build computed it (BuildOptions::persistence).
  std::optional<PersistenceDiagram> persistence;
};

/// Classes of every simplex at one level: vertices by input index, edges and triangles by id.
struct Classification {
  std::vector<SimplexClass> vertices;
  std::vector<SimplexClass> edges;
  std::vector<SimplexClass> triangles;
};

class AlphaFamily {
 public:
  /// Takes the parts (the engine computed the component curves among them).
  explicit AlphaFamily(AlphaFamilyParts parts);

  const HostVector<Point2>& points() const { return parts_.points; }
  const HostVector<uint32_t>& representative() const { return parts_.representative; }
  uint32_t num_unique() const { return parts_.num_unique; }
  uint32_t num_duplicates() const { return static_cast<uint32_t>(parts_.points.size()) - parts_.num_unique; }
  const HostVector<std::array<uint32_t, 3>>& triangles() const { return parts_.triangles; }
  const HostVector<std::array<uint32_t, 2>>& edges() const { return parts_.edges; }
  const AlphaRanks& ranks() const { return parts_.ranks; }
  /// Whether the family was built from weighted points; their weights and hidden flags (empty
  /// when unweighted).
  bool weighted() const { return !parts_.weights.empty(); }
  const HostVector<double>& weights() const { return parts_.weights; }
  bool hidden(uint32_t v) const { return !parts_.hidden.empty() && parts_.hidden[v] != 0; }
  /// The persistence diagram the build computed (BuildOptions::persistence), or null.
  const PersistenceDiagram* persistence() const { return parts_.persistence ? &*parts_.persistence : nullptr; }
  /// Per input index, 1 for a hidden point (empty when unweighted).
  const HostVector<uint8_t>& hidden_flags() const { return parts_.hidden; }
  /// Input indices of the hidden points, ascending.
  std::vector<uint32_t> HiddenPoints() const;
  /// The lower end of level 0: 0 unweighted, minus the largest weight weighted.
  double min_alpha_sq() const { return min_alpha_sq_; }
  const BuildReport& report() const { return parts_.report; }

  /// Host memory the family holds (its arrays' capacities), in bytes: what a cache charges for it.
  size_t HostBytes() const;

  /// The spectrum: nearest doubles of the distinct exact thresholds (alpha_sq), ascending.
  const HostVector<double>& spectrum() const { return parts_.ranks.spectrum; }
  int64_t max_level() const { return static_cast<int64_t>(parts_.ranks.spectrum.size()); }

  /// Level of alpha_sq = `alpha_sq`, exactly. InvalidArgument for NaN.
  absl::StatusOr<int64_t> LevelForAlphaSq(double alpha_sq) const;
  /// Level of the radius `alpha` (alpha^2 compared exactly). InvalidArgument for NaN or alpha < 0.
  absl::StatusOr<int64_t> LevelForAlpha(double alpha) const;
  /// Level of a rank (the complex at spectrum[rank - 1]; rank 0: the points alone, level 0).
  /// OutOfRange beyond K.
  absl::StatusOr<int64_t> LevelForRank(int64_t rank) const;
  /// CGAL's alpha_lower_bound: the first rank whose exact threshold is >= alpha_sq (K + 1 when
  /// none is).
  int64_t RankLowerBound(double alpha_sq) const;

  SimplexClass ClassifyTriangle(uint32_t t, int64_t level) const;
  SimplexClass ClassifyEdge(uint32_t e, int64_t level, ClassifyMode mode) const;
  /// `v` is an input index (a duplicate is classified as its first occurrence).
  SimplexClass ClassifyVertex(uint32_t v, int64_t level, ClassifyMode mode, VertexRule rule) const;
  Classification ClassifyAll(int64_t level, ClassifyMode mode, VertexRule rule) const;

  /// Master-list entries whose interval has rank `rank` (1..K) as an end point; empty for any
  /// other rank (rank 0 and kNeverRank are not end points of the list).
  absl::Span<const MasterEntry> MasterList(int64_t rank) const;

  /// Connected components of the complex at `level` (GENERAL: simplices sharing a vertex connect;
  /// every vertex is in from level 0). O(1).
  uint32_t Components(int64_t level) const;
  /// CGAL's solid components: interior triangles connected through shared edges. O(1).
  uint32_t SolidComponents(int64_t level) const;
  /// Components of the regularized complex at `level` (its b0: closed interior triangles connect
  /// through shared vertices; unlike SolidComponents, which needs a shared edge). O(1).
  uint32_t RegularizedComponents(int64_t level) const;
  /// Holes of the complex at `level` (its first Betti number b1: the bounded components of its
  /// complement; GENERAL: of the whole complex, REGULARIZED: of its closed interior triangles). O(1).
  uint32_t Holes(int64_t level, ClassifyMode mode) const;
  /// Smallest level at which every point lies on an interior triangle (CGAL's find_alpha_solid);
  /// nullopt when no level does (fewer than 3 points or collinear input).
  std::optional<int64_t> SolidLevel() const { return solid_level_; }
  /// Smallest level with at most `n` solid components and every point on a triangle (the sense of
  /// CGAL's find_optimal_alpha, as documented; CGAL's implementation answers one rank later), and,
  /// when `max_holes` is given, at most that many holes of the regularized complex.
  std::optional<int64_t> OptimalLevelRegularized(uint32_t n, std::optional<uint32_t> max_holes = std::nullopt) const;
  /// Smallest level with at most `n` components in the GENERAL sense (binary search), and, when
  /// `max_holes` is given, at most that many holes of the general complex (a scan from there: holes
  /// come and go as alpha grows).
  std::optional<int64_t> OptimalLevelGeneral(uint32_t n, std::optional<uint32_t> max_holes = std::nullopt) const;

  /// The complex at `level` as geometry input: triangles in, singular edges and isolated points
  /// (GENERAL mode only).
  ShapeComplex ComplexAt(int64_t level, ClassifyMode mode) const;

 private:
  AlphaFamilyParts parts_;
  std::optional<int64_t> solid_level_;
  double min_alpha_sq_ = 0.0;
};

/// The complex at a level as geometry input from the classes of every simplex at that level, as
/// ClassifyAll(level, mode, VertexRule::kReport) gives them: triangles INTERIOR, and in GENERAL mode
/// the SINGULAR edges and the distinct points whose vertex is SINGULAR. AlphaFamily::ComplexAt is
/// this; a resident family, whose classes are computed where its tables live, calls it too.
ShapeComplex ComplexFromClasses(absl::Span<const Point2> points, const HostVector<uint32_t>& representative,
                                const HostVector<std::array<uint32_t, 3>>& triangles,
                                const HostVector<std::array<uint32_t, 2>>& edges, const Classification& classes,
                                ClassifyMode mode);

}  // namespace galpha
