#include "core/geometry/shape.hpp"

#include <parallel/algorithm>

#include <algorithm>
#include <cstdio>
#include <unordered_map>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "core/base/status_macros.hpp"
#include "core/exact/predicates.hpp"
#include "core/io/json_text.hpp"
#include "core/io/number_text.hpp"
#include "nlohmann/json.hpp"

namespace galpha {
namespace {

// ---- Validation -------------------------------------------------------------------------------

absl::Status CheckIndex(uint32_t index, size_t num_points, absl::string_view what, size_t item) {
  if (index >= num_points) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " ", item, " names point index ", index, ", but there are only ", num_points, " points"));
  }
  return absl::OkStatus();
}

absl::Status ValidateComplex(const ShapeComplex& complex) {
  const size_t n = complex.points.size();
  // Ring orientation and the turn at pinch vertices rely on strictly ccw triangles. Checked on
  // every core (each check reads three points at random: memory-bound); the error names the first
  // bad triangle, whatever the number of threads.
  const auto num_tri = static_cast<int64_t>(complex.triangles.size());
  int64_t first_bad = num_tri;
#pragma omp parallel for schedule(static) reduction(min : first_bad)
  for (int64_t t = 0; t < num_tri; ++t) {
    const auto& tri = complex.triangles[t];
    const bool bad = tri[0] >= n || tri[1] >= n || tri[2] >= n ||
                     Orient2dSign(complex.points[tri[0]], complex.points[tri[1]], complex.points[tri[2]]) <= 0;
    if (bad && t < first_bad) first_bad = t;
  }
  if (first_bad < num_tri) {
    const auto t = static_cast<size_t>(first_bad);
    const auto& tri = complex.triangles[t];
    for (uint32_t v : tri) GALPHA_RETURN_IF_ERROR(CheckIndex(v, n, "triangle", t));
    return absl::InvalidArgumentError(
        absl::StrCat("triangle ", t, " (", tri[0], ", ", tri[1], ", ", tri[2], ") is not strictly counter-clockwise"));
  }
  for (size_t e = 0; e < complex.singular_edges.size(); ++e) {
    const auto& edge = complex.singular_edges[e];
    for (uint32_t v : edge) GALPHA_RETURN_IF_ERROR(CheckIndex(v, n, "singular edge", e));
    if (edge[0] == edge[1]) {
      return absl::InvalidArgumentError(absl::StrCat("singular edge ", e, " joins point ", edge[0], " to itself"));
    }
  }
  for (size_t i = 0; i < complex.isolated_points.size(); ++i) {
    GALPHA_RETURN_IF_ERROR(CheckIndex(complex.isolated_points[i], n, "isolated point", i));
  }
  return absl::OkStatus();
}

absl::Status OverlapError(absl::string_view detail) {
  return absl::InvalidArgumentError(
      absl::StrCat("the triangles overlap (they are not a subset of one triangulation): ", detail));
}

// ---- Topology -----------------------------------------------------------------------------------

// Union-find with path halving and union by size, over triangle indices.
class UnionFind {
 public:
  explicit UnionFind(size_t n) : parent_(n), size_(n, 1) {
    for (size_t i = 0; i < n; ++i) parent_[i] = static_cast<uint32_t>(i);
  }
  uint32_t Find(uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void Union(uint32_t a, uint32_t b) {
    a = Find(a);
    b = Find(b);
    if (a == b) return;
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
  }

 private:
  std::vector<uint32_t> parent_;
  std::vector<uint32_t> size_;
};

// A triangle's side, keyed by its undirected edge (smaller << 32 | larger) so that sorting puts
// an edge's two sides next to each other, with its direction in the triangle (counter-clockwise).
struct TriangleSide {
  uint64_t key;
  uint32_t triangle;
  bool ascending;  // the triangle runs along it from the smaller vertex to the larger
  uint32_t from() const { return ascending ? static_cast<uint32_t>(key >> 32) : static_cast<uint32_t>(key); }
  uint32_t to() const { return ascending ? static_cast<uint32_t>(key) : static_cast<uint32_t>(key >> 32); }
};

// A boundary edge: its twin is not in the set, so its piece lies on its left only.
using BoundaryEdge = ShapeBoundarySide;

// Whether, around `v` and counter-clockwise from the direction of `ref` (excluded), the direction
// of `a` comes before that of `b`. Exact: the half-plane left of v->ref (the direction opposite
// to ref included) comes first, and within a half-plane two directions are less than pi apart, so
// one orientation orders them. No two edges leave `v` in one direction (triangles do not overlap).
bool CcwBefore(Point2 v, Point2 ref, Point2 a, Point2 b) {
  const int half_a = Orient2dSign(v, ref, a) >= 0 ? 0 : 1;
  const int half_b = Orient2dSign(v, ref, b) >= 0 ? 0 : 1;
  if (half_a != half_b) return half_a < half_b;
  return Orient2dSign(v, a, b) > 0;
}

// A closed walk along boundary edges; `vertices` are the edges' sources in order.
struct Ring {
  uint32_t piece;
  std::vector<uint32_t> vertices;
};

// Traces every boundary edge into rings. Entering vertex v along u->v, the walk leaves along the
// boundary edge of the same piece that comes first counter-clockwise from v->u: the ring then hugs
// one complement region of the piece at v (see shape.hpp for why that makes rings simple). Other
// pieces' edges are ignored there: a ring of one piece may touch another piece, never itself.
absl::StatusOr<std::vector<Ring>> TraceRings(absl::Span<const Point2> points,
                                             const std::vector<BoundaryEdge>& boundary) {
  std::vector<Ring> rings;
  std::vector<bool> used(boundary.size(), false);
  auto out_range = [&boundary](uint32_t v) {
    const auto lo = std::lower_bound(boundary.begin(), boundary.end(), v,
                                     [](const BoundaryEdge& e, uint32_t x) { return e.from < x; });
    auto hi = lo;
    while (hi != boundary.end() && hi->from == v) ++hi;
    return std::make_pair(static_cast<size_t>(lo - boundary.begin()), static_cast<size_t>(hi - boundary.begin()));
  };
  for (size_t start = 0; start < boundary.size(); ++start) {
    if (used[start]) continue;
    Ring ring{boundary[start].piece, {}};
    size_t cur = start;
    while (true) {
      used[cur] = true;
      ring.vertices.push_back(boundary[cur].from);
      const uint32_t u = boundary[cur].from;
      const uint32_t v = boundary[cur].to;
      const auto [lo, hi] = out_range(v);
      size_t next = boundary.size();
      for (size_t e = lo; e < hi; ++e) {
        if (boundary[e].piece != ring.piece) continue;
        if (next == boundary.size() ||
            CcwBefore(points[v], points[u], points[boundary[e].to], points[boundary[next].to])) {
          next = e;
        }
      }
      if (next == boundary.size()) {
        return OverlapError(absl::StrCat("the boundary stops at point ", v));
      }
      if (next == start) break;
      if (used[next]) {
        return OverlapError(absl::StrCat("the boundary does not close into rings at point ", v));
      }
      cur = next;
    }
    rings.push_back(std::move(ring));
  }
  return rings;
}

// +1 when the simple ring is counter-clockwise, -1 when clockwise: the turn at its lowest vertex
// in (x, y) order is convex, so its exact orientation is the ring's. 0 when the ring doubles back
// there, which simple rings of non-overlapping triangles never do.
int RingOrientation(absl::Span<const Point2> points, const std::vector<uint32_t>& ring) {
  const size_t m = ring.size();
  size_t low = 0;
  for (size_t i = 1; i < m; ++i) {
    if (LexLess(points[ring[i]], points[ring[low]])) low = i;
  }
  return Orient2dSign(points[ring[(low + m - 1) % m]], points[ring[low]], points[ring[(low + 1) % m]]);
}

void RotateToSmallest(std::vector<uint32_t>& ring) {
  std::rotate(ring.begin(), std::min_element(ring.begin(), ring.end()), ring.end());
}

// ---- Writers ------------------------------------------------------------------------------------

void AppendWktPoint(std::string& out, const Point2& p) {
  AppendShortestDouble(out, p.x);
  out += ' ';
  AppendShortestDouble(out, p.y);
}

// Appends a WKT ring, closed by repeating its first vertex, as OGC asks.
void AppendWktRing(std::string& out, const std::vector<uint32_t>& ring, absl::Span<const Point2> points) {
  out += '(';
  for (size_t i = 0; i <= ring.size(); ++i) {
    if (i > 0) out += ", ";
    AppendWktPoint(out, points[ring[i % ring.size()]]);
  }
  out += ')';
}

// Appends a polygon's rings without a tag: "((outer), (hole), ...)".
void AppendWktPolygonText(std::string& out, const ShapePolygon& polygon, absl::Span<const Point2> points) {
  out += '(';
  AppendWktRing(out, polygon.outer, points);
  for (const auto& hole : polygon.holes) {
    out += ", ";
    AppendWktRing(out, hole, points);
  }
  out += ')';
}

void AppendWktMultiPolygon(std::string& out, const std::vector<ShapePolygon>& polygons,
                           absl::Span<const Point2> points) {
  out += "MULTIPOLYGON (";
  for (size_t p = 0; p < polygons.size(); ++p) {
    if (p > 0) out += ", ";
    AppendWktPolygonText(out, polygons[p], points);
  }
  out += ')';
}

nlohmann::ordered_json JsonPosition(const Point2& p) { return nlohmann::ordered_json::array({p.x, p.y}); }

// A GeoJSON linear ring: closed by repeating its first position (RFC 7946 section 3.1.6).
nlohmann::ordered_json JsonRing(const std::vector<uint32_t>& ring, absl::Span<const Point2> points) {
  nlohmann::ordered_json positions = nlohmann::ordered_json::array();
  for (size_t i = 0; i <= ring.size(); ++i) positions.push_back(JsonPosition(points[ring[i % ring.size()]]));
  return positions;
}

nlohmann::ordered_json JsonFeature(nlohmann::ordered_json properties, const char* type,
                                   nlohmann::ordered_json coordinates) {
  return {{"type", "Feature"},
          {"properties", std::move(properties)},
          {"geometry", {{"type", type}, {"coordinates", std::move(coordinates)}}}};
}

}  // namespace

absl::StatusOr<ShapeGeometry> AssembleShape(const ShapeComplex& complex) {
  GALPHA_RETURN_IF_ERROR(ValidateComplex(complex));
  const absl::Span<const Point2> points = complex.points;
  const auto& triangles = complex.triangles;
  ShapeGeometry shape;

  // The triangles' areas in parallel, summed in their order (the same double on any machine).
  std::vector<double> areas(triangles.size());
#pragma omp parallel for schedule(static)
  for (int64_t t = 0; t < static_cast<int64_t>(triangles.size()); ++t) {
    const auto& tri = triangles[t];
    areas[t] = 0.5 * Orient2dApprox(points[tri[0]], points[tri[1]], points[tri[2]]);
  }
  for (double a : areas) shape.area += a;

  // Every side of every triangle, sorted by undirected edge: an edge's two sides are then
  // neighbours, found in one scan. (Looking each side's twin up by binary search in the sorted
  // sides was a cache miss a step: 11 s for the 6M sides of a 1M-point shape.)
  std::vector<TriangleSide> sides;
  sides.reserve(3 * triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t from = triangles[t][k], to = triangles[t][(k + 1) % 3];
      sides.push_back({(uint64_t{std::min(from, to)} << 32) | std::max(from, to), static_cast<uint32_t>(t), from < to});
    }
  }
  // (key, triangle) pairs are unique: the parallel sort's order is the one order.
  __gnu_parallel::sort(sides.begin(), sides.end(), [](const TriangleSide& a, const TriangleSide& b) {
    return a.key < b.key || (a.key == b.key && a.triangle < b.triangle);
  });

  // Pieces: triangles joined through shared edges. A piece's interior is connected and distinct
  // pieces' interiors are disjoint (they meet at most at vertices), so each is one polygon. An
  // edge has at most two sides, in opposite directions, in triangles that do not overlap.
  UnionFind pieces(triangles.size());
  std::vector<size_t> lone_sides;
  for (size_t i = 0; i < sides.size();) {
    size_t end = i + 1;
    while (end < sides.size() && sides[end].key == sides[i].key) ++end;
    for (size_t j = i; j < end; ++j) {
      for (size_t k = j + 1; k < end; ++k) {
        if (sides[j].ascending == sides[k].ascending) {
          return OverlapError(absl::StrCat("triangles ", sides[j].triangle, " and ", sides[k].triangle,
                                           " both hold the directed edge ", sides[j].from(), " -> ", sides[j].to()));
        }
      }
    }
    if (end - i == 2) {
      pieces.Union(sides[i].triangle, sides[i + 1].triangle);
    } else {
      lone_sides.push_back(i);
    }
    i = end;
  }
  std::vector<BoundaryEdge> boundary;
  boundary.reserve(lone_sides.size());
  for (size_t i : lone_sides) boundary.push_back({sides[i].from(), sides[i].to(), pieces.Find(sides[i].triangle)});
  return ShapeFromBoundary(points, std::move(boundary), shape.area, complex.singular_edges, complex.isolated_points);
}

absl::StatusOr<ShapeGeometry> ShapeFromBoundary(absl::Span<const Point2> points,
                                                std::vector<ShapeBoundarySide> boundary, double area,
                                                absl::Span<const std::array<uint32_t, 2>> singular_edges,
                                                absl::Span<const uint32_t> isolated_points) {
  ShapeGeometry shape;
  shape.area = area;
  // Sorted by (from, to), as TraceRings needs.
  std::sort(boundary.begin(), boundary.end(), [](const BoundaryEdge& a, const BoundaryEdge& b) {
    return a.from < b.from || (a.from == b.from && a.to < b.to);
  });

  GALPHA_ASSIGN_OR_RETURN(std::vector<Ring> rings, TraceRings(points, boundary));

  // Each piece has exactly one counter-clockwise ring (around the unbounded complement region) and
  // one clockwise ring per bounded complement region (its holes). Anything else means overlap.
  // Polygons by piece label (labels are any numbers: a map, not an array as long as the triangles).
  std::unordered_map<uint32_t, uint32_t> polygon_of_piece;
  std::vector<int> orientation(rings.size());
  for (size_t r = 0; r < rings.size(); ++r) {
    Ring& ring = rings[r];
    orientation[r] = RingOrientation(points, ring.vertices);
    if (orientation[r] == 0) {
      return OverlapError(absl::StrCat("a boundary ring doubles back near point ", ring.vertices[0]));
    }
    if (orientation[r] < 0) continue;
    if (!polygon_of_piece.emplace(ring.piece, static_cast<uint32_t>(shape.polygons.size())).second) {
      return OverlapError(absl::StrCat("the piece of triangle ", ring.piece, " has two outer rings"));
    }
    RotateToSmallest(ring.vertices);
    shape.polygons.push_back({std::move(ring.vertices), {}});
  }
  for (size_t r = 0; r < rings.size(); ++r) {
    if (orientation[r] > 0) continue;
    const auto polygon = polygon_of_piece.find(rings[r].piece);
    if (polygon == polygon_of_piece.end()) {
      return OverlapError(absl::StrCat("the piece of triangle ", rings[r].piece, " has no outer ring"));
    }
    RotateToSmallest(rings[r].vertices);
    shape.polygons[polygon->second].holes.push_back(std::move(rings[r].vertices));
  }
  for (ShapePolygon& polygon : shape.polygons) {
    std::sort(polygon.holes.begin(), polygon.holes.end());
  }
  std::sort(shape.polygons.begin(), shape.polygons.end(),
            [](const ShapePolygon& a, const ShapePolygon& b) { return a.outer < b.outer; });

  for (const auto& edge : singular_edges) {
    shape.singular_edges.push_back({std::min(edge[0], edge[1]), std::max(edge[0], edge[1])});
  }
  std::sort(shape.singular_edges.begin(), shape.singular_edges.end());
  shape.singular_edges.erase(std::unique(shape.singular_edges.begin(), shape.singular_edges.end()),
                             shape.singular_edges.end());
  shape.isolated_points.assign(isolated_points.begin(), isolated_points.end());
  std::sort(shape.isolated_points.begin(), shape.isolated_points.end());
  shape.isolated_points.erase(std::unique(shape.isolated_points.begin(), shape.isolated_points.end()),
                              shape.isolated_points.end());
  return shape;
}

std::string ShapeToWkt(const ShapeGeometry& shape, absl::Span<const Point2> points) {
  const bool polygons_only = shape.singular_edges.empty() && shape.isolated_points.empty();
  if (polygons_only) {
    if (shape.polygons.empty()) return "MULTIPOLYGON EMPTY";
    if (shape.polygons.size() == 1) {
      std::string out = "POLYGON ";
      AppendWktPolygonText(out, shape.polygons[0], points);
      return out;
    }
    std::string out;
    AppendWktMultiPolygon(out, shape.polygons, points);
    return out;
  }
  std::string out = "GEOMETRYCOLLECTION (";
  if (!shape.polygons.empty()) {
    AppendWktMultiPolygon(out, shape.polygons, points);
    out += ", ";
  }
  if (!shape.singular_edges.empty()) {
    out += "MULTILINESTRING (";
    for (size_t e = 0; e < shape.singular_edges.size(); ++e) {
      out += e > 0 ? ", (" : "(";
      AppendWktPoint(out, points[shape.singular_edges[e][0]]);
      out += ", ";
      AppendWktPoint(out, points[shape.singular_edges[e][1]]);
      out += ')';
    }
    out += "), ";
  }
  if (!shape.isolated_points.empty()) {
    out += "MULTIPOINT (";
    for (size_t i = 0; i < shape.isolated_points.size(); ++i) {
      out += i > 0 ? ", (" : "(";
      AppendWktPoint(out, points[shape.isolated_points[i]]);
      out += ')';
    }
    out += "), ";
  }
  out.replace(out.size() - 2, 2, ")");  // the last part's ", "
  return out;
}

nlohmann::ordered_json ShapePolygonsGeoJson(const ShapeGeometry& shape, absl::Span<const Point2> points) {
  nlohmann::ordered_json polygons = nlohmann::ordered_json::array();
  for (const ShapePolygon& polygon : shape.polygons) {
    nlohmann::ordered_json rings = nlohmann::ordered_json::array({JsonRing(polygon.outer, points)});
    for (const auto& hole : polygon.holes) rings.push_back(JsonRing(hole, points));
    polygons.push_back(std::move(rings));
  }
  return {{"type", "MultiPolygon"}, {"coordinates", std::move(polygons)}};
}

std::string ShapeToGeoJson(const ShapeGeometry& shape, absl::Span<const Point2> points) {
  nlohmann::ordered_json features = nlohmann::ordered_json::array();
  if (!shape.polygons.empty()) {
    features.push_back({{"type", "Feature"},
                        {"properties", {{"kind", "polygons"}, {"area", shape.area}}},
                        {"geometry", ShapePolygonsGeoJson(shape, points)}});
  }
  if (!shape.singular_edges.empty()) {
    nlohmann::ordered_json lines = nlohmann::ordered_json::array();
    for (const auto& edge : shape.singular_edges) {
      lines.push_back(nlohmann::ordered_json::array({JsonPosition(points[edge[0]]), JsonPosition(points[edge[1]])}));
    }
    features.push_back(JsonFeature({{"kind", "singular_edges"}}, "MultiLineString", std::move(lines)));
  }
  if (!shape.isolated_points.empty()) {
    nlohmann::ordered_json positions = nlohmann::ordered_json::array();
    for (uint32_t v : shape.isolated_points) positions.push_back(JsonPosition(points[v]));
    features.push_back(JsonFeature({{"kind", "isolated_points"}}, "MultiPoint", std::move(positions)));
  }
  return JsonText({{"type", "FeatureCollection"}, {"features", std::move(features)}});
}

std::string ShapeToSvg(const ShapeGeometry& shape, absl::Span<const Point2> points, absl::string_view description) {
  double min_x = 0.0, max_x = 0.0, min_y = 0.0, max_y = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Point2& p = points[i];
    min_x = i == 0 ? p.x : std::min(min_x, p.x);
    max_x = i == 0 ? p.x : std::max(max_x, p.x);
    min_y = i == 0 ? p.y : std::min(min_y, p.y);
    max_y = i == 0 ? p.y : std::max(max_y, p.y);
  }
  // A degenerate box (one point, or points on a line) still gets a visible square around it.
  double extent = std::max(max_x - min_x, max_y - min_y);
  if (!(extent > 0.0)) extent = 1.0;
  const double margin = 0.05 * extent;
  // Sizes in user units, as fractions of the drawing (renderers differ on non-scaling strokes).
  const double radius = 0.004 * extent;
  // Local coordinates: x from the left edge, y from the top edge (SVG's y grows downwards).
  char buffer[64];
  auto local = [&](const Point2& p) {
    const int len = std::snprintf(buffer, sizeof buffer, "%.9g %.9g", p.x - min_x, max_y - p.y);
    return std::string(buffer, static_cast<size_t>(len));
  };
  auto number = [&](double value) {
    const int len = std::snprintf(buffer, sizeof buffer, "%.9g", value);
    return std::string(buffer, static_cast<size_t>(len));
  };
  const std::string stroke = number(0.0015 * extent);
  const std::string width = number(max_x - min_x + 2 * margin);
  const std::string height = number(max_y - min_y + 2 * margin);
  std::string out = absl::StrCat("<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"", number(-margin), " ",
                                 number(-margin), " ", width, " ", height, "\" width=\"800\" height=\"",
                                 number(800.0 * (max_y - min_y + 2 * margin) / (max_x - min_x + 2 * margin)),
                                 "\" preserveAspectRatio=\"xMidYMid meet\">\n");
  if (!description.empty()) {
    out += "<desc>";
    for (char c : description) {
      out += c == '&'   ? std::string("&amp;")
             : c == '<' ? std::string("&lt;")
             : c == '>' ? std::string("&gt;")
                        : std::string(1, c);
    }
    out += "</desc>\n";
  }
  absl::StrAppend(&out, "<g fill=\"#4a90d9\" fill-opacity=\"0.6\" stroke=\"#1f4e79\" stroke-width=\"", stroke,
                  "\" stroke-linejoin=\"round\" fill-rule=\"evenodd\">\n");
  auto append_ring = [&](const std::vector<uint32_t>& ring) {
    for (size_t i = 0; i < ring.size(); ++i) absl::StrAppend(&out, i == 0 ? "M" : " L", local(points[ring[i]]));
    out += " Z";
  };
  for (const ShapePolygon& polygon : shape.polygons) {
    out += "<path d=\"";
    append_ring(polygon.outer);
    for (const auto& hole : polygon.holes) {
      out += ' ';
      append_ring(hole);
    }
    out += "\"/>\n";
  }
  absl::StrAppend(&out, "</g>\n<g stroke=\"#c0392b\" stroke-width=\"", number(2 * radius / 3),
                  "\" stroke-linecap=\"round\">\n");
  for (const auto& edge : shape.singular_edges) {
    const Point2& a = points[edge[0]];
    const Point2& b = points[edge[1]];
    absl::StrAppend(&out, "<line x1=\"", number(a.x - min_x), "\" y1=\"", number(max_y - a.y), "\" x2=\"",
                    number(b.x - min_x), "\" y2=\"", number(max_y - b.y), "\"/>\n");
  }
  out += "</g>\n<g fill=\"#2c3e50\">\n";
  for (uint32_t v : shape.isolated_points) {
    absl::StrAppend(&out, "<circle cx=\"", number(points[v].x - min_x), "\" cy=\"", number(max_y - points[v].y),
                    "\" r=\"", number(radius), "\"/>\n");
  }
  out += "</g>\n</svg>\n";
  return out;
}

}  // namespace galpha
