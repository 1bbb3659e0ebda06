// Triangulate(): validation, then the backend's run, its failures turned into a status.
#include "gpu/triangulation/delaunay.hpp"

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

}  // namespace

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
