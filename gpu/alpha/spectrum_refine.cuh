// The spectrum's long runs of near ties, ordered by refined keys (core/exact/radius_refined.hpp)
// instead of by exact comparisons inside each run. Runs longer than kMaxDeviceRun used to go to
// the host whole (a three-way quicksort with exact comparisons: 44 s for a 1000 x 1000 lattice
// perturbed by single ulps); here the entries of such a run are first grouped into classes of
// congruent simplices (equal values, proved by RadiusCongruent: a lattice's long runs are mostly
// copies of a few cells), every class gets a key certified within 2^-150 from its first member,
// the classes are radix-sorted by (run, key truncated to 160 bits, id) (refined_sort_words.hpp),
// and only adjacent classes the keys cannot separate are compared exactly: O(n) comparisons, all
// in parallel, on the backend's cores. Each class's other members then follow its first one.
//
// Why the result is exact:
//  - A class is a range of entries of one run, sorted by a hash of their congruence form, in which
//    every entry is congruent to the one before (checked exactly: a hash collision only splits a
//    class), so all of them have one exact value. Ordering the classes orders the entries, and the
//    members after the first are marked equal to it.
//  - Below, "entry" is a class, represented by its first member.
//  - Two adjacent entries whose keys are separated (RefinedKeysSeparated) have exact values in
//    that order, and since the keys are sorted by truncations within 3 * 2^-160 of their values and
//    each is within its certified error of its entry's value, every entry before the pair is below
//    every entry after it: a separated pair is a certified boundary (refined_sort_words.hpp).
//  - Between boundaries lie clusters of entries whose keys may tie. A cluster whose adjacent pairs
//    all compare Less or Equal exactly is in exact order (order is transitive); its links are cut
//    and the equal pairs marked as one value.
//  - A cluster with a pair out of order ("bad": distinct values closer than the keys' error, as a
//    lattice nudged by single ulps has, 2^-146 to 2^-224 apart, among thousands of exact ties) is
//    sorted again on the system (SortBadClusters): by all its pairs' exact signs at once for a
//    cluster of up to kMaxPairwiseCluster entries, by rounds of exact three-way partitions for a
//    larger one. Its boundaries are certified, so it may be reordered freely; both ways give
//    the order by (exact value, key order). A cluster where some bounded
//    comparison is undecided, or that needs more than kMaxPartitionRounds rounds, keeps its first
//    order and its links, and becomes a run of its own for the exact repair of short runs (a
//    thread's insertion sort for up to kMaxDeviceRun entries, the host's beyond).
//  - A run with an entry whose key cannot be refined (exact terms beyond the bounded buffers) is
//    left whole to the existing repair.
//  - A long run whose values are all exactly one double (ExactDoubleRadiusSq: a grid) is settled
//    before any key is computed, by one double comparison per entry.
#pragma once

#include <thrust/copy.h>
#include <thrust/count.h>
#include <thrust/fill.h>
#include <thrust/for_each.h>
#include <thrust/functional.h>
#include <thrust/gather.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/reverse_iterator.h>
#include <thrust/iterator/transform_iterator.h>
#include <thrust/scan.h>
#include <thrust/sequence.h>
#include <thrust/sort.h>
#include <thrust/transform.h>
#include <thrust/transform_reduce.h>

#include <cstdint>
#include <utility>

#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/expansion.hpp"
#include "core/exact/order.hpp"
#include "core/exact/radius_compare.hpp"
#include "core/exact/radius_refined.hpp"
#include "core/exact/refined_sort_words.hpp"
#include "core/family/alpha_ranks.hpp"
#include "gpu/alpha/alpha_functors.cuh"
#include "gpu/system/atomic_increment.cuh"
#include "gpu/system/engine_system.cuh"

namespace galpha::detail {

/// One congruence group of a long run (its first member's simplex) with its refined key.
struct RefinedEntry {
  uint32_t run;    // the run's index in the run list
  uint32_t id;     // the simplex
  uint32_t group;  // the group's index in grouping order (RefineLongRuns)
  RefinedRadiusSq key;
};

/// Word `w` of entry perm[k]'s sort words (one pass of the least-significant-word-first sort).
/// Computed again each pass rather than kept: four words of every entry would be the stage's
/// largest buffer (a lattice nudged by ulps peaked 19 B/pt higher with them, on the H100).
struct SortWordOf {
  const RefinedEntry* entries;
  const uint32_t* perm;
  int w;
  GALPHA_HD uint64_t operator()(uint32_t k) const {
    const RefinedEntry& entry = entries[perm[k]];
    return RefinedSortWordsOf(entry.run, entry.id, entry.key).word[w];
  }
};

/// The smallest and largest value of each sort word over a set of entries.
struct SortWordRange {
  uint64_t low[4];
  uint64_t high[4];
};

struct SortWordRangeOf {
  const RefinedEntry* entries;
  GALPHA_HD SortWordRange operator()(uint32_t k) const {
    const RefinedSortWords words = RefinedSortWordsOf(entries[k].run, entries[k].id, entries[k].key);
    SortWordRange range;
    for (int w = 0; w < 4; ++w) range.low[w] = range.high[w] = words.word[w];
    return range;
  }
};

struct MergeSortWordRanges {
  GALPHA_HD SortWordRange operator()(const SortWordRange& a, const SortWordRange& b) const {
    SortWordRange range;
    for (int w = 0; w < 4; ++w) {
      range.low[w] = a.low[w] < b.low[w] ? a.low[w] : b.low[w];
      range.high[w] = a.high[w] > b.high[w] ? a.high[w] : b.high[w];
    }
    return range;
  }
};

/// 1 for runs longer than kMaxDeviceRun (the runs the device cannot sort itself).
struct IsLongRun {
  const uint32_t* run_begin;
  GALPHA_HD uint8_t operator()(uint32_t r) const { return run_begin[r + 1] - run_begin[r] > kMaxDeviceRun ? 1 : 0; }
};

/// The entries of long runs that are not all one double (those are settled without keys).
struct InLongRun {
  const uint32_t* run_of;  // inclusive scan of run starts: 1-based run index of each entry
  const uint32_t* run_begin;
  const uint8_t* one_double;  // per run: every value is exactly the same double
  GALPHA_HD bool operator()(uint32_t i) const {
    const uint32_t r = run_of[i] - 1;
    return run_begin[r + 1] - run_begin[r] > kMaxDeviceRun && !one_double[r];
  }
};

/// Cuts the links inside a run whose values are all one double: its entries become settled runs
/// of one (SettleRunOfOneDouble has marked the values).
struct CutLinksOfOneDouble {
  const uint32_t* run_of;
  const uint32_t* run_begin;
  const uint8_t* one_double;
  uint8_t* link;
  GALPHA_HD void operator()(uint32_t i) const {
    const uint32_t r = run_of[i] - 1;
    if (one_double[r] && i != run_begin[r]) link[i - 1] = 0;
  }
};

/// Adds a settled run of one double's comparisons (one per entry after its first) to the count.
struct CountSettledComparisons {
  SettledComparisons comparisons;
  unsigned long long* exact_count;
  GALPHA_HD void operator()(uint32_t r) const {
    const uint64_t proved = comparisons(r);
    if (proved > 0) AtomicAddU64(exact_count, proved);
  }
};

/// The refined key of group k, from its first member at spectrum position `positions[k]`; marks
/// its run unrefinable when it has none.
struct ComputeRefinedEntry {
  SimplexPoints simplex;
  const uint32_t* positions;  // per group
  const uint32_t* run_of;
  const uint32_t* ids;
  RefinedEntry* entries;
  uint8_t* run_unrefinable;  // per run; only ever set to 1
  GALPHA_HD void operator()(uint32_t k) const {
    const uint32_t i = positions[k];
    RefinedEntry entry;
    entry.run = run_of[i] - 1;
    entry.id = ids[i];
    entry.group = k;
    Point2 p[3];
    double w[3];
    const int n = simplex(entry.id, p, w);
    entry.key = RefineSimplexRadiusSq(p, simplex.Weights(w), n);
    if (!entry.key.ok) run_unrefinable[entry.run] = 1;
    entries[k] = entry;
  }
};

/// Verdict on sorted entries k - 1 and k of the same refinable run: kPairSeparated (a certified
/// boundary), kPairLess / kPairEqual (decided exactly), or kPairBad (out of order or undecided).
/// The first entry of a run gets kPairSeparated: runs are apart by their 64-bit keys.
constexpr uint8_t kPairSeparated = 0, kPairLess = 1, kPairEqual = 2, kPairBad = 3;

struct JudgeRefinedPair {
  SimplexPoints simplex;
  const RefinedEntry* entries;
  const uint8_t* run_unrefinable;
  uint8_t* verdict;
  unsigned long long* exact_count;  // bounded exact comparisons
  GALPHA_HD void operator()(uint32_t k) const {
    if (k == 0 || entries[k - 1].run != entries[k].run || run_unrefinable[entries[k].run]) {
      verdict[k] = kPairSeparated;
      return;
    }
    const RefinedEntry& a = entries[k - 1];
    const RefinedEntry& b = entries[k];
    if (RefinedKeysSeparated(a.key, b.key)) {
      verdict[k] = kPairSeparated;
      return;
    }
    Point2 pa[3], pb[3];
    double wa[3], wb[3];
    const int na = simplex(a.id, pa, wa), nb = simplex(b.id, pb, wb);
    if (SimplexRadiusCongruent(pa, simplex.Weights(wa), na, pb, simplex.Weights(wb), nb)) {
      verdict[k] = kPairEqual;
      return;
    }
    AtomicAddU64(exact_count, 1);
    const Order order = CompareSimplexRadiusSqBounded(pa, simplex.Weights(wa), na, pb, simplex.Weights(wb), nb);
    verdict[k] = order == Order::kLess ? kPairLess : order == Order::kEqual ? kPairEqual : kPairBad;
  }
};

/// The grouping key of long-run entry k (spectrum position positions[k]): its run and the hash of
/// its congruence form, so that sorting by it puts each run's congruent simplices together. 32
/// bits, the mixed hash's high half: the sort is half the radix passes of a 64-bit key (a lattice
/// nudged by single ulps groups 4.6M entries at 1M), and a collision only splits a class (the
/// classes of one key are told apart by the exact congruence test, StartsCongruenceGroup).
struct CongruenceGroupKey {
  SimplexPoints simplex;
  const uint32_t* positions;
  const uint32_t* run_of;
  const uint32_t* ids;
  GALPHA_HD uint32_t operator()(uint32_t k) const {
    const uint32_t i = positions[k];
    Point2 p[3];
    double w[3];
    const int n = simplex(ids[i], p, w);
    return static_cast<uint32_t>(
        ((SimplexCongruenceHash(p, simplex.Weights(w), n) ^ run_of[i]) * 0x9e3779b97f4a7c15ULL) >> 32);
  }
};

/// 1 where a congruence group starts among the entries in grouping order (member[s]: the entry at
/// grouping position s): at the first entry, a new key, a new run, or a neighbour that the exact
/// congruence test does not confirm (a hash collision: the group is only smaller).
struct StartsCongruenceGroup {
  SimplexPoints simplex;
  const uint32_t* key;
  const uint32_t* member;
  const uint32_t* positions;
  const uint32_t* run_of;
  const uint32_t* ids;
  GALPHA_HD uint32_t operator()(uint32_t s) const {
    if (s == 0 || key[s] != key[s - 1]) return 1;
    const uint32_t i = positions[member[s]], h = positions[member[s - 1]];
    if (run_of[i] != run_of[h]) return 1;
    Point2 pa[3], pb[3];
    double wa[3], wb[3];
    const int na = simplex(ids[h], pa, wa), nb = simplex(ids[i], pb, wb);
    return SimplexRadiusCongruent(pa, simplex.Weights(wa), na, pb, simplex.Weights(wb), nb) ? 0u : 1u;
  }
};

/// Writes the grouping position where each group starts (group_of: 1-based inclusive scan). A
/// scatter rather than a compaction, whose count the host would wait for.
struct MarkGroupFirst {
  const uint32_t* group_of;
  uint32_t* group_first;
  GALPHA_HD void operator()(uint32_t s) const {
    if (s == 0 || group_of[s] != group_of[s - 1]) group_first[group_of[s] - 1] = s;
  }
};

/// The spectrum position of group g's first member (its representative, whose key the group
/// shares exactly).
struct GroupLeaderPosition {
  const uint32_t* group_first;  // grouping position of each group's first member
  const uint32_t* member;
  const uint32_t* positions;
  GALPHA_HD uint32_t operator()(uint32_t g) const { return positions[member[group_first[g]]]; }
};

/// The simplex of the entry at grouping position s (read before the spectrum is rewritten).
struct MemberId {
  const uint32_t* member;
  const uint32_t* positions;
  const uint32_t* ids;
  GALPHA_HD uint32_t operator()(uint32_t s) const { return ids[positions[member[s]]]; }
};

/// The number of members of the group at sorted position k.
struct GroupSizeOfEntry {
  const RefinedEntry* entries;
  const uint32_t* group_first;  // num_groups + 1 entries
  GALPHA_HD uint32_t operator()(uint32_t k) const {
    const uint32_t g = entries[k].group;
    return group_first[g + 1] - group_first[g];
  }
};

/// Marks where each sorted group's members begin among the run positions (for a maximum scan).
struct MarkExpandedStart {
  const uint32_t* expanded_start;
  uint32_t* leader_of;
  GALPHA_HD void operator()(uint32_t k) const { leader_of[expanded_start[k]] = k; }
};

/// Lays the groups out over the runs' positions in sorted order, each group's members after its
/// first one, and gives every position its run, verdict (a member after the first: kPairEqual,
/// proved by congruence) and cluster. Sorting by run first keeps each run over its own positions
/// (they ascend, and a run's groups hold as many members as it has positions).
struct ExpandGroups {
  const RefinedEntry* entries;
  const uint32_t* expanded_start;
  const uint32_t* leader_of;  // sorted position of the group that covers each expanded position
  const uint32_t* group_first;
  const uint32_t* member_id;  // by grouping position
  const uint32_t* positions;
  const uint8_t* verdict;      // per sorted group
  const uint32_t* cluster_of;  // per sorted group
  uint32_t* ids;
  uint32_t* run;  // per expanded position
  uint8_t* expanded_verdict;
  uint32_t* expanded_cluster;
  GALPHA_HD void operator()(uint32_t e) const {
    const uint32_t k = leader_of[e];
    const uint32_t j = e - expanded_start[k];
    const RefinedEntry& entry = entries[k];
    ids[positions[e]] = member_id[group_first[entry.group] + j];
    run[e] = entry.run;
    expanded_verdict[e] = j == 0 ? verdict[k] : kPairEqual;
    expanded_cluster[e] = cluster_of[k];
  }
};

/// 1 where a cluster starts: at a separated pair (or a run's first entry).
struct ClusterStartAsU32 {
  const uint8_t* verdict;
  GALPHA_HD uint32_t operator()(uint32_t k) const { return verdict[k] == kPairSeparated ? 1u : 0u; }
};

/// Sign of value(a) - value(b) for two entries of one bad cluster `cluster`: their keys where they
/// are separated, else a congruence proof or the bounded exact comparison (counted). Where that is
/// undecided the cluster is marked (it goes to the host in its first order) and 0 is answered.
GALPHA_HD inline int ExactClusterEntrySign(const SimplexPoints& simplex, const RefinedEntry& a, const RefinedEntry& b,
                                           uint32_t cluster, uint8_t* cluster_undecided,
                                           unsigned long long* exact_count) {
  if (RefinedKeysSeparated(a.key, b.key)) return -1;
  if (RefinedKeysSeparated(b.key, a.key)) return 1;
  Point2 pa[3], pb[3];
  double wa[3], wb[3];
  const int na = simplex(a.id, pa, wa), nb = simplex(b.id, pb, wb);
  if (SimplexRadiusCongruent(pa, simplex.Weights(wa), na, pb, simplex.Weights(wb), nb)) return 0;
  AtomicAddU64(exact_count, 1);
  const Order order = CompareSimplexRadiusSqBounded(pa, simplex.Weights(wa), na, pb, simplex.Weights(wb), nb);
  if (order != Order::kUndecided) return SignOf(order);
  cluster_undecided[cluster] = 1;  // concurrent writes only ever write 1
  return 0;
}

/// 1 for sorted entries in a bad cluster.
struct InBadCluster {
  const uint32_t* cluster_of;  // 1-based
  const uint8_t* cluster_bad;
  GALPHA_HD bool operator()(uint32_t k) const { return cluster_bad[cluster_of[k] - 1] != 0; }
};

// The bad clusters are sorted by rounds of three-way partitions, in parallel over all of them
// (measured on a lattice nudged by single ulps: a bad cluster holds thousands of entries but only
// a few distinct values, most entries exact ties that are not congruent). The entries of the bad
// clusters sit in "slots"; a slot's segment is a contiguous range of slots, at first its cluster.
// Each round compares every entry of an unsettled segment with the segment's middle entry (the
// pivot) exactly, and a stable sort by (segment, sign) splits the segment into the entries below,
// equal to and above the pivot, in that order. The equal part is settled: one exact value.
// Every segment lies between certified bounds, each round keeps the segments in exact order, and
// a settled segment is one value; so when no slot is unsettled the slots are in exact order. The
// order inside a value is the key order (stable sorts), the same on both backends.

/// 64-bit sort word of slot j for the next round: its segment, then its part (0 below the pivot,
/// 1 equal or settled, 2 above).
struct PartitionWord {
  SimplexPoints simplex;
  const RefinedEntry* entries;  // by sorted position k
  const uint32_t* cluster_of;   // 1-based, by k
  const uint32_t* item;         // slot -> k
  const uint32_t* segment;      // slot -> segment
  const uint32_t* segment_begin;
  const uint32_t* segment_end;  // exclusive
  const uint8_t* settled;
  uint8_t* cluster_undecided;
  unsigned long long* exact_count;
  GALPHA_HD uint64_t operator()(uint32_t j) const {
    const uint64_t high = uint64_t{segment[j]} << 2;
    if (settled[j]) return high | 1;
    const uint32_t pivot_slot = segment_begin[j] + (segment_end[j] - segment_begin[j]) / 2;
    if (pivot_slot == j) return high | 1;
    const uint32_t k = item[j];
    const int sign = ExactClusterEntrySign(simplex, entries[k], entries[item[pivot_slot]], cluster_of[k] - 1,
                                           cluster_undecided, exact_count);
    return high | static_cast<uint64_t>(sign + 1);
  }
};

/// Where slot j's segment begins (as a candidate for a maximum scan) and ends (for a minimum scan
/// from the right).
struct SegmentBeginCandidate {
  const uint32_t* segment;
  GALPHA_HD uint32_t operator()(uint32_t j) const { return j == 0 || segment[j] != segment[j - 1] ? j : 0; }
};
struct SegmentEndCandidate {
  const uint32_t* segment;
  uint32_t num_slots;
  GALPHA_HD uint32_t operator()(uint32_t j) const {
    return j + 1 == num_slots || segment[j] != segment[j + 1] ? j + 1 : num_slots;
  }
};

/// After a round's sort: a new segment starts where the (segment, part) word changes; the equal
/// part (and what was settled before) is settled.
struct NewSegmentStart {
  const uint64_t* word;
  GALPHA_HD uint32_t operator()(uint32_t j) const { return j == 0 || word[j] != word[j - 1] ? 1u : 0u; }
};
struct SettledOfWord {
  GALPHA_HD uint8_t operator()(uint64_t word) const { return (word & 3) == 1 ? 1 : 0; }
};

/// A slot still unsettled when the rounds run out sends its cluster to the host.
struct GiveUpUnsettled {
  const uint32_t* cluster_of;
  const uint32_t* item;
  const uint8_t* settled;
  uint8_t* cluster_undecided;
  GALPHA_HD void operator()(uint32_t j) const {
    if (!settled[j]) cluster_undecided[cluster_of[item[j]] - 1] = 1;
  }
};

/// Puts a sorted bad cluster back over its own sorted positions with its verdicts: a value's first
/// entry kPairLess (the cluster's first stays kPairSeparated), the others kPairEqual. A cluster
/// left undecided keeps its first order and verdicts.
struct ScatterSortedCluster {
  const RefinedEntry* by_slot;  // entries[item[j]]
  const uint32_t* bad_k;        // slot -> its position in the cluster's range (ascending)
  const uint32_t* cluster_of;
  const uint32_t* segment;
  const uint8_t* cluster_undecided;
  RefinedEntry* entries;
  uint8_t* verdict;
  GALPHA_HD void operator()(uint32_t j) const {
    const uint32_t k = bad_k[j];
    if (cluster_undecided[cluster_of[k] - 1]) return;
    entries[k] = by_slot[j];
    if (verdict[k] == kPairSeparated) return;  // the cluster's first slot
    verdict[k] = segment[j] != segment[j - 1] ? kPairLess : kPairEqual;
  }
};

/// Bad clusters of at most this many entries are sorted by comparing all their pairs at once
/// (SignOfClusterPair, PlaceByRank) instead of by partition rounds: a lattice nudged by single ulps
/// at 1M has 19 bad clusters of at most 10 entries, and each round is about ten launches and two
/// waits (five rounds, 1.1 ms on the H200). One thread's insertion sort of such a cluster (tried)
/// waited 1.7 ms on its chain of exact comparisons; all pairs side by side wait for one.
constexpr uint32_t kMaxPairwiseCluster = 32;

/// Writes where each cluster begins: at a separated pair (or the first entry). A scatter rather
/// than a compaction, whose count the host would wait for.
struct MarkClusterBegin {
  const uint8_t* verdict;
  const uint32_t* cluster_of;  // 1-based
  uint32_t* cluster_begin;
  GALPHA_HD void operator()(uint32_t k) const {
    if (verdict[k] == kPairSeparated) cluster_begin[cluster_of[k] - 1] = k;
  }
};

/// 1 for a bad cluster of at most kMaxPairwiseCluster entries.
struct IsSmallBadCluster {
  const uint8_t* cluster_bad;
  const uint32_t* cluster_begin;  // num_clusters + 1
  GALPHA_HD bool operator()(uint32_t c) const {
    return cluster_bad[c] != 0 && cluster_begin[c + 1] - cluster_begin[c] <= kMaxPairwiseCluster;
  }
};

/// Sign of value(i) - value(j) for entries i < j of small bad cluster small[t / 1024] (i and j
/// from t's low bits), into sign[t]. An undecided pair marks its cluster (ExactClusterEntrySign).
struct SignOfClusterPair {
  SimplexPoints simplex;
  const RefinedEntry* entries;
  const uint32_t* small;  // cluster indices
  const uint32_t* cluster_begin;
  uint8_t* cluster_undecided;
  int8_t* sign;  // kMaxPairwiseCluster^2 per small cluster; only i < j written
  unsigned long long* exact_count;
  GALPHA_HD void operator()(uint32_t t) const {
    constexpr uint32_t kSide = kMaxPairwiseCluster;
    const uint32_t c = small[t / (kSide * kSide)];
    const uint32_t i = (t / kSide) % kSide, j = t % kSide;
    const uint32_t begin = cluster_begin[c], size = cluster_begin[c + 1] - begin;
    if (i >= j || j >= size) return;
    sign[t] = static_cast<int8_t>(
        ExactClusterEntrySign(simplex, entries[begin + i], entries[begin + j], c, cluster_undecided, exact_count));
  }
};

/// Places entry i of small bad cluster small[t / 32] at its rank: the entries below it, and the
/// equal ones before it (so equal values keep their key order, as the partition rounds keep it:
/// both give the one order by (exact value, key order)). Writes where the entry comes from
/// (`source`, for a gather) and its verdict: kPairLess where a value starts, kPairEqual inside
/// one; the cluster's first position keeps kPairSeparated. A cluster with an undecided pair keeps
/// its order and verdicts, and so stays bad. Either way it leaves `cluster_bad` (the rounds skip
/// it; the caller marks bad clusters again from the verdicts).
struct PlaceByRank {
  const uint32_t* small;
  const uint32_t* cluster_begin;
  const uint8_t* cluster_undecided;
  const int8_t* sign;
  uint8_t* cluster_bad;
  uint32_t* source;  // per sorted position: the position whose entry goes there
  uint8_t* verdict;
  GALPHA_HD void operator()(uint32_t t) const {
    constexpr uint32_t kSide = kMaxPairwiseCluster;
    const uint32_t slot = t / kSide, i = t % kSide;
    const uint32_t c = small[slot];
    const uint32_t begin = cluster_begin[c], size = cluster_begin[c + 1] - begin;
    if (i == 0) cluster_bad[c] = 0;
    if (i >= size || cluster_undecided[c]) return;
    const int8_t* pairs = sign + size_t{slot} * kSide * kSide;
    uint32_t rank = 0;
    bool equal_before = false;
    for (uint32_t j = 0; j < size; ++j) {
      if (j == i) continue;
      // Sign of value(j) - value(i), from the pair's one comparison.
      const int s = j < i ? pairs[j * kSide + i] : -pairs[i * kSide + j];
      if (s < 0 || (s == 0 && j < i)) ++rank;
      if (s == 0 && j < i) equal_before = true;
    }
    source[begin + rank] = begin + i;
    if (rank > 0) verdict[begin + rank] = equal_before ? kPairEqual : kPairLess;
  }
};

/// Rounds of partitions before a bad cluster is given up to the host: each round at least halves
/// the number of distinct values in a segment it splits evenly, and settles the pivot's value.
constexpr int kMaxPartitionRounds = 64;

/// Marks the clusters that hold a bad pair; concurrent writes only ever write 1.
struct MarkBadCluster {
  const uint8_t* verdict;
  const uint32_t* cluster_of;  // 1-based
  uint8_t* cluster_bad;
  GALPHA_HD void operator()(uint32_t k) const {
    if (verdict[k] == kPairBad) cluster_bad[cluster_of[k] - 1] = 1;
  }
};

/// Writes the verdicts of the expanded positions (ExpandGroups) into the spectrum: entries of a
/// good cluster become runs of one (links cut), with new_value 0 for an entry equal to the one
/// before; a bad cluster keeps its links; every separated pair is cut and starts a new value. Runs
/// left unrefinable are not touched.
struct ApplyRefinedVerdicts {
  const uint32_t* positions;
  const uint32_t* run;  // per expanded position
  const uint8_t* run_unrefinable;
  const uint8_t* verdict;
  const uint32_t* cluster_of;
  const uint8_t* cluster_bad;
  uint8_t* link;       // link[i]: entries i and i + 1 may tie
  uint8_t* new_value;  // 1 where an exact value starts
  GALPHA_HD void operator()(uint32_t e) const {
    if (run_unrefinable[run[e]]) return;
    const uint32_t i = positions[e];
    if (verdict[e] == kPairSeparated) {
      if (e > 0 && run[e - 1] == run[e]) link[i - 1] = 0;
      new_value[i] = 1;  // a run's first entry, or above everything before it
      return;
    }
    if (cluster_bad[cluster_of[e] - 1]) return;  // the cluster stays one run for the exact repair
    link[i - 1] = 0;
    new_value[i] = verdict[e] == kPairEqual ? 0 : 1;
  }
};

/// Sorts refined entries by their sort words (RefinedSortWords): least significant word first, each
/// pass a stable radix sort of one 64-bit word carrying a permutation, then one gather. A word
/// that is the same in every entry (one run at one exponent: a lattice's long run) orders nothing,
/// and its sort is skipped: a stable sort by a constant key leaves the permutation as it is. The
/// constant words are found by one reduction before the passes (one wait instead of four: the
/// passes are short and the stage is mostly launches and waits).
template <class System>
void SortRefinedEntries(System& sys, Buffer<RefinedEntry, System>* entries, uint32_t num_refined) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  Buffer<uint32_t, System> perm(sys, num_refined);
  thrust::sequence(policy, perm.data(), perm.data() + num_refined);
  SortWordRange empty;
  for (int w = 0; w < 4; ++w) {
    empty.low[w] = ~uint64_t{0};
    empty.high[w] = 0;
  }
  const SortWordRange range = thrust::transform_reduce(policy, zero, zero + num_refined,
                                                       SortWordRangeOf{entries->data()}, empty, MergeSortWordRanges{});
  Buffer<uint64_t, System> word(sys, num_refined);
  for (int w = 3; w >= 0; --w) {
    if (range.low[w] == range.high[w]) continue;
    thrust::transform(policy, zero, zero + num_refined, word.data(), SortWordOf{entries->data(), perm.data(), w});
    thrust::stable_sort_by_key(policy, word.data(), word.data() + num_refined, perm.data());
  }
  word.Reset();
  Buffer<RefinedEntry, System> sorted(sys, num_refined);
  thrust::gather(policy, perm.data(), perm.data() + num_refined, entries->data(), sorted.data());
  *entries = std::move(sorted);
}

/// Sorts the bad clusters of at most kMaxPairwiseCluster entries by all their pairs' exact signs
/// (SignOfClusterPair, PlaceByRank) and moves their entries into the sorted order. `cluster_bad`
/// is cleared for every cluster it took, sorted or left undecided.
template <class System>
void SortSmallBadClusters(System& sys, const SimplexPoints& simplex, RefinedEntry* entries, const uint32_t* cluster_of,
                          uint32_t num_clusters, uint32_t num_refined, Buffer<uint8_t, System>* verdict,
                          Buffer<uint8_t, System>* cluster_bad, Buffer<uint8_t, System>* cluster_undecided,
                          unsigned long long* exact_count) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  Buffer<uint32_t, System> cluster_begin(sys, num_clusters + 1);
  thrust::for_each_n(policy, zero, num_refined, MarkClusterBegin{verdict->data(), cluster_of, cluster_begin.data()});
  thrust::fill_n(policy, cluster_begin.data() + num_clusters, 1, num_refined);
  Buffer<uint32_t, System> small(sys, num_clusters);
  const auto num_small =
      static_cast<uint32_t>(thrust::copy_if(policy, zero, zero + num_clusters, small.data(),
                                            IsSmallBadCluster{cluster_bad->data(), cluster_begin.data()}) -
                            small.data());
  if (num_small == 0) return;
  constexpr uint32_t kSide = kMaxPairwiseCluster;
  if (uint64_t{num_small} * kSide * kSide > 0xFFFFFFFFull) {
    throw EngineError(EngineError::Kind::kInternal, "too many small bad clusters for one launch of pair signs");
  }
  Buffer<int8_t, System> sign(sys, size_t{num_small} * kSide * kSide);
  thrust::for_each_n(policy, zero, num_small * kSide * kSide,
                     SignOfClusterPair{simplex, entries, small.data(), cluster_begin.data(), cluster_undecided->data(),
                                       sign.data(), exact_count});
  Buffer<uint32_t, System> source(sys, num_refined);
  thrust::sequence(policy, source.data(), source.data() + num_refined);
  thrust::for_each_n(policy, zero, num_small * kSide,
                     PlaceByRank{small.data(), cluster_begin.data(), cluster_undecided->data(), sign.data(),
                                 cluster_bad->data(), source.data(), verdict->data()});
  Buffer<RefinedEntry, System> moved(sys, num_refined);
  thrust::gather(policy, source.data(), source.data() + num_refined, entries, moved.data());
  thrust::copy_n(policy, moved.data(), num_refined, entries);
}

/// Sorts the entries of the bad clusters still marked in `cluster_bad` exactly by rounds of
/// three-way partitions (see above) and sets their verdicts.
template <class System>
void PartitionBadClusters(System& sys, const SimplexPoints& simplex, RefinedEntry* entries, const uint32_t* cluster_of,
                          uint32_t num_refined, Buffer<uint8_t, System>* verdict,
                          const Buffer<uint8_t, System>& cluster_bad, Buffer<uint8_t, System>* cluster_undecided,
                          unsigned long long* exact_count) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  Buffer<uint32_t, System> bad_k(sys, num_refined);
  const auto num_slots = static_cast<uint32_t>(
      thrust::copy_if(policy, zero, zero + num_refined, bad_k.data(), InBadCluster{cluster_of, cluster_bad.data()}) -
      bad_k.data());
  if (num_slots == 0) return;
  Buffer<uint32_t, System> item(sys, num_slots);
  thrust::copy_n(policy, bad_k.data(), num_slots, item.data());
  Buffer<uint32_t, System> segment(sys, num_slots);
  thrust::gather(policy, bad_k.data(), bad_k.data() + num_slots, cluster_of, segment.data());
  Buffer<uint8_t, System> settled(sys, num_slots);
  thrust::fill_n(policy, settled.data(), num_slots, uint8_t{0});
  Buffer<uint32_t, System> segment_begin(sys, num_slots), segment_end(sys, num_slots);
  Buffer<uint64_t, System> word(sys, num_slots);
  bool all_settled = false;
  for (int round = 0; round < kMaxPartitionRounds && !all_settled; ++round) {
    const auto begins = thrust::make_transform_iterator(zero, SegmentBeginCandidate{segment.data()});
    thrust::inclusive_scan(policy, begins, begins + num_slots, segment_begin.data(), thrust::maximum<uint32_t>());
    const auto ends = thrust::make_transform_iterator(zero, SegmentEndCandidate{segment.data(), num_slots});
    thrust::inclusive_scan(policy, thrust::make_reverse_iterator(ends + num_slots), thrust::make_reverse_iterator(ends),
                           thrust::make_reverse_iterator(segment_end.data() + num_slots), thrust::minimum<uint32_t>());
    thrust::transform(policy, zero, zero + num_slots, word.data(),
                      PartitionWord{simplex, entries, cluster_of, item.data(), segment.data(), segment_begin.data(),
                                    segment_end.data(), settled.data(), cluster_undecided->data(), exact_count});
    thrust::stable_sort_by_key(policy, word.data(), word.data() + num_slots, item.data());
    const auto starts = thrust::make_transform_iterator(zero, NewSegmentStart{word.data()});
    thrust::inclusive_scan(policy, starts, starts + num_slots, segment.data());
    thrust::transform(policy, word.data(), word.data() + num_slots, settled.data(), SettledOfWord{});
    all_settled = thrust::count(policy, settled.data(), settled.data() + num_slots, uint8_t{0}) == 0;
  }
  word.Reset();
  segment_begin.Reset();
  segment_end.Reset();
  if (!all_settled) {
    thrust::for_each_n(policy, zero, num_slots,
                       GiveUpUnsettled{cluster_of, item.data(), settled.data(), cluster_undecided->data()});
  }
  Buffer<RefinedEntry, System> by_slot(sys, num_slots);
  thrust::gather(policy, item.data(), item.data() + num_slots, entries, by_slot.data());
  thrust::for_each_n(policy, zero, num_slots,
                     ScatterSortedCluster{by_slot.data(), bad_k.data(), cluster_of, segment.data(),
                                          cluster_undecided->data(), entries, verdict->data()});
}

/// Sorts the entries of bad clusters exactly (small ones by all their pairs, the others by partition
/// rounds) and sets their verdicts; `cluster_bad` then marks the clusters left undecided.
template <class System>
void SortBadClusters(System& sys, const SimplexPoints& simplex, RefinedEntry* entries, const uint32_t* cluster_of,
                     uint32_t num_clusters, uint32_t num_refined, Buffer<uint8_t, System>* verdict,
                     Buffer<uint8_t, System>* cluster_bad, unsigned long long* exact_count) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  if (thrust::count(policy, cluster_bad->data(), cluster_bad->data() + num_clusters, uint8_t{1}) == 0) return;
  Buffer<uint8_t, System> cluster_undecided(sys, num_clusters);
  thrust::fill_n(policy, cluster_undecided.data(), num_clusters, uint8_t{0});
  SortSmallBadClusters(sys, simplex, entries, cluster_of, num_clusters, num_refined, verdict, cluster_bad,
                       &cluster_undecided, exact_count);
  PartitionBadClusters(sys, simplex, entries, cluster_of, num_refined, verdict, *cluster_bad, &cluster_undecided,
                       exact_count);
  thrust::fill_n(policy, cluster_bad->data(), num_clusters, uint8_t{0});
  thrust::for_each_n(policy, zero, num_refined, MarkBadCluster{verdict->data(), cluster_of, cluster_bad->data()});
}

/// Orders the entries of runs longer than kMaxDeviceRun by refined keys (see the file comment),
/// cutting `link` where the order is settled; returns nonzero when it cut links (the caller then
/// rebuilds its run list from `link`). `ids` and `new_value` hold num_entries entries, `link`
/// num_entries - 1, `run_begin` num_runs + 1.
template <class System>
uint32_t RefineLongRuns(System& sys, const SimplexPoints& simplex, uint8_t* link, const uint32_t* run_begin,
                        uint32_t num_runs, uint32_t* ids, uint8_t* new_value, uint32_t num_entries,
                        ComparisonCounts* counts) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  // Long runs whose values are all exactly one double (a grid's congruent simplices) are settled
  // first, by one double comparison per entry: no keys needed.
  Buffer<uint8_t, System> one_double(sys, num_runs);
  thrust::transform(policy, zero, zero + num_runs, one_double.data(), IsLongRun{run_begin});
  if (thrust::count(policy, one_double.data(), one_double.data() + num_runs, uint8_t{1}) == 0) return 0;
  // The stage's exact comparisons are counted on the system and read once, when it ends.
  Buffer<unsigned long long, System> exact_count(sys, 1);
  thrust::fill_n(policy, exact_count.data(), 1, 0ull);
  Buffer<uint32_t, System> run_of(sys, num_entries);
  const auto starts = thrust::make_transform_iterator(zero, RunStartAsU32{link});
  thrust::inclusive_scan(policy, starts, starts + num_entries, run_of.data());
  thrust::for_each_n(policy, zero, num_entries,
                     CheckRunOfOneDouble{simplex, ids, run_of.data(), run_begin, one_double.data()});
  thrust::for_each_n(policy, zero, num_entries,
                     SettleRunOfOneDouble{run_of.data(), run_begin, one_double.data(), new_value});
  thrust::for_each_n(policy, zero, num_runs,
                     CountSettledComparisons{SettledComparisons{run_begin, one_double.data()}, exact_count.data()});
  Buffer<uint32_t, System> positions(sys, num_entries);
  const auto num_refined =
      static_cast<uint32_t>(thrust::copy_if(policy, zero, zero + num_entries, positions.data(),
                                            InLongRun{run_of.data(), run_begin, one_double.data()}) -
                            positions.data());
  thrust::for_each_n(policy, zero, num_entries, CutLinksOfOneDouble{run_of.data(), run_begin, one_double.data(), link});
  one_double.Reset();
  if (num_refined == 0) {
    counts->bounded_exact += sys.Read(exact_count.data());
    return 1;  // links may have been cut: the caller lists the runs again
  }

  // Congruent entries of a run are equal, and a lattice's long runs are mostly such copies (a
  // lattice nudged by single ulps at 1M: 4.6M entries in 13K classes). Each class is keyed,
  // sorted and judged once, by its first member, and its other members follow that one.
  Buffer<uint32_t, System> member(sys, num_refined);  // grouping position -> entry
  thrust::sequence(policy, member.data(), member.data() + num_refined);
  Buffer<uint32_t, System> group_of(sys, num_refined);  // 1-based, by grouping position
  {
    Buffer<uint32_t, System> group_key(sys, num_refined);
    thrust::transform(policy, zero, zero + num_refined, group_key.data(),
                      CongruenceGroupKey{simplex, positions.data(), run_of.data(), ids});
    thrust::stable_sort_by_key(policy, group_key.data(), group_key.data() + num_refined, member.data());
    // The starts are written first and then scanned, so that the congruence test (two simplices
    // read) is not done inside the scan, whose tiles wait on their predecessors. It was meant to
    // remove a slow refine stage seen in one run; the next run still had one: not shown to matter.
    thrust::transform(
        policy, zero, zero + num_refined, group_of.data(),
        StartsCongruenceGroup{simplex, group_key.data(), member.data(), positions.data(), run_of.data(), ids});
    thrust::inclusive_scan(policy, group_of.data(), group_of.data() + num_refined, group_of.data());
  }
  const uint32_t num_groups = sys.Read(group_of.data() + (num_refined - 1));
  Buffer<uint32_t, System> group_first(sys, num_groups + 1);  // grouping position of each first member
  thrust::for_each_n(policy, zero, num_refined, MarkGroupFirst{group_of.data(), group_first.data()});
  thrust::fill_n(policy, group_first.data() + num_groups, 1, num_refined);
  group_of.Reset();
  Buffer<uint32_t, System> member_id(sys, num_refined);
  thrust::transform(policy, zero, zero + num_refined, member_id.data(), MemberId{member.data(), positions.data(), ids});
  Buffer<uint32_t, System> leader_positions(sys, num_groups);
  thrust::transform(policy, zero, zero + num_groups, leader_positions.data(),
                    GroupLeaderPosition{group_first.data(), member.data(), positions.data()});
  member.Reset();

  Buffer<RefinedEntry, System> entries(sys, num_groups);
  Buffer<uint8_t, System> run_unrefinable(sys, num_runs);
  thrust::fill_n(policy, run_unrefinable.data(), num_runs, uint8_t{0});
  thrust::for_each_n(policy, zero, num_groups,
                     ComputeRefinedEntry{simplex, leader_positions.data(), run_of.data(), ids, entries.data(),
                                         run_unrefinable.data()});
  run_of.Reset();
  leader_positions.Reset();
  SortRefinedEntries(sys, &entries, num_groups);

  Buffer<uint8_t, System> verdict(sys, num_groups);
  thrust::for_each_n(
      policy, zero, num_groups,
      JudgeRefinedPair{simplex, entries.data(), run_unrefinable.data(), verdict.data(), exact_count.data()});

  Buffer<uint32_t, System> cluster_of(sys, num_groups);
  const auto cluster_starts = thrust::make_transform_iterator(zero, ClusterStartAsU32{verdict.data()});
  thrust::inclusive_scan(policy, cluster_starts, cluster_starts + num_groups, cluster_of.data());
  uint32_t num_clusters = 0;
  sys.ToHost(&num_clusters, cluster_of.data() + (num_groups - 1), 1);
  Buffer<uint8_t, System> cluster_bad(sys, num_clusters);
  thrust::fill_n(policy, cluster_bad.data(), num_clusters, uint8_t{0});
  thrust::for_each_n(policy, zero, num_groups, MarkBadCluster{verdict.data(), cluster_of.data(), cluster_bad.data()});
  SortBadClusters(sys, simplex, entries.data(), cluster_of.data(), num_clusters, num_groups, &verdict, &cluster_bad,
                  exact_count.data());

  // The groups, in their exact order, over the runs' positions.
  Buffer<uint32_t, System> expanded_start(sys, num_groups);
  const auto sizes = thrust::make_transform_iterator(zero, GroupSizeOfEntry{entries.data(), group_first.data()});
  thrust::exclusive_scan(policy, sizes, sizes + num_groups, expanded_start.data());
  Buffer<uint32_t, System> leader_of(sys, num_refined);
  thrust::fill_n(policy, leader_of.data(), num_refined, 0u);
  thrust::for_each_n(policy, zero, num_groups, MarkExpandedStart{expanded_start.data(), leader_of.data()});
  thrust::inclusive_scan(policy, leader_of.data(), leader_of.data() + num_refined, leader_of.data(),
                         thrust::maximum<uint32_t>());
  Buffer<uint32_t, System> expanded_run(sys, num_refined), expanded_cluster(sys, num_refined);
  Buffer<uint8_t, System> expanded_verdict(sys, num_refined);
  thrust::for_each_n(policy, zero, num_refined,
                     ExpandGroups{entries.data(), expanded_start.data(), leader_of.data(), group_first.data(),
                                  member_id.data(), positions.data(), verdict.data(), cluster_of.data(), ids,
                                  expanded_run.data(), expanded_verdict.data(), expanded_cluster.data()});
  thrust::for_each_n(
      policy, zero, num_refined,
      ApplyRefinedVerdicts{positions.data(), expanded_run.data(), run_unrefinable.data(), expanded_verdict.data(),
                           expanded_cluster.data(), cluster_bad.data(), link, new_value});
  counts->bounded_exact += sys.Read(exact_count.data());
  return num_refined;
}

}  // namespace galpha::detail
