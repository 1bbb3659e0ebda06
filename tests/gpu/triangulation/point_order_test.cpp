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

// 4,096 random points of a cluster 2^-40 wide, and one point at (1, 1): the whole cluster lies in
// the first cell of the curve over the set's box (as tiny's subnormal half does), so its points
// share one key and keep the lexicographic (x, y) order they arrive in (from the duplicate
// removal), in which consecutive points jump across the cluster. The key within the run orders
// them along a curve over their own box instead.
TEST(PointOrder, AClusterInOneCellOfTheCurveIsOrderedByACurveOverItsOwnBox) {
  const double width = 0x1p-40;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> in_cluster(width, 2 * width);
  std::vector<Point2> pts(4096);
  for (Point2& p : pts) p = {in_cluster(rng), in_cluster(rng)};
  std::sort(pts.begin(), pts.end(), [](const Point2& a, const Point2& b) { return LexLess(a, b); });
  pts.push_back({1.0, 1.0});
  const uint32_t m = static_cast<uint32_t>(pts.size());
  BoundingBox box = PointToBox()(pts[0]);
  for (const Point2& p : pts) box = MergeBoxes()(box, PointToBox()(p));

  std::vector<uint32_t> order(m);
  std::iota(order.begin(), order.end(), 0u);
  SortByKey(&order, [&](uint32_t k) { return HilbertKey{pts.data(), order.data(), box}(k); });
  std::vector<uint64_t> keys(m);
  for (uint32_t k = 0; k < m; ++k) keys[k] = HilbertKey{pts.data(), order.data(), box}(k);
  // The cluster is one run of equal keys, in (x, y) order.
  std::vector<uint32_t> run_number(m);
  uint32_t runs = 0;
  for (uint32_t k = 0; k < m; ++k) {
    runs += StartsKeyRun{keys.data()}(k);
    run_number[k] = runs;
  }
  ASSERT_EQ(runs, 2u);
  std::vector<uint32_t> cluster(order.begin(), order.end() - 1);
  const double lexicographic_length = PathLength(pts, cluster);

  std::vector<BoundingBox> run_box(runs, BoundingBox{INFINITY, INFINITY, -INFINITY, -INFINITY});
  for (uint32_t k = 0; k < m; ++k) {
    BoundingBox& b = run_box[run_number[k] - 1];
    b = MergeBoxes()(b, PointBoxAt{pts.data(), order.data()}(k));
  }
  SortByKey(&order, [&](uint32_t k) {
    return RunHilbertKey{pts.data(), order.data(), run_number.data(), run_box.data()}(k);
  });
  EXPECT_EQ(order.back(), m - 1);  // the runs keep their order: (1, 1) stays last
  cluster.assign(order.begin(), order.end() - 1);
  const double run_order_length = PathLength(pts, cluster);
  // A curve through n random points of a square of side w is about 0.7 w sqrt(n) long (~45 w
  // here); the lexicographic order about n w / 3 (~1,400 w): each step crosses the square in y.
  EXPECT_LT(run_order_length, 100 * width);
  EXPECT_GT(lexicographic_length, 10.0 * run_order_length);
}

}  // namespace
}  // namespace galpha::detail
