#include "gpu/alpha/alpha_engine.hpp"

#include <chrono>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.hpp"
#include "core/io/input_validation.hpp"
#include "gpu/alpha/alpha_backend.hpp"
#include "gpu/alpha/alpha_build_parts.hpp"
#include "gpu/system/engine_status.hpp"
#include "gpu/system/host_copy.hpp"
#include "gpu/triangulation/delaunay_backend.hpp"

namespace galpha {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

namespace detail {

absl::StatusOr<absl::Span<const double>> WeightsToBuildWith(absl::Span<const Point2> points,
                                                            absl::Span<const double> weights) {
  if (weights.size() != points.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("weighted build: ", weights.size(), " weights for ", points.size(), " points"));
  }
  if (points.empty()) return absl::Span<const double>();  // nothing to weigh
  return weights;
}

absl::Status BuildFamilyParts(absl::Span<const Point2> points, absl::Span<const double> weights,
                              const BuildOptions& options, bool resident, AlphaFamilyParts* parts_out,
                              std::unique_ptr<ResidentTables>* tables) {
  auto report = [&](std::string_view phase, double fraction) {
    if (options.progress) options.progress(phase, fraction);
  };
  auto stop_requested = [&] { return options.cancelled && options.cancelled(); };
  const auto cancelled_error = [&](const char* after) {
    return absl::CancelledError(absl::StrCat("build of ", points.size(), " points cancelled after ", after));
  };
  // Host work around the engine call is timed too ("validate", "assemble"), so that the stages
  // account for the whole call.
  const auto validate_start = std::chrono::steady_clock::now();
  GALPHA_RETURN_IF_ERROR(ValidatePoints(points));
  const bool weighted = !weights.empty();
  if (weighted) GALPHA_RETURN_IF_ERROR(ValidateWeights(points, weights));
  const double* weight_data = weighted ? weights.data() : nullptr;
  const double validate_seconds = SecondsSince(validate_start);
  GALPHA_ASSIGN_OR_RETURN(const Backend backend, detail::ResolveBackend(options.backend));
  if (resident && backend == Backend::kCuda && options.cuda_stream != nullptr) {
    return absl::InvalidArgumentError(
        "a resident family runs on a CUDA stream of its own: leave BuildOptions::cuda_stream unset");
  }
  if (stop_requested()) return cancelled_error("0 phases");
  const auto n = static_cast<uint32_t>(points.size());

  // One engine call: the triangulation stays where it was built (device memory on CUDA) and the
  // alpha pipeline reads it there; only the finished family comes back to the host.
  detail::FamilyOutput built;
  detail::BuildHooks hooks;
  hooks.max_exact_comparisons = options.max_exact_comparisons;
  hooks.persistence = options.persistence;
  hooks.resident = resident;
  hooks.after_triangulation = [&] {
    report("triangulation", 0.5);
    if (stop_requested()) {
      throw detail::EngineError(detail::EngineError::Kind::kCancelled,
                                std::string(cancelled_error("the triangulation").message()));
    }
  };
  GALPHA_RETURN_IF_ERROR(detail::RunEngine(absl::StrCat("building the alpha family of ", n, " points"), [&] {
    if (backend == Backend::kCuda) {
      detail::BuildFamilyOnCuda(points.data(), weight_data, n, options.cuda_stream, hooks, &built);
    } else {
      detail::BuildFamilyOnCpu(points.data(), weight_data, n, hooks, &built);
    }
  }));
  report("alpha", 0.9);
  if (stop_requested()) return cancelled_error("the alpha pipeline");

  const auto assemble_start = std::chrono::steady_clock::now();
  AlphaFamilyParts& parts = *parts_out;
  parts.report.backend = BackendName(backend);
  parts.report.stage_times.push_back({"validate", validate_seconds});
  for (StageTime& stage : built.stage_times) parts.report.stage_times.push_back(std::move(stage));
  parts.report.peak_memory_bytes = built.peak_memory_bytes;
  parts.report.comparisons = built.ranks.comparisons;
  parts.points.resize(points.size());
  detail::ParallelCopy(parts.points.data(), points.data(), points.size() * sizeof(Point2));
  parts.representative = std::move(built.representative);
  parts.num_unique = built.num_unique;
  parts.triangles = std::move(built.triangles);
  parts.edges = std::move(built.edges);
  parts.ranks = std::move(built.ranks);
  if (built.has_persistence) parts.persistence = std::move(built.persistence);
  if (weighted) {
    parts.weights.resize(weights.size());
    detail::ParallelCopy(parts.weights.data(), weights.data(), weights.size() * sizeof(double));
    parts.hidden = std::move(built.hidden);
  }
  // The stage list is complete before the family owns it; the constructor's own pass over the
  // points is the little it leaves out.
  parts.report.stage_times.push_back({"assemble", SecondsSince(assemble_start)});
  if (resident) *tables = std::move(built.resident);
  report("components", 1.0);
  return absl::OkStatus();
}

}  // namespace detail

namespace {

/// The build of either family in host memory: `weights` empty for the unweighted one.
absl::StatusOr<AlphaFamily> BuildFamily(absl::Span<const Point2> points, absl::Span<const double> weights,
                                        const BuildOptions& options) {
  AlphaFamilyParts parts;
  GALPHA_RETURN_IF_ERROR(detail::BuildFamilyParts(points, weights, options, /*resident=*/false, &parts, nullptr));
  return AlphaFamily(std::move(parts));
}

}  // namespace

absl::StatusOr<AlphaFamily> BuildAlphaFamily(absl::Span<const Point2> points, const BuildOptions& options) {
  return BuildFamily(points, {}, options);
}

absl::StatusOr<AlphaFamily> BuildWeightedAlphaFamily(absl::Span<const Point2> points, absl::Span<const double> weights,
                                                     const BuildOptions& options) {
  GALPHA_ASSIGN_OR_RETURN(const absl::Span<const double> used, detail::WeightsToBuildWith(points, weights));
  return BuildFamily(points, used, options);
}

bool IsExactComparisonLimit(const absl::Status& status) {
  return absl::IsResourceExhausted(status) && status.GetPayload(detail::kExactComparisonLimitPayload).has_value();
}

}  // namespace galpha
