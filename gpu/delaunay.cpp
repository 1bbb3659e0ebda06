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
#include "gpu/engine_status.hpp"

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

namespace detail {

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

absl::Status RunEngine(const std::string& what, const std::function<void()>& body) {
  try {
    body();
  } catch (const EngineError& e) {
    switch (e.kind()) {
      case EngineError::Kind::kResourceExhausted:
        return absl::ResourceExhaustedError(absl::StrCat(what, ": ", e.what()));
      case EngineError::Kind::kUnavailable:
        return absl::UnavailableError(e.what());
      case EngineError::Kind::kCancelled:
        return absl::CancelledError(e.what());
      case EngineError::Kind::kInternal:
        break;
    }
    return absl::InternalError(absl::StrCat(what, ": ", e.what()));
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(absl::StrCat("out of memory while ", what));
  } catch (const std::exception& e) {  // Thrust reports CUDA failures as system_error
    return absl::InternalError(absl::StrCat(what, " failed: ", e.what()));
  }
  return absl::OkStatus();
}

}  // namespace detail

absl::StatusOr<Triangulation> Triangulate(absl::Span<const Point2> points, const TriangulateOptions& options) {
  GALPHA_RETURN_IF_ERROR(ValidatePoints(points));
  GALPHA_ASSIGN_OR_RETURN(const Backend backend, detail::ResolveBackend(options.backend));
  const auto n = static_cast<uint32_t>(points.size());
  detail::DelaunayOutput raw;
  GALPHA_RETURN_IF_ERROR(detail::RunEngine(absl::StrCat("triangulating ", n, " points"), [&] {
    if (backend == Backend::kCuda) {
      detail::TriangulateOnCuda(points.data(), n, options.cuda_stream, &raw);
    } else {
      detail::TriangulateOnCpu(points.data(), n, &raw);
    }
  }));
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
