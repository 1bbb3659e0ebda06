// The rank tables of an alpha-shape family: what the engine computes after the triangulation
// (the report "Computing 2D Alpha Shapes Using GPU", chapter 3: spectrum, ranks, intervals, master
// list). Plain data shared by the engine backends and AlphaFamily. Semantics: docs/design.md,
// "Semantics".
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/base/hd.hpp"
#include "core/base/host_vector.hpp"

namespace galpha {

/// Rank r in 1..K names spectrum[r - 1]; rank 0 is alpha = 0. kNeverRank marks an interval end that
/// is never reached (infinity): a hull edge never becomes interior, a triangle of collinear points
/// is never born.
constexpr uint32_t kNeverRank = 0xFFFFFFFFu;

enum class SimplexKind : uint8_t { kVertex = 0, kEdge = 1, kTriangle = 2 };
/// Which end point of a simplex's intervals a master-list entry stands for.
enum class Endpoint : uint8_t { kRho = 0, kMuLow = 1, kMuHigh = 2 };

/// One master-list entry, packed in 64 bits so that the engine's array is the list itself and its
/// natural order is the order within a rank: kind (vertex < edge < triangle), then id, then end
/// point.
class MasterEntry {
 public:
  MasterEntry() = default;
  GALPHA_HD MasterEntry(uint32_t id, SimplexKind kind, Endpoint endpoint)
      : packed_((static_cast<uint64_t>(kind) << 34) | (static_cast<uint64_t>(id) << 2) |
                static_cast<uint64_t>(endpoint)) {}
  /// Vertex: input index; edge: edge id; triangle: triangle id.
  GALPHA_HD uint32_t id() const { return static_cast<uint32_t>(packed_ >> 2); }
  GALPHA_HD SimplexKind kind() const { return static_cast<SimplexKind>(packed_ >> 34); }
  GALPHA_HD Endpoint endpoint() const { return static_cast<Endpoint>(packed_ & 3); }
  GALPHA_HD uint64_t packed() const { return packed_; }

 private:
  uint64_t packed_ = 0;
};
static_assert(sizeof(MasterEntry) == sizeof(uint64_t), "master entries are packed");

/// How the exact order of the spectrum was decided, by comparison path (docs/design.md, "Exactness").
struct ComparisonCounts {
  /// Neighbouring pairs of the approximately sorted spectrum ordered by their certified keys alone.
  uint64_t filter = 0;
  /// Exact comparisons in bounded expansion arithmetic (the device's path on CUDA).
  uint64_t bounded_exact = 0;
  /// Exact comparisons that needed GMP rationals on the CPU (unbounded): the "CPU fallback".
  uint64_t cpu_fallback = 0;
};

/// The scale of AlphaRanks::area_units: the area of `units` is units * 2^unit_log2, and at every
/// level the exact area differs from the curve's by at most error_units units (gpu/alpha/area_curve.cuh).
struct AreaCurveScale {
  int32_t unit_log2 = 0;
  uint64_t error_units = 0;
};

struct AlphaRanks {
  /// The spectrum: the doubles nearest to the distinct exact births of triangles and unattached
  /// edges, strictly increasing in exact value (nearest doubles of neighbours may coincide only
  /// when both round to the same double).
  HostVector<double> spectrum;
  /// For every rank r, a simplex whose exact rho^2 is spectrum[r - 1]: id < #triangles is a
  /// triangle, otherwise the edge id - #triangles. Used to compare user thresholds exactly.
  HostVector<uint32_t> spectrum_simplex;

  HostVector<uint32_t> tri_rank;  ///< per triangle: rank of rho (its birth)
  /// Per edge: rank of rho when unattached, 0 when attached; mu-low (first incident triangle in,
  /// kNeverRank without triangles); mu-high (both in; kNeverRank on the hull).
  HostVector<uint32_t> edge_rho_rank, edge_mu_low, edge_mu_high;
  /// Per edge: its incident triangles (-1 where there is none).
  HostVector<std::array<int32_t, 2>> edge_triangles;
  /// Per input index (duplicates repeat their representative's values): mu-low (first incident
  /// edge in), mu-high (every incident edge interior; kNeverRank on the hull), and the rank at
  /// which the first incident triangle is in (CGAL's vertex rule and the regularized mode).
  HostVector<uint32_t> vertex_mu_low, vertex_mu_high, vertex_tri_low;

  /// Master list in CSR form: entries of rank r are master[master_begin[r] .. master_begin[r+1]),
  /// r in 0..K (rank 0 is always empty), ordered vertex < edge < triangle, then by id and end point.
  HostVector<uint32_t> master_begin;
  HostVector<MasterEntry> master;

  /// Per level 0..K: connected components of the complex (GENERAL: simplices sharing a vertex
  /// connect; every distinct point is in from level 0) and solid components (interior triangles
  /// connected through shared edges, CGAL's number_of_solid_components).
  HostVector<uint32_t> components, solid_components;
  /// Per level 0..K: holes (the first Betti number b1: bounded components of the complement) of
  /// the general complex; components (b0: triangles sharing a vertex connect) and holes of the
  /// regularized one (the closed triangles that are in).
  HostVector<uint32_t> holes, regularized_components, regularized_holes;
  /// Per level 0..K: the area of the regularized complex (the triangles that are in), in fixed
  /// point, with a certified error bound (area_scale); the last level's is the convex hull's.
  HostVector<uint64_t> area_units;
  AreaCurveScale area_scale;

  ComparisonCounts comparisons;
};

/// Birth rank of an edge: rho when unattached (rank > 0), else mu-low (its first incident
/// triangle). One rule for the host and the engine's functors.
GALPHA_HD inline uint32_t EdgeBirthRank(uint32_t rho_rank, uint32_t mu_low) {
  return rho_rank != 0 ? rho_rank : mu_low;
}
inline uint32_t EdgeBirthRank(const AlphaRanks& r, uint32_t e) {
  return EdgeBirthRank(r.edge_rho_rank[e], r.edge_mu_low[e]);
}

}  // namespace galpha
