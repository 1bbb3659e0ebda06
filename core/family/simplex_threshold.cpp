#include "core/family/simplex_threshold.hpp"

#include <optional>

#include "core/exact/weighted_radius_rational.hpp"

namespace galpha {

int CompareSimplexThreshold(const SimplexGeometry& geometry, uint32_t id, const mpq_class& value) {
  Point2 pts[3];
  double ws[3];
  int n;
  const auto num_tri = static_cast<uint32_t>(geometry.triangles.size());
  const bool weighted = !geometry.weights.empty();
  if (id < num_tri) {
    n = 3;
    for (int k = 0; k < 3; ++k) {
      pts[k] = geometry.points[geometry.triangles[id][k]];
      ws[k] = weighted ? geometry.weights[geometry.triangles[id][k]] : 0.0;
    }
  } else {
    n = 2;
    for (int k = 0; k < 2; ++k) {
      pts[k] = geometry.points[geometry.edges[id - num_tri][k]];
      ws[k] = weighted ? geometry.weights[geometry.edges[id - num_tri][k]] : 0.0;
    }
  }
  const std::optional<mpq_class> threshold = SimplexRadiusSqRational(pts, weighted ? ws : nullptr, n);
  if (!threshold) return 1;
  const int c = cmp(*threshold, value);
  return (c > 0) - (c < 0);
}

}  // namespace galpha
