#include "core/exact/weighted_radius_rational.hpp"

#include "core/exact/radius_rational.hpp"

namespace galpha {

namespace {

mpq_class Q(double v) { return mpq_class(v); }  // exact: every double is a dyadic rational

}  // namespace

std::optional<mpq_class> SimplexRadiusSqRational(const Point2* p, const double* w, int n) {
  if (w == nullptr) return RadiusSqRational(p, n);
  // The orthogonal circle's centre m and rho^2 = |m - p_0|^2 - w_0, from the module comment of
  // weighted_radius.hpp, here without the relative form: solved directly.
  if (n == 2) {
    const mpq_class vx = Q(p[1].x) - Q(p[0].x), vy = Q(p[1].y) - Q(p[0].y);
    const mpq_class d = vx * vx + vy * vy;
    // m = p0 + t v with 2 t d = d + w0 - w1.
    const mpq_class t = (d + Q(w[0]) - Q(w[1])) / (2 * d);
    mpq_class value = t * t * d - Q(w[0]);
    value.canonicalize();
    return value;
  }
  const mpq_class bx = Q(p[1].x) - Q(p[0].x), by = Q(p[1].y) - Q(p[0].y);
  const mpq_class cx = Q(p[2].x) - Q(p[0].x), cy = Q(p[2].y) - Q(p[0].y);
  const mpq_class area = bx * cy - by * cx;
  if (sgn(area) == 0) return std::nullopt;
  // 2 b.m = |b|^2 - w1 + w0, 2 c.m = |c|^2 - w2 + w0 (m relative to p0), by Cramer's rule.
  const mpq_class wb = bx * bx + by * by - Q(w[1]) + Q(w[0]);
  const mpq_class wc = cx * cx + cy * cy - Q(w[2]) + Q(w[0]);
  const mpq_class mx = (wb * cy - wc * by) / (2 * area);
  const mpq_class my = (bx * wc - cx * wb) / (2 * area);
  mpq_class value = mx * mx + my * my - Q(w[0]);
  value.canonicalize();
  return value;
}

int CompareSimplexRadiusSqRational(const Point2* a, const double* wa, int na, const Point2* b, const double* wb,
                                   int nb) {
  const std::optional<mpq_class> ra = SimplexRadiusSqRational(a, wa, na), rb = SimplexRadiusSqRational(b, wb, nb);
  if (!ra || !rb) return (ra ? 0 : 1) - (rb ? 0 : 1);
  const int c = cmp(*ra, *rb);
  return c > 0 ? 1 : (c < 0 ? -1 : 0);
}

int WeightedAttachedSignRational(Point2 p, Point2 q, Point2 r, double wp, double wq, double wr) {
  // The edge's orthogonal circle: centre m = p + t v, squared radius rho^2; r attaches the edge
  // when |m - r|^2 - wr < rho^2.
  const Point2 edge[2] = {p, q};
  const double weights[2] = {wp, wq};
  const mpq_class rho_sq = *SimplexRadiusSqRational(edge, weights, 2);
  const mpq_class vx = Q(q.x) - Q(p.x), vy = Q(q.y) - Q(p.y);
  const mpq_class d = vx * vx + vy * vy;
  const mpq_class t = (d + Q(wp) - Q(wq)) / (2 * d);
  const mpq_class mx = Q(p.x) + t * vx - Q(r.x), my = Q(p.y) + t * vy - Q(r.y);
  const mpq_class power = mx * mx + my * my - Q(wr) - rho_sq;
  return sgn(power) < 0 ? 1 : (sgn(power) == 0 ? 0 : -1);
}

}  // namespace galpha
