// Triangulate(): validation, then the backend's run, its failures turned into a status.
#include "gpu/triangulation/delaunay.hpp"

#include <algorithm>
#include <array>
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

/// Splits the packed build's output (indices of the whole input) into one triangulation a set
/// (indices of the set), keeping each set's order.
void SplitBySet(absl::Span<const Point2> points, absl::Span<const uint32_t> set_begin, detail::DelaunaySetsOutput& raw,
                std::vector<Triangulation>* sets) {
  const size_t num_sets = set_begin.size() - 1;
  std::vector<uint32_t> set_of(points.size());
  for (size_t s = 0; s < num_sets; ++s) {
    Triangulation& t = (*sets)[s];
    const uint32_t begin = set_begin[s], end = set_begin[s + 1];
    std::fill(set_of.begin() + begin, set_of.begin() + end, static_cast<uint32_t>(s));
    t.points.assign(points.begin() + begin, points.begin() + end);
    t.representative.resize(end - begin);
    for (uint32_t i = begin; i < end; ++i) {
      t.representative[i - begin] = raw.meshes.representative[i] - begin;
      if (raw.meshes.representative[i] == i) ++t.num_unique;
    }
  }
  const std::vector<std::array<uint32_t, 3>>& tri = raw.meshes.triangles;
  std::vector<int32_t> local_id(tri.size());
  for (size_t g = 0; g < tri.size(); ++g) {
    Triangulation& t = (*sets)[set_of[tri[g][0]]];
    const uint32_t begin = set_begin[set_of[tri[g][0]]];
    local_id[g] = static_cast<int32_t>(t.triangles.size());
    t.triangles.push_back({tri[g][0] - begin, tri[g][1] - begin, tri[g][2] - begin});
  }
  const std::vector<std::array<uint32_t, 2>>& edges = raw.meshes.edges;
  for (size_t g = 0; g < tri.size(); ++g) {
    Triangulation& t = (*sets)[set_of[tri[g][0]]];
    const uint32_t begin = set_begin[set_of[tri[g][0]]];
    std::array<int32_t, 3> nbr = raw.meshes.neighbors[g];
    for (int32_t& n : nbr) n = n < 0 ? Triangulation::kNoNeighbor : local_id[n];
    t.neighbors.push_back(nbr);
    t.tri_edge_begin.push_back(static_cast<uint32_t>(t.edges.size()));
    const size_t edge_end = g + 1 < tri.size() ? raw.meshes.tri_edge_begin[g + 1] : edges.size();
    for (size_t e = raw.meshes.tri_edge_begin[g]; e < edge_end; ++e) {
      t.edges.push_back({edges[e][0] - begin, edges[e][1] - begin});
    }
  }
  for (const std::array<uint32_t, 2>& e : raw.chain_edges) {
    const uint32_t s = set_of[e[0]];
    (*sets)[s].edges.push_back({e[0] - set_begin[s], e[1] - set_begin[s]});
  }
}

}  // namespace

absl::StatusOr<TriangulatedSets> TriangulateSets(absl::Span<const Point2> points, absl::Span<const uint32_t> set_begin,
                                                 const TriangulateOptions& options) {
  GALPHA_RETURN_IF_ERROR(ValidateSetOffsets(set_begin, points.size()));
  const size_t num_sets = set_begin.size() - 1;
  for (size_t s = 0; s < num_sets; ++s) {
    const absl::Status valid = ValidatePoints(points.subspan(set_begin[s], set_begin[s + 1] - set_begin[s]));
    if (!valid.ok()) return absl::Status(valid.code(), absl::StrCat("set ", s, ": ", valid.message()));
  }
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
  SplitBySet(points, set_begin, raw, &result.sets);
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
