// The area curve: the area of the regularized complex (the triangles that are in) at every level,
// in fixed point, one source for both backends.
//
// Why fixed point: integer sums do not depend on the order of the additions, so the curve is the
// same on CUDA and OpenMP bit for bit (a floating-point scan is not: its association order differs
// between the backends). Each triangle's twice-area is evaluated in doubles on differences scaled
// by one power of two (the bounding box's larger side to [0.5, 1)), rounded to an integer number of
// units of 2^-kAreaFractionBits, and its error bound (Shewchuk's ccwerrboundA times the permanent,
// plus one unit for the rounding to an integer and for any underflow) is summed beside it. The
// curve is then a certified approximation: |exact twice-area at level L - curve[L]| <= the error
// sum, in units, at every level. core/family/area_ratio.* decides the area-ratio thresholds with it
// and falls back to exact arithmetic only where the bound cannot decide.
#pragma once

#include <thrust/fill.h>
#include <thrust/for_each.h>
#include <thrust/functional.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/transform_iterator.h>
#include <thrust/reduce.h>
#include <thrust/scan.h>
#include <thrust/transform.h>
#include <thrust/transform_reduce.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/exact/expansion.hpp"
#include "core/family/alpha_ranks.hpp"
#include "gpu/alpha/alpha_functors.cuh"
#include "gpu/system/atomic_increment.cuh"
#include "gpu/system/engine_system.cuh"
#include "gpu/triangulation/point_order.cuh"

namespace galpha::detail {

/// A scaled twice-area is below 2 (scaled differences are below 1); 2^57 units each keeps the
/// whole sum (twice the scaled hull area, below 2) under 2^59 and the error sum far below 2^63.
constexpr int kAreaFractionBits = 57;
/// Shewchuk's ccwerrboundA, (3 + 16 eps) eps: |computed - exact| of bx*cy - by*cx on differences
/// of the coordinates is at most this times |bx*cy| + |by*cx| (the predicates' filter, which we
/// enlarge the same way: by a relative 2^-20).
constexpr double kTwiceAreaErrBound = (3.0 + 16.0 * exact::kEpsilon) * exact::kEpsilon * (1.0 + 0x1p-20);

/// One triangle's twice-area in units and its error bound in units.
struct TriangleAreaUnits {
  const Point2* points;
  const TriIdx* tri;
  int scale_log2;  ///< the differences are multiplied by 2^scale_log2
  /// A packed build of many sets: each set's own scale (set_scale_log2[input_set[vertex]]) instead
  /// of `scale_log2`; null for one set.
  const uint32_t* input_set = nullptr;
  const int* set_scale_log2 = nullptr;

  GALPHA_HD void Evaluate(uint32_t t, unsigned long long* units, unsigned long long* error) const {
    // The rotation that starts at the smallest index: the same rounding whichever rotation of
    // the triangle a backend stores.
    const TriIdx& v = tri[t];
    const int scale_log2 = set_scale_log2 == nullptr ? this->scale_log2 : set_scale_log2[input_set[v.v[0]]];
    const int first = v.v[0] < v.v[1] ? (v.v[0] < v.v[2] ? 0 : 2) : (v.v[1] < v.v[2] ? 1 : 2);
    const Point2 a = points[v.v[first]], b = points[v.v[(first + 1) % 3]], c = points[v.v[(first + 2) % 3]];
    using exact::Mul;
    using exact::ScaleByPow2;
    using exact::Sub;
    const double bx = ScaleByPow2(Sub(b.x, a.x), scale_log2), by = ScaleByPow2(Sub(b.y, a.y), scale_log2);
    const double cx = ScaleByPow2(Sub(c.x, a.x), scale_log2), cy = ScaleByPow2(Sub(c.y, a.y), scale_log2);
    const double left = Mul(bx, cy), right = Mul(by, cx);
    const double det = exact::Abs(Sub(left, right));
    const double permanent = exact::Add(exact::Abs(left), exact::Abs(right));
    const double unit = exact::Pow2(kAreaFractionBits);
    *units = static_cast<unsigned long long>(llround(Mul(det, unit)));
    // The bound rounded up, plus one unit: the rounding to an integer (half a unit) and products
    // or differences that underflowed (below 2^-1000 units each).
    *error = static_cast<unsigned long long>(ceil(Mul(Mul(kTwiceAreaErrBound, permanent), unit))) + 1ull;
  }
};

/// Adds each born triangle's units into its birth rank.
struct AddTriangleArea {
  TriangleAreaUnits area;
  const uint32_t* tri_rank;
  unsigned long long* units_at_rank;
  GALPHA_HD void operator()(uint32_t t) const {
    if (tri_rank[t] == kNeverRank) return;  // collinear: never in, and of area zero
    unsigned long long units = 0, error = 0;
    area.Evaluate(t, &units, &error);
    AtomicAddU64(&units_at_rank[tri_rank[t]], units);
  }
};

/// Each born triangle's error bound (summed by a reduction).
struct TriangleAreaError {
  TriangleAreaUnits area;
  const uint32_t* tri_rank;
  GALPHA_HD unsigned long long operator()(uint32_t t) const {
    if (tri_rank[t] == kNeverRank) return 0;
    unsigned long long units = 0, error = 0;
    area.Evaluate(t, &units, &error);
    return error;
  }
};

/// The area curve's scale of a bounding box: 2^scale_log2 brings its larger side to [0.5, 1). Zero
/// for a box without extent (then there are no triangles).
GALPHA_HD inline int AreaScaleLog2Of(const BoundingBox& box) {
  const double width = exact::Sub(box.max_x, box.min_x), height = exact::Sub(box.max_y, box.min_y);
  const double side = width > height ? width : height;
  if (side == 0.0) return 0;
  return -(exact::ExponentOf(side) + 1);
}

template <class System>
int AreaScaleLog2(System& sys, const Point2* points, uint32_t n) {
  if (n == 0) return 0;
  auto policy = sys.policy();
  return AreaScaleLog2Of(
      thrust::transform_reduce(policy, points, points + n, PointToBox(), PointToBox()(sys.Read(points)), MergeBoxes()));
}

/// A set's box as its area scale.
struct BoxAreaScale {
  GALPHA_HD int operator()(const BoundingBox& box) const { return AreaScaleLog2Of(box); }
};

/// The unit of a curve whose differences were scaled by 2^scale_log2: units of twice the area, halved.
inline int32_t AreaUnitLog2(int scale_log2) { return -(kAreaFractionBits + 2 * scale_log2) - 1; }

struct AreaCurveIn {
  const Point2* points;
  const TriIdx* tri;
  const uint32_t* tri_rank;
  uint32_t n, num_tri, num_ranks;
};

/// The area curve over levels 0..num_ranks into `units_out` (twice the area, in units of
/// 2^-(kAreaFractionBits + 2 * scale)); returns the scale and the error bound in units.
template <class System>
AreaCurveScale AreaCurve(System& sys, const AreaCurveIn& in, unsigned long long* units_out) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  const uint32_t levels = in.num_ranks + 1;
  AreaCurveScale scale;
  const int scale_log2 = AreaScaleLog2(sys, in.points, in.n);
  scale.unit_log2 = AreaUnitLog2(scale_log2);
  thrust::fill_n(policy, units_out, levels, 0ull);
  if (in.num_tri == 0) return scale;
  const TriangleAreaUnits area{in.points, in.tri, scale_log2};
  thrust::for_each_n(policy, zero, in.num_tri, AddTriangleArea{area, in.tri_rank, units_out});
  thrust::inclusive_scan(policy, units_out, units_out + levels, units_out);
  scale.error_units = thrust::transform_reduce(policy, zero, zero + in.num_tri, TriangleAreaError{area, in.tri_rank},
                                               0ull, thrust::plus<unsigned long long>());
  return scale;
}

/// The set of a triangle of a packed build (of its first vertex, an input index).
struct TriangleSetOf {
  const TriIdx* tri;
  const uint32_t* input_set;
  GALPHA_HD uint32_t operator()(uint32_t t) const { return input_set[tri[t].v[0]]; }
};

/// The area curves of a packed build of `num_sets` sets (input indices grouped by set, `input_set`
/// naming each one's; triangles grouped by set; ranks numbered set after set): every triangle is
/// measured in its set's own scale (the box of the set's input, as the set's build alone measures
/// it), the units are added into the packed levels and scanned once, and each set's error bound is
/// the sum over its own triangles. Set s's curve is then units_out[R_s + l] - units_out[R_s] at
/// its level l (R_s: the ranks of the sets before it), in its scale: the levels of the other sets
/// add constants below and above it. The scan may wrap past 2^64 over thousands of sets; the
/// differences are exact all the same (unsigned arithmetic is modular, and each set's own sum stays
/// below 2^59). `set_scales` receives each set's scale and error.
template <class System>
void PackedAreaCurves(System& sys, const AreaCurveIn& in, const uint32_t* input_set, uint32_t num_sets,
                      unsigned long long* units_out, std::vector<AreaCurveScale>* set_scales) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  const uint32_t levels = in.num_ranks + 1;
  thrust::fill_n(policy, units_out, levels, 0ull);
  std::vector<int> scale_log2(num_sets, 0);
  std::vector<unsigned long long> error(num_sets, 0);
  if (in.n > 0) {
    // Every nonempty set's box (its input indices are one run), as its scale.
    Buffer<uint32_t, System> keys(sys, num_sets);
    Buffer<BoundingBox, System> boxes(sys, num_sets);
    const auto end = thrust::reduce_by_key(policy, input_set, input_set + in.n,
                                           thrust::make_transform_iterator(in.points, PointToBox()), keys.data(),
                                           boxes.data(), thrust::equal_to<uint32_t>(), MergeBoxes());
    const auto num_nonempty = static_cast<uint32_t>(end.first - keys.data());
    Buffer<int, System> scales(sys, num_nonempty);
    thrust::transform(policy, boxes.data(), boxes.data() + num_nonempty, scales.data(), BoxAreaScale{});
    const std::vector<uint32_t> host_keys = keys.ToHostVector(num_nonempty);
    const std::vector<int> host_scales = scales.ToHostVector(num_nonempty);
    for (uint32_t j = 0; j < num_nonempty; ++j) scale_log2[host_keys[j]] = host_scales[j];
  }
  if (in.num_tri > 0) {
    Buffer<int, System> set_scale(sys, num_sets);
    sys.FromHost(set_scale.data(), scale_log2.data(), num_sets);
    TriangleAreaUnits area{in.points, in.tri, 0, input_set, set_scale.data()};
    thrust::for_each_n(policy, zero, in.num_tri, AddTriangleArea{area, in.tri_rank, units_out});
    thrust::inclusive_scan(policy, units_out, units_out + levels, units_out);
    Buffer<uint32_t, System> tri_set(sys, in.num_tri);
    thrust::transform(policy, zero, zero + in.num_tri, tri_set.data(), TriangleSetOf{in.tri, input_set});
    Buffer<uint32_t, System> keys(sys, num_sets);
    Buffer<unsigned long long, System> sums(sys, num_sets);
    const auto errors = thrust::make_transform_iterator(zero, TriangleAreaError{area, in.tri_rank});
    const auto end =
        thrust::reduce_by_key(policy, tri_set.data(), tri_set.data() + in.num_tri, errors, keys.data(), sums.data());
    const auto num_meshes = static_cast<uint32_t>(end.first - keys.data());
    const std::vector<uint32_t> host_keys = keys.ToHostVector(num_meshes);
    const std::vector<unsigned long long> host_sums = sums.ToHostVector(num_meshes);
    for (uint32_t j = 0; j < num_meshes; ++j) error[host_keys[j]] = host_sums[j];
  }
  set_scales->resize(num_sets);
  for (uint32_t s = 0; s < num_sets; ++s) (*set_scales)[s] = AreaCurveScale{AreaUnitLog2(scale_log2[s]), error[s]};
}

}  // namespace galpha::detail
