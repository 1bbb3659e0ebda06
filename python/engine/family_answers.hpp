// The answers of galpha._engine.Family in plain C++ (no Python, so they run with the GIL
// released): the galpha service's semantics (server/query_answers.cpp) over a FamilyState, the same
// threshold resolution, bounds, errors and orders, without the wire format. Results are
// std::vectors that the binding hands to NumPy without copying (numpy_arrays.hpp).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "absl/strings/string_view.h"

#include "absl/status/statusor.h"
#include "core/family/alpha_family.hpp"
#include "core/family/classification_summary.hpp"
#include "core/family/threshold.hpp"
#include "core/geometry/shape.hpp"
#include "core/geometry/shape_holes.hpp"
#include "python/engine/family_state.hpp"

namespace galpha::python {

/// Thresholds and their resolution are the core's (core/family/threshold.hpp), as the service's.
using Threshold = galpha::Threshold;
using ResolvedLevel = galpha::ResolvedThreshold;

/// "alpha_sq", "alpha" or "rank"; InvalidArgument otherwise.
absl::StatusOr<Threshold::Kind> ParseThresholdKind(absl::string_view kind);
/// "general" or "regularized"; InvalidArgument otherwise.
absl::StatusOr<ClassifyMode> ParseMode(absl::string_view mode);
/// "report" or "cgal"; InvalidArgument otherwise.
absl::StatusOr<VertexRule> ParseVertexRule(absl::string_view rule);

/// core/family/threshold.hpp's ResolveThreshold, under the name the answers use.
inline absl::StatusOr<ResolvedLevel> ResolveLevel(const AlphaFamily& family, const Threshold& threshold) {
  return ResolveThreshold(family, threshold);
}

/// Classes as the wire protocol numbers them: EXTERIOR = 1 .. INTERIOR = 4.
inline uint8_t WireClass(SimplexClass c) { return static_cast<uint8_t>(static_cast<int>(c) + 1); }

/// Every simplex's class at one threshold. Without `filtered` the simplices are the state's
/// canonical arrays (DistinctVertices, EdgeVerticesInOrder, TriangleVerticesInOrder) and only the
/// classes are here; with it (non_exterior_only) the kept simplices are copied too.
struct ClassifyAnswer {
  ResolvedLevel level;
  ClassificationSummary counts;
  uint32_t components = 0;
  uint32_t solid_components = 0;
  /// b1 of the complex in the request's mode.
  uint32_t holes = 0;
  /// The convex hull's area, from the area curve (core/family/area_ratio.hpp).
  double hull_area = 0.0;
  bool summary_only = false;
  bool filtered = false;
  std::vector<uint32_t> vertices, edges, triangles;  // only when filtered
  std::vector<uint8_t> vertex_classes, edge_classes, triangle_classes;
};
absl::StatusOr<ClassifyAnswer> AnswerClassify(const FamilyState& state, const Threshold& threshold, ClassifyMode mode,
                                              VertexRule rule, bool non_exterior_only, bool summary_only);

/// The shape at one threshold (core/geometry/shape.hpp's AssembleShape of the complex there), with
/// the holes whose area is below min_hole_area filled as the service's Shape fills them
/// (core/geometry/shape_holes.hpp's FillHolesSmallerThan; 0 keeps every hole). InvalidArgument for
/// a negative or NaN min_hole_area, by the service's message.
absl::StatusOr<ShapeGeometry> AnswerShape(const AlphaFamily& family, const Threshold& threshold, ClassifyMode mode,
                                          double min_hole_area = 0.0);

/// Every hole of the regularized shape at one threshold with an area of at least min_area, largest
/// first, as `alphactl holes` lists them (core/geometry/shape_holes.hpp's ListHoles: rings
/// clockwise, as AssembleShape writes them; areas by RingArea). InvalidArgument for a negative or
/// NaN min_area.
absl::StatusOr<std::vector<ShapeHole>> AnswerHoles(const AlphaFamily& family, const Threshold& threshold,
                                                   double min_area);

/// Spectrum ranks first_rank .. first_rank + count - 1, clipped at K, as [begin, end) positions in
/// family.spectrum(). InvalidArgument for first_rank outside 1..K+1 or a negative count.
absl::StatusOr<std::pair<size_t, size_t>> AnswerSpectrumRange(const AlphaFamily& family, int64_t first_rank,
                                                              int64_t count);

/// CGAL's alpha_lower_bound (the first rank whose threshold is >= alpha_sq; K + 1 when none is).
/// InvalidArgument for NaN.
absl::StatusOr<int64_t> AnswerRankLowerBound(const AlphaFamily& family, double alpha_sq);

/// Master-list entries of ranks first_rank .. last_rank (last_rank 0: first_rank alone), in rank
/// order; vertex_indices holds 1, 2 or 3 ascending indices per entry by its kind. Kinds and end
/// points are the wire's numbers (VERTEX = 1, EDGE, TRIANGLE; RHO = 1, MU_LOW, MU_HIGH).
struct MasterListAnswer {
  std::vector<int64_t> ranks;
  std::vector<uint8_t> kinds, endpoints;
  std::vector<uint32_t> vertex_indices;
};
absl::StatusOr<MasterListAnswer> AnswerMasterList(const AlphaFamily& family, int64_t first_rank, int64_t last_rank);

/// Components and solid components at levels first_level .. last_level (within 0..K).
struct ComponentsAnswer {
  int64_t first_level = 0;
  std::vector<uint32_t> components, solid_components;
};
absl::StatusOr<ComponentsAnswer> AnswerComponents(const AlphaFamily& family, int64_t first_level, int64_t last_level);

/// The Betti numbers at levels first_level .. last_level (within 0..K), as the service's Betti: b0
/// and b1 of the general complex and of the regularized one. O(1) a level.
struct BettiAnswer {
  int64_t first_level = 0;
  std::vector<uint32_t> components, holes, regularized_components, regularized_holes;
};
absl::StatusOr<BettiAnswer> AnswerBetti(const AlphaFamily& family, int64_t first_level, int64_t last_level);

/// The smallest rank with at most N components (and, when given, at most H holes), in the
/// regularized sense and the general one.
struct OptimalLevel {
  int64_t rank = 0;
  double alpha_sq = 0.0;
  uint32_t components = 0;
  uint32_t holes = 0;
};
struct OptimalAnswer {
  std::optional<OptimalLevel> regularized, general;
};
/// InvalidArgument unless 1 <= max_components <= 2^32 - 1 and 0 <= max_holes <= 2^32 - 1 (the
/// wire's uint32s).
absl::StatusOr<OptimalAnswer> AnswerOptimal(const AlphaFamily& family, int64_t max_components,
                                            std::optional<int64_t> max_holes = std::nullopt);

/// The persistence pairs of one dimension as the service's Persistence stream lists them: ranks
/// (death -1 when essential), published values (alpha_sq; death +infinity when essential), and the
/// creator's and killer's vertices, ascending within a simplex (dimension + 1 and dimension + 2 a
/// pair; 0xFFFFFFFF for an essential class's killer).
struct PersistencePairs {
  std::vector<int64_t> birth_rank, death_rank;
  std::vector<double> birth_alpha_sq, death_alpha_sq;
  std::vector<uint32_t> creator_vertices, killer_vertices;
};
/// The diagram (core/family/persistence.hpp, from the state's canonical orders) filtered like the
/// service's Persistence: only the dimensions asked for (an empty list: both), only pairs whose
/// death_alpha_sq - birth_alpha_sq is at least min_persistence (essential classes always). A
/// dimension not asked for is empty. InvalidArgument for a dimension other than 0 or 1, or a
/// negative or NaN min_persistence. O(n log n).
absl::StatusOr<std::array<PersistencePairs, 2>> AnswerPersistence(const FamilyState& state,
                                                                  const std::vector<int64_t>& dimensions,
                                                                  double min_persistence);

}  // namespace galpha::python
