// Triangulate(): validation, then the backend's run, its failures turned into a status.
#include "gpu/triangulation/delaunay.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <exception>
#include <new>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.hpp"
#include "core/io/input_validation.hpp"
#include "gpu/system/backend.hpp"
#include "gpu/system/engine_status.hpp"
#include "gpu/triangulation/delaunay_backend.hpp"

namespace galpha {
namespace {

/// Both entry points: `weights` null for the Delaunay triangulation.
absl::StatusOr<Triangulation> Run(absl::Span<const Point2> points, const double* weights,
                                  const TriangulateOptions& options) {
  GALPHA_ASSIGN_OR_RETURN(const Backend backend, detail::ResolveBackend(options.backend));
  const auto n = static_cast<uint32_t>(points.size());
  detail::DelaunayOutput raw;
  GALPHA_RETURN_IF_ERROR(
      detail::RunEngine(absl::StrCat("triangulating ", n, weights != nullptr ? " weighted points" : " points"), [&] {
        if (backend == Backend::kCuda) {
          detail::TriangulateOnCuda(points.data(), weights, n, options.cuda_stream, &raw);
        } else {
          detail::TriangulateOnCpu(points.data(), weights, n, &raw);
        }
      }));
  Triangulation result;
  result.points.assign(points.begin(), points.end());
  result.representative = std::move(raw.representative);
  result.num_unique = raw.num_unique;
  result.hidden = std::move(raw.hidden);
  result.triangles = std::move(raw.triangles);
  result.neighbors = std::move(raw.neighbors);
  result.tri_edge_begin = std::move(raw.tri_edge_begin);
  result.edges = std::move(raw.edges);
  result.backend = backend;
  result.stage_times = std::move(raw.stage_times);
  result.peak_memory_bytes = raw.peak_memory_bytes;
  return result;
}

/// The offsets of TriangulateSets' sets: from 0 to n, never decreasing, at most
/// kMaxTriangulatedSets sets.
absl::Status ValidateSetOffsets(absl::Span<const uint32_t> set_begin, size_t n) {
  if (set_begin.empty()) return absl::InvalidArgumentError("set offsets: none given (at least the 0 that ends them)");
  if (set_begin.size() - 1 > kMaxTriangulatedSets) {
    return absl::InvalidArgumentError(
        absl::StrCat(set_begin.size() - 1, " sets: at most ", kMaxTriangulatedSets, " in one call"));
  }
  if (set_begin.front() != 0) {
    return absl::InvalidArgumentError(absl::StrCat("set offsets: the first is ", set_begin.front(), ", not 0"));
  }
  if (set_begin.back() != n) {
    return absl::InvalidArgumentError(
        absl::StrCat("set offsets: the last is ", set_begin.back(), ", not the ", n, " points given"));
  }
  for (size_t s = 0; s + 1 < set_begin.size(); ++s) {
    if (set_begin[s + 1] < set_begin[s]) {
      return absl::InvalidArgumentError(
          absl::StrCat("set offsets: set ", s, " ends at ", set_begin[s + 1], " before it begins at ", set_begin[s]));
    }
  }
  return absl::OkStatus();
}

/// Splits the packed build's output (indices of the whole input, each set's triangles one run) into
/// one triangulation a set (indices of the set), keeping each set's order. False when the host's
/// memory ran out (caught in the parallel loop, whose exceptions would otherwise terminate).
bool SplitBySet(absl::Span<const Point2> points, absl::Span<const uint32_t> set_begin,
                const detail::DelaunaySetsOutput& raw, std::vector<Triangulation>* sets) {
  const size_t num_sets = set_begin.size() - 1;
  const detail::DelaunayOutput& all = raw.meshes;
  const size_t num_tri = all.triangles.size();
  int out_of_memory = 0;
  // The sets are independent: one a thread, the host's cores sharing them out in small chunks.
#pragma omp parallel for schedule(dynamic, 16)
  for (int64_t set = 0; set < static_cast<int64_t>(num_sets); ++set) {
    const auto s = static_cast<size_t>(set);
    Triangulation& t = (*sets)[s];
    const uint32_t begin = set_begin[s], end = set_begin[s + 1];
    try {
      t.points.assign(points.begin() + begin, points.begin() + end);
      t.representative.resize(end - begin);
      for (uint32_t i = begin; i < end; ++i) {
        t.representative[i - begin] = all.representative[i] - begin;
        if (all.representative[i] == i) ++t.num_unique;
      }
      if (num_tri == 0) continue;  // no set has a mesh
      const uint32_t tri_begin = raw.set_triangle_begin[s], tri_end = raw.set_triangle_begin[s + 1];
      const size_t edge_begin = tri_begin < num_tri ? all.tri_edge_begin[tri_begin] : all.edges.size();
      const size_t edge_end = tri_end < num_tri ? all.tri_edge_begin[tri_end] : all.edges.size();
      t.triangles.resize(tri_end - tri_begin);
      t.neighbors.resize(tri_end - tri_begin);
      t.tri_edge_begin.resize(tri_end - tri_begin);
      for (uint32_t g = tri_begin; g < tri_end; ++g) {
        const std::array<uint32_t, 3>& x = all.triangles[g];
        t.triangles[g - tri_begin] = {x[0] - begin, x[1] - begin, x[2] - begin};
        std::array<int32_t, 3> n = all.neighbors[g];
        for (int32_t& k : n) k = k < 0 ? Triangulation::kNoNeighbor : k - static_cast<int32_t>(tri_begin);
        t.neighbors[g - tri_begin] = n;
        t.tri_edge_begin[g - tri_begin] = static_cast<uint32_t>(all.tri_edge_begin[g] - edge_begin);
      }
      t.edges.resize(edge_end - edge_begin);
      for (size_t e = edge_begin; e < edge_end; ++e) {
        t.edges[e - edge_begin] = {all.edges[e][0] - begin, all.edges[e][1] - begin};
      }
    } catch (const std::bad_alloc&) {
#pragma omp atomic write
      out_of_memory = 1;
    }
  }
  if (out_of_memory != 0) return false;
  // The chains of the sets on one line, set after set.
  try {
    size_t s = 0;
    for (const std::array<uint32_t, 2>& e : raw.chain_edges) {
      while (e[0] >= set_begin[s + 1]) ++s;
      (*sets)[s].edges.push_back({e[0] - set_begin[s], e[1] - set_begin[s]});
    }
  } catch (const std::bad_alloc&) {
    return false;
  }
  return true;
}

}  // namespace

absl::Status ValidatePointSets(absl::Span<const Point2> points, absl::Span<const uint32_t> set_begin) {
  // The packed build numbers all the points together: its limit is one build's.
  if (points.size() > kMaxPoints) {
    return absl::ResourceExhaustedError(absl::StrCat("too many points: ", points.size(),
                                                     " in all the sets exceeds the limit of ", kMaxPoints,
                                                     " of one build (32-bit triangle indices)"));
  }
  GALPHA_RETURN_IF_ERROR(ValidateSetOffsets(set_begin, points.size()));
  const size_t num_sets = set_begin.size() - 1;
  // Each set is validated as Triangulate validates it (its own input domain), the sets shared out
  // over the host's cores (ValidatePoints' own parallel pass then runs on one thread), and the
  // first set in order that fails names the error.
  std::vector<absl::Status> valid(num_sets);
#pragma omp parallel for schedule(dynamic, 16)
  for (int64_t set = 0; set < static_cast<int64_t>(num_sets); ++set) {
    const auto s = static_cast<size_t>(set);
    valid[s] = ValidatePoints(points.subspan(set_begin[s], set_begin[s + 1] - set_begin[s]));
  }
  for (size_t s = 0; s < num_sets; ++s) {
    if (!valid[s].ok()) return absl::Status(valid[s].code(), absl::StrCat("set ", s, ": ", valid[s].message()));
  }
  return absl::OkStatus();
}

absl::StatusOr<TriangulatedSets> TriangulateSets(absl::Span<const Point2> points, absl::Span<const uint32_t> set_begin,
                                                 const TriangulateOptions& options) {
  GALPHA_RETURN_IF_ERROR(ValidatePointSets(points, set_begin));
  const size_t num_sets = set_begin.size() - 1;
  GALPHA_ASSIGN_OR_RETURN(const Backend backend, detail::ResolveBackend(options.backend));
  TriangulatedSets result;
  result.backend = backend;
  result.sets.resize(num_sets);
  for (Triangulation& t : result.sets) t.backend = backend;
  if (points.empty()) return result;
  const auto n = static_cast<uint32_t>(points.size());
  detail::DelaunaySetsOutput raw;
  GALPHA_RETURN_IF_ERROR(detail::RunEngine(absl::StrCat("triangulating ", num_sets, " sets of ", n, " points"), [&] {
    if (backend == Backend::kCuda) {
      detail::TriangulateSetsOnCuda(points.data(), set_begin.data(), static_cast<uint32_t>(num_sets), n,
                                    options.cuda_stream, &raw);
    } else {
      detail::TriangulateSetsOnCpu(points.data(), set_begin.data(), static_cast<uint32_t>(num_sets), n, &raw);
    }
  }));
  if (!SplitBySet(points, set_begin, raw, &result.sets)) {
    return absl::ResourceExhaustedError(
        absl::StrCat("out of host memory splitting the triangulations of ", num_sets, " sets of ", n, " points"));
  }
  result.stage_times = std::move(raw.meshes.stage_times);
  result.peak_memory_bytes = raw.meshes.peak_memory_bytes;
  TriangulateOptions alone = options;
  alone.backend = backend;
  for (size_t s = 0; s < num_sets; ++s) {
    if (raw.build_alone[s] == 0) continue;
    absl::StatusOr<Triangulation> own =
        Run(points.subspan(set_begin[s], set_begin[s + 1] - set_begin[s]), nullptr, alone);
    if (!own.ok()) return absl::Status(own.status().code(), absl::StrCat("set ", s, ": ", own.status().message()));
    result.sets[s] = *std::move(own);
    result.sets[s].stage_times.clear();
    result.sets[s].peak_memory_bytes = 0;
    ++result.built_alone;
  }
  return result;
}

absl::StatusOr<Triangulation> Triangulate(absl::Span<const Point2> points, const TriangulateOptions& options) {
  GALPHA_RETURN_IF_ERROR(ValidatePoints(points));
  return Run(points, nullptr, options);
}

absl::StatusOr<Triangulation> TriangulateWeighted(absl::Span<const Point2> points, absl::Span<const double> weights,
                                                  const TriangulateOptions& options) {
  GALPHA_RETURN_IF_ERROR(ValidatePoints(points));
  GALPHA_RETURN_IF_ERROR(ValidateWeights(points, weights));
  return Run(points, weights.data(), options);
}

}  // namespace galpha
