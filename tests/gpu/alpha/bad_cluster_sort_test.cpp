// The exact sort of the refined spectrum's bad clusters (SortBadClusters in
// gpu/alpha/spectrum_refine.cuh), run on the OpenMP backend as the CPU engine runs it, against GMP
// rationals. A bad cluster is a range of entries whose refined keys cannot order them; clusters
// of up to kMaxPairwiseCluster entries are sorted by all their pairs' exact signs at once, larger
// ones by rounds of three-way partitions. Both must give the order by (exact value, input order), mark each value's
// first entry kPairLess and the others kPairEqual, and leave the cluster's first verdict (a
// certified boundary) alone. The entries are windows of an ulp-perturbed lattice's simplices
// (near ties 2^-146 to 2^-224 apart and exact ties that are not congruent), shuffled.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "core/exact/simplex_radius.hpp"
#include "gpu/alpha/spectrum_refine.cuh"
#include "gpu/system/engine_system.cuh"
#include "tests/gpu/alpha/simplex_pool.hpp"

namespace galpha::detail {
namespace {

using testing_pool::Compare;
using testing_pool::SimplexPool;
using testing_pool::UlpLatticePool;

// Sorts clusters of the given sizes, each a shuffled window of the pool's exact order, as one call,
// and checks every cluster. Returns the bounded exact comparisons made.
uint64_t SortAndCheck(const SimplexPool& pool, const std::vector<uint32_t>& sizes, uint64_t seed) {
  const std::vector<uint32_t> by_value = testing_pool::ByExactValue(pool);
  std::mt19937_64 rng(seed);
  std::vector<RefinedEntry> host_entries;
  std::vector<uint32_t> host_cluster_of;
  std::vector<uint8_t> host_verdict;
  std::vector<uint32_t> cluster_begin;
  const SimplexPoints simplex = pool.view();
  for (uint32_t c = 0; c < sizes.size(); ++c) {
    cluster_begin.push_back(static_cast<uint32_t>(host_entries.size()));
    const uint32_t start = static_cast<uint32_t>(rng() % (pool.size() - sizes[c]));
    std::vector<uint32_t> ids(by_value.begin() + start, by_value.begin() + start + sizes[c]);
    std::shuffle(ids.begin(), ids.end(), rng);
    for (uint32_t i = 0; i < sizes[c]; ++i) {
      RefinedEntry entry;
      entry.run = c;
      entry.id = ids[i];
      entry.group = static_cast<uint32_t>(host_entries.size());  // the input position, for the stability check
      Point2 p[3];
      const int n = simplex(ids[i], p);
      entry.key = RefineSimplexRadiusSq(p, nullptr, n);
      EXPECT_TRUE(entry.key.ok);
      host_entries.push_back(entry);
      host_cluster_of.push_back(c + 1);
      host_verdict.push_back(i == 0 ? kPairSeparated : kPairBad);
    }
  }
  cluster_begin.push_back(static_cast<uint32_t>(host_entries.size()));
  const auto num_refined = static_cast<uint32_t>(host_entries.size());
  const auto num_clusters = static_cast<uint32_t>(sizes.size());

  CpuSystem sys;
  Buffer<RefinedEntry, CpuSystem> entries(sys, num_refined);
  Buffer<uint32_t, CpuSystem> cluster_of(sys, num_refined);
  Buffer<uint8_t, CpuSystem> verdict(sys, num_refined);
  Buffer<uint8_t, CpuSystem> cluster_bad(sys, num_clusters);
  sys.FromHost(entries.data(), host_entries.data(), num_refined);
  sys.FromHost(cluster_of.data(), host_cluster_of.data(), num_refined);
  sys.FromHost(verdict.data(), host_verdict.data(), num_refined);
  const std::vector<uint8_t> all_bad(num_clusters, 1);
  sys.FromHost(cluster_bad.data(), all_bad.data(), num_clusters);
  Buffer<unsigned long long, CpuSystem> exact_count(sys, 1);
  *exact_count.data() = 0;
  SortBadClusters(sys, simplex, entries.data(), cluster_of.data(), num_clusters, num_refined, &verdict, &cluster_bad,
                  exact_count.data());

  const std::vector<RefinedEntry> sorted = entries.ToHostVector(num_refined);
  const std::vector<uint8_t> verdicts = verdict.ToHostVector(num_refined);
  const std::vector<uint8_t> still_bad = cluster_bad.ToHostVector(num_clusters);
  for (uint32_t c = 0; c < num_clusters; ++c) {
    SCOPED_TRACE("cluster of " + std::to_string(sizes[c]) + " entries");
    EXPECT_EQ(still_bad[c], 0) << "the bounded arithmetic decides every pair of these simplices";
    const uint32_t begin = cluster_begin[c], end = cluster_begin[c + 1];
    std::vector<uint32_t> in_ids, out_ids;
    for (uint32_t k = begin; k < end; ++k) {
      in_ids.push_back(host_entries[k].id);
      out_ids.push_back(sorted[k].id);
    }
    std::sort(in_ids.begin(), in_ids.end());
    std::sort(out_ids.begin(), out_ids.end());
    EXPECT_EQ(in_ids, out_ids) << "the cluster lost or duplicated an entry";
    EXPECT_EQ(verdicts[begin], kPairSeparated) << "the cluster's boundary verdict was rewritten";
    for (uint32_t k = begin + 1; k < end; ++k) {
      const int sign = Compare(pool, sorted[k - 1].id, sorted[k].id);
      EXPECT_LE(sign, 0) << "out of exact order at " << k - begin;
      EXPECT_EQ(verdicts[k], sign < 0 ? kPairLess : kPairEqual) << "verdict at " << k - begin;
      if (sign == 0) {
        EXPECT_LT(sorted[k - 1].group, sorted[k].group) << "equal values out of input order";
      }
    }
  }
  return *exact_count.data();
}

TEST(BadClusterSortTest, ClustersSortedByTheirPairs) {
  const SimplexPool pool = UlpLatticePool(41);
  const uint64_t bounded = SortAndCheck(pool, {2, 3, 7, 16, 31, kMaxPairwiseCluster, 5, 12}, 42);
  EXPECT_GT(bounded, 0u) << "the windows hold pairs the keys cannot order";
}

TEST(BadClusterSortTest, ClustersSortedByPartitionRounds) {
  const SimplexPool pool = UlpLatticePool(51);
  const uint64_t bounded = SortAndCheck(pool, {kMaxPairwiseCluster + 1, 60, 150, 300}, 52);
  EXPECT_GT(bounded, 0u);
}

TEST(BadClusterSortTest, BothKindsInOneCall) {
  const SimplexPool pool = UlpLatticePool(61);
  for (uint64_t seed = 0; seed < 20; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    SortAndCheck(pool, {4, 90, kMaxPairwiseCluster, 2, kMaxPairwiseCluster + 1, 20, 200}, 100 + seed);
    if (HasFailure()) return;
  }
}

}  // namespace
}  // namespace galpha::detail
