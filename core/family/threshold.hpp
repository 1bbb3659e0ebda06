// A threshold as every front end takes it (a squared radius, a radius, a rank or an area ratio) and its
// resolution against a family: one definition for the service, alphactl and the Python module,
// so that their levels, published alpha_sq values and messages cannot drift apart.
#pragma once

#include <cstdint>

#include "absl/status/statusor.h"
#include "core/family/alpha_family.hpp"

namespace galpha {

struct Threshold {
  enum class Kind { kAlphaSq, kAlpha, kRank, kRatio };
  Kind kind = Kind::kAlphaSq;
  double value = 0.0;  ///< alpha_sq, alpha, or the area ratio (0..1) of kRatio
  int64_t rank = 0;    ///< for kRank
};

/// A threshold resolved to a level (the number of spectrum values <= it) and the squared radius
/// it stands for: the given alpha_sq, alpha * alpha rounded, or for a rank and an area ratio the
/// published spectrum value of the level (PublishedAlphaSq).
struct ResolvedThreshold {
  int64_t level = 0;
  double alpha_sq = 0.0;
};

/// The published squared radius of `level`: spectrum[level - 1]; for levels 0 and -1 the lower end
/// of level 0 (0 unweighted, minus the largest weight weighted).
double PublishedAlphaSq(const AlphaFamily& family, int64_t level);

/// InvalidArgument for a NaN, a negative alpha, a rank outside 0..K ("rank R is outside 0..K
/// (the spectrum has K values)") and a ratio outside 0..1. A ratio resolves to the smallest level
/// whose regularized area is at least ratio times the convex hull's (core/family/area_ratio.hpp).
absl::StatusOr<ResolvedThreshold> ResolveThreshold(const AlphaFamily& family, const Threshold& threshold);

}  // namespace galpha
