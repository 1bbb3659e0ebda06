#include "core/family/alpha_family.hpp"

#include <gmpxx.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/family/simplex_threshold.hpp"

namespace galpha {

const char* SimplexClassName(SimplexClass c) {
  switch (c) {
    case SimplexClass::kExterior:
      return "EXTERIOR";
    case SimplexClass::kSingular:
      return "SINGULAR";
    case SimplexClass::kRegular:
      return "REGULAR";
    case SimplexClass::kInterior:
      return "INTERIOR";
  }
  return "UNKNOWN";
}

AlphaFamily::AlphaFamily(AlphaFamilyParts parts) : parts_(std::move(parts)) {
  const AlphaRanks& r = parts_.ranks;
  const uint32_t num_tri = static_cast<uint32_t>(parts_.triangles.size());
  // Every point on a triangle from the largest first-triangle rank over the distinct points
  // (weighted: those that are vertices).
  if (num_tri > 0) {
    uint32_t worst = 0;
    for (uint32_t v = 0; v < parts_.points.size(); ++v) {
      if (parts_.representative[v] == v && !hidden(v)) worst = std::max(worst, r.vertex_tri_low[v]);
    }
    if (worst != kNeverRank) solid_level_ = worst;
  }
  // 0.0 - w, not -w: with a largest weight of 0 the bound is +0, as unweighted (-w would be -0).
  if (weighted()) min_alpha_sq_ = 0.0 - *std::max_element(parts_.weights.begin(), parts_.weights.end());
}

std::vector<uint32_t> AlphaFamily::HiddenPoints() const {
  std::vector<uint32_t> out;
  for (uint32_t v = 0; v < parts_.hidden.size(); ++v) {
    if (parts_.hidden[v] != 0) out.push_back(v);
  }
  return out;
}

namespace {

/// sign(exact threshold of `rank` - value), exactly.
int CompareRankWith(const AlphaFamilyParts& p, int64_t rank, const mpq_class& value) {
  return CompareSimplexThreshold(SimplexGeometry{p.points, p.weights, p.triangles, p.edges},
                                 p.ranks.spectrum_simplex[static_cast<size_t>(rank - 1)], value);
}

/// Number of ranks whose exact threshold is <= value (binary search; thresholds increase).
int64_t CountAtMost(const AlphaFamilyParts& p, const mpq_class& value) {
  int64_t lo = 0, hi = static_cast<int64_t>(p.ranks.spectrum.size());
  while (lo < hi) {
    const int64_t mid = lo + (hi - lo) / 2;  // rank mid + 1
    if (CompareRankWith(p, mid + 1, value) <= 0) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

}  // namespace

absl::StatusOr<int64_t> AlphaFamily::LevelForAlphaSq(double alpha_sq) const {
  const LevelQuery query = StartLevelForAlphaSq(alpha_sq, min_alpha_sq_, max_level());
  if (query.answer) return *query.answer;
  return CountAtMost(parts_, query.alpha_sq);
}

absl::StatusOr<int64_t> AlphaFamily::LevelForAlpha(double alpha) const {
  const LevelQuery query = StartLevelForAlpha(alpha, min_alpha_sq_, max_level());
  if (query.answer) return *query.answer;
  return CountAtMost(parts_, query.alpha_sq);
}

absl::StatusOr<int64_t> AlphaFamily::LevelForRank(int64_t rank) const { return LevelOfRank(rank, max_level()); }

int64_t AlphaFamily::RankLowerBound(double alpha_sq) const {
  if (std::isnan(alpha_sq) || (alpha_sq <= 0 && !weighted())) return 1;  // unweighted values are positive
  if (std::isinf(alpha_sq)) return alpha_sq > 0 ? max_level() + 1 : 1;
  // Ranks below the answer are those with threshold < alpha_sq.
  const mpq_class value(alpha_sq);
  int64_t lo = 0, hi = max_level();
  while (lo < hi) {
    const int64_t mid = lo + (hi - lo) / 2;
    if (CompareRankWith(parts_, mid + 1, value) < 0) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo + 1;
}

SimplexClass AlphaFamily::ClassifyTriangle(uint32_t t, int64_t level) const {
  return TriangleClassAt(parts_.ranks.tri_rank[t], level);
}

SimplexClass AlphaFamily::ClassifyEdge(uint32_t e, int64_t level, ClassifyMode mode) const {
  const AlphaRanks& r = parts_.ranks;
  return EdgeClassAt(r.edge_rho_rank[e], r.edge_mu_low[e], r.edge_mu_high[e], level, mode);
}

SimplexClass AlphaFamily::ClassifyVertex(uint32_t v, int64_t level, ClassifyMode mode, VertexRule rule) const {
  const AlphaRanks& r = parts_.ranks;
  return VertexClassAt(hidden(v), r.vertex_mu_low[v], r.vertex_mu_high[v], r.vertex_tri_low[v], level, mode, rule);
}

Classification AlphaFamily::ClassifyAll(int64_t level, ClassifyMode mode, VertexRule rule) const {
  Classification c;
  c.vertices.resize(parts_.points.size());
  c.edges.resize(parts_.edges.size());
  c.triangles.resize(parts_.triangles.size());
  // Independent per simplex: the host's cores share the work (a served family answers Classify
  // calls while other builds run, so the loops stay simple and static).
  const int64_t nv = static_cast<int64_t>(c.vertices.size()), ne = static_cast<int64_t>(c.edges.size()),
                nt = static_cast<int64_t>(c.triangles.size());
#pragma omp parallel
  {
#pragma omp for schedule(static) nowait
    for (int64_t v = 0; v < nv; ++v) c.vertices[v] = ClassifyVertex(static_cast<uint32_t>(v), level, mode, rule);
#pragma omp for schedule(static) nowait
    for (int64_t e = 0; e < ne; ++e) c.edges[e] = ClassifyEdge(static_cast<uint32_t>(e), level, mode);
#pragma omp for schedule(static) nowait
    for (int64_t t = 0; t < nt; ++t) c.triangles[t] = ClassifyTriangle(static_cast<uint32_t>(t), level);
  }
  return c;
}

absl::Span<const MasterEntry> AlphaFamily::MasterList(int64_t rank) const {
  const AlphaRanks& r = parts_.ranks;
  if (rank < 1 || rank > max_level()) return {};
  const uint32_t b = r.master_begin[static_cast<size_t>(rank)], e = r.master_begin[static_cast<size_t>(rank) + 1];
  return absl::MakeConstSpan(r.master.data() + b, e - b);
}

uint32_t AlphaFamily::Components(int64_t level) const {
  if (level < 0) return 0;
  return parts_.ranks.components[static_cast<size_t>(std::min(level, max_level()))];
}

uint32_t AlphaFamily::SolidComponents(int64_t level) const {
  if (level < 0) return 0;
  return parts_.ranks.solid_components[static_cast<size_t>(std::min(level, max_level()))];
}

uint32_t AlphaFamily::RegularizedComponents(int64_t level) const {
  if (level < 0) return 0;
  return parts_.ranks.regularized_components[static_cast<size_t>(std::min(level, max_level()))];
}

uint32_t AlphaFamily::Holes(int64_t level, ClassifyMode mode) const {
  if (level < 0) return 0;
  const HostVector<uint32_t>& curve =
      mode == ClassifyMode::kGeneral ? parts_.ranks.holes : parts_.ranks.regularized_holes;
  return curve[static_cast<size_t>(std::min(level, max_level()))];
}

std::optional<int64_t> AlphaFamily::OptimalLevelRegularized(uint32_t n, std::optional<uint32_t> max_holes) const {
  if (!solid_level_) return std::nullopt;
  // Solid components and holes are not monotone in alpha: a scan from the level where every point
  // is covered (O(K), once per query).
  const AlphaRanks& r = parts_.ranks;
  for (int64_t level = *solid_level_; level <= max_level(); ++level) {
    const auto at = static_cast<size_t>(level);
    if (r.solid_components[at] <= n && (!max_holes || r.regularized_holes[at] <= *max_holes)) return level;
  }
  return std::nullopt;
}

std::optional<int64_t> AlphaFamily::OptimalLevelGeneral(uint32_t n, std::optional<uint32_t> max_holes) const {
  // Components never increase with alpha: binary search for the first level with at most n.
  const AlphaRanks& r = parts_.ranks;
  if (r.components.back() > n) return std::nullopt;
  const auto it = std::partition_point(r.components.begin(), r.components.end(), [n](uint32_t c) { return c > n; });
  int64_t level = it - r.components.begin();
  if (!max_holes) return level;
  // Holes do not shrink monotonically (a loop closes, then fills): the first level from there.
  for (; level <= max_level(); ++level) {
    if (r.holes[static_cast<size_t>(level)] <= *max_holes) return level;
  }
  return std::nullopt;
}

ShapeComplex AlphaFamily::ComplexAt(int64_t level, ClassifyMode mode) const {
  return ComplexFromClasses(parts_.points, parts_.representative, parts_.triangles, parts_.edges,
                            ClassifyAll(level, mode, VertexRule::kReport), mode);
}

ShapeComplex ComplexFromClasses(absl::Span<const Point2> points, const HostVector<uint32_t>& representative,
                                const HostVector<std::array<uint32_t, 3>>& triangles,
                                const HostVector<std::array<uint32_t, 2>>& edges, const Classification& classes,
                                ClassifyMode mode) {
  ShapeComplex complex;
  complex.points = points;
  for (uint32_t t = 0; t < triangles.size(); ++t) {
    if (classes.triangles[t] == SimplexClass::kInterior) complex.triangles.push_back(triangles[t]);
  }
  if (mode == ClassifyMode::kGeneral) {
    for (uint32_t e = 0; e < edges.size(); ++e) {
      if (classes.edges[e] == SimplexClass::kSingular) complex.singular_edges.push_back(edges[e]);
    }
    for (uint32_t v = 0; v < points.size(); ++v) {
      if (representative[v] == v && classes.vertices[v] == SimplexClass::kSingular)
        complex.isolated_points.push_back(v);
    }
  }
  return complex;
}

namespace {
template <typename T>
size_t VectorBytes(const HostVector<T>& v) {
  return v.capacity() * sizeof(T);
}
}  // namespace

size_t AlphaFamily::HostBytes() const {
  const AlphaRanks& r = parts_.ranks;
  return sizeof(*this) + VectorBytes(parts_.points) + VectorBytes(parts_.representative) + VectorBytes(parts_.weights) +
         VectorBytes(parts_.hidden) + VectorBytes(parts_.triangles) + VectorBytes(parts_.edges) +
         VectorBytes(r.spectrum) + VectorBytes(r.spectrum_simplex) + VectorBytes(r.tri_rank) +
         VectorBytes(r.edge_rho_rank) + VectorBytes(r.edge_mu_low) + VectorBytes(r.edge_mu_high) +
         VectorBytes(r.edge_triangles) + VectorBytes(r.vertex_mu_low) + VectorBytes(r.vertex_mu_high) +
         VectorBytes(r.vertex_tri_low) + VectorBytes(r.master_begin) + VectorBytes(r.master) +
         VectorBytes(r.components) + VectorBytes(r.solid_components) + VectorBytes(r.holes) +
         VectorBytes(r.regularized_components) + VectorBytes(r.regularized_holes) + VectorBytes(r.area_units) +
         // The diagram's array is reserved for the most pairs there could be and never touched
         // beyond those there are (core/family/persistence_pair.hpp): only those are resident.
         (parts_.persistence ? parts_.persistence->pairs.size() * sizeof(PersistencePair) : 0);
}

}  // namespace galpha
