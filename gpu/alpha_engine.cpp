#include "gpu/alpha_engine.hpp"

#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/input_validation.hpp"
#include "core/status_macros.hpp"
#include "gpu/alpha_backend.hpp"
#include "gpu/delaunay_backend.hpp"
#include "gpu/engine_status.hpp"

namespace galpha {

absl::StatusOr<AlphaFamily> BuildAlphaFamily(absl::Span<const Point2> points, const BuildOptions& options) {
  auto report = [&](std::string_view phase, double fraction) {
    if (options.progress) options.progress(phase, fraction);
  };
  auto stop_requested = [&] { return options.cancelled && options.cancelled(); };
  const auto cancelled_error = [&](const char* after) {
    return absl::CancelledError(absl::StrCat("build of ", points.size(), " points cancelled after ", after));
  };
  GALPHA_RETURN_IF_ERROR(ValidatePoints(points));
  GALPHA_ASSIGN_OR_RETURN(const Backend backend, detail::ResolveBackend(options.backend));
  if (stop_requested()) return cancelled_error("0 phases");
  const auto n = static_cast<uint32_t>(points.size());

  // One engine call: the triangulation stays where it was built (device memory on CUDA) and the
  // alpha pipeline reads it there; only the finished family comes back to the host.
  detail::FamilyOutput built;
  detail::BuildHooks hooks;
  hooks.after_triangulation = [&] {
    report("triangulation", 0.5);
    if (stop_requested()) {
      throw detail::EngineError(detail::EngineError::Kind::kCancelled,
                                std::string(cancelled_error("the triangulation").message()));
    }
  };
  GALPHA_RETURN_IF_ERROR(detail::RunEngine(absl::StrCat("building the alpha family of ", n, " points"), [&] {
    if (backend == Backend::kCuda) {
      detail::BuildFamilyOnCuda(points.data(), n, options.cuda_stream, hooks, &built);
    } else {
      detail::BuildFamilyOnCpu(points.data(), n, hooks, &built);
    }
  }));
  report("alpha", 0.9);
  if (stop_requested()) return cancelled_error("the alpha pipeline");

  AlphaFamilyParts parts;
  parts.report.backend = BackendName(backend);
  parts.report.stage_times = std::move(built.stage_times);
  parts.report.peak_memory_bytes = built.peak_memory_bytes;
  parts.report.comparisons = built.ranks.comparisons;
  parts.points.assign(points.begin(), points.end());
  parts.representative = std::move(built.representative);
  parts.num_unique = built.num_unique;
  parts.triangles = std::move(built.triangles);
  parts.edges = std::move(built.edges);
  parts.ranks = std::move(built.ranks);
  report("components", 1.0);
  return AlphaFamily(std::move(parts));
}

}  // namespace galpha
