// The build both family forms share (alpha_engine.cpp): validation, the engine call on the chosen
// backend and the assembly of the host parts; with `resident`, the rank tables stay where they
// were built (ResidentAlphaFamily, resident_family.hpp).
#pragma once

#include <memory>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/family/alpha_family.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gpu/alpha/resident_backend.hpp"

namespace galpha::detail {

/// The weights a weighted build of `points` runs with: `weights` itself, or none for an empty set
/// (nothing to weigh: the empty family is the unweighted one). InvalidArgument when the counts
/// differ. One rule for both family forms' weighted builds.
absl::StatusOr<absl::Span<const double>> WeightsToBuildWith(absl::Span<const Point2> points,
                                                            absl::Span<const double> weights);

/// Builds the family of `points` (with `weights`, or empty for the unweighted family) into
/// `parts`; with `resident`, `*tables` receives the rank tables and `parts->ranks` holds only the
/// comparison counts and the area scale.
absl::Status BuildFamilyParts(absl::Span<const Point2> points, absl::Span<const double> weights,
                              const BuildOptions& options, bool resident, AlphaFamilyParts* parts,
                              std::unique_ptr<ResidentTables>* tables);

}  // namespace galpha::detail
