// Exact comparison of a user's threshold with a simplex's threshold (the squared radius of its
// smallest circle, weighted: of its smallest orthogonal circle), the step every resolution of an
// alpha or alpha_sq to a level takes, for families in host memory and resident ones alike.
#pragma once

#include <gmpxx.h>

#include <array>
#include <cstdint>
#include <optional>

#include "absl/status/statusor.h"
#include "core/base/host_vector.hpp"
#include "core/base/point.hpp"

namespace galpha {

/// The host arrays a simplex's threshold is computed from (weights empty when unweighted).
struct SimplexGeometry {
  const HostVector<Point2>& points;
  const HostVector<double>& weights;
  const HostVector<std::array<uint32_t, 3>>& triangles;
  const HostVector<std::array<uint32_t, 2>>& edges;
};

/// sign(exact threshold of simplex `id` - value): `id` below the triangle count is a triangle,
/// else the edge id plus the triangle count (AlphaRanks::spectrum_simplex's naming).
int CompareSimplexThreshold(const SimplexGeometry& geometry, uint32_t id, const mpq_class& value);

/// A threshold on its way to a level, for either form of family: the answer when no comparison
/// with a simplex is needed (an error for NaN or a negative radius; -1 below min_alpha_sq; K at
/// infinity), else the exact squared radius whose place among the ranks a search must find.
struct LevelQuery {
  std::optional<absl::StatusOr<int64_t>> answer;
  mpq_class alpha_sq;
};
/// The rules of AlphaFamily::LevelForAlphaSq and LevelForAlpha before their searches.
LevelQuery StartLevelForAlphaSq(double alpha_sq, double min_alpha_sq, int64_t max_level);
LevelQuery StartLevelForAlpha(double alpha, double min_alpha_sq, int64_t max_level);
/// AlphaFamily::LevelForRank: the rank itself, or OutOfRange outside 0..K.
absl::StatusOr<int64_t> LevelOfRank(int64_t rank, int64_t max_level);

}  // namespace galpha
