#include "server/family_reader.hpp"

#include <algorithm>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.hpp"
#include "core/family/area_ratio.hpp"
#include "gpu/alpha/persistence_engine.hpp"

namespace galpha::server {

absl::StatusOr<ResolvedThreshold> HostFamilyReader::Resolve(const Threshold& threshold) const {
  return ResolveThreshold(*family_, threshold);
}

absl::StatusOr<int64_t> HostFamilyReader::RankLowerBound(double alpha_sq) const {
  return family_->RankLowerBound(alpha_sq);
}

absl::StatusOr<Classification> HostFamilyReader::ClassifyAll(int64_t level, ClassifyMode mode, VertexRule rule) const {
  return family_->ClassifyAll(level, mode, rule);
}

absl::StatusOr<std::vector<TopologyAtLevel>> HostFamilyReader::TopologyBetween(int64_t first, int64_t last) const {
  std::vector<TopologyAtLevel> out;
  for (int64_t level = first; level <= last; ++level) {
    out.push_back(TopologyAtLevel{family_->Components(level), family_->SolidComponents(level),
                                  family_->RegularizedComponents(level), family_->Holes(level, ClassifyMode::kGeneral),
                                  family_->Holes(level, ClassifyMode::kRegularized)});
  }
  return out;
}

absl::StatusOr<double> HostFamilyReader::HullAreaApprox() const { return galpha::HullAreaApprox(*family_); }

absl::StatusOr<double> HostFamilyReader::PublishedAlphaSq(int64_t level) const {
  return galpha::PublishedAlphaSq(*family_, level);
}

absl::StatusOr<std::optional<int64_t>> HostFamilyReader::OptimalLevelRegularized(
    uint32_t n, std::optional<uint32_t> max_holes) const {
  return family_->OptimalLevelRegularized(n, max_holes);
}

absl::StatusOr<std::optional<int64_t>> HostFamilyReader::OptimalLevelGeneral(uint32_t n,
                                                                             std::optional<uint32_t> max_holes) const {
  return family_->OptimalLevelGeneral(n, max_holes);
}

absl::StatusOr<std::vector<double>> HostFamilyReader::Spectrum(int64_t first_index, int64_t count) const {
  const auto& spectrum = family_->spectrum();
  const int64_t k = family_->max_level();
  first_index = std::clamp<int64_t>(first_index, 0, k);
  count = std::clamp<int64_t>(count, 0, k - first_index);
  return std::vector<double>(spectrum.begin() + first_index, spectrum.begin() + first_index + count);
}

absl::StatusOr<std::vector<uint32_t>> HostFamilyReader::MasterBegins(int64_t first_rank, int64_t count) const {
  const auto& begin = family_->ranks().master_begin;
  if (first_rank < 0 || count < 0 || static_cast<size_t>(first_rank + count) > begin.size()) {
    return absl::OutOfRangeError(absl::StrCat("master-list starts ", first_rank, "..", first_rank + count - 1,
                                              " are outside 0..", begin.size() - 1));
  }
  return std::vector<uint32_t>(begin.begin() + first_rank, begin.begin() + first_rank + count);
}

absl::StatusOr<std::vector<MasterEntry>> HostFamilyReader::MasterEntries(uint64_t position, uint64_t count) const {
  const auto& master = family_->ranks().master;
  if (position + count > master.size()) {
    return absl::OutOfRangeError(
        absl::StrCat("master-list entries ", position, "..", position + count, " pass its end, ", master.size()));
  }
  return std::vector<MasterEntry>(master.begin() + static_cast<int64_t>(position),
                                  master.begin() + static_cast<int64_t>(position + count));
}

absl::StatusOr<ResolvedThreshold> ResidentFamilyReader::Resolve(const Threshold& threshold) const {
  ResolvedThreshold resolved;
  absl::StatusOr<int64_t> level;
  switch (threshold.kind) {
    case Threshold::Kind::kRank: {
      level = family_->LevelForRank(threshold.rank);
      // The message ResolveThreshold gives (core/family/threshold.cpp).
      if (!level.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("rank ", threshold.rank, " is outside 0..", family_->max_level(),
                                                       " (the spectrum has ", family_->max_level(), " values)"));
      }
      GALPHA_ASSIGN_OR_RETURN(resolved.alpha_sq, family_->PublishedAlphaSq(*level));
      break;
    }
    case Threshold::Kind::kAlphaSq:
      level = family_->LevelForAlphaSq(threshold.value);
      resolved.alpha_sq = threshold.value;
      break;
    case Threshold::Kind::kAlpha:
      level = family_->LevelForAlpha(threshold.value);
      resolved.alpha_sq = threshold.value * threshold.value;
      break;
    case Threshold::Kind::kRatio:
      level = family_->LevelForAreaRatio(threshold.value);
      if (level.ok()) {
        GALPHA_ASSIGN_OR_RETURN(resolved.alpha_sq, family_->PublishedAlphaSq(*level));
      }
      break;
  }
  if (!level.ok()) {
    if (level.status().code() == absl::StatusCode::kInvalidArgument) {
      return absl::InvalidArgumentError(level.status().message());
    }
    return level.status();  // a device failure stays what it is
  }
  resolved.level = *level;
  return resolved;
}

absl::StatusOr<PersistenceDiagram> HostFamilyReader::Persistence(absl::Span<const uint32_t> edge_order,
                                                                 absl::Span<const uint32_t> triangle_order) const {
  return PersistenceDiagramOf(*family_, edge_order, triangle_order);
}

absl::StatusOr<PersistenceDiagram> ResidentFamilyReader::Persistence(absl::Span<const uint32_t>,
                                                                     absl::Span<const uint32_t>) const {
  return family_->Persistence();  // the device sorts its canonical orders itself
}

absl::StatusOr<std::shared_ptr<const AlphaFamily>> ResidentFamilyReader::HostFamily() const {
  GALPHA_ASSIGN_OR_RETURN(AlphaFamily host, family_->ToHostFamily());
  return std::make_shared<const AlphaFamily>(std::move(host));
}

}  // namespace galpha::server
