#include "core/family/threshold.hpp"

#include "absl/strings/str_cat.h"
#include "core/family/area_ratio.hpp"

namespace galpha {

double PublishedAlphaSq(const AlphaFamily& family, int64_t level) {
  return level <= 0 ? family.min_alpha_sq() : family.spectrum()[static_cast<size_t>(level - 1)];
}

absl::StatusOr<ResolvedThreshold> ResolveThreshold(const AlphaFamily& family, const Threshold& threshold) {
  ResolvedThreshold resolved;
  absl::StatusOr<int64_t> level;
  switch (threshold.kind) {
    case Threshold::Kind::kRank:
      level = family.LevelForRank(threshold.rank);
      // A rank outside 0..K is a bad argument of the request (LevelForRank says OutOfRange).
      if (!level.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("rank ", threshold.rank, " is outside 0..", family.max_level(),
                                                       " (the spectrum has ", family.max_level(), " values)"));
      }
      resolved.alpha_sq = PublishedAlphaSq(family, *level);
      break;
    case Threshold::Kind::kAlphaSq:
      level = family.LevelForAlphaSq(threshold.value);
      resolved.alpha_sq = threshold.value;
      break;
    case Threshold::Kind::kAlpha:
      level = family.LevelForAlpha(threshold.value);
      resolved.alpha_sq = threshold.value * threshold.value;
      break;
    case Threshold::Kind::kRatio:
      level = LevelForAreaRatio(family, threshold.value);
      if (level.ok()) resolved.alpha_sq = PublishedAlphaSq(family, *level);
      break;
  }
  if (!level.ok()) return absl::InvalidArgumentError(level.status().message());
  resolved.level = *level;
  return resolved;
}

}  // namespace galpha
