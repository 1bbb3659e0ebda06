// The insertion order's keys (gpu/triangulation/point_order.cuh): the Hilbert key over the whole
// set, and the key within its runs that orders a cluster falling into one cell of that curve.
#include "gpu/triangulation/point_order.cuh"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

namespace galpha::detail {
namespace {

double PathLength(const std::vector<Point2>& pts, const std::vector<uint32_t>& order) {
  double length = 0.0;
  for (size_t k = 1; k < order.size(); ++k) {
    length += std::hypot(pts[order[k]].x - pts[order[k - 1]].x, pts[order[k]].y - pts[order[k - 1]].y);
  }
  return length;
}

// Sorts `order` stably by key(position), as the pipeline's stable radix sorts do.
template <class Key>
void SortByKey(std::vector<uint32_t>* order, const Key& key) {
  std::vector<uint64_t> keys(order->size());
  for (uint32_t k = 0; k < keys.size(); ++k) keys[k] = key(k);
  std::vector<uint32_t> by(order->size());
  std::iota(by.begin(), by.end(), 0u);
  std::stable_sort(by.begin(), by.end(), [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
  std::vector<uint32_t> sorted(order->size());
  for (size_t k = 0; k < by.size(); ++k) sorted[k] = (*order)[by[k]];
  *order = sorted;
}

// A 64 x 64 lattice of spacing 2^-60 in input order (shuffled), and one point at (1, 1): the whole
// lattice lies in the first cell of the curve over the set's box (as tiny's subnormal half does).
// The key within the run orders it along a curve over its own box: consecutive points are
// lattice neighbours or nearly, instead of random.
TEST(PointOrder, AClusterInOneCellOfTheCurveIsOrderedByACurveOverItsOwnBox) {
  const double h = 0x1p-60;
  std::vector<Point2> pts;
  for (int i = 1; i <= 64; ++i) {
    for (int j = 1; j <= 64; ++j) pts.push_back({i * h, j * h});
  }
  std::mt19937_64 rng(7);
  std::shuffle(pts.begin(), pts.end(), rng);
  pts.push_back({1.0, 1.0});
  const uint32_t m = static_cast<uint32_t>(pts.size());
  BoundingBox box = PointToBox()(pts[0]);
  for (const Point2& p : pts) box = MergeBoxes()(box, PointToBox()(p));

  std::vector<uint32_t> order(m);
  std::iota(order.begin(), order.end(), 0u);
  SortByKey(&order, [&](uint32_t k) { return HilbertKey{pts.data(), order.data(), box}(k); });
  std::vector<uint64_t> keys(m);
  for (uint32_t k = 0; k < m; ++k) keys[k] = HilbertKey{pts.data(), order.data(), box}(k);
  // The lattice is one run of equal keys, in input order.
  std::vector<uint32_t> run_number(m);
  uint32_t runs = 0;
  for (uint32_t k = 0; k < m; ++k) run_number[k] = runs += StartsKeyRun{keys.data()}(k);
  ASSERT_EQ(runs, 2u);
  std::vector<uint32_t> lattice(order.begin(), order.end() - 1);
  const double input_order_length = PathLength(pts, lattice);

  std::vector<BoundingBox> run_box(runs, BoundingBox{INFINITY, INFINITY, -INFINITY, -INFINITY});
  for (uint32_t k = 0; k < m; ++k) {
    BoundingBox& b = run_box[run_number[k] - 1];
    b = MergeBoxes()(b, PointBoxAt{pts.data(), order.data()}(k));
  }
  SortByKey(&order, [&](uint32_t k) {
    return RunHilbertKey{pts.data(), order.data(), run_number.data(), run_box.data()}(k);
  });
  EXPECT_EQ(order.back(), m - 1);  // the runs keep their order: (1, 1) stays last
  lattice.assign(order.begin(), order.end() - 1);
  const double run_order_length = PathLength(pts, lattice);
  // 4,095 steps: a curve through the lattice takes steps of about one spacing (at most 2 on
  // average here, as the lattice does not align with the curve's cells); a random order, about a
  // third of the lattice's width (~21 spacings) a step.
  EXPECT_LT(run_order_length, 2.0 * 4095 * h);
  EXPECT_GT(input_order_length, 10.0 * run_order_length);
}

}  // namespace
}  // namespace galpha::detail
