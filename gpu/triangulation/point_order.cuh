// Functors that order the input: exact-duplicate detection (lexicographic sort, first occurrence
// wins) and the Hilbert curve key that gives the insertion rounds their locality.
#pragma once

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/base/hd.hpp"
#include "core/base/point.hpp"

namespace galpha::detail {

/// A 64-bit key with the order of the double (-0.0 and +0.0 get the same key): radix-sortable.
GALPHA_HD inline uint64_t OrderedDoubleKey(double v) {
  const double normalized = v + 0.0;  // -0.0 + 0.0 == +0.0
  uint64_t bits;
  memcpy(&bits, &normalized, sizeof bits);
  return (bits >> 63) ? ~bits : (bits | 0x8000000000000000ull);
}

/// The sort key of coordinate y (kY) or x (kX) of the input point a permutation entry names. Sorting
/// stably by y, then by x, orders by (x, y) with ties in index order (exact
/// duplicates adjacent, first occurrence first), with two radix sorts instead of a comparison sort.
struct CoordinateKey {
  enum Axis { kX, kY };
  const Point2* pts;
  const uint32_t* order;
  Axis axis;
  GALPHA_HD uint64_t operator()(uint32_t k) const {
    const Point2 p = pts[order[k]];
    return OrderedDoubleKey(axis == kX ? p.x : p.y);
  }
};

/// Position of the head of the run of equal points that sorted position k belongs to (0 when k is
/// not a head, for a max-scan). Packed (`input_set` set: many point sets, sorted by set first), a
/// run is one point of one set.
struct RunHeadPosition {
  const Point2* pts;
  const uint32_t* sorted;
  const uint32_t* input_set = nullptr;
  GALPHA_HD uint32_t operator()(uint32_t k) const {
    if (k == 0 || !(pts[sorted[k]] == pts[sorted[k - 1]])) return k;
    return input_set != nullptr && input_set[sorted[k]] != input_set[sorted[k - 1]] ? k : 0u;
  }
};

/// A packed build's set of the input index at position k of a permutation (or of a list of input
/// indices: distinct points, vertices).
struct SetOfIndex {
  const uint32_t* input_set;
  const uint32_t* input_index;
  GALPHA_HD uint32_t operator()(uint32_t k) const { return input_set[input_index[k]]; }
};

/// representative[input index] = input index of the run's head.
struct WriteRepresentative {
  const uint32_t* sorted;
  const uint32_t* head;
  uint32_t* representative;
  GALPHA_HD void operator()(uint32_t k) const { representative[sorted[k]] = sorted[head[k]]; }
};

/// Weighted input: the sort key of the weight of the input point a permutation entry names, heaviest
/// first. Sorted stably by it before y and x, the points are ordered by (x, y, weight descending,
/// index): at one position the heaviest point leads and hides the others.
struct DescendingWeightKey {
  const double* weights;
  const uint32_t* order;
  GALPHA_HD uint64_t operator()(uint32_t k) const { return ~OrderedDoubleKey(weights[order[k]]); }
};

/// RunHeadPosition for weighted points: a run is one position and one weight.
struct WeightedRunHeadPosition {
  const Point2* pts;
  const double* weights;
  const uint32_t* sorted;
  GALPHA_HD uint32_t operator()(uint32_t k) const {
    if (k == 0) return 0u;
    const uint32_t i = sorted[k], j = sorted[k - 1];
    return (pts[i] == pts[j] && weights[i] + 0.0 == weights[j] + 0.0) ? 0u : k;
  }
};

/// Weighted input: a run head at the position of the run before it is lighter than that run (the
/// sort put the heaviest first): hidden, with every point of its run.
struct MarkLighterAtSamePosition {
  const Point2* pts;
  const uint32_t* sorted;
  const uint32_t* head;
  uint8_t* hidden;  // per input index
  GALPHA_HD void operator()(uint32_t k) const {
    const uint32_t h = head[k];
    hidden[sorted[k]] = (h > 0 && pts[sorted[h]] == pts[sorted[h - 1]]) ? 1 : 0;
  }
};

/// The distinct points that become mesh vertices: heads of runs that are not hidden.
struct IsVisibleRunHead {
  const uint32_t* head;
  const uint32_t* sorted;
  const uint8_t* hidden;  // per input index; nullptr: unweighted
  GALPHA_HD bool operator()(uint32_t k) const { return head[k] == k && (hidden == nullptr || !hidden[sorted[k]]); }
};

struct BoundingBox {
  double min_x, min_y, max_x, max_y;
};

struct PointToBox {
  GALPHA_HD BoundingBox operator()(const Point2& p) const { return {p.x, p.y, p.x, p.y}; }
};

struct MergeBoxes {
  GALPHA_HD BoundingBox operator()(const BoundingBox& a, const BoundingBox& b) const {
    return {a.min_x < b.min_x ? a.min_x : b.min_x, a.min_y < b.min_y ? a.min_y : b.min_y,
            a.max_x > b.max_x ? a.max_x : b.max_x, a.max_y > b.max_y ? a.max_y : b.max_y};
  }
};

/// Hilbert curve index of a point quantized to a 2^kHilbertOrder grid over the bounding box.
/// Only the insertion order depends on it, never a topological decision.
struct HilbertKey {
  static constexpr int kHilbertOrder = 21;
  const Point2* pts;
  const uint32_t* input_index;
  BoundingBox box;

  GALPHA_HD static uint32_t Quantize(double v, double lo, double hi) {
    const double span = hi - lo;
    if (!(span > 0.0)) return 0;
    double f = (v - lo) / span;
    f = f < 0.0 ? 0.0 : (f > 1.0 ? 1.0 : f);
    return static_cast<uint32_t>(f * static_cast<double>((1u << kHilbertOrder) - 1));
  }

  GALPHA_HD uint64_t operator()(uint32_t i) const {
    const Point2 p = pts[input_index[i]];
    uint32_t x = Quantize(p.x, box.min_x, box.max_x);
    uint32_t y = Quantize(p.y, box.min_y, box.max_y);
    const uint32_t n = 1u << kHilbertOrder;
    uint64_t d = 0;
    for (uint32_t s = n >> 1; s > 0; s >>= 1) {
      const uint32_t rx = (x & s) ? 1u : 0u;
      const uint32_t ry = (y & s) ? 1u : 0u;
      d += static_cast<uint64_t>(s) * s * ((3u * rx) ^ ry);
      if (ry == 0) {  // rotate the quadrant so the curve stays continuous
        if (rx == 1) {
          x = n - 1 - x;
          y = n - 1 - y;
        }
        const uint32_t tmp = x;
        x = y;
        y = tmp;
      }
    }
    return d;
  }
};

/// A packed build's Hilbert key: the point's set in the bits above the curve's 42 (so that the
/// sets stay apart, in order), and its key on the curve over its set's box below.
struct SetHilbertKey {
  static constexpr int kSetShift = 2 * HilbertKey::kHilbertOrder;
  const Point2* pts;
  const uint32_t* input_index;
  const uint32_t* input_set;
  const BoundingBox* set_box;
  GALPHA_HD uint64_t operator()(uint32_t i) const {
    const uint32_t set = input_set[input_index[i]];
    return (static_cast<uint64_t>(set) << kSetShift) | HilbertKey{pts, input_index, set_box[set]}(i);
  }
};

/// 1 where sorted position k starts a run of equal Hilbert keys (points in one cell of the curve).
struct StartsKeyRun {
  const uint64_t* keys;
  GALPHA_HD uint32_t operator()(uint32_t k) const { return (k == 0 || keys[k] != keys[k - 1]) ? 1u : 0u; }
};

/// The point at sorted position k, as a box (for the boxes of the runs).
struct PointBoxAt {
  const Point2* pts;
  const uint32_t* input_index;
  GALPHA_HD BoundingBox operator()(uint32_t k) const { return PointToBox()(pts[input_index[k]]); }
};

/// The order within the runs of equal Hilbert keys: the run's index (its number from the inclusive
/// scan of StartsKeyRun, less one) in the high 32 bits, so that runs keep their order, and the
/// Hilbert key over the run's own box (its top 32 bits) below. A cluster far smaller than the whole
/// set (tiny's subnormal half lies within 2^-74 of the box) falls into one cell of the curve, where
/// it would keep the (x, y) order it arrives in: lexicographic, so consecutive points jump across
/// the cluster (the insertion rounds' walks and the mesh's memory lose their locality).
struct RunHilbertKey {
  const Point2* pts;
  const uint32_t* input_index;
  const uint32_t* run_number;  // from 1
  const BoundingBox* run_box;
  GALPHA_HD uint64_t operator()(uint32_t k) const {
    const uint32_t run = run_number[k] - 1;
    const uint64_t within = HilbertKey{pts, input_index, run_box[run]}(k) >> (2 * HilbertKey::kHilbertOrder - 32);
    return (static_cast<uint64_t>(run) << 32) | within;
  }
};

/// The smallest nonzero magnitude among a point's coordinates (+inf when both are zero).
struct SmallestNonzeroMagnitude {
  GALPHA_HD double operator()(const Point2& p) const {
    const double ax = fabs(p.x), ay = fabs(p.y);
    const double sx = ax > 0.0 ? ax : INFINITY, sy = ay > 0.0 ? ay : INFINITY;
    return sx < sy ? sx : sy;
  }
};

struct Minimum {
  GALPHA_HD double operator()(double a, double b) const { return a < b ? a : b; }
};

/// The power of two the triangulation scales its points by: the one that brings the largest
/// magnitude into [1, 2), limited so that the scaling stays exact. Scaling by a power of two
/// multiplies every orientation determinant by a positive constant (and every in-circle one by its
/// square), so every predicate keeps its sign and the triangulation is the same; but the floating
/// filters, which give up where products underflow (coordinates near 1e-300, subnormals) or
/// overflow, then succeed as on well-scaled input instead of sending every test to exact
/// arithmetic. Scaling up is exact while nothing overflows; scaling down while the smallest
/// nonzero coordinate stays a normal number (`smallest_nonzero` is asked for only then).
template <class SmallestNonzero>
inline int ExactScaleExponent(const BoundingBox& box, SmallestNonzero smallest_nonzero) {
  const double largest = fmax(fmax(fabs(box.min_x), fabs(box.max_x)), fmax(fabs(box.min_y), fabs(box.max_y)));
  if (!(largest > 0.0)) return 0;
  const int up = -ilogb(largest);
  if (up >= 0) return up;
  const double smallest = smallest_nonzero();
  const int down_allowed = ilogb(smallest) - DBL_MIN_EXP + 1;  // stays >= 2^-1022
  return down_allowed <= 0 ? 0 : -(down_allowed < -up ? down_allowed : -up);
}

/// Gathers the distinct points into Hilbert order with their input indices (the SoS ranks),
/// scaled by 2^scale_exponent (exact: ExactScaleExponent).
struct GatherVertex {
  const Point2* input_points;
  const uint32_t* input_index;
  Point2* vertex_points;
  int scale_exponent;
  GALPHA_HD void operator()(uint32_t v) const {
    const Point2 p = input_points[input_index[v]];
    vertex_points[v] = Point2{ldexp(p.x, scale_exponent), ldexp(p.y, scale_exponent)};
  }
};

/// GatherVertex for a packed build: each point scaled by its set's power of two.
struct GatherSetVertex {
  const Point2* input_points;
  const uint32_t* input_index;
  const uint32_t* input_set;
  const int* set_scale_exponent;
  Point2* vertex_points;
  GALPHA_HD void operator()(uint32_t v) const {
    const uint32_t i = input_index[v];
    const Point2 p = input_points[i];
    const int e = set_scale_exponent[input_set[i]];
    vertex_points[v] = Point2{ldexp(p.x, e), ldexp(p.y, e)};
  }
};

/// Weighted input: each vertex's weight, scaled by the square of the points' power of two (the power
/// test's sign is unchanged: every lift scales by it), and its Simulation-of-Simplicity rank, its
/// position in decreasing lexicographic order (core/exact/power.hpp).
struct GatherWeightedVertex {
  const double* input_weights;
  const uint32_t* input_index;
  const uint32_t* lexicographic_position;  // per input index, among the m distinct points
  uint32_t m;
  double* vertex_weights;
  uint32_t* sos_rank;
  int scale_exponent;
  GALPHA_HD void operator()(uint32_t v) const {
    const uint32_t i = input_index[v];
    vertex_weights[v] = ldexp(input_weights[i], 2 * scale_exponent);
    sos_rank[v] = m - 1 - lexicographic_position[i];
  }
};

/// Scatters each distinct point's position in the (x, y) order to its input index.
struct WriteLexicographicPosition {
  const uint32_t* unique;
  uint32_t* position;
  GALPHA_HD void operator()(uint32_t j) const { position[unique[j]] = j; }
};

/// The smallest nonzero |weight| (+inf for 0).
struct SmallestNonzeroWeight {
  GALPHA_HD double operator()(double w) const { return w != 0.0 ? fabs(w) : INFINITY; }
};

/// ExactScaleExponent for weighted points: weights scale by twice the exponent, so scaling down is
/// further limited to keep the smallest nonzero weight normal (exact).
inline int WeightedScaleExponent(int point_exponent, double smallest_nonzero_weight) {
  if (point_exponent >= 0 || !(smallest_nonzero_weight < INFINITY)) return point_exponent;
  const int allowed = -((ilogb(smallest_nonzero_weight) - DBL_MIN_EXP + 1) / 2);
  if (allowed >= 0) return 0;
  return point_exponent > allowed ? point_exponent : allowed;
}

}  // namespace galpha::detail
