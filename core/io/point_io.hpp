// Reading and writing the raw binary point format (data/README.md; docs/design.md, "Formats"):
// little-endian uint64 N, then N pairs of little-endian float64 (x, y); weighted, the header's
// top bit set and N triples (x, y, weight). Nothing is deduplicated,
// rounded or validated for finiteness here: the engine's validation layer does that.
#pragma once

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"
#include "core/io/georeferenced_points.hpp"

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

/// The weighted variant of the format: the header's bit 63 set (a flag no point count reaches;
/// ReadPointsBin refuses such a file by name), the count in the other bits, then N triples of
/// little-endian float64 (x, y, weight). Same errors as ReadPointsBin, and InvalidArgument for a
/// file without the flag.
inline constexpr uint64_t kWeightedBinFlag = uint64_t{1} << 63;
absl::StatusOr<GeoreferencedPoints> ReadWeightedPointsBin(const std::string& path);
absl::Status WriteWeightedPointsBin(const std::string& path, absl::Span<const Point2> points,
                                    absl::Span<const double> weights);

}  // namespace galpha
