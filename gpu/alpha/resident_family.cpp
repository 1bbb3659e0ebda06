#include "gpu/alpha/resident_family.hpp"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.hpp"
#include "core/family/area_ratio.hpp"
#include "core/family/classification_summary.hpp"
#include "core/family/simplex_threshold.hpp"
#include "gpu/alpha/alpha_build_parts.hpp"
#include "gpu/alpha/persistence_pairs.cuh"
#include "gpu/alpha/resident_backend.hpp"
#include "gpu/system/engine_status.hpp"

namespace galpha {

ResidentAlphaFamily::ResidentAlphaFamily(AlphaFamilyParts host, std::unique_ptr<detail::ResidentTables> tables)
    : host_(std::move(host)), tables_(std::move(tables)), mutex_(std::make_unique<absl::Mutex>()) {
  max_level_ = tables_->num_ranks();
  solid_level_ = tables_->solid_level();
  // 0.0 - w, as AlphaFamily: with a largest weight of 0 the bound is +0.
  if (weighted()) min_alpha_sq_ = 0.0 - *std::max_element(host_.weights.begin(), host_.weights.end());
}

ResidentAlphaFamily::ResidentAlphaFamily(ResidentAlphaFamily&&) noexcept = default;
ResidentAlphaFamily& ResidentAlphaFamily::operator=(ResidentAlphaFamily&&) noexcept = default;
ResidentAlphaFamily::~ResidentAlphaFamily() = default;

namespace {

template <typename T>
size_t VectorBytes(const HostVector<T>& v) {
  return v.capacity() * sizeof(T);
}

/// Runs `body` on the tables, one call at a time, with the engine's exceptions as a status.
template <typename Body>
absl::Status OnTables(absl::Mutex& mutex, const std::string& what, Body&& body) {
  absl::MutexLock lock(&mutex);
  return detail::RunEngine(what, body);
}

}  // namespace

size_t ResidentAlphaFamily::ResidentBytes() const {
  absl::MutexLock lock(mutex_.get());
  return tables_->Bytes();
}

bool ResidentAlphaFamily::TablesInDeviceMemory() const { return tables_->InDeviceMemory(); }

size_t ResidentAlphaFamily::HostBytes() const {
  return sizeof(*this) + VectorBytes(host_.points) + VectorBytes(host_.representative) + VectorBytes(host_.weights) +
         VectorBytes(host_.hidden) + VectorBytes(host_.triangles) + VectorBytes(host_.edges) +
         (host_.persistence ? host_.persistence->pairs.size() * sizeof(PersistencePair) : 0);
}

absl::StatusOr<int64_t> ResidentAlphaFamily::CountThresholds(const mpq_class& value, double lo, double hi,
                                                             bool strict) const {
  // Every spectrum value is the nearest double d of its exact threshold t, and the doubles do not
  // decrease with the rank. If d < lo for a double lo <= value, then t < lo too (t lies within
  // half a gap of d, below the next double, which is at most lo); if d > hi, t > hi. So only the
  // indices whose double lies in [lo, hi] are compared exactly, by a binary search (the exact
  // thresholds increase): one device search and a few reads, not the host's whole search.
  int64_t first = 0, last = 0;
  GALPHA_RETURN_IF_ERROR(OnTables(*mutex_, "finding the spectrum values near a threshold",
                                  [&] { std::tie(first, last) = tables_->SpectrumIndicesBetween(lo, hi); }));
  const SimplexGeometry geometry{host_.points, host_.weights, host_.triangles, host_.edges};
  while (first < last) {
    const int64_t mid = first + (last - first) / 2;
    uint32_t simplex = 0;
    GALPHA_RETURN_IF_ERROR(
        OnTables(*mutex_, "reading a spectrum simplex", [&] { simplex = tables_->SpectrumSimplex(mid); }));
    const int c = CompareSimplexThreshold(geometry, simplex, value);
    if (strict ? c < 0 : c <= 0) {
      first = mid + 1;
    } else {
      last = mid;
    }
  }
  return first;
}

absl::StatusOr<int64_t> ResidentAlphaFamily::LevelForAlphaSq(double alpha_sq) const {
  const LevelQuery query = StartLevelForAlphaSq(alpha_sq, min_alpha_sq_, max_level());
  if (query.answer) return *query.answer;
  return CountThresholds(query.alpha_sq, alpha_sq, alpha_sq, /*strict=*/false);
}

absl::StatusOr<int64_t> ResidentAlphaFamily::LevelForAlpha(double alpha) const {
  const LevelQuery query = StartLevelForAlpha(alpha, min_alpha_sq_, max_level());
  if (query.answer) return *query.answer;
  // The doubles around alpha^2 (>= 0): mpq's get_d truncates, which is rounding down here.
  double lo = DBL_MAX, hi = HUGE_VAL;
  if (query.alpha_sq <= mpq_class(DBL_MAX)) {
    lo = query.alpha_sq.get_d();
    hi = mpq_class(lo) == query.alpha_sq ? lo : std::nextafter(lo, HUGE_VAL);
  }
  return CountThresholds(query.alpha_sq, lo, hi, /*strict=*/false);
}

absl::StatusOr<int64_t> ResidentAlphaFamily::LevelForRank(int64_t rank) const { return LevelOfRank(rank, max_level()); }

absl::StatusOr<int64_t> ResidentAlphaFamily::RankLowerBound(double alpha_sq) const {
  if (std::isnan(alpha_sq) || (alpha_sq <= 0 && !weighted())) return 1;  // unweighted values are positive
  if (std::isinf(alpha_sq)) return alpha_sq > 0 ? max_level() + 1 : 1;
  GALPHA_ASSIGN_OR_RETURN(const int64_t below,
                          CountThresholds(mpq_class(alpha_sq), alpha_sq, alpha_sq, /*strict=*/true));
  return below + 1;
}

absl::StatusOr<Classification> ResidentAlphaFamily::ClassifyAll(int64_t level, ClassifyMode mode,
                                                                VertexRule rule) const {
  Classification c;
  c.vertices.resize(host_.points.size());
  c.edges.resize(host_.edges.size());
  c.triangles.resize(host_.triangles.size());
  GALPHA_RETURN_IF_ERROR(OnTables(*mutex_, absl::StrCat("classifying the family at level ", level), [&] {
    tables_->Classify(level, mode, rule, c.vertices.data(), c.edges.data(), c.triangles.data());
  }));
  return c;
}

absl::StatusOr<ShapeGeometry> ResidentAlphaFamily::ShapeAt(int64_t level, ClassifyMode mode) const {
  detail::ShapeBoundary found;
  GALPHA_RETURN_IF_ERROR(OnTables(*mutex_, absl::StrCat("finding the shape's boundary at level ", level),
                                  [&] { found = tables_->ShapeBoundaryAt(level, mode); }));
  // Each boundary edge directed as its complex triangle (counter-clockwise) runs along it.
  std::vector<ShapeBoundarySide> sides(found.edges.size());
  const int64_t count = static_cast<int64_t>(sides.size());
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < count; ++i) {
    const std::array<uint32_t, 2>& edge = host_.edges[found.edges[static_cast<size_t>(i)]];
    const std::array<uint32_t, 3>& tri = host_.triangles[found.inside[static_cast<size_t>(i)]];
    const int k = tri[0] == edge[0] ? 0 : tri[1] == edge[0] ? 1 : 2;
    const bool along = tri[static_cast<size_t>((k + 1) % 3)] == edge[1];
    sides[static_cast<size_t>(i)] = {along ? edge[0] : edge[1], along ? edge[1] : edge[0],
                                     found.piece[static_cast<size_t>(i)]};
  }
  std::vector<std::array<uint32_t, 2>> singular_edges;
  singular_edges.reserve(found.singular_edges.size());
  for (const uint32_t e : found.singular_edges) singular_edges.push_back(host_.edges[e]);
  std::vector<uint32_t> isolated;  // distinct points only, as ComplexFromClasses keeps them
  for (const uint32_t v : found.singular_vertices) {
    if (host_.representative[v] == v) isolated.push_back(v);
  }
  const double area = InteriorAreaOfFlagged(host_.points, host_.triangles, found.triangle_in_complex);
  return ShapeFromBoundary(host_.points, std::move(sides), area, singular_edges, isolated);
}

absl::StatusOr<TopologyAtLevel> ResidentAlphaFamily::TopologyAt(int64_t level) const {
  TopologyAtLevel at;
  if (level < 0) return at;
  detail::CurveValues values;
  GALPHA_RETURN_IF_ERROR(OnTables(*mutex_, absl::StrCat("reading the curves at level ", level),
                                  [&] { values = tables_->CurvesAt(std::min(level, max_level())); }));
  at.components = values.components;
  at.solid_components = values.solid_components;
  at.regularized_components = values.regularized_components;
  at.holes = values.holes;
  at.regularized_holes = values.regularized_holes;
  return at;
}

absl::StatusOr<std::vector<TopologyAtLevel>> ResidentAlphaFamily::TopologyBetween(int64_t first, int64_t last) const {
  std::vector<TopologyAtLevel> out;
  if (last < first) return out;
  out.resize(static_cast<size_t>(last - first + 1));
  // Levels below 0 are all zero; above K they repeat K's.
  const int64_t hi = std::min(last, max_level()), lo = std::min(std::max<int64_t>(first, 0), hi);
  std::vector<detail::CurveValues> values;
  if (last >= 0) {
    GALPHA_RETURN_IF_ERROR(OnTables(*mutex_, absl::StrCat("reading the curves at levels ", lo, "..", hi),
                                    [&] { values = tables_->CurvesBetween(lo, hi); }));
  }
  for (int64_t level = std::max<int64_t>(first, 0); level <= last; ++level) {
    const detail::CurveValues& v = values[static_cast<size_t>(std::min(level, hi) - lo)];
    out[static_cast<size_t>(level - first)] =
        TopologyAtLevel{v.components, v.solid_components, v.regularized_components, v.holes, v.regularized_holes};
  }
  return out;
}

absl::StatusOr<double> ResidentAlphaFamily::RegularizedAreaApprox(int64_t level) const {
  if (level < 0) return 0.0;
  detail::CurveValues values;
  GALPHA_RETURN_IF_ERROR(OnTables(*mutex_, absl::StrCat("reading the area curve at level ", level),
                                  [&] { values = tables_->CurvesAt(std::min(level, max_level())); }));
  return std::ldexp(static_cast<double>(values.area_units), host_.ranks.area_scale.unit_log2);
}

absl::StatusOr<int64_t> ResidentAlphaFamily::LevelForAreaRatio(double ratio) const {
  AreaCurveReader curve;
  curve.max_level = max_level();
  curve.complete = true;  // the build computes every level's value
  curve.error_units = host_.ranks.area_scale.error_units;
  curve.units_at = [this](int64_t level) -> absl::StatusOr<uint64_t> {
    detail::CurveValues values;
    GALPHA_RETURN_IF_ERROR(OnTables(*mutex_, absl::StrCat("reading the area curve at level ", level),
                                    [&] { values = tables_->CurvesAt(level); }));
    return values.area_units;
  };
  GALPHA_ASSIGN_OR_RETURN(const AreaRatioBracket bracket, BracketAreaRatio(curve, ratio));
  if (bracket.decided()) return bracket.high;
  GALPHA_ASSIGN_OR_RETURN(const AlphaFamily host, ToHostFamily());
  return LevelForAreaRatioWithin(host, ratio, bracket);
}

absl::StatusOr<PersistenceDiagram> ResidentAlphaFamily::Persistence() const {
  static_assert(sizeof(detail::EdgeIdx) == sizeof(host_.edges[0]));
  static_assert(sizeof(detail::TriIdx) == sizeof(host_.triangles[0]));
  const detail::PersistenceIn mesh{static_cast<uint32_t>(host_.points.size()),
                                   static_cast<uint32_t>(host_.edges.size()),
                                   static_cast<uint32_t>(host_.triangles.size()),
                                   reinterpret_cast<const detail::EdgeIdx*>(host_.edges.data()),
                                   nullptr,
                                   reinterpret_cast<const detail::TriIdx*>(host_.triangles.data()),
                                   nullptr,
                                   nullptr,
                                   nullptr,
                                   host_.representative.data(),
                                   host_.hidden.empty() ? nullptr : host_.hidden.data()};
  detail::PersistenceOut out;
  GALPHA_RETURN_IF_ERROR(OnTables(*mutex_,
                                  absl::StrCat("computing the persistence diagram of ", host_.points.size(), " points"),
                                  [&] { tables_->Persistence(mesh, /*host_finish=*/true, &out); }));
  return detail::TakeDiagram(&out);
}

absl::StatusOr<double> ResidentAlphaFamily::PublishedAlphaSq(int64_t level) const {
  if (level <= 0) return min_alpha_sq_;
  GALPHA_ASSIGN_OR_RETURN(const std::vector<double> value, Spectrum(level - 1, 1));
  if (value.size() != 1) return absl::OutOfRangeError(absl::StrCat("level ", level, " is above ", max_level()));
  return value[0];
}

absl::StatusOr<std::optional<int64_t>> ResidentAlphaFamily::OptimalLevelRegularized(
    uint32_t n, std::optional<uint32_t> max_holes) const {
  if (!solid_level_) return std::optional<int64_t>();
  std::optional<int64_t> level;
  GALPHA_RETURN_IF_ERROR(OnTables(*mutex_, "searching the solid components' curve", [&] {
    level = tables_->FirstLevelWhere(
        *solid_level_, detail::FamilyCurve::kSolidComponents, n,
        max_holes ? std::make_optional(std::make_pair(detail::FamilyCurve::kRegularizedHoles, *max_holes))
                  : std::nullopt);
  }));
  return level;
}

absl::StatusOr<std::optional<int64_t>> ResidentAlphaFamily::OptimalLevelGeneral(
    uint32_t n, std::optional<uint32_t> max_holes) const {
  // Components never increase with alpha, so the levels with at most n are a suffix, and the first
  // of them with at most max_holes holes is AlphaFamily's answer (its binary search, then scan).
  std::optional<int64_t> level;
  GALPHA_RETURN_IF_ERROR(OnTables(*mutex_, "searching the components' curve", [&] {
    level = tables_->FirstLevelWhere(
        0, detail::FamilyCurve::kComponents, n,
        max_holes ? std::make_optional(std::make_pair(detail::FamilyCurve::kHoles, *max_holes)) : std::nullopt);
  }));
  return level;
}

absl::StatusOr<std::vector<MasterEntry>> ResidentAlphaFamily::MasterList(int64_t rank) const {
  if (rank < 1 || rank > max_level()) return std::vector<MasterEntry>();
  GALPHA_ASSIGN_OR_RETURN(const std::vector<uint32_t> bounds, MasterBegins(rank, 2));
  return MasterEntries(bounds[0], bounds[1] - bounds[0]);
}

absl::StatusOr<std::vector<uint32_t>> ResidentAlphaFamily::MasterBegins(int64_t first_rank, int64_t count) const {
  if (first_rank < 0 || count < 0 || first_rank + count > max_level() + 2) {
    return absl::OutOfRangeError(absl::StrCat("master-list starts ", first_rank, "..", first_rank + count - 1,
                                              " are outside 0..", max_level() + 1));
  }
  std::vector<uint32_t> begins;
  GALPHA_RETURN_IF_ERROR(OnTables(*mutex_, "reading the master list's starts",
                                  [&] { begins = tables_->MasterBegins(first_rank, count); }));
  return begins;
}

absl::StatusOr<std::vector<MasterEntry>> ResidentAlphaFamily::MasterEntries(uint64_t position, uint64_t count) const {
  if (position + count > tables_->num_master()) {
    return absl::OutOfRangeError(absl::StrCat("master-list entries ", position, "..", position + count,
                                              " pass its end, ", tables_->num_master()));
  }
  std::vector<MasterEntry> entries;
  GALPHA_RETURN_IF_ERROR(
      OnTables(*mutex_, "reading master-list entries", [&] { entries = tables_->MasterEntries(position, count); }));
  return entries;
}

absl::StatusOr<std::vector<double>> ResidentAlphaFamily::Spectrum(int64_t first, int64_t count) const {
  std::vector<double> values;
  first = std::clamp<int64_t>(first, 0, max_level());
  count = std::clamp<int64_t>(count, 0, max_level() - first);
  GALPHA_RETURN_IF_ERROR(OnTables(*mutex_, "reading the spectrum", [&] { values = tables_->Spectrum(first, count); }));
  return values;
}

absl::StatusOr<AlphaFamily> ResidentAlphaFamily::ToHostFamily() const {
  AlphaFamilyParts parts = host_;
  GALPHA_RETURN_IF_ERROR(
      OnTables(*mutex_, "downloading a resident family", [&] { tables_->DownloadInto(&parts.ranks); }));
  return AlphaFamily(std::move(parts));
}

namespace {

absl::StatusOr<ResidentAlphaFamily> BuildResident(absl::Span<const Point2> points, absl::Span<const double> weights,
                                                  const BuildOptions& options) {
  AlphaFamilyParts parts;
  std::unique_ptr<detail::ResidentTables> tables;
  GALPHA_RETURN_IF_ERROR(detail::BuildFamilyParts(points, weights, options, /*resident=*/true, &parts, &tables));
  return ResidentAlphaFamily(std::move(parts), std::move(tables));
}

}  // namespace

absl::StatusOr<ResidentAlphaFamily> BuildResidentAlphaFamily(absl::Span<const Point2> points,
                                                             const BuildOptions& options) {
  return BuildResident(points, {}, options);
}

absl::StatusOr<ResidentAlphaFamily> BuildWeightedResidentAlphaFamily(absl::Span<const Point2> points,
                                                                     absl::Span<const double> weights,
                                                                     const BuildOptions& options) {
  GALPHA_ASSIGN_OR_RETURN(const absl::Span<const double> used, detail::WeightsToBuildWith(points, weights));
  return BuildResident(points, used, options);
}

}  // namespace galpha
