// Reading and writing the raw binary point format (data/README.md; docs/design.md, "Formats"):
// little-endian uint64 N, then N pairs of little-endian float64 (x, y). Nothing is deduplicated,
// rounded or validated for finiteness here: the engine's validation layer does that.
#pragma once

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"

namespace galpha {

/// Reads a points `.bin` file, O(N).
///
/// Errors name the file: NotFound when it does not exist, PermissionDenied (or another errno-derived
/// code) when it cannot be opened, InvalidArgument when it is not a regular file or is shorter than
/// the 8-byte header, DataLoss when the header's point count disagrees with the file size
/// (truncated file or trailing bytes) or a read fails.
absl::StatusOr<std::vector<Point2>> ReadPointsBin(const std::string& path);

/// Writes `points` as a points `.bin` file, replacing any file at `path`. Errors name the file:
/// errno-derived codes when it cannot be opened, DataLoss when a write or the close fails.
absl::Status WritePointsBin(const std::string& path, absl::Span<const Point2> points);

}  // namespace galpha
