// Exact power tests for weighted points, for the host and the device: the predicates of the
// regular (weighted Delaunay) triangulation.
//
// A weighted point (p, w) is a circle of squared radius w centred at p (w may be negative). Its
// lift is (x, y, x^2 + y^2 - w); the regular triangulation is the projection of the lower convex
// hull of the lifts, and a point whose lift lies above that hull is *hidden* (redundant).
//
// PowerSign(a, b, c, d) = sign of -det4 [[1, x, y, x^2 + y^2 - w]] over the rows a, b, c, d:
//   +1: d's lift lies strictly below the plane through the lifts of the counter-clockwise a, b, c
//       (d is "in conflict" with the triangle: it has negative power with respect to the circle
//       orthogonal to the three weighted circles), -1 above, 0 on it.
// With every weight 0 it is InCircleSign (core/exact/predicates.hpp).
//
// CollinearPowerSign(u, w, p) for p on the segment from u to w (exactly collinear): +1 when p's
// lift lies strictly below the segment between the lifts of u and w, -1 above, 0 on it.
//
// Evaluation: a floating-point filter with a rigorous error bound, then the exact determinant in
// expansion arithmetic (core/exact/expansion.hpp) on coordinates and weights scaled by 2^s and
// 2^(2s) (the sign does not change). PowerSoS never returns 0: it breaks exact ties by Simulation of
// Simplicity with the lifted coordinate perturbed as an independent coordinate, the scheme
// Orient2dSoS and InCircleSoS share (predicates.hpp), on the ranks the caller gives. The engine's
// ranks put the lexicographically largest point first, so that the first term of the perturbation
// (the lift of the point of rank 0 raised) is CGAL's (Regular_triangulation_2::power_test with
// perturbation, which raises the lift of the lexicographically largest point first): exact power
// ties hide the same points as CGAL's weighted triangulation wherever that term decides.
//
// SUPPORTED RANGE: as InCircleSign's (predicates.hpp), with sqrt(|w|) counted as a coordinate
// magnitude: with H the largest of the |coordinates| and sqrt(|w|) of one call and m the smallest
// nonzero one (floored at 2^-1022), H < 2^500 and H / m < 2^437. The engine validates weights
// against it (core/io/input_validation.hpp, ValidateWeights).
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/expansion.hpp"
#include "core/exact/predicates.hpp"

#if defined(__CUDACC__)
#define GALPHA_POWER_COLD __noinline__
#else
#define GALPHA_POWER_COLD __attribute__((noinline))
#endif

namespace galpha {

namespace exact {

/// Capacity of PowerExpansion's output: 4 terms of lift (5) x minor (12) -> 120 each = 480.
constexpr int kPowerExpansionCapacity = 480;

}  // namespace exact

namespace power_detail {

using namespace exact;

/// The scale 2^s that brings the largest of the |coordinates| and sqrt(|w|) of n weighted points
/// to [2^247, 2^249): coordinates then lie below 2^249 and weights below 2^498, as the in-circle
/// test's lifts do (predicates.hpp, kInCircleScaleTarget). Returns false when everything is zero.
template <int n>
GALPHA_HD inline bool ScaleWeighted(const Point2* p, const double* w, double* x, double* y, double* ws) {
  double max_coordinate = 0.0, max_weight = 0.0;
  for (int i = 0; i < n; ++i) {
    max_coordinate = Abs(p[i].x) > max_coordinate ? Abs(p[i].x) : max_coordinate;
    max_coordinate = Abs(p[i].y) > max_coordinate ? Abs(p[i].y) : max_coordinate;
    max_weight = Abs(w[i]) > max_weight ? Abs(w[i]) : max_weight;
  }
  if (max_coordinate == 0.0 && max_weight == 0.0) return false;
  int e = max_coordinate > 0.0 ? ExponentOf(max_coordinate) : -1074;
  if (max_weight > 0.0) {
    // |w| < 2^(ew + 1), so sqrt(|w|) < 2^((ew + 1) / 2) <= 2^((ew + 2) >> 1).
    const int ew = (ExponentOf(max_weight) + 2) >> 1;
    e = ew > e ? ew : e;
  }
  const int s = kInCircleScaleTarget - e;
  for (int i = 0; i < n; ++i) {
    x[i] = ScaleByPow2(p[i].x, s);
    y[i] = ScaleByPow2(p[i].y, s);
    ws[i] = ScaleByPow2(ScaleByPow2(w[i], s), s);
  }
  return true;
}

/// z = x^2 + y^2 - w exactly: at most 5 components.
GALPHA_HD inline int WeightedLift(double x, double y, double w, double* z) {
  double lift[4];
  const int ll = pred_detail::Lift(x, y, lift);
  const double minus_w = -w;
  return ExpansionSumZeroElim(ll, lift, minus_w != 0.0 ? 1 : 0, &minus_w, z);
}

}  // namespace power_detail

namespace exact {

/// The exact power determinant (PowerSign's sign), times 2^(4s) for an internal s, as a
/// nonoverlapping expansion of at most kPowerExpansionCapacity components; returns its length.
/// Evaluated as InCircleExpansion is, on scaled raw coordinates:
///   z_a [1,x,y](b,c,d) - z_b [1,x,y](a,c,d) + z_c [1,x,y](a,b,d) - z_d [1,x,y](a,b,c)
/// with z = x^2 + y^2 - w.
GALPHA_HD GALPHA_POWER_COLD inline int PowerExpansion(const Point2* p, const double* w, double* out) {
  using namespace power_detail;
  double x[4], y[4], ws[4];
  if (!ScaleWeighted<4>(p, w, x, y, ws)) return 0;
  double cr[6][4];
  int cl[6];
  cl[0] = pred_detail::Cross(x[0], y[0], x[1], y[1], cr[0]);
  cl[1] = pred_detail::Cross(x[0], y[0], x[2], y[2], cr[1]);
  cl[2] = pred_detail::Cross(x[0], y[0], x[3], y[3], cr[2]);
  cl[3] = pred_detail::Cross(x[1], y[1], x[2], y[2], cr[3]);
  cl[4] = pred_detail::Cross(x[1], y[1], x[3], y[3], cr[4]);
  cl[5] = pred_detail::Cross(x[2], y[2], x[3], y[3], cr[5]);
  // The minor of the other three points, as in InCircleExpansion.
  constexpr int kTerms[4][3] = {{3, 5, 4}, {1, 5, 2}, {0, 4, 2}, {0, 3, 1}};
  double term[2][120], part[2][240];
  int terml[2], partl[2];
  for (int i = 0; i < 4; ++i) {
    double minor[12], z[5];
    const int* k = kTerms[i];
    const int ml = pred_detail::SumSumDiff(cl[k[0]], cr[k[0]], cl[k[1]], cr[k[1]], cl[k[2]], cr[k[2]], minor);
    const int zl = WeightedLift(x[i], y[i], ws[i], z);
    terml[i & 1] = ExpansionProduct<12, 5>(ml, minor, zl, z, term[i & 1]);
    if (i & 1) partl[i >> 1] = ExpansionDiffZeroElim(terml[0], term[0], terml[1], term[1], part[i >> 1]);
  }
  return ExpansionSumZeroElim(partl[0], part[0], partl[1], part[1], out);
}

}  // namespace exact

namespace power_detail {

/// The filter's bound: the lift gains one operation over the in-circle test's (the weight
/// difference), so Shewchuk's (10 + 96 eps) eps grows to below 12 eps to first order; 16 eps, with
/// the predicates' margin for underflow, is safe.
constexpr double kPowerErrBound = (16.0 + 256.0 * exact::kEpsilon) * exact::kEpsilon * (1.0 + 0x1p-20);

GALPHA_HD GALPHA_POWER_COLD inline int PowerSignExact(const Point2* p, const double* w) {
  double e[exact::kPowerExpansionCapacity];
  return exact::ExpansionSign(exact::PowerExpansion(p, w, e), e);
}

}  // namespace power_detail

/// Exact power test (see the file comment): +1 when d's lift lies strictly below the plane of the
/// lifts of the counter-clockwise a, b, c, -1 above, 0 on it. The sign flips for clockwise a, b, c.
GALPHA_HD GALPHA_FORCEINLINE int PowerSign(Point2 a, double wa, Point2 b, double wb, Point2 c, double wc, Point2 d,
                                           double wd) {
  using namespace exact;
  const double adx = Sub(a.x, d.x), ady = Sub(a.y, d.y);
  const double bdx = Sub(b.x, d.x), bdy = Sub(b.y, d.y);
  const double cdx = Sub(c.x, d.x), cdy = Sub(c.y, d.y);
  const double awd = Sub(wa, wd), bwd = Sub(wb, wd), cwd = Sub(wc, wd);
  const double bdxcdy = Mul(bdx, cdy), cdxbdy = Mul(cdx, bdy);
  const double cdxady = Mul(cdx, ady), adxcdy = Mul(adx, cdy);
  const double adxbdy = Mul(adx, bdy), bdxady = Mul(bdx, ady);
  const double asq = Add(Mul(adx, adx), Mul(ady, ady));
  const double bsq = Add(Mul(bdx, bdx), Mul(bdy, bdy));
  const double csq = Add(Mul(cdx, cdx), Mul(cdy, cdy));
  const double alift = Sub(asq, awd), blift = Sub(bsq, bwd), clift = Sub(csq, cwd);
  const double det =
      Add(Add(Mul(alift, Sub(bdxcdy, cdxbdy)), Mul(blift, Sub(cdxady, adxcdy))), Mul(clift, Sub(adxbdy, bdxady)));
  const double amag = Add(asq, Abs(awd)), bmag = Add(bsq, Abs(bwd)), cmag = Add(csq, Abs(cwd));
  const double pa = Add(Abs(bdxcdy), Abs(cdxbdy));
  const double pb = Add(Abs(cdxady), Abs(adxcdy));
  const double pc = Add(Abs(adxbdy), Abs(bdxady));
  const double permanent = Add(Add(Mul(pa, amag), Mul(pb, bmag)), Mul(pc, cmag));
  const double errbound = Mul(power_detail::kPowerErrBound, permanent);
  // Underflow, as in InCircleSign: an error of at most 2^-1075 in a product is multiplied by a
  // lift's magnitude, a cross term or 1.
  const double gate = Mul(pred_detail::kUnderflowGate, Add(Add(Add(Add(amag, bmag), Add(cmag, pa)), Add(pb, pc)), 1.0));
  if (errbound >= gate && (det > errbound || -det > errbound)) return det > 0.0 ? 1 : -1;
  const Point2 p[4] = {a, b, c, d};
  const double w[4] = {wa, wb, wc, wd};
  return power_detail::PowerSignExact(p, w);
}

namespace power_detail {

/// [1,u,z](i,j,k) with z = x^2 + y^2 - w, exactly, from scaled coordinates (u_i (z_j - z_k) + ..., on
/// weighted lifts of up to 5 components); returns its sign.
GALPHA_HD GALPHA_POWER_COLD inline int WeightedMinorUZSign(const double* u, const double (*z)[5], const int* zl, int i,
                                                           int j, int k) {
  const int idx[3] = {i, j, k};
  double acc[60], next[60];
  int accl = 0;
  for (int t = 0; t < 3; ++t) {
    const int p = idx[t], q = idx[(t + 1) % 3], r = idx[(t + 2) % 3];
    double zd[10], term[20];
    const int zdl = ExpansionDiffZeroElim(zl[q], z[q], zl[r], z[r], zd);
    const int tl = ScaleExpansionZeroElim(zdl, zd, u[p], term);
    accl = ExpansionSumZeroElim(accl, acc, tl, term, next);
    for (int m = 0; m < accl; ++m) acc[m] = next[m];
  }
  return ExpansionSign(accl, acc);
}

/// Det4SoSSign (predicates.hpp) with weighted lifts: the same perturbation and the same terms,
/// rows sorted by rank.
GALPHA_HD inline int WeightedDet4SoSSign(const Point2* p, const double* w) {
  int t = -Orient2dSign(p[1], p[2], p[3]);  // 2: the lift of rank 0 raised
  if (t != 0) return t;
  double x[4] = {0.0, 0.0, 0.0, 0.0}, y[4] = {0.0, 0.0, 0.0, 0.0}, ws[4] = {0.0, 0.0, 0.0, 0.0}, z[4][5];
  int zl[4];
  ScaleWeighted<4>(p, w, x, y, ws);  // leaves the zeros when everything is 0
  for (int i = 0; i < 4; ++i) zl[i] = WeightedLift(x[i], y[i], ws[i], z[i]);
  t = WeightedMinorUZSign(x, z, zl, 1, 2, 3);                 // 3
  if (t == 0) t = -WeightedMinorUZSign(y, z, zl, 1, 2, 3);    // 4
  if (t == 0) t = Orient2dSign(p[0], p[2], p[3]);             // 5
  if (t == 0) t = pred_detail::CompareSign(p[3].x, p[2].x);   // 6
  if (t == 0) t = -pred_detail::CompareSign(p[3].y, p[2].y);  // 7
  if (t == 0) t = -Orient2dSign(p[0], p[1], p[3]);            // 14
  if (t == 0) t = -pred_detail::CompareSign(p[3].x, p[1].x);  // 15
  if (t == 0) t = pred_detail::CompareSign(p[3].y, p[1].y);   // 16
  if (t == 0) t = pred_detail::CompareSign(p[3].x, p[0].x);   // 17
  return t != 0 ? t : -1;                                     // 18
}

GALPHA_HD GALPHA_POWER_COLD inline int PowerSoSDegenerate(Point2 a, double wa, uint32_t ia, Point2 b, double wb,
                                                          uint32_t ib, Point2 c, double wc, uint32_t ic, Point2 d,
                                                          double wd, uint32_t id) {
  Point2 p[4] = {a, b, c, d};
  double w[4] = {wa, wb, wc, wd};
  uint32_t rank[4] = {ia, ib, ic, id};
  int parity = 1;
  for (int i = 1; i < 4; ++i) {
    for (int j = i; j > 0 && rank[j] < rank[j - 1]; --j) {
      const uint32_t tr = rank[j];
      rank[j] = rank[j - 1];
      rank[j - 1] = tr;
      const Point2 tp = p[j];
      p[j] = p[j - 1];
      p[j - 1] = tp;
      const double tw = w[j];
      w[j] = w[j - 1];
      w[j - 1] = tw;
      parity = -parity;
    }
  }
  return -(parity * WeightedDet4SoSSign(p, w));
}

}  // namespace power_detail

/// Power test under Simulation of Simplicity on distinct ranks (the perturbation Orient2dSoS uses,
/// so that the two predicates describe one perturbed point set): never 0, equal to PowerSign
/// whenever that is nonzero.
GALPHA_HD GALPHA_FORCEINLINE int PowerSoS(Point2 a, double wa, uint32_t ia, Point2 b, double wb, uint32_t ib, Point2 c,
                                          double wc, uint32_t ic, Point2 d, double wd, uint32_t id) {
  const int s = PowerSign(a, wa, b, wb, c, wc, d, wd);
  return s != 0 ? s : power_detail::PowerSoSDegenerate(a, wa, ia, b, wb, ib, c, wc, ic, d, wd, id);
}

/// The power test of three collinear weighted points, p between u and w (see the file comment):
/// +1 when p's lift lies strictly below the segment of the lifts of u and w, -1 above, 0 on it.
/// With t the coordinate along which u and w differ, the sign of
///   (z_u (t_w - t_p) + z_w (t_p - t_u) - z_p (t_w - t_u)) * sign(t_w - t_u),
/// evaluated exactly (no filter: it decides the rare points on hull segments).
GALPHA_HD GALPHA_POWER_COLD inline int CollinearPowerSign(Point2 u, double wu, Point2 w, double ww, Point2 p,
                                                          double wp) {
  using namespace exact;
  using namespace power_detail;
  const Point2 pts[3] = {u, w, p};
  const double wts[3] = {wu, ww, wp};
  double x[3], y[3], ws[3];
  if (!ScaleWeighted<3>(pts, wts, x, y, ws)) return 0;
  const double* t = x[0] != x[1] ? x : y;
  const int direction = t[1] > t[0] ? 1 : -1;
  double z[3][5];
  int zl[3];
  for (int i = 0; i < 3; ++i) zl[i] = WeightedLift(x[i], y[i], ws[i], z[i]);
  // Differences t_w - t_p, t_p - t_u, t_w - t_u, exact as two components each.
  double d[3][2];
  int dl[3];
  double hi, lo;
  TwoDiff(t[1], t[2], hi, lo);
  dl[0] = TwoToExpansion(hi, lo, d[0]);
  TwoDiff(t[2], t[0], hi, lo);
  dl[1] = TwoToExpansion(hi, lo, d[1]);
  TwoDiff(t[1], t[0], hi, lo);
  dl[2] = TwoToExpansion(hi, lo, d[2]);
  double term[3][20], sum[40], total[60];
  int terml[3];
  for (int i = 0; i < 3; ++i) terml[i] = ExpansionProduct<5, 2>(zl[i], z[i], dl[i], d[i], term[i]);
  const int suml = ExpansionSumZeroElim(terml[0], term[0], terml[1], term[1], sum);
  const int totall = ExpansionDiffZeroElim(suml, sum, terml[2], term[2], total);
  return direction * ExpansionSign(totall, total);
}

}  // namespace galpha

#undef GALPHA_POWER_COLD
