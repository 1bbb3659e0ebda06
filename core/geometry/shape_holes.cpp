#include "core/geometry/shape_holes.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace galpha {

double RingArea(absl::Span<const uint32_t> ring, absl::Span<const Point2> points) {
  if (ring.size() < 3) return 0.0;
  const Point2 origin = points[ring[0]];
  double twice = 0.0;
  for (size_t i = 1; i + 1 < ring.size(); ++i) {
    const Point2 a = points[ring[i]], b = points[ring[i + 1]];
    twice += (a.x - origin.x) * (b.y - origin.y) - (b.x - origin.x) * (a.y - origin.y);
  }
  return 0.5 * std::abs(twice);
}

std::vector<ShapeHole> ListHoles(const ShapeGeometry& shape, absl::Span<const Point2> points, double min_area) {
  std::vector<ShapeHole> holes;
  for (size_t p = 0; p < shape.polygons.size(); ++p) {
    for (const std::vector<uint32_t>& ring : shape.polygons[p].holes) {
      const double area = RingArea(ring, points);
      if (area >= min_area) holes.push_back({p, ring, area});
    }
  }
  // Stable: equal areas keep polygon order, then ring order.
  std::stable_sort(holes.begin(), holes.end(), [](const ShapeHole& a, const ShapeHole& b) { return a.area > b.area; });
  return holes;
}

size_t FillHolesSmallerThan(ShapeGeometry* shape, absl::Span<const Point2> points, double min_area) {
  size_t filled = 0;
  for (ShapePolygon& polygon : shape->polygons) {
    std::vector<std::vector<uint32_t>> kept;
    for (std::vector<uint32_t>& ring : polygon.holes) {
      const double area = RingArea(ring, points);
      if (area < min_area) {
        shape->area += area;
        ++filled;
      } else {
        kept.push_back(std::move(ring));
      }
    }
    polygon.holes = std::move(kept);
  }
  return filled;
}

}  // namespace galpha
