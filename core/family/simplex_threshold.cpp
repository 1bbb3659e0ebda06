#include "core/family/simplex_threshold.hpp"

#include <cmath>
#include <optional>

#include "absl/strings/str_cat.h"

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

LevelQuery StartLevelForAlphaSq(double alpha_sq, double min_alpha_sq, int64_t max_level) {
  LevelQuery query;
  if (std::isnan(alpha_sq)) {
    query.answer = absl::InvalidArgumentError("alpha_sq is NaN");
  } else if (alpha_sq < min_alpha_sq) {
    query.answer = int64_t{-1};
  } else if (std::isinf(alpha_sq)) {
    query.answer = max_level;
  } else {
    query.alpha_sq = mpq_class(alpha_sq);
  }
  return query;
}

LevelQuery StartLevelForAlpha(double alpha, double min_alpha_sq, int64_t max_level) {
  LevelQuery query;
  if (std::isnan(alpha)) {
    query.answer = absl::InvalidArgumentError("alpha is NaN");
  } else if (alpha < 0) {
    query.answer = absl::InvalidArgumentError(absl::StrCat("alpha is a radius and must be >= 0, got ", alpha));
  } else if (std::isinf(alpha)) {
    query.answer = max_level;
  } else {
    const mpq_class radius(alpha);
    query.alpha_sq = radius * radius;
    if (query.alpha_sq < mpq_class(min_alpha_sq)) query.answer = int64_t{-1};  // weighted, every weight negative
  }
  return query;
}

absl::StatusOr<int64_t> LevelOfRank(int64_t rank, int64_t max_level) {
  if (rank < 0 || rank > max_level) {
    return absl::OutOfRangeError(
        absl::StrCat("rank ", rank, " is outside 0..", max_level, " (the spectrum has ", max_level, " values)"));
  }
  return rank;
}

}  // namespace galpha
