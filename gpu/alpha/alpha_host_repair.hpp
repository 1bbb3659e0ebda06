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

/// `max_comparisons` for no limit on the host's exact comparisons.
inline constexpr uint64_t kNoComparisonLimit = ~uint64_t{0};

/// Sorts ids[b..e) exactly for every run {b, e} and sets new_value[i] to 1 where an exact value
/// starts, 0 inside a tie. Past `max_comparisons` exact comparisons (over it by at most a few
/// hundred per thread) it stops comparing and returns false: the order is unfinished then, and
/// the caller must not use it.
[[nodiscard]] bool RepairRunsOnHost(const AlphaInput& in, const std::vector<std::array<uint32_t, 2>>& runs,
                                    uint64_t max_comparisons, uint32_t* ids, uint8_t* new_value,
                                    ComparisonCounts* counts);

/// Inserts the simplices `odd` (keys not certified) into the exact order ids/new_value; stops and
/// returns false as RepairRunsOnHost past `max_comparisons`.
[[nodiscard]] bool MergeUncertifiedOnHost(const AlphaInput& in, std::vector<uint32_t> odd, uint64_t max_comparisons,
                                          std::vector<uint32_t>* ids, std::vector<uint8_t>* new_value,
                                          ComparisonCounts* counts);

/// out->spectrum[r] for every rank with needs[r], by GMP.
void NearestValuesOnHost(const AlphaInput& in, const std::vector<uint8_t>& needs, AlphaRanks* out);

/// Weighted: whether each edge of `edge_ids` (edge ids) is attached by the third vertex of one of
/// its triangles (`edge_triangles`, per edge), by GMP: the edges whose attachment the bounded
/// arithmetic left undecided. attached[i] is 1 or 0.
void ResolveAttachmentOnHost(const AlphaInput& in, const std::array<int32_t, 2>* edge_triangles,
                             const std::vector<uint32_t>& edge_ids, std::vector<uint8_t>* attached);

}  // namespace galpha::detail
