#include "gpu/alpha_engine.hpp"

#include <algorithm>
#include <exception>
#include <new>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/status_macros.hpp"
#include "gpu/alpha_backend.hpp"
#include "gpu/delaunay_backend.hpp"

namespace galpha {

absl::StatusOr<AlphaFamily> BuildAlphaFamily(absl::Span<const Point2> points, const BuildOptions& options) {
  auto report = [&](std::string_view phase, double fraction) {
    if (options.progress) options.progress(phase, fraction);
  };
  auto stop_requested = [&] { return options.cancelled && options.cancelled(); };
  const auto cancelled_error = [&](const char* after) {
    return absl::CancelledError(absl::StrCat("build of ", points.size(), " points cancelled after ", after));
  };
  if (stop_requested()) return cancelled_error("0 phases");
  TriangulateOptions topt;
  topt.backend = options.backend;
  topt.cuda_stream = options.cuda_stream;
  GALPHA_ASSIGN_OR_RETURN(Triangulation tri, Triangulate(points, topt));
  report("triangulation", 0.5);
  if (stop_requested()) return cancelled_error("the triangulation");

  AlphaFamilyParts parts;
  parts.report.backend = BackendName(tri.backend);
  parts.report.stage_times = std::move(tri.stage_times);
  detail::AlphaInput in;
  in.points = tri.points.data();
  in.num_points = static_cast<uint32_t>(tri.points.size());
  in.num_unique = tri.num_unique;
  in.representative = tri.representative.data();
  in.triangles = tri.triangles.data();
  in.neighbors = tri.neighbors.data();
  in.tri_edge_begin = tri.tri_edge_begin.data();
  in.num_triangles = static_cast<uint32_t>(tri.triangles.size());
  in.edges = tri.edges.data();
  in.num_edges = static_cast<uint32_t>(tri.edges.size());
  size_t alpha_peak = 0;
  try {
    if (tri.backend == Backend::kCuda) {
      detail::BuildAlphaOnCuda(in, options.cuda_stream, &parts.ranks, &parts.report.stage_times, &alpha_peak);
    } else {
      detail::BuildAlphaOnCpu(in, &parts.ranks, &parts.report.stage_times, &alpha_peak);
    }
  } catch (const detail::EngineError& e) {
    if (e.kind() == detail::EngineError::Kind::kResourceExhausted) return absl::ResourceExhaustedError(e.what());
    return absl::InternalError(e.what());
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(absl::StrCat("out of memory while building the alpha family of ",
                                                     points.size(), " points"));
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("alpha family build failed: ", e.what()));
  }
  report("alpha", 0.9);
  if (stop_requested()) return cancelled_error("the alpha pipeline");
  parts.report.peak_memory_bytes = std::max(tri.peak_memory_bytes, alpha_peak);
  parts.report.comparisons = parts.ranks.comparisons;
  parts.points = std::move(tri.points);
  parts.representative = std::move(tri.representative);
  parts.num_unique = tri.num_unique;
  parts.triangles = std::move(tri.triangles);
  parts.edges = std::move(tri.edges);
  report("components", 1.0);
  return AlphaFamily(std::move(parts));
}

}  // namespace galpha
