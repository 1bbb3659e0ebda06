// ResidentAlphaFamily: a family whose rank tables stay where the engine built them (device memory
// after a CUDA build; on the OpenMP backend the host memory the build computed them in, with no
// second copy), queryable at once: classification, curves, optimal levels, master-list and
// spectrum slices run there and only their answers come back (issue 16; docs/design.md,
// "Engine API"). The points and the mesh (triangles, edges, duplicate map) are kept on the
// host, where geometry and exact threshold comparisons read them. ToHostFamily() gives the same
// family as BuildAlphaFamily, array for array.
#pragma once

#include <gmpxx.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/types/span.h"
#include "core/family/alpha_family.hpp"
#include "core/geometry/shape.hpp"
#include "gpu/alpha/alpha_engine.hpp"

namespace galpha {

namespace detail {
class ResidentTables;
}

/// The curves' values at one level (AlphaFamily's Components, SolidComponents,
/// RegularizedComponents and Holes).
struct TopologyAtLevel {
  uint32_t components = 0, solid_components = 0, regularized_components = 0;
  uint32_t holes = 0, regularized_holes = 0;
};

class ResidentAlphaFamily {
 public:
  ResidentAlphaFamily(AlphaFamilyParts host, std::unique_ptr<detail::ResidentTables> tables);
  ResidentAlphaFamily(ResidentAlphaFamily&&) noexcept;
  ResidentAlphaFamily& operator=(ResidentAlphaFamily&&) noexcept;
  ~ResidentAlphaFamily();

  const HostVector<Point2>& points() const { return host_.points; }
  const HostVector<uint32_t>& representative() const { return host_.representative; }
  uint32_t num_unique() const { return host_.num_unique; }
  const HostVector<std::array<uint32_t, 3>>& triangles() const { return host_.triangles; }
  const HostVector<std::array<uint32_t, 2>>& edges() const { return host_.edges; }
  bool weighted() const { return !host_.weights.empty(); }
  /// Weighted: every input point's weight, and 1 for each hidden point (both empty unweighted).
  const HostVector<double>& weights() const { return host_.weights; }
  const HostVector<uint8_t>& hidden_flags() const { return host_.hidden; }
  const BuildReport& report() const { return host_.report; }
  const ComparisonCounts& comparisons() const { return host_.ranks.comparisons; }
  /// K, the number of spectrum values (the highest level).
  int64_t max_level() const { return max_level_; }
  double min_alpha_sq() const { return min_alpha_sq_; }
  std::optional<int64_t> SolidLevel() const { return solid_level_; }

  /// Bytes the rank tables hold where they live (device memory after a CUDA build).
  size_t ResidentBytes() const;
  /// Whether the tables are in device memory (after a CUDA build) rather than the host's.
  bool TablesInDeviceMemory() const;
  /// Host bytes: the points, weights and mesh.
  size_t HostBytes() const;

  /// Levels as AlphaFamily resolves them (exactly; the same errors).
  absl::StatusOr<int64_t> LevelForAlphaSq(double alpha_sq) const;
  absl::StatusOr<int64_t> LevelForAlpha(double alpha) const;
  absl::StatusOr<int64_t> LevelForRank(int64_t rank) const;
  /// CGAL's alpha_lower_bound (AlphaFamily::RankLowerBound).
  absl::StatusOr<int64_t> RankLowerBound(double alpha_sq) const;

  /// AlphaFamily::ClassifyAll, computed where the tables live.
  absl::StatusOr<Classification> ClassifyAll(int64_t level, ClassifyMode mode, VertexRule rule) const;
  /// AssembleShape(ComplexAt(level, mode)) of the host family, the same ShapeGeometry: the
  /// boundary, the pieces and the singular simplices are found where the tables live, and only
  /// they and the complex's triangle flags come back; the host traces the rings from the boundary
  /// (core/geometry/shape.hpp, ShapeFromBoundary) and adds the area in triangle order.
  absl::StatusOr<ShapeGeometry> ShapeAt(int64_t level, ClassifyMode mode) const;
  /// The curves at `level` (below 0: all zero; above K: K's).
  absl::StatusOr<TopologyAtLevel> TopologyAt(int64_t level) const;
  /// The same at every level of first..last, in one download.
  absl::StatusOr<std::vector<TopologyAtLevel>> TopologyBetween(int64_t first, int64_t last) const;
  /// AlphaFamily's RegularizedAreaApprox (core/family/area_ratio.hpp): the area curve's value at
  /// `level` as a double; at K, the convex hull's.
  absl::StatusOr<double> RegularizedAreaApprox(int64_t level) const;
  /// LevelForAreaRatio (core/family/area_ratio.hpp): the certified curve is read where it lives
  /// (a few values); a ratio it cannot decide reads the tables into host memory for the exact areas.
  absl::StatusOr<int64_t> LevelForAreaRatio(double ratio) const;
  /// PublishedAlphaSq (core/family/threshold.hpp): spectrum[level - 1], min_alpha_sq at or below 0.
  absl::StatusOr<double> PublishedAlphaSq(int64_t level) const;
  /// AlphaFamily::OptimalLevelRegularized and OptimalLevelGeneral.
  absl::StatusOr<std::optional<int64_t>> OptimalLevelRegularized(
      uint32_t n, std::optional<uint32_t> max_holes = std::nullopt) const;
  absl::StatusOr<std::optional<int64_t>> OptimalLevelGeneral(uint32_t n,
                                                             std::optional<uint32_t> max_holes = std::nullopt) const;
  /// AlphaFamily::MasterList (empty outside 1..K).
  absl::StatusOr<std::vector<MasterEntry>> MasterList(int64_t rank) const;
  /// ranks().master_begin[first_rank, first_rank + count) (ranks 0..K+1) and master[position,
  /// position + count): a master list read in pieces.
  absl::StatusOr<std::vector<uint32_t>> MasterBegins(int64_t first_rank, int64_t count) const;
  absl::StatusOr<std::vector<MasterEntry>> MasterEntries(uint64_t position, uint64_t count) const;
  /// spectrum[first, first + count) clipped to 0..K-1.
  absl::StatusOr<std::vector<double>> Spectrum(int64_t first, int64_t count) const;

  /// The persistence diagram (ComputePersistenceOnBackend's, pair for pair) computed where the
  /// tables live: on CUDA only the mesh is uploaded for it.
  absl::StatusOr<PersistenceDiagram> Persistence() const;

  /// The same family in host memory: the tables downloaded, the host arrays copied.
  absl::StatusOr<AlphaFamily> ToHostFamily() const;

 private:
  /// Ranks (0..K) whose exact threshold is < value (`strict`) or <= value; `lo` and `hi` are doubles
  /// with lo <= value <= hi.
  absl::StatusOr<int64_t> CountThresholds(const mpq_class& value, double lo, double hi, bool strict) const;

  AlphaFamilyParts host_;  // every array but the rank tables'; ranks: comparisons and area scale only
  std::unique_ptr<detail::ResidentTables> tables_;
  std::unique_ptr<absl::Mutex> mutex_;  // the tables' system runs one call at a time
  int64_t max_level_ = 0;
  double min_alpha_sq_ = 0.0;
  std::optional<int64_t> solid_level_;
};

/// Builds the family as BuildAlphaFamily does and keeps its rank tables where they were built.
/// On CUDA the build runs on a stream of the family's own: a BuildOptions::cuda_stream is refused
/// (InvalidArgument).
absl::StatusOr<ResidentAlphaFamily> BuildResidentAlphaFamily(absl::Span<const Point2> points,
                                                             const BuildOptions& options = {});
/// The weighted family (BuildWeightedAlphaFamily), resident.
absl::StatusOr<ResidentAlphaFamily> BuildWeightedResidentAlphaFamily(absl::Span<const Point2> points,
                                                                     absl::Span<const double> weights,
                                                                     const BuildOptions& options = {});

}  // namespace galpha
