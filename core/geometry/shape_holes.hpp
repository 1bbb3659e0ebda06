// The holes of an alpha shape as geometry: each hole ring of each polygon with its area, and the
// shape with the holes below an area filled (what `alphactl holes` lists and what the Shape answer
// drops on request: lakes smaller than a pond, pockets smaller than a probe).
//
// Areas are exact: the shoelace sum of the ring in GMP rationals (every double is one), so the
// order of the holes and the comparisons with the caller's bound never depend on rounding; the
// area reported is the exact area's nearest double. The topology (which rings are holes, of which
// polygon) comes from AssembleShape's exact construction.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/types/span.h"
#include "core/base/point.hpp"
#include "core/geometry/shape.hpp"

namespace galpha {

/// Area of a simple ring (either orientation), in squared input units: the nearest double of the
/// exact area.
double RingArea(absl::Span<const uint32_t> ring, absl::Span<const Point2> points);

/// One hole: the polygon it belongs to (an index into ShapeGeometry::polygons), its ring (as
/// AssembleShape wrote it: clockwise) and its area.
struct ShapeHole {
  size_t polygon = 0;
  std::vector<uint32_t> ring;
  double area = 0.0;
};

/// Every hole of `shape` whose exact area is at least `min_area`, largest exact area first (then
/// by polygon and ring order).
std::vector<ShapeHole> ListHoles(const ShapeGeometry& shape, absl::Span<const Point2> points, double min_area);

/// Fills every hole whose exact area is below `min_area`: the ring leaves its polygon and its area
/// (RingArea's double) joins the shape's. Returns how many holes were filled.
size_t FillHolesSmallerThan(ShapeGeometry* shape, absl::Span<const Point2> points, double min_area);

}  // namespace galpha
