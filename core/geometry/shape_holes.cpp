#include "core/geometry/shape_holes.hpp"

#include <gmpxx.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/exact/radius_rational.hpp"

namespace galpha {

namespace {

/// Twice the ring's signed area, exactly (sum of x_i * y_{i+1} - x_{i+1} * y_i).
mpq_class TwiceSignedArea(absl::Span<const uint32_t> ring, absl::Span<const Point2> points) {
  mpq_class twice = 0;
  for (size_t i = 0; i < ring.size(); ++i) {
    const Point2 a = points[ring[i]], b = points[ring[(i + 1) % ring.size()]];
    twice += mpq_class(a.x) * mpq_class(b.y) - mpq_class(b.x) * mpq_class(a.y);
  }
  return twice;
}

mpq_class ExactArea(absl::Span<const uint32_t> ring, absl::Span<const Point2> points) {
  mpq_class area = abs(TwiceSignedArea(ring, points)) / 2;
  area.canonicalize();
  return area;
}

}  // namespace

double RingArea(absl::Span<const uint32_t> ring, absl::Span<const Point2> points) {
  return NearestDouble(ExactArea(ring, points));
}

std::vector<ShapeHole> ListHoles(const ShapeGeometry& shape, absl::Span<const Point2> points, double min_area) {
  const mpq_class bound(min_area);
  std::vector<std::pair<mpq_class, ShapeHole>> holes;
  for (size_t p = 0; p < shape.polygons.size(); ++p) {
    for (const std::vector<uint32_t>& ring : shape.polygons[p].holes) {
      mpq_class area = ExactArea(ring, points);
      if (area >= bound) {
        const double nearest = NearestDouble(area);
        holes.emplace_back(std::move(area), ShapeHole{p, ring, nearest});
      }
    }
  }
  // Stable: equal areas keep polygon order, then ring order.
  std::stable_sort(holes.begin(), holes.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<ShapeHole> out;
  out.reserve(holes.size());
  for (auto& [area, hole] : holes) out.push_back(std::move(hole));
  return out;
}

size_t FillHolesSmallerThan(ShapeGeometry* shape, absl::Span<const Point2> points, double min_area) {
  const mpq_class bound(min_area);
  size_t filled = 0;
  for (ShapePolygon& polygon : shape->polygons) {
    std::vector<std::vector<uint32_t>> kept;
    for (std::vector<uint32_t>& ring : polygon.holes) {
      const mpq_class area = ExactArea(ring, points);
      if (area < bound) {
        shape->area += NearestDouble(area);
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
