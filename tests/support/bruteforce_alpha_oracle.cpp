// The brute-force alpha family (bruteforce_alpha_oracle.hpp): every definition, exactly.
#include "tests/support/bruteforce_alpha_oracle.hpp"

#include <gmpxx.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <map>
#include <numeric>
#include <optional>
#include <vector>

namespace galpha::testing {
namespace {

using Tri = BruteTri;
using Edge = BruteEdge;

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

}  // namespace

// ---- Exact primitives ----------------------------------------------------------------------------

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

// No three distinct points collinear and no four co-circular, exactly: a unique Delaunay
// triangulation.
bool InGeneralPosition(const std::vector<Point2>& points) {
  std::vector<QPoint> q;
  q.reserve(points.size());
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

// ---- The family by brute force -------------------------------------------------------------------

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

uint32_t BruteRegularizedComponents(const BruteFamily& b, const mpq_class& A) {
  DisjointSets sets(b.points.size());
  std::vector<bool> covered(b.points.size());
  for (size_t t = 0; t < b.tris.size(); ++t) {
    if (b.tri_birth[t] > A) continue;
    for (uint32_t v : b.tris[t]) covered[v] = true;
    sets.Union(b.tris[t][0], b.tris[t][1]);
    sets.Union(b.tris[t][0], b.tris[t][2]);
  }
  uint32_t count = 0;
  for (uint32_t v : b.uniq) count += covered[v] && sets.Find(v) == v;
  return count;
}

namespace {

/// Rank over GF(2) of the vectors `rows` (bit sets of `width` bits), by Gaussian elimination.
uint32_t RankGf2(std::vector<std::vector<uint64_t>> rows, size_t width) {
  uint32_t rank = 0;
  for (size_t bit = 0; bit < width && rank < rows.size(); ++bit) {
    const size_t word = bit / 64;
    const uint64_t mask = uint64_t{1} << (bit % 64);
    size_t pivot = rank;
    while (pivot < rows.size() && (rows[pivot][word] & mask) == 0) ++pivot;
    if (pivot == rows.size()) continue;
    std::swap(rows[rank], rows[pivot]);
    for (size_t i = 0; i < rows.size(); ++i) {
      if (i != rank && (rows[i][word] & mask) != 0) {
        for (size_t w = 0; w < rows[i].size(); ++w) rows[i][w] ^= rows[rank][w];
      }
    }
    ++rank;
  }
  return rank;
}

std::vector<uint64_t> BitRow(size_t width, std::initializer_list<size_t> bits) {
  std::vector<uint64_t> row((width + 63) / 64, 0);
  for (size_t bit : bits) row[bit / 64] ^= uint64_t{1} << (bit % 64);
  return row;
}

}  // namespace

uint32_t BruteHoles(const BruteFamily& b, const mpq_class& A, ClassifyMode mode) {
  if (sgn(A) < 0) return 0;
  std::vector<bool> tri_in(b.tris.size()), edge_in(b.edges.size());
  for (size_t t = 0; t < b.tris.size(); ++t) tri_in[t] = b.tri_birth[t] <= A;
  for (size_t e = 0; e < b.edges.size(); ++e) {
    if (mode == ClassifyMode::kGeneral) {
      edge_in[e] = b.edge_birth[e] <= A;
    } else {
      for (uint32_t t : b.edge_tris[e]) edge_in[e] = edge_in[e] || tri_in[t];
    }
  }
  // d1: one row per edge over the vertices; d2: one row per triangle over the edges.
  std::map<BruteEdge, size_t> edge_index;
  for (size_t e = 0; e < b.edges.size(); ++e) edge_index[b.edges[e]] = e;
  std::vector<std::vector<uint64_t>> d1, d2;
  for (size_t e = 0; e < b.edges.size(); ++e) {
    if (edge_in[e]) d1.push_back(BitRow(b.points.size(), {b.edges[e][0], b.edges[e][1]}));
  }
  for (size_t t = 0; t < b.tris.size(); ++t) {
    if (!tri_in[t]) continue;
    const BruteTri& tri = b.tris[t];
    d2.push_back(BitRow(b.edges.size(), {edge_index.at({tri[0], tri[1]}), edge_index.at({tri[0], tri[2]}),
                                         edge_index.at({tri[1], tri[2]})}));
  }
  const auto edges_in = static_cast<uint32_t>(d1.size());
  return edges_in - RankGf2(std::move(d1), b.points.size()) - RankGf2(std::move(d2), b.edges.size());
}

bool EveryPointOnATriangle(const BruteFamily& b, const mpq_class& A) {
  for (uint32_t v : b.uniq) {
    bool covered = false;
    for (uint32_t t : b.vertex_tris[v]) covered |= b.tri_birth[t] <= A;
    if (!covered) return false;
  }
  return true;
}

}  // namespace galpha::testing
