// The validation layer every point set passes before the engine sees it.
#pragma once

#include <cstdint>

#include "absl/status/status.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"

namespace galpha {

/// Largest number of input points: triangle ids are signed 32-bit and a triangulation of n points
/// has up to 2n triangles on the sphere (the vertex at infinity included).
inline constexpr uint64_t kMaxPoints = uint64_t{1} << 30;

/// OK when every coordinate is finite and the count fits the engine's 32-bit indices.
/// InvalidArgument names the first index holding NaN or infinity; ResourceExhausted gives the limit.
absl::Status ValidatePoints(absl::Span<const Point2> points);

}  // namespace galpha
