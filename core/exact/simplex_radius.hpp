// One entry point per radius operation for the alpha pipeline, weighted or not: `w` is the
// simplex's weights, or nullptr for an unweighted family (radius_*.hpp, unchanged); weighted
// simplices take weighted_radius.hpp. The weighted paths are kept out of line on the device, so
// that the unweighted kernels keep their registers and their speed. Host and device alike.
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/attachment.hpp"
#include "core/exact/order.hpp"
#include "core/exact/radius_compare.hpp"
#include "core/exact/radius_key.hpp"
#include "core/exact/radius_nearest.hpp"
#include "core/exact/radius_refined.hpp"
#include "core/exact/weighted_radius.hpp"

namespace galpha {

namespace simplex_radius_detail {

GALPHA_HD GALPHA_NOINLINE inline RadiusSqApprox ApproxWeighted(const Point2* p, const double* w, int n) {
  return ApproxWeightedRadiusSq(p, w, n);
}
GALPHA_HD GALPHA_NOINLINE inline Order CompareWeighted(const Point2* a, const double* wa, int na, const Point2* b,
                                                       const double* wb, int nb) {
  return CompareWeightedRadiusSqBounded(a, wa, na, b, wb, nb);
}
GALPHA_HD GALPHA_NOINLINE inline bool NearestWeighted(const Point2* p, const double* w, int n, double* out) {
  return NearestWeightedRadiusSqFast(p, w, n, out) || NearestWeightedRadiusSqBounded(p, w, n, out);
}
GALPHA_HD GALPHA_NOINLINE inline RefinedRadiusSq RefineWeighted(const Point2* p, const double* w, int n) {
  return RefineWeightedRadiusSq(p, w, n);
}
GALPHA_HD GALPHA_NOINLINE inline int AttachedWeighted(Point2 p, Point2 q, Point2 r, double wp, double wq, double wr) {
  return WeightedAttachedSign(p, q, r, wp, wq, wr);
}

}  // namespace simplex_radius_detail

/// Certified key of rho^2 (radius_key.hpp's order; signed keys when weighted).
GALPHA_HD inline RadiusSqApprox ApproxSimplexRadiusSq(const Point2* p, const double* w, int n) {
  return w != nullptr ? simplex_radius_detail::ApproxWeighted(p, w, n) : ApproxRadiusSq(p, n);
}

/// Exact order of two simplices' rho^2 in bounded arithmetic (Order::kUndecided: the host decides).
GALPHA_HD inline Order CompareSimplexRadiusSqBounded(const Point2* a, const double* wa, int na, const Point2* b,
                                                     const double* wb, int nb) {
  return wa != nullptr ? simplex_radius_detail::CompareWeighted(a, wa, na, b, wb, nb)
                       : CompareRadiusSqBounded(a, na, b, nb);
}

/// Equal rho^2 proved without arithmetic (congruent simplices; weighted: one weight throughout).
GALPHA_HD inline bool SimplexRadiusCongruent(const Point2* a, const double* wa, int na, const Point2* b,
                                             const double* wb, int nb) {
  return wa != nullptr ? WeightedRadiusCongruent(a, wa, na, b, wb, nb) : RadiusCongruent(a, na, b, nb);
}

/// A hash that SimplexRadiusCongruent's equal pairs share (CongruenceHash; weighted, with the
/// first weight mixed in: congruent weighted simplices carry one weight throughout). Equal hashes
/// prove nothing.
GALPHA_HD inline uint64_t SimplexCongruenceHash(const Point2* p, const double* w, int n) {
  const uint64_t h = CongruenceHash(p, n);
  if (w == nullptr) return h;
  const uint64_t weight = exact::DoubleBits(w[0] == 0.0 ? 0.0 : w[0]);
  return (h ^ weight) * 0x94d049bb133111ebULL;
}

/// rho^2 when it is exactly a double computed exactly (unweighted grids; never claimed weighted).
GALPHA_HD inline bool ExactDoubleSimplexRadiusSq(const Point2* p, const double* w, int n, double* out) {
  return w == nullptr && ExactDoubleRadiusSq(p, n, out);
}

/// The refined key (radius_refined.hpp; signed when weighted).
GALPHA_HD inline RefinedRadiusSq RefineSimplexRadiusSq(const Point2* p, const double* w, int n) {
  return w != nullptr ? simplex_radius_detail::RefineWeighted(p, w, n) : RefineRadiusSq(p, n);
}

/// The nearest double of rho^2; false when the host must round it.
GALPHA_HD inline bool NearestSimplexRadiusSq(const Point2* p, const double* w, int n, double* out) {
  if (w != nullptr) return simplex_radius_detail::NearestWeighted(p, w, n, out);
  return NearestRadiusSqFast(p, n, out) || NearestRadiusSqBounded(p, n, out);
}

/// +1 when r attaches the edge pq (unweighted: strictly inside its diametral circle; weighted:
/// negative power with respect to its smallest orthogonal circle), 0 on the circle, -1 outside,
/// 2 undecided by bounded arithmetic (weighted only: the host decides). `w` holds the weights of
/// p, q, r, or is nullptr.
GALPHA_HD inline int SimplexAttachedSign(Point2 p, Point2 q, Point2 r, const double* w) {
  return w != nullptr ? simplex_radius_detail::AttachedWeighted(p, q, r, w[0], w[1], w[2])
                      : InDiametralCircleSign(p, q, r);
}

}  // namespace galpha
