// The exact repair of the spectrum's short runs (OrderRunNeighbours, then RepairRun, in
// gpu/alpha/alpha_functors.cuh), run on the host as the OpenMP backend runs it, against GMP
// rationals: runs of near ties, congruent copies and exact ties that are not copies, shuffled or
// already in exact order (as the keys leave most runs), must come out in exact order with every
// new value marked. The inputs are what the runs hold on real data: centimetre-quantized
// coordinates far from the origin (copies and co-circular ties by the thousand), points on a
// circle (values 2^-40 to 2^-100 apart, which the double-double enclosures separate without the
// bounded arithmetic) and an ulp-perturbed lattice.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "gpu/alpha/alpha_functors.cuh"
#include "tests/gpu/alpha/simplex_pool.hpp"

namespace galpha::detail {
namespace {

using testing_pool::Compare;
using testing_pool::PoolOf;
using testing_pool::SimplexPool;

struct Outcome {
  int runs = 0;
  int in_order = 0;      // runs whose neighbours' verdicts were all Less or Equal: marked, not sorted
  int ties = 0;          // adjacent pairs of equal value in the repaired runs
  uint64_t bounded = 0;  // comparisons that needed the bounded exact arithmetic
};

// Repairs `trials` runs of 2..16 entries drawn from the pool, each run made of simplices whose
// values are close (the pool sorted by exact value, a window of it: shuffled in odd trials, in
// exact order in even ones, with its equal values in id order), and checks each
// against GMP.
Outcome RepairRandomRuns(const SimplexPool& pool, int trials, uint64_t seed) {
  const std::vector<uint32_t> by_value = testing_pool::ByExactValue(pool);
  std::mt19937_64 rng(seed);
  Outcome outcome;
  for (int t = 0; t < trials; ++t) {
    const uint32_t length = 2 + static_cast<uint32_t>(rng() % (kMaxDeviceRun - 1));
    const uint32_t start = static_cast<uint32_t>(rng() % (pool.size() - length));
    std::vector<uint32_t> ids(by_value.begin() + start, by_value.begin() + start + length);
    if (t % 2 == 1) std::shuffle(ids.begin(), ids.end(), rng);
    const std::vector<uint32_t> before = ids;
    const uint32_t run_begin[2] = {0, length};
    const uint32_t tied = 0;
    std::vector<uint8_t> verdict(length, 0xFF);  // a sentinel: the last entry's stays unread
    for (uint32_t pair = 0; pair + 1 < length; ++pair) {
      OrderRunNeighbours{pool.view(), &tied, 1, run_begin, ids.data(), verdict.data()}(pair);
    }
    bool neighbours_in_order = true;
    for (uint32_t i = 0; i + 1 < length; ++i) {
      const int c = Compare(pool, ids[i], ids[i + 1]);
      const Order order = DecodeVerdict(verdict[i]);
      if (order != Order::kUndecided) {
        EXPECT_EQ(static_cast<int>(order), c) << "verdict " << i << " in trial " << t;
      }
      neighbours_in_order = neighbours_in_order && c <= 0 && order != Order::kUndecided;
    }
    std::vector<uint8_t> new_value(length, 7);  // a sentinel: every mark must be written
    uint8_t needs_host = 9;
    uint32_t comparisons = 0;
    RepairRun{pool.view(), &run_begin[0],    &run_begin[1], verdict.data(),
              ids.data(),  new_value.data(), &needs_host,   &comparisons}(0);
    if (needs_host != 0) {
      EXPECT_EQ(ids, before) << "a run left for the host must keep its order";
      continue;
    }
    ++outcome.runs;
    if (neighbours_in_order) {
      ++outcome.in_order;
      EXPECT_EQ(ids, before) << "a run in exact order must keep its order (trial " << t << ")";
    }
    outcome.bounded += comparisons;
    std::vector<uint32_t> sorted_ids = ids, sorted_before = before;
    std::sort(sorted_ids.begin(), sorted_ids.end());
    std::sort(sorted_before.begin(), sorted_before.end());
    EXPECT_EQ(sorted_ids, sorted_before) << "the run lost or duplicated an entry";
    EXPECT_EQ(new_value[0], 1);
    for (uint32_t i = 1; i < length; ++i) {
      const int c = Compare(pool, ids[i - 1], ids[i]);
      EXPECT_LE(c, 0) << "out of order at " << i << " in trial " << t;
      EXPECT_EQ(new_value[i], c < 0 ? 1 : 0) << "new value mark at " << i << " in trial " << t;
      if (c == 0) ++outcome.ties;
    }
  }
  return outcome;
}

TEST(RunRepairTest, CentimetreQuantizedCoordinatesFarFromTheOrigin) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> cm(0, 6);
  // The LiDAR generator's arithmetic: whole centimetres times 0.01, plus a UTM-like offset.
  const SimplexPool pool = PoolOf(14, [&] {
    return Point2{static_cast<double>(cm(rng)) * 0.01 + 500000.0, static_cast<double>(cm(rng)) * 0.01 + 4000000.0};
  });
  const Outcome outcome = RepairRandomRuns(pool, 3000, 12);
  EXPECT_GT(outcome.runs, 2500);
  EXPECT_GT(outcome.in_order, 1200);  // the even trials: marked from the neighbours' verdicts
  EXPECT_GT(outcome.ties, 1000);      // congruent copies and co-circular triangles
}

TEST(RunRepairTest, PointsOnACircle) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> angle(0.0, 6.283185307179586);
  const SimplexPool pool = PoolOf(16, [&] {
    const double a = angle(rng);
    return Point2{1000.0 + 3.0 * std::cos(a), -250.0 + 3.0 * std::sin(a)};
  });
  const Outcome outcome = RepairRandomRuns(pool, 3000, 22);
  EXPECT_GT(outcome.runs, 2900);
  EXPECT_GT(outcome.in_order, 1400);
  // Every triangle's value lies within rounding of the circle's: near ties, which the enclosures
  // order without the bounded arithmetic.
  EXPECT_LT(outcome.bounded, 100u);
}

TEST(RunRepairTest, UlpPerturbedLattice) {
  const SimplexPool pool = testing_pool::UlpLatticePool(31);
  const Outcome outcome = RepairRandomRuns(pool, 3000, 32);
  EXPECT_GT(outcome.runs, 2500);
  EXPECT_GT(outcome.in_order, 1200);
}

}  // namespace
}  // namespace galpha::detail
