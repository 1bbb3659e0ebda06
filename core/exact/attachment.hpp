// The exact attachment test of the alpha-shape family (the report "Computing 2D Alpha Shapes Using GPU",
// chapter 2; docs/design.md, "Semantics"): an edge pq is attached when the third vertex r of an
// incident Delaunay triangle lies strictly inside the edge's diametral circle (the smallest circle
// through p and q). By Thales' theorem that is the sign of the dot product (p - r) . (q - r):
// negative inside, zero on the circle (unattached, as in CGAL), positive outside. Same three layers
// as core/exact/predicates.hpp: a floating filter, then expansion arithmetic; one source for host
// and device.
#pragma once

#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/expansion.hpp"
#include "core/exact/predicates.hpp"

namespace galpha {

namespace exact {

/// Capacity of DiametralDotExpansion's output: (2x2 -> 8) + (2x2 -> 8) = 16 components.
constexpr int kDiametralExpansionCapacity = 16;

/// (p - r) . (q - r), scaled by a power of two so that nothing underflows or overflows, as a
/// nonoverlapping expansion of at most kDiametralExpansionCapacity components; returns its length.
/// Exact over the range of Orient2dSign (core/exact/predicates.hpp): the computation has the same shape.
GALPHA_HD inline int DiametralDotExpansion(Point2 p, Point2 q, Point2 r, double* out) {
  // p - r and q - r, by coordinate
  double d[4][2];
  int dl[4];
  if (!ScaledDifferences({p.x, p.y, q.x, q.y}, {r.x, r.y, r.x, r.y}, d, dl)) return 0;
  double xx[8], yy[8];
  const int xl = ExpansionProduct<2, 2>(dl[0], d[0], dl[2], d[2], xx);  // (px - rx)(qx - rx)
  const int yl = ExpansionProduct<2, 2>(dl[1], d[1], dl[3], d[3], yy);  // (py - ry)(qy - ry)
  return ExpansionSumZeroElim(xl, xx, yl, yy, out);
}

}  // namespace exact

/// +1 when r lies strictly inside the circle with diameter pq (pq is attached, if r is the third
/// vertex of an incident triangle), 0 on it, -1 outside. Exact; symmetric in p and q.
GALPHA_HD GALPHA_FORCEINLINE int InDiametralCircleSign(Point2 p, Point2 q, Point2 r) {
  using namespace exact;
  const double xx = Mul(Sub(p.x, r.x), Sub(q.x, r.x));
  const double yy = Mul(Sub(p.y, r.y), Sub(q.y, r.y));
  const double dot = Add(xx, yy);
  // The bound of orient2d's filter holds for a sum of two products of differences as for their
  // difference (Shewchuk's analysis uses absolute values only).
  const double errbound = Mul(pred_detail::kCcwErrBound, Add(Abs(xx), Abs(yy)));
  if (errbound >= pred_detail::kUnderflowGate && (dot > errbound || -dot > errbound)) {
    return dot < 0.0 ? 1 : -1;
  }
  double e[kDiametralExpansionCapacity];
  return -ExpansionSign(DiametralDotExpansion(p, q, r, e), e);
}

}  // namespace galpha
