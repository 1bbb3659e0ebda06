// The seam between ResidentAlphaFamily (resident_family.hpp) and the backend that keeps a family's
// rank tables where they were built (device memory on CUDA; on OpenMP the host memory the build
// computed them in, without a second copy): the queries that read them run there and only their
// answers come back. Plain C++ and std types only; implemented by resident_arrays.cuh.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "core/family/alpha_ranks.hpp"
#include "core/family/simplex_class.hpp"

namespace galpha::detail {

/// The per-level curves of a family (AlphaRanks' arrays of K + 1 values).
enum class FamilyCurve { kComponents, kSolidComponents, kHoles, kRegularizedComponents, kRegularizedHoles };

/// Every curve's value at one level.
struct CurveValues {
  uint32_t components = 0, solid_components = 0, holes = 0, regularized_components = 0, regularized_holes = 0;
  uint64_t area_units = 0;
};

/// The boundary of the shape at one level (ResidentTables::ShapeBoundaryAt), by ids: what the
/// host needs to trace the shape's rings (core/geometry/shape.hpp, ShapeFromBoundary).
struct ShapeBoundary {
  /// Each edge with a complex triangle on exactly one side: the edge, that triangle, and the
  /// triangle's piece (the smallest triangle id of its edge-connected piece), in edge order.
  std::vector<uint32_t> edges, inside, piece;
  /// Per triangle, 1 when it is in the complex (INTERIOR): the shape's area adds those.
  std::vector<uint8_t> triangle_in_complex;
  /// GENERAL mode: the SINGULAR edges, and the SINGULAR input points (duplicates among them).
  std::vector<uint32_t> singular_edges, singular_vertices;
};

struct PersistenceIn;
struct PersistenceOut;

/// The rank tables of one family where its backend keeps them. Not thread-safe: the owner
/// serializes calls. Every call may throw EngineError (or a Thrust/std exception).
class ResidentTables {
 public:
  virtual ~ResidentTables() = default;

  /// Bytes the tables hold where they live, and whether that is device memory (not the host's).
  virtual size_t Bytes() const = 0;
  virtual bool InDeviceMemory() const = 0;
  /// K, the number of spectrum values, and the master list's length.
  virtual uint32_t num_ranks() const = 0;
  virtual uint64_t num_master() const = 0;
  /// The smallest level at which every distinct point (weighted: not hidden) lies on a triangle;
  /// nullopt when none does (AlphaFamily::SolidLevel).
  virtual std::optional<int64_t> solid_level() const = 0;

  /// Classes at `level` (-1..K) of every input point, edge and triangle, into host arrays of
  /// n, #edges and #triangles entries (SimplexClass values).
  virtual void Classify(int64_t level, ClassifyMode mode, VertexRule rule, SimplexClass* vertices, SimplexClass* edges,
                        SimplexClass* triangles) = 0;
  /// The shape's boundary at `level` (-1..K) in `mode`, found where the tables live: only the
  /// boundary, the complex's triangle flags and the singular simplices come back, not every class.
  virtual ShapeBoundary ShapeBoundaryAt(int64_t level, ClassifyMode mode) = 0;
  /// The curves at `level` (0..K).
  virtual CurveValues CurvesAt(int64_t level) = 0;
  /// The curves at levels first..last (within 0..K), one entry a level.
  virtual std::vector<CurveValues> CurvesBetween(int64_t first, int64_t last) = 0;
  /// The first level in from..K where curve `a` is at most `max_a` and, when given, curve `b` at
  /// most `max_b`; nullopt when none is.
  virtual std::optional<int64_t> FirstLevelWhere(int64_t from, FamilyCurve a, uint32_t max_a,
                                                 std::optional<std::pair<FamilyCurve, uint32_t>> b) = 0;
  /// master_begin[first_rank, first_rank + count) (ranks 0..K+1): where each rank's entries start.
  virtual std::vector<uint32_t> MasterBegins(int64_t first_rank, int64_t count) = 0;
  /// master[position, position + count).
  virtual std::vector<MasterEntry> MasterEntries(uint64_t position, uint64_t count) = 0;
  /// spectrum[first, first + count) (indices 0..K-1).
  virtual std::vector<double> Spectrum(int64_t first, int64_t count) = 0;
  /// The simplex whose exact threshold is spectrum value `index` (0..K-1): a triangle id below the
  /// triangle count, else the edge id plus it.
  virtual uint32_t SpectrumSimplex(int64_t index) = 0;
  /// [first, last): the spectrum indices whose nearest double lies in [lo, hi] (the values are
  /// non-decreasing).
  virtual std::pair<int64_t, int64_t> SpectrumIndicesBetween(double lo, double hi) = 0;
  /// Every table into `out`'s arrays (the host form of the family); `out`'s comparison counts and
  /// area scale are left as they are.
  virtual void DownloadInto(AlphaRanks* out) = 0;
  /// The persistence diagram (persistence_pairs.cuh) from the tables where they live and the mesh
  /// in `mesh` (host arrays: edges, triangles, representatives, hidden flags; its table pointers
  /// are not read): only the mesh is uploaded.
  virtual void Persistence(const PersistenceIn& mesh, bool host_finish, PersistenceOut* out) = 0;
};

}  // namespace galpha::detail
