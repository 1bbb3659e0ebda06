// Triangulate(): validation, backend choice, and the one place where engine exceptions become
// absl::Status.
#include "gpu/delaunay.hpp"

#include <exception>
#include <new>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/input_validation.hpp"
#include "core/status_macros.hpp"
#include "gpu/delaunay_backend.hpp"

namespace galpha {

const char* BackendName(Backend backend) {
  switch (backend) {
    case Backend::kAuto:
      return "auto";
    case Backend::kCpu:
      return "cpu";
    case Backend::kCuda:
      return "cuda";
  }
  return "unknown";
}

bool CudaBackendAvailable() { return detail::CudaDeviceVisible(); }

namespace {

absl::Status ToStatus(const detail::EngineError& error) {
  switch (error.kind()) {
    case detail::EngineError::Kind::kResourceExhausted:
      return absl::ResourceExhaustedError(error.what());
    case detail::EngineError::Kind::kUnavailable:
      return absl::UnavailableError(error.what());
    case detail::EngineError::Kind::kInternal:
      break;
  }
  return absl::InternalError(error.what());
}

absl::StatusOr<Backend> ResolveBackend(Backend requested) {
  const bool cuda = CudaBackendAvailable();
  switch (requested) {
    case Backend::kAuto:
      return cuda ? Backend::kCuda : Backend::kCpu;
    case Backend::kCpu:
      return Backend::kCpu;
    case Backend::kCuda:
      if (!cuda) return absl::UnavailableError("the CUDA backend was requested but no GPU is usable in this build");
      return Backend::kCuda;
  }
  return absl::InvalidArgumentError("unknown backend");
}

}  // namespace

absl::StatusOr<Triangulation> Triangulate(absl::Span<const Point2> points, const TriangulateOptions& options) {
  GALPHA_RETURN_IF_ERROR(ValidatePoints(points));
  GALPHA_ASSIGN_OR_RETURN(const Backend backend, ResolveBackend(options.backend));
  const auto n = static_cast<uint32_t>(points.size());
  detail::DelaunayOutput raw;
  try {
    if (backend == Backend::kCuda) {
      detail::TriangulateOnCuda(points.data(), n, options.cuda_stream, &raw);
    } else {
      detail::TriangulateOnCpu(points.data(), n, &raw);
    }
  } catch (const detail::EngineError& e) {
    return ToStatus(e);
  } catch (const std::bad_alloc& e) {
    return absl::ResourceExhaustedError(absl::StrCat("out of memory while triangulating ", n, " points"));
  } catch (const std::exception& e) {  // Thrust reports CUDA failures as system_error
    return absl::InternalError(absl::StrCat("triangulation failed: ", e.what()));
  }
  Triangulation result;
  result.points.assign(points.begin(), points.end());
  result.representative = std::move(raw.representative);
  result.num_unique = raw.num_unique;
  result.triangles = std::move(raw.triangles);
  result.neighbors = std::move(raw.neighbors);
  result.tri_edge_begin = std::move(raw.tri_edge_begin);
  result.edges = std::move(raw.edges);
  result.backend = backend;
  result.stage_times = std::move(raw.stage_times);
  result.peak_memory_bytes = raw.peak_memory_bytes;
  return result;
}

}  // namespace galpha
