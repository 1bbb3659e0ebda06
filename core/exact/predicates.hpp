// Exact geometric predicates for the plane, for the host and the device, with Simulation of
// Simplicity (SoS) on the points' input indices.
//
// Orient2dSign(a, b, c)    = sign det [[bx-ax, by-ay], [cx-ax, cy-ay]]
//                            (+1: a, b, c counter-clockwise)
// InCircleSign(a, b, c, d) = sign of -det [[1, x, y, x^2+y^2]] over the rows a, b, c, d
//                            (+1: d strictly inside the circle through the ccw triangle a, b, c)
//
// Each sign is computed adaptively (Shewchuk 1997): a floating-point filter with a rigorous error
// bound decides the common case; only when it cannot, an exact evaluation with expansion
// arithmetic (core/exact/expansion.hpp) runs. The SoS variants never return 0: they evaluate the exact
// sign first and fall back to the perturbation terms only when it is 0.
//
// SUPPORTED COORDINATE RANGE (the guarantee; tests/core/exact/predicates_test.cpp checks it). Let
// H be the largest |coordinate| and m the smallest nonzero |coordinate| among the points of one call,
// and m' = max(m, 2^-1022) (subnormals count as 2^-1022). Then:
//   * Orient2dSign is exact when H < 2^1022 (~4.4e307) and H / m' < 2^930 (~9e279);
//   * InCircleSign, Orient2dSoS and InCircleSoS are exact when H < 2^1022 and H / m' < 2^437
//     (~3.5e131).
// For example: coordinates up to 1e15 in a call whose smallest nonzero coordinate is above
// ~1e-116 (Orient2dSign: above ~1e-264); tiny inputs, subnormals
// included, whenever every coordinate of the call is below 2^-584 (~1.6e-176; Orient2dSign: below
// 2^-92); magnitudes mixed anywhere within 1e-65 .. 1e65 (Orient2dSign: 1e-135 .. 1e135). Why
// there is a limit: the exact stage rescales its input by a power of two so that nothing
// overflows, but one binary64 exponent range (2^-1074 .. 2^1024) cannot hold every partial product
// of a degree-4 polynomial whose inputs span more than ~2^437 (degree 2: ~2^930); outside the range
// a product's tail may underflow and the sign is then only almost always right.
// Non-finite inputs (inf, NaN) are not supported. The engine keeps every call within this range by
// refusing point sets outside its input domain (core/io/input_validation.hpp) before any work.
//
// Filters and underflow: Shewchuk's bounds assume no underflow. An underflowing product can be off
// by up to 2^-1075 absolutely, which such bounds do not cover, so the filters also require the
// bound itself to be large compared with what underflow could contribute (2^-1000 times the
// magnitudes the underflow errors get multiplied by); otherwise they defer to the exact stage.
// Overflow in a filter produces inf or NaN, for which the comparisons fail, so again the exact
// stage (which rescales) decides.
//
// Device use: the exact stages keep fixed-size local arrays; on sm_90 a kernel calling
// InCircleSign or InCircleSoS needs ~9.1 KB of stack (local memory) per thread, one calling
// Orient2dSign or Orient2dSoS ~0.4 KB. The exact stages and the SoS tails are noinline on the
// device, so they do not weigh on the register allocation of the callers' fast paths (~54-90
// registers for kernels that only evaluate one of these predicates).
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/double_double.hpp"
#include "core/exact/expansion.hpp"

#if defined(__CUDACC__)
#define GALPHA_PRED_COLD __noinline__
#else
#define GALPHA_PRED_COLD __attribute__((noinline))
#endif

namespace galpha {

// ---- Plain approximations (heuristics only; never fused, so host and device agree bit for bit) --

/// det [[bx-ax, by-ay], [cx-ax, cy-ay]] in plain double arithmetic.
GALPHA_HD GALPHA_FORCEINLINE double Orient2dApprox(Point2 a, Point2 b, Point2 c) {
  using namespace exact;
  return Sub(Mul(Sub(b.x, a.x), Sub(c.y, a.y)), Mul(Sub(b.y, a.y), Sub(c.x, a.x)));
}

/// The in-circle determinant (positive when d is inside the ccw circle a, b, c), plain doubles,
/// in Shewchuk's form with d as the origin.
GALPHA_HD GALPHA_FORCEINLINE double InCircleApprox(Point2 a, Point2 b, Point2 c, Point2 d) {
  using namespace exact;
  const double adx = Sub(a.x, d.x), ady = Sub(a.y, d.y);
  const double bdx = Sub(b.x, d.x), bdy = Sub(b.y, d.y);
  const double cdx = Sub(c.x, d.x), cdy = Sub(c.y, d.y);
  const double alift = Add(Mul(adx, adx), Mul(ady, ady));
  const double blift = Add(Mul(bdx, bdx), Mul(bdy, bdy));
  const double clift = Add(Mul(cdx, cdx), Mul(cdy, cdy));
  return Add(Add(Mul(alift, Sub(Mul(bdx, cdy), Mul(cdx, bdy))), Mul(blift, Sub(Mul(cdx, ady), Mul(adx, cdy)))),
             Mul(clift, Sub(Mul(adx, bdy), Mul(bdx, ady))));
}

namespace exact {

/// Capacity of Orient2dExpansion's output: (2x2 -> 8) - (2x2 -> 8) = 16 components.
constexpr int kOrient2dExpansionCapacity = 16;
/// Capacity of InCircleExpansion's output: 4 terms of lift (4) x minor (12) -> 96 each = 384.
constexpr int kInCircleExpansionCapacity = 384;

/// Scaling targets: the exact stages multiply their inputs by 2^s so that the largest magnitude
/// lies in [2^target, 2^(target+1)). Orient: differences < 2^501, products < 2^1002, the
/// determinant < 2^1003 (no overflow); products stay exact while both factors have exponents
/// >= -485, i.e. for a spread of 985 binary orders between the largest and the smallest nonzero
/// component of the differences. InCircle: coordinates < 2^249, 2x2 terms < 2^499, minors < 2^501,
/// lifts < 2^499, degree-4 terms < 2^1000, the sum < 2^1002; a degree-4 partial product is exact
/// when the grid of the (scaled) coordinates is >= 2^-242, i.e. for a spread of 490 orders between
/// the largest coordinate and the smallest coordinate ulp.
constexpr int kOrientScaleTarget = 500;
constexpr int kInCircleScaleTarget = 248;

}  // namespace exact

namespace pred_detail {

using namespace exact;

/// Scales the coordinates of n points by 2^s so that the largest lies in [2^248, 2^249); returns
/// false when all coordinates are zero.
template <int n>
GALPHA_HD inline bool ScaleForInCircle(const Point2* p, double* x, double* y) {
  double maxabs = 0.0;
  for (int i = 0; i < n; ++i) {
    maxabs = Abs(p[i].x) > maxabs ? Abs(p[i].x) : maxabs;
    maxabs = Abs(p[i].y) > maxabs ? Abs(p[i].y) : maxabs;
  }
  if (maxabs == 0.0) return false;
  const int s = kInCircleScaleTarget - ExponentOf(maxabs);
  for (int i = 0; i < n; ++i) {
    x[i] = ScaleByPow2(p[i].x, s);
    y[i] = ScaleByPow2(p[i].y, s);
  }
  return true;
}

/// z = x^2 + y^2 exactly: at most 4 components.
GALPHA_HD inline int Lift(double x, double y, double* z) {
  double x1, x0, y1, y0, ex[2], ey[2];
  TwoProduct(x, x, x1, x0);
  TwoProduct(y, y, y1, y0);
  const int lx = TwoToExpansion(x1, x0, ex);
  const int ly = TwoToExpansion(y1, y0, ey);
  return ExpansionSumZeroElim(lx, ex, ly, ey, z);
}

/// x_i * y_j - x_j * y_i exactly: at most 4 components.
GALPHA_HD inline int Cross(double xi, double yi, double xj, double yj, double* out) {
  double p1, p0, q1, q0, ep[2], eq[2];
  TwoProduct(xi, yj, p1, p0);
  TwoProduct(xj, yi, q1, q0);
  const int lp = TwoToExpansion(p1, p0, ep);
  const int lq = TwoToExpansion(q1, q0, eq);
  return ExpansionDiffZeroElim(lp, ep, lq, eq, out);
}

/// p + q - r for 4-component inputs, e.g. [1,x,y](i,j,k) = C(i,j) + C(j,k) + C(k,i): at most 12
/// components.
GALPHA_HD inline int SumSumDiff(int lp, const double* p, int lq, const double* q, int lr, const double* r,
                                double* out) {
  double t[8];
  const int lt = ExpansionSumZeroElim(lp, p, lq, q, t);
  return ExpansionDiffZeroElim(lt, t, lr, r, out);
}

/// sign(u - v), exactly (a comparison cannot round).
GALPHA_HD GALPHA_FORCEINLINE int CompareSign(double u, double v) { return (u > v) - (u < v); }

}  // namespace pred_detail

namespace exact {

/// The four exact differences u[i] - v[i] (Two-Diff, never rounded), all scaled by one power of two
/// 2^s that brings the largest to 2^kOrientScaleTarget, as expansions d[i] of dl[i] <= 2
/// components. Products of two of them, and sums of such products, are then exact (no underflow,
/// no overflow) over Orient2dSign's range. Returns false when every difference is zero.
GALPHA_HD inline bool ScaledDifferences(const double (&u)[4], const double (&v)[4], double (&d)[4][2], int (&dl)[4]) {
  double hi[4], lo[4];
  for (int i = 0; i < 4; ++i) TwoDiff(u[i], v[i], hi[i], lo[i]);
  double maxabs = 0.0;
  for (const double h : hi) maxabs = Abs(h) > maxabs ? Abs(h) : maxabs;
  if (maxabs == 0.0) return false;  // hi == 0 means the difference was exact, so lo == 0 too
  const int s = kOrientScaleTarget - ExponentOf(maxabs);
  for (int i = 0; i < 4; ++i) dl[i] = TwoToExpansion(ScaleByPow2(hi[i], s), ScaleByPow2(lo[i], s), d[i]);
  return true;
}

/// The exact determinant of Orient2dSign, times 2^(2s) for an internal s (so with the same sign),
/// as a nonoverlapping expansion of at most kOrient2dExpansionCapacity components; returns its
/// length (0 for zero). Built on the exact differences b-a and c-a (Two-Diff), never on rounded
/// ones.
GALPHA_HD GALPHA_PRED_COLD inline int Orient2dExpansion(Point2 a, Point2 b, Point2 c, double* out) {
  // bax, bay, cax, cay
  double d[4][2];
  int dl[4];
  if (!ScaledDifferences({b.x, b.y, c.x, c.y}, {a.x, a.y, a.x, a.y}, d, dl)) return 0;
  double left[8], right[8];
  const int ll = ExpansionProduct<2, 2>(dl[0], d[0], dl[3], d[3], left);   // bax * cay
  const int rl = ExpansionProduct<2, 2>(dl[2], d[2], dl[1], d[1], right);  // cax * bay
  return ExpansionDiffZeroElim(ll, left, rl, right, out);
}

/// The exact in-circle determinant (positive inside), times 2^(4s) for an internal s, as a
/// nonoverlapping expansion of at most kInCircleExpansionCapacity components; returns its length.
/// Evaluated on the (scaled) raw coordinates as
///   z_a [1,x,y](b,c,d) - z_b [1,x,y](a,c,d) + z_c [1,x,y](a,b,d) - z_d [1,x,y](a,b,c),
/// which is -det4 [[1,x,y,z]] expanded along the z column (z = x^2 + y^2, exact). The
/// raw-coordinate form keeps every factor a single double (lifts 4 and minors 12 components) where
/// exact differences would double each factor (1536 components, 4x the local memory).
GALPHA_HD GALPHA_PRED_COLD inline int InCircleExpansion(Point2 a, Point2 b, Point2 c, Point2 d, double* out) {
  using namespace pred_detail;
  const Point2 p[4] = {a, b, c, d};
  double x[4], y[4];
  if (!ScaleForInCircle<4>(p, x, y)) return 0;
  // C(i,j) = x_i y_j - x_j y_i for the pairs 01 02 03 12 13 23.
  double cr[6][4];
  int cl[6];
  cl[0] = Cross(x[0], y[0], x[1], y[1], cr[0]);
  cl[1] = Cross(x[0], y[0], x[2], y[2], cr[1]);
  cl[2] = Cross(x[0], y[0], x[3], y[3], cr[2]);
  cl[3] = Cross(x[1], y[1], x[2], y[2], cr[3]);
  cl[4] = Cross(x[1], y[1], x[3], y[3], cr[4]);
  cl[5] = Cross(x[2], y[2], x[3], y[3], cr[5]);
  // [1,x,y](i,j,k) = C(i,j) + C(j,k) + C(k,i); for each point the minor of the other three:
  // bcd = C12 + C23 - C13, acd = C02 + C23 - C03, abd = C01 + C13 - C03, abc = C01 + C12 - C02.
  constexpr int kTerms[4][3] = {{3, 5, 4}, {1, 5, 2}, {0, 4, 2}, {0, 3, 1}};
  double term[2][96], part[2][192];
  int terml[2], partl[2];
  for (int i = 0; i < 4; ++i) {
    double minor[12], z[4];
    const int* k = kTerms[i];
    const int ml = SumSumDiff(cl[k[0]], cr[k[0]], cl[k[1]], cr[k[1]], cl[k[2]], cr[k[2]], minor);
    const int zl = Lift(x[i], y[i], z);
    terml[i & 1] = ExpansionProduct<12, 4>(ml, minor, zl, z, term[i & 1]);
    if (i & 1) {  // part0 = z_a M_a - z_b M_b, part1 = z_c M_c - z_d M_d
      partl[i >> 1] = ExpansionDiffZeroElim(terml[0], term[0], terml[1], term[1], part[i >> 1]);
    }
  }
  return ExpansionSumZeroElim(partl[0], part[0], partl[1], part[1], out);
}

}  // namespace exact

namespace pred_detail {

/// Shewchuk's bounds (ccwerrboundA = (3 + 16 eps) eps, iccerrboundA = (10 + 96 eps) eps) enlarged
/// by a relative 2^-20, a margin that absorbs the underflow contributions the gates below allow.
constexpr double kCcwErrBound = (3.0 + 16.0 * exact::kEpsilon) * exact::kEpsilon * (1.0 + 0x1p-20);
constexpr double kIccErrBound = (10.0 + 96.0 * exact::kEpsilon) * exact::kEpsilon * (1.0 + 0x1p-20);
/// Underflow gate: each product that underflows is off by at most 2^-1075; a bound of at least
/// 2^-1000 times the factors such errors are multiplied by dwarfs them (by 2^-70 or more).
constexpr double kUnderflowGate = 0x1p-1000;

/// Accumulates whether every operation of a computation was exact: each result is formed with an
/// error-free transformation, and the computation is exact iff every tail is zero.
struct ExactnessWitness {
  bool exact = true;
  GALPHA_HD GALPHA_FORCEINLINE double Diff(double a, double b) {
    double x, y;
    exact::TwoDiff(a, b, x, y);
    exact = exact && y == 0.0;
    return x;
  }
  GALPHA_HD GALPHA_FORCEINLINE double Sum(double a, double b) {
    double x, y;
    exact::TwoSum(a, b, x, y);
    exact = exact && y == 0.0;
    return x;
  }
  GALPHA_HD GALPHA_FORCEINLINE double Product(double a, double b) {
    double x, y;
    exact::TwoProduct(a, b, x, y);
    exact = exact && y == 0.0;
    return x;
  }
};

/// Whether every nonzero value among v[0..n) has its binary exponent in [lowest, highest): the
/// range where the error-free transformations' zero tails prove an operation exact (no partial
/// product underflows, no split overflows), for the stages that try plain doubles first.
GALPHA_HD GALPHA_FORCEINLINE bool NonzeroExponentsWithin(const double* v, int n, int lowest, int highest) {
  for (int i = 0; i < n; ++i) {
    if (v[i] != 0.0 && (exact::ExponentOf(v[i]) < lowest || exact::ExponentOf(v[i]) >= highest)) return false;
  }
  return true;
}

/// The exact orientation sign once the filter has failed: the determinant in plain doubles when
/// every operation in it happens to be exact (integer coordinates: grids, and points on lines, whose
/// collinear triples are exact zeros), else the expansion. At 1M points the filter fails on 43% of
/// parallel_lines' orientation tests and 19% of two_lines' (exact zeros, all of them exact in
/// doubles), which then skip the expansion. A zero tail proves an operation exact only where no
/// partial product of Two-Product underflows: the nonzero differences must lie in [2^-480, 2^500)
/// (the lowest bit of a product of two such doubles, or of their split halves, is then at least
/// 2^-1064, and the split does not overflow); otherwise the expansion decides.
GALPHA_HD GALPHA_PRED_COLD inline int Orient2dSignBeyondFilter(Point2 a, Point2 b, Point2 c) {
  using namespace exact;
  ExactnessWitness w;
  const double bax = w.Diff(b.x, a.x), bay = w.Diff(b.y, a.y);
  const double cax = w.Diff(c.x, a.x), cay = w.Diff(c.y, a.y);
  const double differences[4] = {bax, bay, cax, cay};
  if (w.exact && NonzeroExponentsWithin(differences, 4, -480, 500)) {
    const double det = w.Diff(w.Product(bax, cay), w.Product(bay, cax));
    if (w.exact) return det > 0.0 ? 1 : (det < 0.0 ? -1 : 0);
  }
  double e[kOrient2dExpansionCapacity];
  return ExpansionSign(Orient2dExpansion(a, b, c, e), e);
}

}  // namespace pred_detail

/// Exact orientation of (a, b, c): +1 counter-clockwise, -1 clockwise, 0 collinear.
GALPHA_HD GALPHA_FORCEINLINE int Orient2dSign(Point2 a, Point2 b, Point2 c) {
  using namespace exact;
  const double detleft = Mul(Sub(b.x, a.x), Sub(c.y, a.y));
  const double detright = Mul(Sub(b.y, a.y), Sub(c.x, a.x));
  const double det = Sub(detleft, detright);
  const double errbound = Mul(pred_detail::kCcwErrBound, Add(Abs(detleft), Abs(detright)));
  // Underflow in the two products costs at most 2^-1074 in total; demand errbound >= 2^-1000.
  if (errbound >= pred_detail::kUnderflowGate && (det > errbound || -det > errbound)) {
    return det > 0.0 ? 1 : -1;
  }
  return pred_detail::Orient2dSignBeyondFilter(a, b, c);
}

namespace pred_detail {

/// The in-circle determinant in plain doubles when every operation in it happens to be exact, as
/// for small integer coordinates (grids): then its sign is exact, zero included, and the costly
/// expansion stage is skipped. Returns false when some operation rounded, or when a nonzero
/// coordinate difference lies outside [2^-240, 2^241), where Two-Product's tail could underflow or
/// its split overflow and a zero tail would prove nothing.
GALPHA_HD GALPHA_PRED_COLD inline bool InCircleSignIfExactInDoubles(Point2 a, Point2 b, Point2 c, Point2 d, int* sign) {
  ExactnessWitness w;
  const double adx = w.Diff(a.x, d.x), ady = w.Diff(a.y, d.y);
  const double bdx = w.Diff(b.x, d.x), bdy = w.Diff(b.y, d.y);
  const double cdx = w.Diff(c.x, d.x), cdy = w.Diff(c.y, d.y);
  if (!w.exact) return false;
  const double differences[6] = {adx, ady, bdx, bdy, cdx, cdy};
  if (!NonzeroExponentsWithin(differences, 6, -240, 241)) return false;
  const double ma = w.Diff(w.Product(bdx, cdy), w.Product(cdx, bdy));
  const double mb = w.Diff(w.Product(cdx, ady), w.Product(adx, cdy));
  const double mc = w.Diff(w.Product(adx, bdy), w.Product(bdx, ady));
  const double alift = w.Sum(w.Product(adx, adx), w.Product(ady, ady));
  const double blift = w.Sum(w.Product(bdx, bdx), w.Product(bdy, bdy));
  const double clift = w.Sum(w.Product(cdx, cdx), w.Product(cdy, cdy));
  const double det = w.Sum(w.Sum(w.Product(alift, ma), w.Product(blift, mb)), w.Product(clift, mc));
  if (!w.exact) return false;
  *sign = det > 0.0 ? 1 : (det < 0.0 ? -1 : 0);
  return true;
}

/// Scaling of the difference stages: the largest difference is brought into [2^120, 2^121), and
/// every nonzero part of every difference must then be at least 2^-80.
constexpr int kDifferencesScaleTarget = 120;
constexpr int kDifferencesLowestExponent = -80;

/// The six differences to d as double-doubles, x = (adx, bdx, cdx) and y = (ady, bdy, cdy): each
/// difference exactly (Two-Diff: the rounded difference and its tail), all scaled by one power of
/// two so that the largest lies in [2^120, 2^121) (all zero when the four points coincide).
/// `*exact` says whether every tail is zero (the differences are doubles, as for near points of a
/// well-scaled set: Sterbenz). Returns false when a nonzero part is subnormal or the nonzero parts
/// span more binary orders than the grid allows (the smallest must reach 2^-80 after scaling).
///
/// The grid: every scaled part is then a multiple of 2^(-80-52) = 2^-132 and below 2^121, so every
/// quantity of degree k that the difference stages form (sums, products, the tails of Two-Sum and
/// Two-Product) is an integer multiple of 2^(-132k) >= 2^-528 (a rounding
/// keeps a value on a grid coarser than its ulp, and tails are differences of values on the grid)
/// and below 2^500: no operation underflows or overflows, which is all that expansion arithmetic
/// needs to be exact and all that the bounds of double_double.hpp assume.
GALPHA_HD GALPHA_FORCEINLINE bool ScaledDifferencesToD(Point2 a, Point2 b, Point2 c, Point2 d, exact::DoubleDouble* x,
                                                       exact::DoubleDouble* y, bool* exact) {
  using namespace exact;
  const double from[6] = {a.x, b.x, c.x, a.y, b.y, c.y};
  double hi[6], lo[6];
  double maxabs = 0.0, minabs = 0x1.fffffffffffffp1023;
  *exact = true;
  for (int i = 0; i < 6; ++i) {
    TwoDiff(from[i], i < 3 ? d.x : d.y, hi[i], lo[i]);
    *exact = *exact && lo[i] == 0.0;
    maxabs = Abs(hi[i]) > maxabs ? Abs(hi[i]) : maxabs;
    if (hi[i] != 0.0 && Abs(hi[i]) < minabs) minabs = Abs(hi[i]);
    if (lo[i] != 0.0 && Abs(lo[i]) < minabs) minabs = Abs(lo[i]);
  }
  int s = 0;
  if (maxabs > 0.0) {
    // Subnormal parts: ExponentOf would overestimate their magnitude.
    if (minabs < 0x1p-1022) return false;
    s = kDifferencesScaleTarget - ExponentOf(maxabs);
    if (ExponentOf(minabs) + s < kDifferencesLowestExponent) return false;
  }
  for (int i = 0; i < 3; ++i) {
    x[i] = DoubleDouble{ScaleByPow2(hi[i], s), ScaleByPow2(lo[i], s)};
    y[i] = DoubleDouble{ScaleByPow2(hi[3 + i], s), ScaleByPow2(lo[3 + i], s)};
  }
  return true;
}

/// The double-double stage decides when |det| exceeds this fraction of the permanent (its error is
/// below 2^-100 of it: 16 times smaller).
constexpr double kDoubleDoubleInCircleBound = 0x1p-96;

/// The sign of the in-circle determinant of the scaled differences of ScaledDifferencesToD, when a
/// double-double evaluation (core/exact/double_double.hpp) with a rigorous error bound decides it;
/// false otherwise (an exact zero, or a determinant below 2^-96 of its permanent). Registers only:
/// it decides the in-circle tests that miss the plain filter by a few binary orders
/// (near-co-circular points: 2^-50 to 2^-68 of the permanent on circle, two_lines and
/// ulp_lattice) for a small fraction of the cost of an expansion stage, and on the GPU without
/// their kilobytes of local memory.
///
/// Why the sign is exact, with u = 2^-53 (on ScaledDifferencesToD's grid, every bound of
/// double_double.hpp holds): for term i, with lift L_i = X_i^2 + Y_i^2 and minor
/// m_i = X_j Y_k - X_k Y_j (j, k the next two indices, cyclically), let L'_i = x_i.hi^2 + y_i.hi^2
/// and P'_i = |x_j.hi y_k.hi| + |x_k.hi y_j.hi|. Each product of two differences is within
/// 8.01 u^2 of the product of their his (MulDd), each sum of two products adds 3.01 u^2 (AddDd):
/// the lift is within 11.03 u^2 L'_i and the minor within 11.03 u^2 P'_i of their exact values.
/// Their product adds 8.01 u^2 L'_i P'_i (MulDd) to the inputs' errors carried through: 30.1 u^2
/// L'_i P'_i in all. The two sums of terms add 6.1 u^2 sum_i L'_i P'_i. So the computed hi + lo is
/// within 37 u^2 perm < 2^-100.7 perm of the exact determinant, perm = sum_i L'_i P'_i, and the
/// permanent computed below in doubles (perm_c, from the rounded products: perm_c >= (1 - 11u)
/// perm) keeps the error under 2^-100 perm_c. When |hi| > 2^-96 perm_c, then
/// |hi + lo| >= (1 - u) |hi| exceeds the error, and the determinant has the sign of hi.
GALPHA_HD GALPHA_FORCEINLINE bool InCircleSignFromDoubleDouble(const exact::DoubleDouble* x,
                                                               const exact::DoubleDouble* y, int* sign) {
  using namespace exact;
  DoubleDouble det;
  double permanent = 0.0;
  for (int i = 0; i < 3; ++i) {
    const int j = i == 2 ? 0 : i + 1, k = j == 2 ? 0 : j + 1;
    const DoubleDouble jk = MulDd(x[j], y[k]), kj = MulDd(x[k], y[j]);
    const DoubleDouble xx = MulDd(x[i], x[i]), yy = MulDd(y[i], y[i]);
    const DoubleDouble minor = AddDd(jk, kj, /*negate_b=*/true);
    const DoubleDouble lift = AddDd(xx, yy);
    det = AddDd(det, MulDd(lift, minor));
    permanent = Add(permanent, Mul(Add(xx.hi, yy.hi), Add(Abs(jk.hi), Abs(kj.hi))));
  }
  const double bound = Mul(kDoubleDoubleInCircleBound, permanent);
  if (det.hi > bound) {
    *sign = 1;
    return true;
  }
  if (-det.hi > bound) {
    *sign = -1;
    return true;
  }
  return false;
}

/// The exact sign of the in-circle determinant of six exact, scaled differences (ScaledDifferencesToD
/// with every tail zero), in expansion arithmetic: Shewchuk's form with d as the origin, 96
/// components at most, where the raw-coordinate form of InCircleExpansion needs 384 (four times
/// the local memory and work).
/// The differences come by value, so that the caller's stay in registers.
GALPHA_HD GALPHA_PRED_COLD inline int InCircleSignOfDifferencesExpansion(double adx, double bdx, double cdx, double ady,
                                                                         double bdy, double cdy) {
  using namespace exact;
  const double x[3] = {adx, bdx, cdx}, y[3] = {ady, bdy, cdy};
  // det = alift * (bdx cdy - cdx bdy) + blift * (cdx ady - adx cdy) + clift * (adx bdy - bdx ady),
  // each lift * minor as dx * (dx * minor) + dy * (dy * minor): 4 -> 8 -> 16 components, 32 a
  // term, 96 in all.
  double total[2][96];
  int total_len = 0, which = 0;
  for (int i = 0; i < 3; ++i) {
    const int j = i == 2 ? 0 : i + 1, k = j == 2 ? 0 : j + 1;
    double minor[4];
    const int minor_len = Cross(x[j], y[j], x[k], y[k], minor);
    double term[32], once[8], twice[2][16];
    int twice_len[2];
    for (int axis = 0; axis < 2; ++axis) {
      const double lift_factor = axis == 0 ? x[i] : y[i];
      const int once_len = ScaleExpansionZeroElim(minor_len, minor, lift_factor, once);
      twice_len[axis] = ScaleExpansionZeroElim(once_len, once, lift_factor, twice[axis]);
    }
    const int term_len = ExpansionSumZeroElim(twice_len[0], twice[0], twice_len[1], twice[1], term);
    total_len = ExpansionSumZeroElim(total_len, total[which], term_len, term, total[1 - which]);
    which = 1 - which;
  }
  return ExpansionSign(total_len, total[which]);
}

/// The exact in-circle sign once the filters have failed: the double-double stage on the exact
/// differences to d; where it cannot decide (exact zeros, extreme near-zeros), the expansion of the
/// differences when they are doubles, else the raw-coordinate expansion.
GALPHA_HD GALPHA_PRED_COLD inline int InCircleSignBeyondFilters(Point2 a, Point2 b, Point2 c, Point2 d) {
  exact::DoubleDouble x[3], y[3];
  bool exact_differences = false;
  if (ScaledDifferencesToD(a, b, c, d, x, y, &exact_differences)) {
    int sign;
    if (InCircleSignFromDoubleDouble(x, y, &sign)) return sign;
    if (exact_differences) {
      return InCircleSignOfDifferencesExpansion(x[0].hi, x[1].hi, x[2].hi, y[0].hi, y[1].hi, y[2].hi);
    }
  }
  double e[exact::kInCircleExpansionCapacity];
  return exact::ExpansionSign(exact::InCircleExpansion(a, b, c, d, e), e);
}

}  // namespace pred_detail

/// Exact in-circle test: +1 if d lies strictly inside the circle through a, b, c (given
/// counter-clockwise; the sign flips for clockwise a, b, c), -1 outside, 0 on it.
GALPHA_HD GALPHA_FORCEINLINE int InCircleSign(Point2 a, Point2 b, Point2 c, Point2 d) {
  using namespace exact;
  const double adx = Sub(a.x, d.x), ady = Sub(a.y, d.y);
  const double bdx = Sub(b.x, d.x), bdy = Sub(b.y, d.y);
  const double cdx = Sub(c.x, d.x), cdy = Sub(c.y, d.y);
  const double bdxcdy = Mul(bdx, cdy), cdxbdy = Mul(cdx, bdy);
  const double cdxady = Mul(cdx, ady), adxcdy = Mul(adx, cdy);
  const double adxbdy = Mul(adx, bdy), bdxady = Mul(bdx, ady);
  const double alift = Add(Mul(adx, adx), Mul(ady, ady));
  const double blift = Add(Mul(bdx, bdx), Mul(bdy, bdy));
  const double clift = Add(Mul(cdx, cdx), Mul(cdy, cdy));
  const double det =
      Add(Add(Mul(alift, Sub(bdxcdy, cdxbdy)), Mul(blift, Sub(cdxady, adxcdy))), Mul(clift, Sub(adxbdy, bdxady)));
  const double pa = Add(Abs(bdxcdy), Abs(cdxbdy));
  const double pb = Add(Abs(cdxady), Abs(adxcdy));
  const double pc = Add(Abs(adxbdy), Abs(bdxady));
  const double permanent = Add(Add(Mul(pa, alift), Mul(pb, blift)), Mul(pc, clift));
  const double errbound = Mul(pred_detail::kIccErrBound, permanent);
  // An underflow error (<= 2^-1075) in a 2x2 product is multiplied by a lift, one in a lift by a
  // cross term, one in a final product by 1: bound their total by 2^-1000 * (sum of those).
  const double gate =
      Mul(pred_detail::kUnderflowGate, Add(Add(Add(Add(alift, blift), Add(clift, pa)), Add(pb, pc)), 1.0));
  if (errbound >= gate && (det > errbound || -det > errbound)) return det > 0.0 ? 1 : -1;
  int sign;
  if (pred_detail::InCircleSignIfExactInDoubles(a, b, c, d, &sign)) return sign;
  return pred_detail::InCircleSignBeyondFilters(a, b, c, d);
}

namespace pred_detail {

/// Sorts n points by index, ascending (insertion sort); returns the permutation's parity (+1 even,
/// -1 odd).
template <int n>
GALPHA_HD inline int SortByIndex(Point2* p, uint32_t* id) {
  int parity = 1;
  for (int i = 1; i < n; ++i) {
    for (int j = i; j > 0 && id[j] < id[j - 1]; --j) {
      const uint32_t ti = id[j];
      id[j] = id[j - 1];
      id[j - 1] = ti;
      const Point2 tp = p[j];
      p[j] = p[j - 1];
      p[j - 1] = tp;
      parity = -parity;
    }
  }
  return parity;
}

/// The SoS orientation of a, b, c once their exact determinant is known to be 0.
///
/// Perturbation (Edelsbrunner & Muecke 1990, d = 3 with the lifted z as a third coordinate, shared
/// with InCircleSoS): the point of rank r (1 = smallest input index) moves by eps^(2^(3r-1)) in x,
/// eps^(2^(3r-2)) in y, eps^(2^(3r-3)) in z. With rows sorted by index, the perturbed determinant
/// is D + [1,x](r1,r2) eps^2 - [1,y](r1,r2) eps^4 - [1,x](r0,r2) eps^16 + eps^20 + ...; its sign is
/// the sign of the first nonzero coefficient. For distinct points the second or third term is
/// nonzero; the last two only matter for duplicates and make the function total.
GALPHA_HD GALPHA_PRED_COLD inline int Orient2dSoSDegenerate(Point2 a, uint32_t ia, Point2 b, uint32_t ib, Point2 c,
                                                            uint32_t ic) {
  Point2 p[3] = {a, b, c};
  uint32_t id[3] = {ia, ib, ic};
  const int parity = SortByIndex<3>(p, id);
  int t = CompareSign(p[2].x, p[1].x);           // +[1,x](r1,r2)
  if (t == 0) t = -CompareSign(p[2].y, p[1].y);  // -[1,y](r1,r2)
  if (t == 0) t = -CompareSign(p[2].x, p[0].x);  // -[1,x](r0,r2)
  if (t == 0) t = 1;                             // +1
  return parity * t;
}

/// Sign of the minor [1,u,z](i,j,k) = u_i (z_j - z_k) + u_j (z_k - z_i) + u_k (z_i - z_j) for three
/// collinear points i, j, k, from one
/// coordinate u of each (x or y; z is the lift x^2 + y^2). On their line p = p_i + tau (p_k - p_i)
/// the lift is quadratic in tau, so by column operations the minor is
/// (u_k - u_i) |p_k - p_i|^2 det[[1, tau, tau^2]] = (u_k - u_i) |p_k - p_i|^2 tau_j (1 - tau_j), whose
/// sign is sign(u_k - u_i) sign(tau_j) sign(1 - tau_j) = sign(u_k - u_i) sign(u_j - u_i)
/// sign(u_k - u_j) whenever u_k != u_i (tau_j = (u_j - u_i) / (u_k - u_i)); when u_k == u_i the
/// minor is 0, as the first factor says. Duplicates give 0 as the minor does (two equal rows).
/// Comparisons only: no lifts, no expansions (every degenerate in-circle test of two crossing lines
/// of points, four points on one line, ends here).
GALPHA_HD inline int CollinearMinorUZSign(double ui, double uj, double uk) {
  return CompareSign(uk, ui) * CompareSign(uj, ui) * CompareSign(uk, uj);
}

/// The SoS sign of det4 [[1, x, y, z]] (rows r0..r3 sorted by index, z = x^2 + y^2 perturbed as
/// an independent coordinate) once its exact value is known to be 0: the sign of the first nonzero
/// coefficient, in order of increasing eps power, of
///    1 D4                  eps^0    7 -[1,y](r2,r3)        eps^12   13 -[1,z](r2,r3)      eps^34
///    2 -[1,x,y](r1,r2,r3)  eps^1    8 -[1,x,z](r0,r2,r3)   eps^16   14 -[1,x,y](r0,r1,r3) eps^64
///    3 +[1,x,z](r1,r2,r3)  eps^2    9 -[1,x](r2,r3)        eps^17   15 -[1,x](r1,r3)      eps^66
///    4 -[1,y,z](r1,r2,r3)  eps^4   10 +[1,z](r2,r3)        eps^20   16 +[1,y](r1,r3)      eps^68
///    5 +[1,x,y](r0,r2,r3)  eps^8   11 +[1,y,z](r0,r2,r3)   eps^32   17 +[1,x](r0,r3)      eps^80
///    6 +[1,x](r2,r3)       eps^10  12 +[1,y](r2,r3)        eps^33   18 -1                 eps^84
/// For distinct points the sequence provably stops by term 7: terms 6 and 7 are the x and y of
/// r3 - r2, not both zero. Terms 8-13 are minors that contain both rows r2 and r3, so they are 0
/// whenever they are reached (r2 == r3), and we skip them. Terms 14-18 are kept so that the
/// function stays total and deterministic if a caller breaks the distinct-points promise.
GALPHA_HD inline int Det4SoSSign(const Point2* p) {
  int t = -Orient2dSign(p[1], p[2], p[3]);  // 2: decides unless r1, r2, r3 are collinear
  if (t != 0) return t;
  t = CollinearMinorUZSign(p[1].x, p[2].x, p[3].x);               // 3
  if (t == 0) t = -CollinearMinorUZSign(p[1].y, p[2].y, p[3].y);  // 4
  if (t == 0) t = Orient2dSign(p[0], p[2], p[3]);                 // 5
  if (t == 0) t = CompareSign(p[3].x, p[2].x);                    // 6
  if (t == 0) t = -CompareSign(p[3].y, p[2].y);                   // 7
  if (t == 0) t = -Orient2dSign(p[0], p[1], p[3]);                // 14
  if (t == 0) t = -CompareSign(p[3].x, p[1].x);                   // 15
  if (t == 0) t = CompareSign(p[3].y, p[1].y);                    // 16
  if (t == 0) t = CompareSign(p[3].x, p[0].x);                    // 17
  return t != 0 ? t : -1;                                         // 18
}

/// The SoS in-circle sign once the exact in-circle determinant is known to be 0.
GALPHA_HD GALPHA_PRED_COLD inline int InCircleSoSDegenerate(Point2 a, uint32_t ia, Point2 b, uint32_t ib, Point2 c,
                                                            uint32_t ic, Point2 d, uint32_t id) {
  Point2 p[4] = {a, b, c, d};
  uint32_t ids[4] = {ia, ib, ic, id};
  const int parity = SortByIndex<4>(p, ids);
  return -(parity * Det4SoSSign(p));
}

}  // namespace pred_detail

/// Orientation under Simulation of Simplicity on the input indices (distinct): never 0, equal to
/// Orient2dSign whenever that is nonzero, and antisymmetric under swapping two arguments (with
/// their indices).
GALPHA_HD GALPHA_FORCEINLINE int Orient2dSoS(Point2 a, uint32_t ia, Point2 b, uint32_t ib, Point2 c, uint32_t ic) {
  const int s = Orient2dSign(a, b, c);
  return s != 0 ? s : pred_detail::Orient2dSoSDegenerate(a, ia, b, ib, c, ic);
}

/// In-circle test under Simulation of Simplicity (same perturbation as Orient2dSoS): never 0,
/// equal to InCircleSign whenever that is nonzero (+1: d inside the ccw circle a, b, c).
GALPHA_HD GALPHA_FORCEINLINE int InCircleSoS(Point2 a, uint32_t ia, Point2 b, uint32_t ib, Point2 c, uint32_t ic,
                                             Point2 d, uint32_t id) {
  const int s = InCircleSign(a, b, c, d);
  return s != 0 ? s : pred_detail::InCircleSoSDegenerate(a, ia, b, ib, c, ic, d, id);
}

}  // namespace galpha

#undef GALPHA_PRED_COLD
