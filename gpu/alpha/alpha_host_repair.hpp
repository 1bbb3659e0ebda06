// The host's part of the exact spectrum: long runs of possibly tied entries (three-way quicksort
// with exact comparisons, so that a run of n equal values costs n comparisons), entries whose keys
// are not certified (merged by exact binary search), and nearest doubles beyond the bounded
// arithmetic. Comparisons try the bounded expansions first and fall back to GMP rationals.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/family/alpha_ranks.hpp"
#include "gpu/alpha/alpha_backend.hpp"

namespace galpha::detail {

/// Sorts ids[b..e) exactly for every run {b, e} and sets new_value[i] to 1 where an exact value
/// starts, 0 inside a tie.
void RepairRunsOnHost(const AlphaInput& in, const std::vector<std::array<uint32_t, 2>>& runs, uint32_t* ids,
                      uint8_t* new_value, ComparisonCounts* counts);

/// Inserts the simplices `odd` (keys not certified) into the exact order ids/new_value.
void MergeUncertifiedOnHost(const AlphaInput& in, std::vector<uint32_t> odd, std::vector<uint32_t>* ids,
                            std::vector<uint8_t>* new_value, ComparisonCounts* counts);

/// out->spectrum[r] for every rank with needs[r], by GMP.
void NearestValuesOnHost(const AlphaInput& in, const std::vector<uint8_t>& needs, AlphaRanks* out);

}  // namespace galpha::detail
