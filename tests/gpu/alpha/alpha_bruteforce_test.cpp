// The alpha family against its definitions (docs/design.md, "Semantics"), computed by brute force with GMP
// rationals, independently of CGAL and of the engine: on small point sets whose Delaunay
// triangulation is unique, a triple is a Delaunay triangle iff no other point lies inside or on its
// circumcircle; births, attachment and the spectrum come straight from their definitions; every
// simplex is classified at every level from those births alone. The family must agree on the
// simplices, the spectrum (exact values and nearest doubles), the rank tables, the classes in both
// modes under both vertex rules, the component curves, the optimal levels and the resolution of
// user thresholds (alpha_sq and alpha) to levels.
#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/family/alpha_family.hpp"
#include "core/exact/radius_rational.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gtest/gtest.h"

namespace galpha {
namespace {

using Tri = std::array<uint32_t, 3>;
using Edge = std::array<uint32_t, 2>;

// ---- Exact primitives (GMP rationals; every double is a dyadic rational) ------------------------

struct QPoint {
  mpq_class x, y;
};

QPoint ToQ(const Point2& p) { return {mpq_class(p.x), mpq_class(p.y)}; }

int Orient(const QPoint& a, const QPoint& b, const QPoint& c) {
  const mpq_class d = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  return sgn(d);
}

// > 0 when d lies strictly inside the circle through a, b, c (in either orientation), 0 on it.
int InCircle(const QPoint& a, const QPoint& b, const QPoint& c, const QPoint& d) {
  const mpq_class adx = a.x - d.x, ady = a.y - d.y;
  const mpq_class bdx = b.x - d.x, bdy = b.y - d.y;
  const mpq_class cdx = c.x - d.x, cdy = c.y - d.y;
  const mpq_class alift = adx * adx + ady * ady;
  const mpq_class blift = bdx * bdx + bdy * bdy;
  const mpq_class clift = cdx * cdx + cdy * cdy;
  const mpq_class det =
      adx * (bdy * clift - cdy * blift) - ady * (bdx * clift - cdx * blift) + alift * (bdx * cdy - cdx * bdy);
  return sgn(det) * Orient(a, b, c);
}

// Squared circumradius through the exact circumcentre (a different formula from the library's).
mpq_class CircumradiusSq(const QPoint& a, const QPoint& b, const QPoint& c) {
  const mpq_class bx = b.x - a.x, by = b.y - a.y, cx = c.x - a.x, cy = c.y - a.y;
  const mpq_class d = 2 * (bx * cy - by * cx);
  const mpq_class b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  const mpq_class ux = (cy * b2 - by * c2) / d;
  const mpq_class uy = (bx * c2 - cx * b2) / d;
  return ux * ux + uy * uy;
}

mpq_class HalfLengthSq(const QPoint& a, const QPoint& b) {
  const mpq_class dx = b.x - a.x, dy = b.y - a.y;
  return (dx * dx + dy * dy) / 4;
}

// Strictly inside the diametral circle of (a, b): the angle a-c-b is obtuse.
bool InsideDiametral(const QPoint& a, const QPoint& b, const QPoint& c) {
  return sgn((a.x - c.x) * (b.x - c.x) + (a.y - c.y) * (b.y - c.y)) < 0;
}

// Whether `d` is a double nearest to `value` (checked against both neighbours, exactly).
bool IsNearestDouble(double d, const mpq_class& value) {
  if (!std::isfinite(d)) return false;
  const mpq_class err = abs(mpq_class(d) - value);
  for (double n : {std::nextafter(d, -INFINITY), std::nextafter(d, INFINITY)}) {
    if (std::isfinite(n) && abs(mpq_class(n) - value) < err) return false;
  }
  return true;
}

// ---- The family by brute force -------------------------------------------------------------------

class DisjointSets {
 public:
  explicit DisjointSets(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }
  uint32_t Find(uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void Union(uint32_t a, uint32_t b) { parent_[Find(a)] = Find(b); }

 private:
  std::vector<uint32_t> parent_;
};

struct BruteClasses {
  std::vector<SimplexClass> vertices;  // by input index
  std::vector<SimplexClass> edges;     // by brute edge index
  std::vector<SimplexClass> triangles;
};

struct BruteFamily {
  std::vector<Point2> points;
  std::vector<QPoint> q;
  std::vector<uint32_t> rep;   // first occurrence of each input point
  std::vector<uint32_t> uniq;  // the distinct points, by input index
  std::vector<Tri> tris;       // ascending input indices
  std::vector<Edge> edges;     // (smaller, larger)
  std::vector<std::vector<uint32_t>> edge_tris, vertex_edges, vertex_tris;
  std::vector<bool> on_hull;  // by input index (representatives)
  std::vector<mpq_class> tri_birth, edge_rho, edge_birth;
  std::vector<bool> attached;
  std::vector<mpq_class> spectrum;  // sorted distinct births of triangles and unattached edges
  bool valid_triangulation = true;  // the brute-force triangles tile the convex hull

  int64_t K() const { return static_cast<int64_t>(spectrum.size()); }
  mpq_class Threshold(int64_t level) const {
    if (level < 0) return mpq_class(-1);
    if (level == 0) return mpq_class(0);
    return spectrum[static_cast<size_t>(level - 1)];
  }
  uint32_t RankOf(const mpq_class& v) const {
    const auto it = std::lower_bound(spectrum.begin(), spectrum.end(), v);
    if (it == spectrum.end() || *it != v) return kNeverRank - 1;  // not a spectrum value: a failure
    return static_cast<uint32_t>(it - spectrum.begin()) + 1;
  }
  // Number of spectrum values <= v (the level of v; -1 for v < 0).
  int64_t LevelOf(const mpq_class& v) const {
    if (sgn(v) < 0) return -1;
    return std::upper_bound(spectrum.begin(), spectrum.end(), v) - spectrum.begin();
  }
};

// Convex hull area (twice) by Andrew's monotone chain on the distinct points, exactly.
mpq_class HullAreaTwice(const std::vector<QPoint>& pts) {
  std::vector<QPoint> p = pts;
  std::sort(p.begin(), p.end(),
            [](const QPoint& a, const QPoint& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  std::vector<QPoint> hull;
  for (int pass = 0; pass < 2; ++pass) {
    const size_t start = hull.size();
    for (const QPoint& pt : p) {
      while (hull.size() >= start + 2 && Orient(hull[hull.size() - 2], hull.back(), pt) <= 0) hull.pop_back();
      hull.push_back(pt);
    }
    hull.pop_back();
    std::reverse(p.begin(), p.end());
  }
  mpq_class area = 0;
  for (size_t i = 0; i < hull.size(); ++i) {
    const QPoint& a = hull[i];
    const QPoint& b = hull[(i + 1) % hull.size()];
    area += a.x * b.y - a.y * b.x;
  }
  return area;
}

BruteFamily BruteForce(const std::vector<Point2>& points) {
  BruteFamily b;
  b.points = points;
  const uint32_t n = static_cast<uint32_t>(points.size());
  for (const Point2& p : points) b.q.push_back(ToQ(p));
  b.rep.resize(n);
  for (uint32_t i = 0; i < n; ++i) {
    b.rep[i] = i;
    for (uint32_t j = 0; j < i; ++j) {
      if (points[j].x == points[i].x && points[j].y == points[i].y) {
        b.rep[i] = j;
        break;
      }
    }
    if (b.rep[i] == i) b.uniq.push_back(i);
  }
  b.vertex_edges.assign(n, {});
  b.vertex_tris.assign(n, {});
  b.on_hull.assign(n, true);

  bool collinear = true;
  for (size_t k = 2; k < b.uniq.size() && collinear; ++k) {
    collinear = Orient(b.q[b.uniq[0]], b.q[b.uniq[1]], b.q[b.uniq[k]]) == 0;
  }
  if (collinear) {
    // Edges join consecutive points along the line (lexicographic order is the order on a line).
    std::vector<uint32_t> order = b.uniq;
    std::sort(order.begin(), order.end(), [&](uint32_t i, uint32_t j) {
      return b.q[i].x < b.q[j].x || (b.q[i].x == b.q[j].x && b.q[i].y < b.q[j].y);
    });
    for (size_t k = 0; k + 1 < order.size(); ++k) {
      b.edges.push_back({std::min(order[k], order[k + 1]), std::max(order[k], order[k + 1])});
    }
  } else {
    std::map<Edge, uint32_t> edge_index;
    const size_t m = b.uniq.size();
    for (size_t i = 0; i < m; ++i) {
      for (size_t j = i + 1; j < m; ++j) {
        for (size_t k = j + 1; k < m; ++k) {
          const uint32_t a = b.uniq[i], c = b.uniq[j], d = b.uniq[k];
          if (Orient(b.q[a], b.q[c], b.q[d]) == 0) continue;
          bool empty = true;
          for (size_t o = 0; o < m && empty; ++o) {
            if (o == i || o == j || o == k) continue;
            empty = InCircle(b.q[a], b.q[c], b.q[d], b.q[b.uniq[o]]) < 0;
          }
          if (!empty) continue;
          const uint32_t t = static_cast<uint32_t>(b.tris.size());
          b.tris.push_back({a, c, d});
          for (const Edge& e : {Edge{a, c}, Edge{a, d}, Edge{c, d}}) {
            auto [it, inserted] = edge_index.emplace(e, static_cast<uint32_t>(edge_index.size()));
            (void)inserted;
            if (it->second >= b.edge_tris.size()) b.edge_tris.resize(it->second + 1);
            b.edge_tris[it->second].push_back(t);
          }
        }
      }
    }
    b.edges.resize(edge_index.size());
    for (const auto& [e, id] : edge_index) b.edges[id] = e;
    // Every triangle has an empty circumcircle, so none overlap: they triangulate the hull iff
    // their areas add up to the hull's. Otherwise the Delaunay triangulation is not unique.
    mpq_class sum = 0;
    for (const Tri& t : b.tris)
      sum += abs((b.q[t[1]].x - b.q[t[0]].x) * (b.q[t[2]].y - b.q[t[0]].y) -
                 (b.q[t[1]].y - b.q[t[0]].y) * (b.q[t[2]].x - b.q[t[0]].x));
    std::vector<QPoint> distinct;
    for (uint32_t v : b.uniq) distinct.push_back(b.q[v]);
    b.valid_triangulation = sum == HullAreaTwice(distinct);
    for (uint32_t v : b.uniq) b.on_hull[v] = false;
    for (size_t e = 0; e < b.edges.size(); ++e) {
      if (b.edge_tris[e].size() == 1) b.on_hull[b.edges[e][0]] = b.on_hull[b.edges[e][1]] = true;
    }
  }
  b.edge_tris.resize(b.edges.size());

  for (uint32_t t = 0; t < b.tris.size(); ++t) {
    const Tri& tr = b.tris[t];
    b.tri_birth.push_back(CircumradiusSq(b.q[tr[0]], b.q[tr[1]], b.q[tr[2]]));
    for (uint32_t v : tr) b.vertex_tris[v].push_back(t);
  }
  for (uint32_t e = 0; e < b.edges.size(); ++e) {
    const Edge& ed = b.edges[e];
    b.vertex_edges[ed[0]].push_back(e);
    b.vertex_edges[ed[1]].push_back(e);
    b.edge_rho.push_back(HalfLengthSq(b.q[ed[0]], b.q[ed[1]]));
    bool attached = false;
    std::optional<mpq_class> min_tri;
    for (uint32_t t : b.edge_tris[e]) {
      for (uint32_t v : b.tris[t]) {
        if (v != ed[0] && v != ed[1] && InsideDiametral(b.q[ed[0]], b.q[ed[1]], b.q[v])) attached = true;
      }
      if (!min_tri || b.tri_birth[t] < *min_tri) min_tri = b.tri_birth[t];
    }
    b.attached.push_back(attached);
    b.edge_birth.push_back(attached ? *min_tri : b.edge_rho[e]);
  }
  b.spectrum = b.tri_birth;
  for (uint32_t e = 0; e < b.edges.size(); ++e) {
    if (!b.attached[e]) b.spectrum.push_back(b.edge_rho[e]);
  }
  std::sort(b.spectrum.begin(), b.spectrum.end());
  b.spectrum.erase(std::unique(b.spectrum.begin(), b.spectrum.end()), b.spectrum.end());
  return b;
}

// Classes at alpha_sq = A by the definitions (closed at the threshold).
BruteClasses ClassifyBrute(const BruteFamily& b, const mpq_class& A, ClassifyMode mode, VertexRule rule) {
  BruteClasses c;
  const bool general = mode == ClassifyMode::kGeneral;
  std::vector<bool> tri_in(b.tris.size());
  for (size_t t = 0; t < b.tris.size(); ++t) {
    tri_in[t] = b.tri_birth[t] <= A;
    c.triangles.push_back(tri_in[t] ? SimplexClass::kInterior : SimplexClass::kExterior);
  }
  std::vector<SimplexClass> general_edges;
  for (size_t e = 0; e < b.edges.size(); ++e) {
    SimplexClass cls = SimplexClass::kExterior;
    if (b.edge_birth[e] <= A) {
      size_t in = 0;
      for (uint32_t t : b.edge_tris[e]) in += tri_in[t];
      cls = in == 0 ? SimplexClass::kSingular : in == 1 ? SimplexClass::kRegular : SimplexClass::kInterior;
    }
    general_edges.push_back(cls);
    c.edges.push_back(!general && cls == SimplexClass::kSingular ? SimplexClass::kExterior : cls);
  }
  c.vertices.assign(b.points.size(), SimplexClass::kExterior);
  for (uint32_t v : b.uniq) {
    SimplexClass cls = SimplexClass::kExterior;
    if (sgn(A) >= 0) {
      bool any_edge = false, all_edges_interior = true, any_tri = false, all_tris = true;
      for (uint32_t e : b.vertex_edges[v]) {
        any_edge |= general_edges[e] != SimplexClass::kExterior;
        all_edges_interior &= general_edges[e] == SimplexClass::kInterior;
      }
      for (uint32_t t : b.vertex_tris[v]) {
        any_tri |= tri_in[t];
        all_tris &= tri_in[t];
      }
      if (rule == VertexRule::kReport) {
        cls = !any_edge                             ? SimplexClass::kSingular
              : all_edges_interior && !b.on_hull[v] ? SimplexClass::kInterior
                                                    : SimplexClass::kRegular;
      } else {
        cls = !any_tri                    ? SimplexClass::kSingular
              : b.on_hull[v] || !all_tris ? SimplexClass::kRegular
                                          : SimplexClass::kInterior;
      }
      if (!general && !any_tri) cls = SimplexClass::kExterior;
    }
    c.vertices[v] = cls;
  }
  for (uint32_t v = 0; v < b.points.size(); ++v) c.vertices[v] = c.vertices[b.rep[v]];
  return c;
}

uint32_t BruteComponents(const BruteFamily& b, const mpq_class& A) {
  if (sgn(A) < 0) return 0;
  DisjointSets sets(b.points.size());
  for (size_t e = 0; e < b.edges.size(); ++e) {
    if (b.edge_birth[e] <= A) sets.Union(b.edges[e][0], b.edges[e][1]);
  }
  uint32_t count = 0;
  for (uint32_t v : b.uniq) count += sets.Find(v) == v;
  return count;
}

uint32_t BruteSolidComponents(const BruteFamily& b, const mpq_class& A) {
  DisjointSets sets(b.tris.size());
  for (size_t e = 0; e < b.edges.size(); ++e) {
    const auto& ts = b.edge_tris[e];
    if (ts.size() == 2 && b.tri_birth[ts[0]] <= A && b.tri_birth[ts[1]] <= A) sets.Union(ts[0], ts[1]);
  }
  uint32_t count = 0;
  for (uint32_t t = 0; t < b.tris.size(); ++t) count += b.tri_birth[t] <= A && sets.Find(t) == t;
  return count;
}

bool EveryPointOnATriangle(const BruteFamily& b, const mpq_class& A) {
  for (uint32_t v : b.uniq) {
    bool covered = false;
    for (uint32_t t : b.vertex_tris[v]) covered |= b.tri_birth[t] <= A;
    if (!covered) return false;
  }
  return true;
}

std::string Describe(const std::vector<Point2>& points) {
  std::string out = "points {";
  char buf[96];
  for (const Point2& p : points) {
    std::snprintf(buf, sizeof buf, "{%.17g, %.17g}, ", p.x, p.y);
    out += buf;
  }
  return out + "}";
}

// ---- The comparison ------------------------------------------------------------------------------

uint32_t MinRank(const std::vector<uint32_t>& ranks) {
  return ranks.empty() ? kNeverRank : *std::min_element(ranks.begin(), ranks.end());
}

void CheckLevelResolution(const AlphaFamily& f, const BruteFamily& b) {
  const int64_t k = b.K();
  std::vector<double> probes = {
      0.0,   -1.0,  -0.0, std::numeric_limits<double>::denorm_min(), -std::numeric_limits<double>::denorm_min(),
      1e300, 1e-300};
  for (int64_t r = 1; r <= k; ++r) {
    const double d = NearestDouble(b.spectrum[static_cast<size_t>(r - 1)]);
    probes.push_back(d);
    probes.push_back(std::nextafter(d, -INFINITY));
    probes.push_back(std::nextafter(d, INFINITY));
    if (r < k)
      probes.push_back(
          NearestDouble((b.spectrum[static_cast<size_t>(r - 1)] + b.spectrum[static_cast<size_t>(r)]) / 2));
  }
  for (double x : probes) {
    if (!std::isfinite(x)) continue;
    const absl::StatusOr<int64_t> level = f.LevelForAlphaSq(x);
    ASSERT_TRUE(level.ok()) << level.status();
    ASSERT_EQ(*level, b.LevelOf(mpq_class(x))) << "LevelForAlphaSq(" << x << ")";
    // CGAL's alpha_lower_bound: the first rank whose exact threshold is >= x.
    const int64_t below = std::lower_bound(b.spectrum.begin(), b.spectrum.end(), mpq_class(x)) - b.spectrum.begin();
    ASSERT_EQ(f.RankLowerBound(x), below + 1) << "RankLowerBound(" << x << ")";
    if (x < 0) continue;
    // The radius: compared through its exact square, so alpha = sqrt(x) resolves like x only when
    // the square root is exact.
    const double root = std::sqrt(x);
    for (double a : {root, std::nextafter(root, 0.0), std::nextafter(root, INFINITY)}) {
      const absl::StatusOr<int64_t> by_radius = f.LevelForAlpha(a);
      ASSERT_TRUE(by_radius.ok()) << by_radius.status();
      const mpq_class a_sq = mpq_class(a) * mpq_class(a);
      ASSERT_EQ(*by_radius, b.LevelOf(a_sq)) << "LevelForAlpha(" << a << ")";
      if (a_sq == mpq_class(x)) {
        ASSERT_EQ(*by_radius, *level) << "LevelForAlpha(" << a << ") vs LevelForAlphaSq(" << x << ")";
      }
    }
  }
  // Radii whose squares leave the double range (exact squares, compared exactly).
  for (double a :
       {1e200, std::numeric_limits<double>::max(), std::numeric_limits<double>::denorm_min(), 1e-160, 1e-300}) {
    const absl::StatusOr<int64_t> by_radius = f.LevelForAlpha(a);
    ASSERT_TRUE(by_radius.ok()) << by_radius.status();
    ASSERT_EQ(*by_radius, b.LevelOf(mpq_class(a) * mpq_class(a))) << "LevelForAlpha(" << a << ")";
  }
  EXPECT_EQ(*f.LevelForAlphaSq(std::numeric_limits<double>::max()), k);
  EXPECT_EQ(*f.LevelForAlphaSq(INFINITY), k);
  EXPECT_EQ(*f.LevelForAlphaSq(-INFINITY), -1);
  EXPECT_EQ(*f.LevelForAlpha(INFINITY), k);
  EXPECT_FALSE(f.LevelForAlphaSq(std::nan("")).ok());
  EXPECT_FALSE(f.LevelForAlpha(std::nan("")).ok());
  EXPECT_FALSE(f.LevelForAlpha(-1.0).ok());
  EXPECT_EQ(f.RankLowerBound(INFINITY), k + 1);
  for (int64_t r = 0; r <= k; ++r) EXPECT_EQ(*f.LevelForRank(r), r);
  EXPECT_FALSE(f.LevelForRank(-1).ok());
  EXPECT_FALSE(f.LevelForRank(k + 1).ok());
}

void CompareWithBruteForce(const std::vector<Point2>& points, Backend backend) {
  SCOPED_TRACE(Describe(points));
  const BruteFamily b = BruteForce(points);
  ASSERT_TRUE(b.valid_triangulation) << "test input error: the Delaunay triangulation is not unique";
  BuildOptions options;
  options.backend = backend;
  absl::StatusOr<AlphaFamily> built = BuildAlphaFamily(points, options);
  ASSERT_TRUE(built.ok()) << built.status();
  const AlphaFamily& f = *built;
  const AlphaRanks& r = f.ranks();
  const uint32_t n = static_cast<uint32_t>(points.size());

  // Points and duplicates.
  ASSERT_EQ(f.points().size(), points.size());
  ASSERT_EQ(f.representative(), b.rep);
  ASSERT_EQ(f.num_unique(), b.uniq.size());
  ASSERT_EQ(f.num_duplicates(), n - b.uniq.size());

  // The same simplices: family id -> brute index.
  ASSERT_EQ(f.triangles().size(), b.tris.size());
  ASSERT_EQ(f.edges().size(), b.edges.size());
  std::map<Tri, uint32_t> brute_tri;
  for (uint32_t t = 0; t < b.tris.size(); ++t) brute_tri[b.tris[t]] = t;
  std::map<Edge, uint32_t> brute_edge;
  for (uint32_t e = 0; e < b.edges.size(); ++e) brute_edge[b.edges[e]] = e;
  std::vector<uint32_t> tri_map, edge_map;
  for (const Tri& t : f.triangles()) {
    ASSERT_EQ(Orient(b.q[t[0]], b.q[t[1]], b.q[t[2]]), 1) << "triangle not counter-clockwise";
    Tri sorted = t;
    std::sort(sorted.begin(), sorted.end());
    const auto it = brute_tri.find(sorted);
    ASSERT_NE(it, brute_tri.end()) << "not a Delaunay triangle: " << t[0] << " " << t[1] << " " << t[2];
    tri_map.push_back(it->second);
  }
  for (const Edge& e : f.edges()) {
    ASSERT_LT(e[0], e[1]);
    const auto it = brute_edge.find(e);
    ASSERT_NE(it, brute_edge.end()) << "not a Delaunay edge: " << e[0] << " " << e[1];
    edge_map.push_back(it->second);
  }
  std::vector<uint32_t> sorted_map = tri_map;
  std::sort(sorted_map.begin(), sorted_map.end());
  ASSERT_TRUE(std::adjacent_find(sorted_map.begin(), sorted_map.end()) == sorted_map.end()) << "repeated triangle";
  sorted_map = edge_map;
  std::sort(sorted_map.begin(), sorted_map.end());
  ASSERT_TRUE(std::adjacent_find(sorted_map.begin(), sorted_map.end()) == sorted_map.end()) << "repeated edge";

  // The spectrum: exact values (through the simplex the family names for each rank) and nearest
  // doubles.
  const int64_t k = b.K();
  ASSERT_EQ(f.max_level(), k);
  ASSERT_EQ(r.spectrum_simplex.size(), static_cast<size_t>(k));
  const uint32_t num_tri = static_cast<uint32_t>(f.triangles().size());
  for (int64_t rank = 1; rank <= k; ++rank) {
    const uint32_t id = r.spectrum_simplex[static_cast<size_t>(rank - 1)];
    Point2 p[3];
    int count = 2;
    if (id < num_tri) {
      for (int i = 0; i < 3; ++i) p[i] = points[f.triangles()[id][i]];
      count = 3;
    } else {
      ASSERT_LT(id - num_tri, f.edges().size());
      p[0] = points[f.edges()[id - num_tri][0]];
      p[1] = points[f.edges()[id - num_tri][1]];
    }
    const std::optional<mpq_class> value = RadiusSqRational(p, count);
    ASSERT_TRUE(value.has_value());
    const mpq_class& want = b.spectrum[static_cast<size_t>(rank - 1)];
    ASSERT_EQ(*value, want) << "rank " << rank;
    const double d = f.spectrum()[static_cast<size_t>(rank - 1)];
    ASSERT_EQ(d, NearestDouble(want)) << "rank " << rank;
    ASSERT_TRUE(IsNearestDouble(d, want)) << "rank " << rank << ": " << d;
  }

  // The rank tables (core/family/alpha_ranks.hpp), entry by entry.
  for (uint32_t t = 0; t < num_tri; ++t) {
    ASSERT_EQ(r.tri_rank[t], b.RankOf(b.tri_birth[tri_map[t]])) << "triangle " << t;
  }
  std::vector<uint32_t> brute_tri_rank(b.tris.size());
  for (uint32_t t = 0; t < num_tri; ++t) brute_tri_rank[tri_map[t]] = r.tri_rank[t];
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    const uint32_t be = edge_map[e];
    SCOPED_TRACE(testing::Message() << "edge " << f.edges()[e][0] << "-" << f.edges()[e][1]);
    ASSERT_EQ(EdgeBirthRank(r, e), b.RankOf(b.edge_birth[be]));
    ASSERT_EQ(r.edge_rho_rank[e], b.attached[be] ? 0u : b.RankOf(b.edge_rho[be]));
    std::vector<uint32_t> ranks, ids;
    for (uint32_t t : b.edge_tris[be]) ranks.push_back(brute_tri_rank[t]);
    ASSERT_EQ(r.edge_mu_low[e], MinRank(ranks));
    ASSERT_EQ(r.edge_mu_high[e], ranks.size() == 2 ? std::max(ranks[0], ranks[1]) : kNeverRank);
    for (int32_t t : r.edge_triangles[e]) {
      if (t >= 0) ids.push_back(tri_map[static_cast<size_t>(t)]);
    }
    std::sort(ids.begin(), ids.end());
    std::vector<uint32_t> want_ids = b.edge_tris[be];
    std::sort(want_ids.begin(), want_ids.end());
    ASSERT_EQ(ids, want_ids);
  }
  std::vector<uint32_t> brute_edge_birth(b.edges.size()), brute_edge_high(b.edges.size());
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    brute_edge_birth[edge_map[e]] = EdgeBirthRank(r, e);
    brute_edge_high[edge_map[e]] = r.edge_mu_high[e];
  }
  for (uint32_t v = 0; v < n; ++v) {
    const uint32_t w = b.rep[v];
    std::vector<uint32_t> births, tri_ranks;
    uint32_t high = b.vertex_edges[w].empty() || b.on_hull[w] ? kNeverRank : 0;
    for (uint32_t e : b.vertex_edges[w]) {
      births.push_back(brute_edge_birth[e]);
      if (high != kNeverRank) high = std::max(high, brute_edge_high[e]);
    }
    for (uint32_t t : b.vertex_tris[w]) tri_ranks.push_back(brute_tri_rank[t]);
    ASSERT_EQ(r.vertex_mu_low[v], MinRank(births)) << "vertex " << v;
    ASSERT_EQ(r.vertex_mu_high[v], high) << "vertex " << v;
    ASSERT_EQ(r.vertex_tri_low[v], MinRank(tri_ranks)) << "vertex " << v;
  }

  // Every level, and a negative alpha_sq (level -1): classes in both modes under both rules,
  // components and solid components.
  for (int64_t level = -1; level <= k; ++level) {
    const mpq_class A = b.Threshold(level);
    for (ClassifyMode mode : {ClassifyMode::kGeneral, ClassifyMode::kRegularized}) {
      for (VertexRule rule : {VertexRule::kReport, VertexRule::kCgal}) {
        SCOPED_TRACE(testing::Message() << "level " << level
                                        << (mode == ClassifyMode::kGeneral ? " GENERAL" : " REGULARIZED")
                                        << (rule == VertexRule::kReport ? " report rule" : " CGAL rule"));
        const BruteClasses want = ClassifyBrute(b, A, mode, rule);
        const Classification got = f.ClassifyAll(level, mode, rule);
        ASSERT_EQ(got.vertices.size(), n);
        ASSERT_EQ(got.edges.size(), b.edges.size());
        ASSERT_EQ(got.triangles.size(), b.tris.size());
        for (uint32_t v = 0; v < n; ++v) {
          ASSERT_EQ(SimplexClassName(got.vertices[v]), std::string(SimplexClassName(want.vertices[v])))
              << "vertex " << v;
          ASSERT_EQ(f.ClassifyVertex(v, level, mode, rule), got.vertices[v]) << "vertex " << v;
        }
        for (uint32_t e = 0; e < got.edges.size(); ++e) {
          ASSERT_EQ(SimplexClassName(got.edges[e]), std::string(SimplexClassName(want.edges[edge_map[e]])))
              << "edge " << f.edges()[e][0] << "-" << f.edges()[e][1];
          ASSERT_EQ(f.ClassifyEdge(e, level, mode), got.edges[e]);
        }
        for (uint32_t t = 0; t < got.triangles.size(); ++t) {
          ASSERT_EQ(SimplexClassName(got.triangles[t]), std::string(SimplexClassName(want.triangles[tri_map[t]])))
              << "triangle " << t;
          ASSERT_EQ(f.ClassifyTriangle(t, level), got.triangles[t]);
        }
      }
    }
    ASSERT_EQ(f.Components(level), BruteComponents(b, A)) << "level " << level;
    ASSERT_EQ(f.SolidComponents(level), BruteSolidComponents(b, A)) << "level " << level;
  }

  // Optimal levels, by their definitions in core/family/alpha_family.hpp, over all levels 0..K.
  std::optional<int64_t> solid;
  if (!b.tris.empty()) {
    for (int64_t level = 0; level <= k && !solid; ++level) {
      if (EveryPointOnATriangle(b, b.Threshold(level))) solid = level;
    }
  }
  ASSERT_EQ(f.SolidLevel(), solid);
  for (uint32_t want_n = 1; want_n <= 4; ++want_n) {
    std::optional<int64_t> general, regularized;
    for (int64_t level = 0; level <= k; ++level) {
      const mpq_class A = b.Threshold(level);
      if (!general && BruteComponents(b, A) <= want_n) general = level;
      if (!regularized && !b.tris.empty() && EveryPointOnATriangle(b, A) && BruteSolidComponents(b, A) <= want_n) {
        regularized = level;
      }
    }
    ASSERT_EQ(f.OptimalLevelGeneral(want_n), general) << "n = " << want_n;
    ASSERT_EQ(f.OptimalLevelRegularized(want_n), regularized) << "n = " << want_n;
  }

  CheckLevelResolution(f, b);
}

// ---- Inputs --------------------------------------------------------------------------------------

// No three distinct points collinear and no four co-circular, exactly: a unique Delaunay
// triangulation.
bool InGeneralPosition(const std::vector<Point2>& points) {
  std::vector<QPoint> q;
  for (const Point2& p : points) q.push_back(ToQ(p));
  const size_t n = q.size();
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      if (q[i].x == q[j].x && q[i].y == q[j].y) return false;
      for (size_t k = j + 1; k < n; ++k) {
        if (Orient(q[i], q[j], q[k]) == 0) return false;
        for (size_t l = k + 1; l < n; ++l) {
          if (InCircle(q[i], q[j], q[k], q[l]) == 0) return false;
        }
      }
    }
  }
  return true;
}

enum class Scale { kUnit, kOffset1e9, kTiny, kMixedSigns, kSmallIntegers };

std::vector<Point2> RandomSet(std::mt19937_64& rng, size_t n, Scale scale) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (;;) {
    std::vector<Point2> points;
    for (size_t i = 0; i < n; ++i) {
      double x = unit(rng), y = unit(rng);
      switch (scale) {
        case Scale::kUnit:
          break;
        case Scale::kOffset1e9:
          x = 1e9 + 1000 * x;
          y = 1e9 + 1000 * y;
          break;
        case Scale::kTiny:
          x *= 1e-300;
          y *= 1e-300;
          break;
        case Scale::kMixedSigns:
          x = 2 * x - 1;
          y = (2 * y - 1) * 1e-3;  // flat: many obtuse triangles and attached edges
          break;
        case Scale::kSmallIntegers:
          // Exact ties of lengths and radii, right angles (third vertices on diametral circles),
          // collinear runs and duplicates; kept only where the triangulation is still unique.
          x = std::floor(24 * x);
          y = std::floor(24 * y);
          break;
      }
      points.push_back({x, y});
    }
    if (scale == Scale::kSmallIntegers ? BruteForce(points).valid_triangulation : InGeneralPosition(points)) {
      return points;
    }
  }
}

class AlphaBruteForceTest : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override {
    if (GetParam() == Backend::kCuda && !CudaBackendAvailable()) GTEST_SKIP() << "no GPU";
  }
};

TEST_P(AlphaBruteForceTest, RandomGeneralPosition) {
  std::mt19937_64 rng(20240607);
  for (Scale scale : {Scale::kUnit, Scale::kOffset1e9, Scale::kTiny, Scale::kMixedSigns}) {
    const int sets = scale == Scale::kTiny ? 40 : 80;
    for (int s = 0; s < sets; ++s) {
      const size_t n = 4 + static_cast<size_t>(rng() % 11);  // 4..14
      SCOPED_TRACE(testing::Message() << "scale " << static_cast<int>(scale) << " set " << s);
      CompareWithBruteForce(RandomSet(rng, n, scale), GetParam());
      if (HasFatalFailure()) return;
    }
  }
}

TEST_P(AlphaBruteForceTest, RandomSmallIntegersWithUniqueTriangulation) {
  std::mt19937_64 rng(4242);
  for (int s = 0; s < 150; ++s) {
    const size_t n = 4 + static_cast<size_t>(rng() % 9);  // 4..12
    SCOPED_TRACE(testing::Message() << "set " << s);
    CompareWithBruteForce(RandomSet(rng, n, Scale::kSmallIntegers), GetParam());
    if (HasFatalFailure()) return;
  }
}

TEST_P(AlphaBruteForceTest, RandomWithDuplicates) {
  std::mt19937_64 rng(77);
  for (int s = 0; s < 60; ++s) {
    std::vector<Point2> points = RandomSet(rng, 3 + rng() % 8, Scale::kUnit);
    const size_t copies = 1 + rng() % 4;
    for (size_t c = 0; c < copies; ++c) {
      const Point2 p = points[rng() % points.size()];
      points.insert(points.begin() + static_cast<std::ptrdiff_t>(rng() % (points.size() + 1)), p);
    }
    CompareWithBruteForce(points, GetParam());
    if (HasFatalFailure()) return;
  }
}

TEST_P(AlphaBruteForceTest, SmallAndCollinear) {
  const std::vector<std::vector<Point2>> cases = {
      {},
      {{1.5, -2}},
      {{1.5, -2}, {1.5, -2}, {1.5, -2}},
      {{0, 0}, {3, 4}},
      {{3, 4}, {0, 0}, {3, 4}},
      // Collinear chains, with repeated gap lengths (ties in the spectrum) and shuffled order.
      {{0, 1}, {3, 7}, {1, 3}, {2, 5}, {5, 11}},
      {{2, 0}, {2, -1}, {2, 5}, {2, 4}, {2, 2}, {2, -1}},
      {{-1e9, 1e9}, {1e9, -1e9}, {0, 0}, {0.5, -0.5}},
      {{1e-300, 2e-300}, {3e-300, 6e-300}, {2e-300, 4e-300}},
      {{0.1, 0.1}, {0.3, 0.3}, {0.2, 0.2}, {0.7, 0.7}},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(testing::Message() << "case " << i);
    CompareWithBruteForce(cases[i], GetParam());
    if (HasFatalFailure()) return;
  }
}

TEST_P(AlphaBruteForceTest, DegenerateButUnique) {
  const std::vector<std::vector<Point2>> cases = {
      // Three collinear and one off the line; and longer runs with points on either side.
      {{0, 0}, {1, 0}, {3, 0}, {0.7, 2.3}},
      {{3, 0}, {0.7, 2.3}, {1, 0}, {0, 0}},
      {{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}, {5, 0}, {2.5, 1.7}},
      {{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}, {1.3, 2.1}, {2.9, -1.7}},
      {{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}, {2, 0.25}},
      // A right triangle: the hypotenuse's third vertex lies on its diametral circle (unattached,
      // born together with the triangle: an exact tie).
      {{0, 0}, {2, 0}, {0, 2}},
      {{0, 0}, {2, 0}, {0, 2}, {3.1, 2.9}},
      // Isosceles (two equal edges) and obtuse (an attached edge).
      {{0, 0}, {4, 0}, {2, 3}},
      {{0, 0}, {10, 0}, {5, 1}},
      {{0, 0}, {10, 0}, {5, 1}, {5, -1.5}},
      // Exact duplicates of a degenerate set.
      {{0, 0}, {1, 0}, {3, 0}, {0.7, 2.3}, {1, 0}, {0.7, 2.3}},
      // Huge offset and tiny scale, 3 collinear and 1 off.
      {{1e9, 1e9}, {1e9 + 1, 1e9}, {1e9 + 3, 1e9}, {1e9 + 0.7, 1e9 + 2.3}},
      {{0, 0}, {1e-300, 0}, {3e-300, 0}, {7e-301, 2.3e-300}},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(testing::Message() << "case " << i);
    CompareWithBruteForce(cases[i], GetParam());
    if (HasFatalFailure()) return;
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, AlphaBruteForceTest, ::testing::Values(Backend::kCpu, Backend::kCuda),
                         [](const ::testing::TestParamInfo<Backend>& info) { return BackendName(info.param); });

}  // namespace
}  // namespace galpha
