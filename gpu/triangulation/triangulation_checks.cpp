#include "gpu/triangulation/triangulation_checks.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>
#include <unordered_map>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.hpp"
#include "core/exact/predicates.hpp"

namespace galpha {
namespace {

using Tri = std::array<uint32_t, 3>;
using Edge = std::array<uint32_t, 2>;

uint64_t DirectedKey(uint32_t from, uint32_t to) { return (uint64_t{from} << 32) | to; }

// Round-trip precision: points at huge offsets differ only in their last digits.
std::string PointName(const Triangulation& t, uint32_t i) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "(%.17g, %.17g)", t.points[i].x, t.points[i].y);
  return absl::StrCat("point ", i, " ", buffer);
}

std::string TriangleName(const Triangulation& t, size_t tri) {
  const Tri& v = t.triangles[tri];
  return absl::StrCat("triangle ", tri, " (", v[0], ", ", v[1], ", ", v[2], ")");
}

// Everything a check needs besides the triangulation itself.
struct Context {
  const Triangulation& t;
  // Input indices sorted lexicographically by point, ties by index: duplicates are adjacent and the
  // first of each run is its representative.
  std::vector<uint32_t> lex_order;
  // The representatives, in lexicographic order of their points.
  std::vector<uint32_t> distinct;
  // Directed edge (from, to) of a triangle -> 3 * triangle + local index of its opposite vertex.
  std::unordered_map<uint64_t, uint32_t> directed_edges;
};

absl::Status CheckShapes(const Triangulation& t) {
  const size_t n = t.points.size();
  if (n > std::numeric_limits<uint32_t>::max()) {
    return absl::FailedPreconditionError(absl::StrCat(n, " points do not fit 32-bit indices"));
  }
  if (t.representative.size() != n) {
    return absl::FailedPreconditionError(
        absl::StrCat("representative has ", t.representative.size(), " entries for ", n, " points"));
  }
  for (size_t i = 0; i < n; ++i) {
    if (t.representative[i] >= n) {
      return absl::FailedPreconditionError(
          absl::StrCat("representative[", i, "] = ", t.representative[i], " is out of range"));
    }
  }
  const size_t f = t.triangles.size();
  if (t.neighbors.size() != f || t.tri_edge_begin.size() != f) {
    return absl::FailedPreconditionError(absl::StrCat(f, " triangles but ", t.neighbors.size(),
                                                      " neighbour triples and ", t.tri_edge_begin.size(),
                                                      " tri_edge_begin entries"));
  }
  for (size_t tri = 0; tri < f; ++tri) {
    for (int k = 0; k < 3; ++k) {
      if (t.triangles[tri][k] >= n) {
        return absl::FailedPreconditionError(absl::StrCat(TriangleName(t, tri), " has a vertex out of range"));
      }
      const int32_t nb = t.neighbors[tri][k];
      if (nb != Triangulation::kNoNeighbor && (nb < 0 || static_cast<size_t>(nb) >= f)) {
        return absl::FailedPreconditionError(
            absl::StrCat(TriangleName(t, tri), " has neighbour ", nb, " out of range"));
      }
    }
  }
  for (size_t e = 0; e < t.edges.size(); ++e) {
    if (t.edges[e][0] >= n || t.edges[e][1] >= n) {
      return absl::FailedPreconditionError(absl::StrCat("edge ", e, " has a vertex out of range"));
    }
  }
  return absl::OkStatus();
}

absl::Status CheckRepresentatives(Context& c) {
  const Triangulation& t = c.t;
  c.lex_order.resize(t.points.size());
  std::iota(c.lex_order.begin(), c.lex_order.end(), 0u);
  std::sort(c.lex_order.begin(), c.lex_order.end(), [&](uint32_t a, uint32_t b) {
    if (LexLess(t.points[a], t.points[b])) return true;
    if (LexLess(t.points[b], t.points[a])) return false;
    return a < b;
  });
  uint32_t first = 0;
  for (size_t r = 0; r < c.lex_order.size(); ++r) {
    const uint32_t i = c.lex_order[r];
    if (r == 0 || !(t.points[i] == t.points[c.lex_order[r - 1]])) {
      first = i;
      c.distinct.push_back(i);
    }
    if (t.representative[i] != first) {
      return absl::InternalError(absl::StrCat("representative[", i, "] is ", t.representative[i],
                                              " but the first occurrence of ", PointName(t, i), " is ", first));
    }
  }
  if (t.num_unique != c.distinct.size()) {
    return absl::InternalError(
        absl::StrCat("num_unique is ", t.num_unique, " but there are ", c.distinct.size(), " distinct points"));
  }
  return absl::OkStatus();
}

// No triangles: 0-2 distinct points or a collinear set, joined in order along their line.
absl::Status CheckEdgeOnlyOutput(const Context& c) {
  const Triangulation& t = c.t;
  const std::vector<uint32_t>& d = c.distinct;
  for (size_t k = 2; k < d.size(); ++k) {
    if (Orient2dSign(t.points[d[0]], t.points[d[1]], t.points[d[k]]) != 0) {
      return absl::InternalError(absl::StrCat("no triangles, but ", PointName(t, d[0]), ", ", PointName(t, d[1]),
                                              " and ", PointName(t, d[k]), " are not collinear"));
    }
  }
  // On a line the lexicographic order is the order along it.
  std::vector<Edge> expected;
  for (size_t k = 0; k + 1 < d.size(); ++k) {
    expected.push_back({std::min(d[k], d[k + 1]), std::max(d[k], d[k + 1])});
  }
  std::vector<Edge> actual = t.edges;
  std::sort(expected.begin(), expected.end());
  std::sort(actual.begin(), actual.end());
  if (actual.size() != expected.size()) {
    return absl::InternalError(absl::StrCat("collinear output has ", actual.size(),
                                            " edges; consecutive distinct points need ", expected.size()));
  }
  for (size_t e = 0; e < expected.size(); ++e) {
    if (actual[e] != expected[e]) {
      return absl::InternalError(absl::StrCat("collinear output: expected edge (", expected[e][0], ", ", expected[e][1],
                                              ") between consecutive points along the line, found (", actual[e][0],
                                              ", ", actual[e][1], ")"));
    }
  }
  return absl::OkStatus();
}

absl::Status CheckTriangleVertices(const Context& c) {
  const Triangulation& t = c.t;
  for (size_t tri = 0; tri < t.triangles.size(); ++tri) {
    const Tri& v = t.triangles[tri];
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) {
      return absl::InternalError(absl::StrCat(TriangleName(t, tri), " repeats a vertex"));
    }
    for (uint32_t vertex : v) {
      if (t.representative[vertex] != vertex) {
        return absl::InternalError(absl::StrCat(TriangleName(t, tri), " uses duplicate ", vertex,
                                                " instead of its representative ", t.representative[vertex]));
      }
    }
    const int orientation = Orient2dSign(t.points[v[0]], t.points[v[1]], t.points[v[2]]);
    if (orientation <= 0) {
      return absl::InternalError(
          absl::StrCat(TriangleName(t, tri), " is not strictly counter-clockwise (orientation ", orientation, ")"));
    }
  }
  return absl::OkStatus();
}

// The local index j of `nb`'s edge running from `from` to `to`, or -1.
int FindDirectedEdge(const Tri& nb, uint32_t from, uint32_t to) {
  for (int j = 0; j < 3; ++j) {
    if (nb[(j + 1) % 3] == from && nb[(j + 2) % 3] == to) return j;
  }
  return -1;
}

absl::Status CheckNeighbors(const Context& c) {
  const Triangulation& t = c.t;
  for (size_t tri = 0; tri < t.triangles.size(); ++tri) {
    for (int k = 0; k < 3; ++k) {
      const int32_t nb = t.neighbors[tri][k];
      if (nb == Triangulation::kNoNeighbor) continue;
      const uint32_t a = t.triangles[tri][(k + 1) % 3];
      const uint32_t b = t.triangles[tri][(k + 2) % 3];
      const std::string where =
          absl::StrCat(TriangleName(t, tri), " has neighbour ", TriangleName(t, nb), " across edge (", a, ", ", b, ")");
      if (static_cast<size_t>(nb) == tri) return absl::InternalError(where + ": itself");
      const int j = FindDirectedEdge(t.triangles[nb], b, a);
      if (j < 0) {
        return absl::InternalError(
            absl::StrCat("neighbour symmetry: ", where, ", which lacks the edge (", b, ", ", a, ")"));
      }
      if (t.neighbors[nb][j] != static_cast<int32_t>(tri)) {
        return absl::InternalError(
            absl::StrCat("neighbour symmetry: ", where, ", whose neighbour across it is ", t.neighbors[nb][j]));
      }
    }
  }
  return absl::OkStatus();
}

// Each directed edge once (else triangles overlap), and no hull edge with a reverse twin (else a
// neighbour link is missing).
absl::Status CheckDirectedEdges(Context& c) {
  const Triangulation& t = c.t;
  c.directed_edges.reserve(3 * t.triangles.size());
  for (size_t tri = 0; tri < t.triangles.size(); ++tri) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t.triangles[tri][(k + 1) % 3];
      const uint32_t b = t.triangles[tri][(k + 2) % 3];
      const auto [it, inserted] = c.directed_edges.emplace(DirectedKey(a, b), static_cast<uint32_t>(3 * tri + k));
      if (!inserted) {
        return absl::InternalError(absl::StrCat("directed edge (", a, ", ", b, ") occurs in ",
                                                TriangleName(t, it->second / 3), " and ", TriangleName(t, tri),
                                                ": triangles overlap"));
      }
    }
  }
  for (size_t tri = 0; tri < t.triangles.size(); ++tri) {
    for (int k = 0; k < 3; ++k) {
      if (t.neighbors[tri][k] != Triangulation::kNoNeighbor) continue;
      const uint32_t a = t.triangles[tri][(k + 1) % 3];
      const uint32_t b = t.triangles[tri][(k + 2) % 3];
      const auto twin = c.directed_edges.find(DirectedKey(b, a));
      if (twin != c.directed_edges.end()) {
        return absl::InternalError(absl::StrCat(TriangleName(t, tri), " has no neighbour across edge (", a, ", ", b,
                                                ") but ", TriangleName(t, twin->second / 3), " holds its reverse"));
      }
    }
  }
  return absl::OkStatus();
}

absl::Status CheckConnected(const Context& c) {
  const Triangulation& t = c.t;
  std::vector<bool> reached(t.triangles.size(), false);
  std::vector<uint32_t> stack = {0};
  reached[0] = true;
  size_t count = 1;
  while (!stack.empty()) {
    const uint32_t tri = stack.back();
    stack.pop_back();
    for (int32_t nb : t.neighbors[tri]) {
      if (nb == Triangulation::kNoNeighbor || reached[nb]) continue;
      reached[nb] = true;
      ++count;
      stack.push_back(nb);
    }
  }
  if (count != t.triangles.size()) {
    const size_t missed = std::find(reached.begin(), reached.end(), false) - reached.begin();
    return absl::InternalError(
        absl::StrCat("triangles are not edge-connected: ", TriangleName(t, missed), " is unreachable from 0"));
  }
  return absl::OkStatus();
}

// The report "Computing 2D Alpha Shapes Using GPU", section 3.1: triangle t owns its local edge e
// (vertex e to vertex e+1) when the indices increase along it or it is a hull edge; owned edges are
// laid out triangle by triangle, in local order, starting at the exclusive scan of the owned counts.
absl::Status CheckEdgeList(const Context& c) {
  const Triangulation& t = c.t;
  size_t next = 0;
  for (size_t tri = 0; tri < t.triangles.size(); ++tri) {
    if (t.tri_edge_begin[tri] != next) {
      return absl::InternalError(absl::StrCat("tri_edge_begin of ", TriangleName(t, tri), " is ", t.tri_edge_begin[tri],
                                              "; the scan of owned edge counts gives ", next));
    }
    const Tri& v = t.triangles[tri];
    for (int e = 0; e < 3; ++e) {
      const uint32_t from = v[e];
      const uint32_t to = v[(e + 1) % 3];
      const bool hull = t.neighbors[tri][(e + 2) % 3] == Triangulation::kNoNeighbor;
      if (from > to && !hull) continue;
      const Edge expected = {std::min(from, to), std::max(from, to)};
      if (next >= t.edges.size() || t.edges[next] != expected) {
        return absl::InternalError(absl::StrCat("edge list: ", TriangleName(t, tri), " owns edge (", expected[0], ", ",
                                                expected[1], ") at position ", next, ", which holds ",
                                                next < t.edges.size()
                                                    ? absl::StrCat("(", t.edges[next][0], ", ", t.edges[next][1], ")")
                                                    : std::string("nothing")));
      }
      ++next;
    }
  }
  if (next != t.edges.size()) {
    return absl::InternalError(absl::StrCat("edge list has ", t.edges.size(), " edges; the triangles own ", next));
  }
  std::vector<Edge> sorted = t.edges;
  std::sort(sorted.begin(), sorted.end());
  const auto repeat = std::adjacent_find(sorted.begin(), sorted.end());
  if (repeat != sorted.end()) {
    return absl::InternalError(
        absl::StrCat("edge (", (*repeat)[0], ", ", (*repeat)[1], ") appears twice in the edge list"));
  }
  return absl::OkStatus();
}

absl::Status CheckVerticesAndEuler(const Context& c) {
  const Triangulation& t = c.t;
  std::vector<bool> used(t.points.size(), false);
  size_t hull_edges = 0;
  for (size_t tri = 0; tri < t.triangles.size(); ++tri) {
    for (int k = 0; k < 3; ++k) {
      used[t.triangles[tri][k]] = true;
      if (t.neighbors[tri][k] == Triangulation::kNoNeighbor) ++hull_edges;
    }
  }
  for (uint32_t i : c.distinct) {
    if (!used[i]) {
      return absl::InternalError(absl::StrCat(PointName(t, i), " is not a vertex of any triangle"));
    }
  }
  const int64_t v = t.num_unique;
  const int64_t e = static_cast<int64_t>(t.edges.size());
  const int64_t f = static_cast<int64_t>(t.triangles.size());
  if (2 * e != 3 * f + static_cast<int64_t>(hull_edges)) {
    return absl::InternalError(
        absl::StrCat("edge count: 2E = ", 2 * e, " but 3F + h = ", 3 * f + static_cast<int64_t>(hull_edges)));
  }
  if (v - e + f != 1) {
    return absl::InternalError(absl::StrCat("Euler: V - E + F = ", v, " - ", e, " + ", f, " = ", v - e + f, ", not 1"));
  }
  return absl::OkStatus();
}

// Andrew's monotone chain over the distinct points, popping only at strict right turns so that
// points on hull edges stay (CGAL keeps them as vertices too). Counter-clockwise, starting at the
// lexicographically smallest point. Needs three non-collinear points.
std::vector<uint32_t> ConvexHullWithCollinear(const Context& c) {
  const std::vector<Point2>& p = c.t.points;
  auto chain = [&](auto begin, auto end) {
    std::vector<uint32_t> h;
    for (auto it = begin; it != end; ++it) {
      while (h.size() >= 2 && Orient2dSign(p[h[h.size() - 2]], p[h.back()], p[*it]) < 0) {
        h.pop_back();
      }
      h.push_back(*it);
    }
    h.pop_back();  // the other chain starts there
    return h;
  };
  std::vector<uint32_t> hull = chain(c.distinct.begin(), c.distinct.end());
  const std::vector<uint32_t> upper = chain(c.distinct.rbegin(), c.distinct.rend());
  hull.insert(hull.end(), upper.begin(), upper.end());
  return hull;
}

absl::Status CheckHull(const Context& c) {
  const Triangulation& t = c.t;
  std::unordered_map<uint32_t, uint32_t> next;
  for (size_t tri = 0; tri < t.triangles.size(); ++tri) {
    for (int k = 0; k < 3; ++k) {
      if (t.neighbors[tri][k] != Triangulation::kNoNeighbor) continue;
      const uint32_t a = t.triangles[tri][(k + 1) % 3];
      const uint32_t b = t.triangles[tri][(k + 2) % 3];
      if (!next.emplace(a, b).second) {
        return absl::InternalError(
            absl::StrCat("boundary is not a simple cycle: vertex ", a, " starts two hull edges"));
      }
    }
  }
  const std::vector<uint32_t> hull = ConvexHullWithCollinear(c);
  // Walk the boundary from the hull's first vertex, which is the lexicographically smallest point
  // and so on every correct boundary.
  std::vector<uint32_t> boundary = {hull[0]};
  while (boundary.size() <= next.size()) {
    const auto step = next.find(boundary.back());
    if (step == next.end()) {
      return absl::InternalError(absl::StrCat("boundary: no hull edge leaves ", PointName(t, boundary.back())));
    }
    if (step->second == hull[0]) break;
    boundary.push_back(step->second);
  }
  if (boundary.size() != next.size()) {
    return absl::InternalError(
        absl::StrCat("boundary edges do not form one closed cycle: the cycle"
                     " through ",
                     PointName(t, hull[0]), " has ", boundary.size(), " of the ", next.size(), " hull edges"));
  }
  for (size_t k = 0; k < std::min(hull.size(), boundary.size()); ++k) {
    if (hull[k] != boundary[k]) {
      return absl::InternalError(absl::StrCat("boundary differs from the convex hull at position ", k, ": expected ",
                                              PointName(t, hull[k]), ", found ", PointName(t, boundary[k])));
    }
  }
  if (hull.size() != boundary.size()) {
    return absl::InternalError(
        absl::StrCat("boundary has ", boundary.size(), " vertices, the convex hull ", hull.size()));
  }
  return absl::OkStatus();
}

absl::Status CheckLocallyDelaunay(const Context& c) {
  const Triangulation& t = c.t;
  const std::vector<Point2>& p = t.points;
  for (size_t tri = 0; tri < t.triangles.size(); ++tri) {
    const Tri& v = t.triangles[tri];
    for (int k = 0; k < 3; ++k) {
      const int32_t nb = t.neighbors[tri][k];
      if (nb == Triangulation::kNoNeighbor) continue;
      const uint32_t a = v[(k + 1) % 3];
      const uint32_t b = v[(k + 2) % 3];
      const uint32_t d = t.triangles[nb][FindDirectedEdge(t.triangles[nb], b, a)];
      if (InCircleSoS(p[v[0]], v[0], p[v[1]], v[1], p[v[2]], v[2], p[d], d) > 0) {
        return absl::InternalError(absl::StrCat("edge (", a, ", ", b, ") is not locally Delaunay: vertex ", d, " of ",
                                                TriangleName(t, nb), " lies inside the circumcircle of ",
                                                TriangleName(t, tri), " (in-circle with Simulation of Simplicity)"));
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status CheckTriangulation(const Triangulation& t) {
  GALPHA_RETURN_IF_ERROR(CheckShapes(t));
  Context c{t, {}, {}, {}};
  GALPHA_RETURN_IF_ERROR(CheckRepresentatives(c));
  if (t.triangles.empty()) return CheckEdgeOnlyOutput(c);
  GALPHA_RETURN_IF_ERROR(CheckTriangleVertices(c));
  GALPHA_RETURN_IF_ERROR(CheckNeighbors(c));
  GALPHA_RETURN_IF_ERROR(CheckDirectedEdges(c));
  GALPHA_RETURN_IF_ERROR(CheckConnected(c));
  GALPHA_RETURN_IF_ERROR(CheckEdgeList(c));
  GALPHA_RETURN_IF_ERROR(CheckVerticesAndEuler(c));
  GALPHA_RETURN_IF_ERROR(CheckHull(c));
  return CheckLocallyDelaunay(c);
}

}  // namespace galpha
