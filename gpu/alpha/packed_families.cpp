// BuildAlphaFamilies(): validation, the packed build on one backend (packed_family.cuh), then each
// set's family cut out of the packed one on the host, one set a thread.
#include <algorithm>
#include <array>
#include <cstdint>
#include <new>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.hpp"
#include "gpu/alpha/alpha_backend.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gpu/system/backend.hpp"
#include "gpu/system/engine_status.hpp"

namespace galpha {
namespace {

/// Where one set lies in the packed family: its input indices, triangles, edges and ranks (the
/// packed ranks R + 1..R + K are its 1..K).
struct SetRuns {
  uint32_t point_begin, point_end;
  uint32_t tri_begin, tri_end;
  uint32_t edge_begin, edge_end;
  uint32_t rank_base, num_ranks;
  uint32_t num_tri_all;  // the packed family's triangles: its simplex ids of edges start there

  /// A packed rank as the set's: 0 (none: attached) and kNeverRank stay.
  uint32_t Rank(uint32_t packed) const { return packed == 0 || packed == kNeverRank ? packed : packed - rank_base; }
  /// A packed simplex id (triangles, then edges) as the set's.
  uint32_t SimplexId(uint32_t id) const {
    return id < num_tri_all ? id - tri_begin : (id - num_tri_all - edge_begin) + (tri_end - tri_begin);
  }
};

template <class T, class F>
void CopyRange(const HostVector<T>& from, uint32_t begin, uint32_t end, HostVector<T>* to, F convert) {
  to->resize(end - begin);
  for (uint32_t i = begin; i < end; ++i) (*to)[i - begin] = convert(from[i]);
}

/// Set `s`'s family parts, cut out of the packed family `all` (see packed_family.cuh for why each
/// table is the set's own).
void CutOutSet(const detail::PackedFamilyOutput& packed, const SetRuns& r, size_t s, absl::Span<const Point2> points,
               const char* backend, AlphaFamilyParts* parts) {
  const detail::FamilyOutput& all = packed.all;
  const AlphaRanks& a = all.ranks;
  const uint32_t pb = r.point_begin;
  parts->report.backend = backend;
  parts->points.resize(r.point_end - pb);
  std::copy(points.begin() + pb, points.begin() + r.point_end, parts->points.data());
  parts->representative.resize(r.point_end - pb);
  for (uint32_t i = pb; i < r.point_end; ++i) {
    parts->representative[i - pb] = all.representative[i] - pb;
    if (all.representative[i] == i) ++parts->num_unique;
  }
  CopyRange(all.triangles, r.tri_begin, r.tri_end, &parts->triangles, [pb](const std::array<uint32_t, 3>& t) {
    return std::array<uint32_t, 3>{t[0] - pb, t[1] - pb, t[2] - pb};
  });
  CopyRange(all.edges, r.edge_begin, r.edge_end, &parts->edges, [pb](const std::array<uint32_t, 2>& e) {
    return std::array<uint32_t, 2>{e[0] - pb, e[1] - pb};
  });

  AlphaRanks& ranks = parts->ranks;
  const uint32_t rb = r.rank_base, re = r.rank_base + r.num_ranks;
  auto same = [](auto v) { return v; };
  auto rank = [&r](uint32_t v) { return r.Rank(v); };
  CopyRange(a.spectrum, rb, re, &ranks.spectrum, same);
  CopyRange(a.spectrum_simplex, rb, re, &ranks.spectrum_simplex, [&r](uint32_t id) { return r.SimplexId(id); });
  CopyRange(a.tri_rank, r.tri_begin, r.tri_end, &ranks.tri_rank, rank);
  CopyRange(a.edge_rho_rank, r.edge_begin, r.edge_end, &ranks.edge_rho_rank, rank);
  CopyRange(a.edge_mu_low, r.edge_begin, r.edge_end, &ranks.edge_mu_low, rank);
  CopyRange(a.edge_mu_high, r.edge_begin, r.edge_end, &ranks.edge_mu_high, rank);
  const auto tb = static_cast<int32_t>(r.tri_begin);
  CopyRange(a.edge_triangles, r.edge_begin, r.edge_end, &ranks.edge_triangles, [tb](const std::array<int32_t, 2>& t) {
    return std::array<int32_t, 2>{t[0] < 0 ? t[0] : t[0] - tb, t[1] < 0 ? t[1] : t[1] - tb};
  });
  CopyRange(a.vertex_mu_low, pb, r.point_end, &ranks.vertex_mu_low, rank);
  CopyRange(a.vertex_mu_high, pb, r.point_end, &ranks.vertex_mu_high, rank);
  CopyRange(a.vertex_tri_low, pb, r.point_end, &ranks.vertex_tri_low, rank);

  // The master list: packed rank R + l is the set's rank l (rank 0 is empty in both).
  ranks.master_begin.resize(size_t{r.num_ranks} + 2);
  const uint32_t first_entry = a.master_begin[rb + 1];
  ranks.master_begin[0] = 0;
  for (uint32_t l = 1; l <= r.num_ranks + 1; ++l) ranks.master_begin[l] = a.master_begin[rb + l] - first_entry;
  CopyRange(a.master, first_entry, a.master_begin[re + 1], &ranks.master, [&r](const MasterEntry& m) {
    const uint32_t shift = m.kind() == SimplexKind::kVertex
                               ? r.point_begin
                               : (m.kind() == SimplexKind::kEdge ? r.edge_begin : r.tri_begin);
    return MasterEntry(m.id() - shift, m.kind(), m.endpoint());
  });

  // The curves: the packed levels R..R + K, less level R, plus the set's own level 0.
  auto curve = [&](const HostVector<uint32_t>& from, HostVector<uint32_t>* to, uint32_t level0) {
    to->resize(size_t{r.num_ranks} + 1);
    for (uint32_t l = 0; l <= r.num_ranks; ++l) (*to)[l] = from[rb + l] - from[rb] + level0;
  };
  curve(a.components, &ranks.components, parts->num_unique);  // every distinct point, apart
  curve(a.solid_components, &ranks.solid_components, 0);
  curve(a.holes, &ranks.holes, 0);
  curve(a.regularized_components, &ranks.regularized_components, 0);
  curve(a.regularized_holes, &ranks.regularized_holes, 0);
  ranks.area_units.resize(size_t{r.num_ranks} + 1);
  for (uint32_t l = 0; l <= r.num_ranks; ++l) ranks.area_units[l] = a.area_units[rb + l] - a.area_units[rb];
  ranks.area_scale = packed.set_area_scale[s];
}

/// Cuts every set's family out of the packed one, the sets shared out over the host's cores. False
/// when the host's memory ran out.
bool SplitFamilies(absl::Span<const Point2> points, absl::Span<const uint32_t> set_begin,
                   const detail::PackedFamilyOutput& packed, const char* backend,
                   std::vector<std::optional<AlphaFamily>>* families) {
  const size_t num_sets = set_begin.size() - 1;
  const auto num_tri_all = static_cast<uint32_t>(packed.all.triangles.size());
  int out_of_memory = 0;
#pragma omp parallel for schedule(dynamic, 16)
  for (int64_t set = 0; set < static_cast<int64_t>(num_sets); ++set) {
    const auto s = static_cast<size_t>(set);
    if (packed.build_alone[s] != 0) continue;
    const SetRuns runs{set_begin[s],
                       set_begin[s + 1],
                       packed.set_triangle_begin[s],
                       packed.set_triangle_begin[s + 1],
                       packed.set_edge_begin[s],
                       packed.set_edge_end[s],
                       packed.set_rank_begin[s],
                       packed.set_rank_begin[s + 1] - packed.set_rank_begin[s],
                       num_tri_all};
    try {
      AlphaFamilyParts parts;
      CutOutSet(packed, runs, s, points, backend, &parts);
      (*families)[s].emplace(std::move(parts));
    } catch (const std::bad_alloc&) {
#pragma omp atomic write
      out_of_memory = 1;
    }
  }
  return out_of_memory == 0;
}

}  // namespace

absl::StatusOr<AlphaFamilies> BuildAlphaFamilies(absl::Span<const Point2> points, absl::Span<const uint32_t> set_begin,
                                                 const BuildOptions& options) {
  if (options.persistence) {
    return absl::InvalidArgumentError(
        "a packed build of many sets does not compute persistence diagrams: build the sets one by one");
  }
  auto report = [&](std::string_view phase, double fraction) {
    if (options.progress) options.progress(phase, fraction);
  };
  auto stop_requested = [&] { return options.cancelled && options.cancelled(); };
  GALPHA_RETURN_IF_ERROR(ValidatePointSets(points, set_begin));
  const size_t num_sets = set_begin.size() - 1;
  const auto n = static_cast<uint32_t>(points.size());
  GALPHA_ASSIGN_OR_RETURN(const Backend backend, detail::ResolveBackend(options.backend));
  const auto cancelled_error = [&](const char* after) {
    return absl::CancelledError(absl::StrCat("build of ", num_sets, " sets of ", n, " points cancelled after ", after));
  };
  if (stop_requested()) return cancelled_error("0 phases");
  AlphaFamilies result;
  result.report.backend = BackendName(backend);
  std::vector<std::optional<AlphaFamily>> families(num_sets);
  detail::PackedFamilyOutput packed;
  if (n > 0) {
    detail::BuildHooks hooks;
    hooks.max_exact_comparisons = options.max_exact_comparisons;
    hooks.after_triangulation = [&] {
      report("triangulation", 0.5);
      if (stop_requested()) {
        throw detail::EngineError(detail::EngineError::Kind::kCancelled,
                                  std::string(cancelled_error("the triangulation").message()));
      }
    };
    GALPHA_RETURN_IF_ERROR(
        detail::RunEngine(absl::StrCat("building the alpha families of ", num_sets, " sets of ", n, " points"), [&] {
          if (backend == Backend::kCuda) {
            detail::BuildFamiliesOnCuda(points.data(), set_begin.data(), static_cast<uint32_t>(num_sets), n,
                                        options.cuda_stream, hooks, &packed);
          } else {
            detail::BuildFamiliesOnCpu(points.data(), set_begin.data(), static_cast<uint32_t>(num_sets), n, hooks,
                                       &packed);
          }
        }));
    report("alpha", 0.9);
    if (stop_requested()) return cancelled_error("the alpha pipeline");
    if (!SplitFamilies(points, set_begin, packed, BackendName(backend), &families)) {
      return absl::ResourceExhaustedError(
          absl::StrCat("out of host memory splitting the families of ", num_sets, " sets of ", n, " points"));
    }
    result.report.stage_times = std::move(packed.all.stage_times);
    result.report.peak_memory_bytes = packed.all.peak_memory_bytes;
    result.report.comparisons = packed.all.ranks.comparisons;
  } else {
    packed.build_alone.assign(num_sets, 1);  // no points: every family is the empty one
  }
  BuildOptions alone = options;
  alone.backend = backend;
  alone.progress = nullptr;
  result.families.reserve(num_sets);
  for (size_t s = 0; s < num_sets; ++s) {
    if (packed.build_alone[s] != 0) {
      absl::StatusOr<AlphaFamily> own =
          BuildAlphaFamily(points.subspan(set_begin[s], set_begin[s + 1] - set_begin[s]), alone);
      if (!own.ok()) return absl::Status(own.status().code(), absl::StrCat("set ", s, ": ", own.status().message()));
      if (n > 0) ++result.built_alone;
      families[s].emplace(*std::move(own));
    }
    result.families.push_back(*std::move(families[s]));
  }
  report("split", 1.0);
  return result;
}

}  // namespace galpha
