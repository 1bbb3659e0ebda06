// BuildAlphaFamily: points in, the exact family of alpha shapes out (core/family/alpha_family.hpp). Runs
// the triangulation and the alpha pipeline on one backend (CUDA on one stream, or OpenMP).
#pragma once

#include <cstdint>
#include <functional>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"
#include "core/family/alpha_family.hpp"
#include "gpu/triangulation/delaunay.hpp"

namespace galpha {

struct BuildOptions {
  Backend backend = Backend::kAuto;
  /// CUDA stream (a cudaStream_t) to run on; nullptr: one of the engine's own.
  void* cuda_stream = nullptr;
  /// Called after each phase ("triangulation", "alpha", "components") with the fraction done.
  std::function<void(std::string_view phase, double fraction)> progress;
  /// Polled between phases; when it answers true the build stops, frees what it holds and returns
  /// Cancelled (a server passes its client's cancellation and deadline here).
  std::function<bool()> cancelled;
  /// The most exact radius comparisons (bounded expansions and CPU fallbacks together, as the
  /// report counts them) the build may make; 0: no limit. A build that passes it stops and returns
  /// ResourceExhausted (IsExactComparisonLimit). The device's passes are checked as they end; the
  /// host's sequential repair, the only part whose work has no bound in the input's size, stops
  /// within 255 comparisons a host thread of the limit.
  uint64_t max_exact_comparisons = 0;
  /// Also compute the persistence diagram (H0 and H1) in the build, on its backend, from the
  /// family's arrays where they lie (gpu/alpha/persistence_pairs.cuh; stages persistence_*), and
  /// keep it with the family (AlphaFamily::persistence()).
  bool persistence = false;
};

/// Many families built together (BuildAlphaFamilies).
struct AlphaFamilies {
  /// One family a set, in the sets' order, each equal on every table to BuildAlphaFamily's of the
  /// set alone on the same backend (its indices the set's own, from 0). Their reports name the
  /// backend only: the stage times, exact comparisons and peak memory are the build's, below (a
  /// set built alone, and every set of a call without points, keeps its own build's report).
  std::vector<AlphaFamily> families;
  /// The packed build's: its stage times, the exact comparisons of all the sets, its peak memory.
  BuildReport report;
  /// Sets built alone after the packed build (a mesh with a flat triangle; none measured).
  uint32_t built_alone = 0;
};

/// Builds the families of many point sets in one packed build: set s is points[set_begin[s],
/// set_begin[s + 1]) (TriangulateSets' offsets; empty sets allowed). The sets are triangulated
/// together (TriangulateSets) and the alpha pipeline runs once over all their simplices, not once
/// a set: thousands of small sets take about what one build of all their points takes.
/// docs/design.md, "Many sets in one build".
///
/// Options: `max_exact_comparisons` bounds all the sets' together; `cancelled` and `progress` as
/// BuildAlphaFamily's (phases "triangulation", "alpha", "split"); `persistence` is not computed in
/// a packed build (InvalidArgument: build the sets one by one).
///
/// Errors: TriangulateSets' (a set's error prefixed by the set), ResourceExhausted for the limit
/// of exact comparisons (IsExactComparisonLimit) or for host memory, and Cancelled. Unweighted.
absl::StatusOr<AlphaFamilies> BuildAlphaFamilies(absl::Span<const Point2> points, absl::Span<const uint32_t> set_begin,
                                                 const BuildOptions& options = {});

/// Whether `status` is a build stopped by BuildOptions::max_exact_comparisons.
bool IsExactComparisonLimit(const absl::Status& status);

/// Builds the family. Errors as Triangulate's (gpu/triangulation/delaunay.hpp), and Cancelled.
absl::StatusOr<AlphaFamily> BuildAlphaFamily(absl::Span<const Point2> points, const BuildOptions& options = {});

/// Builds the weighted family (issue 18; docs/design.md, "Weighted alpha shapes"): the
/// subcomplexes of the regular triangulation of the points with `weights` (one per point, the
/// squared radius of its disk; negative values are valid), thresholds the squared radii of the
/// smallest orthogonal circles, hidden points EXTERIOR at every level. Errors as
/// TriangulateWeighted's (a weight count that is not the point count among them), and Cancelled.
absl::StatusOr<AlphaFamily> BuildWeightedAlphaFamily(absl::Span<const Point2> points, absl::Span<const double> weights,
                                                     const BuildOptions& options = {});

}  // namespace galpha
