// The alpha shape as geometry (docs/design.md, "Semantics"): the complex at one threshold turned
// into polygons, line strings and points that GEOS, PostGIS and GeoJSON readers accept as valid,
// and the writers for WKT, GeoJSON (RFC 7946) and SVG.
//
// Polygons are assembled topologically. The triangles are grouped into pieces connected through
// shared edges (the interior of each piece is connected, and different pieces' interiors are
// disjoint, so each piece is exactly one OGC polygon). Each piece's boundary is traced on its own:
// at a vertex where the piece's boundary passes more than once, the walk arriving along u->v
// leaves along the piece's first outgoing boundary edge counter-clockwise from v->u (the exact
// Orient2dSign decides), so a ring hugs one region of the piece's complement. Within one piece a
// complement region meets a vertex at most once (a path through the piece joining the two sides
// would separate them), so every ring is simple; the unbounded region gives the one
// counter-clockwise outer ring, each bounded region a clockwise hole, so a piece never yields two
// outer rings (if it did, the triangles would overlap, and AssembleShape reports that rather than
// guess). Holes belong to their piece by construction: no point-in-polygon test. Rings may touch
// other rings at vertices, which OGC allows; no ring touches itself. Pieces inside another piece's
// hole are polygons of their own.
//
// Cost: the triangles' sides are sorted by undirected edge (a parallel sort), so that an edge's two
// sides are neighbours and one scan finds the pieces and the boundary; the orientation checks and
// the areas run on every core. O(n log n), about a second for the 2M triangles of a 1M-point shape
// on 2 cores (it was 10 s with a binary search for each side's twin).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"
#include "nlohmann/json.hpp"

namespace galpha {

/// What the alpha complex holds at one threshold, by input indices. The triangles are a subset of
/// one triangulation's (Delaunay's, as the engine builds it): they never overlap.
struct ShapeComplex {
  /// All input points; the indices below name them.
  absl::Span<const Point2> points;
  /// Counter-clockwise triangles in the complex.
  std::vector<std::array<uint32_t, 3>> triangles;
  /// Edges in the complex with no triangle in it, in either direction.
  std::vector<std::array<uint32_t, 2>> singular_edges;
  /// Vertices in the complex with no edge in it.
  std::vector<uint32_t> isolated_points;
};

/// One polygon: a counter-clockwise outer ring and clockwise holes, vertex indices, each ring
/// simple and not closed (the first vertex is not repeated at the end). Each ring starts at its
/// smallest vertex index; holes are sorted lexicographically.
struct ShapePolygon {
  std::vector<uint32_t> outer;
  std::vector<std::vector<uint32_t>> holes;
};

/// The alpha shape as valid OGC geometry, by input indices.
struct ShapeGeometry {
  /// One polygon per edge-connected piece of triangles, sorted lexicographically by outer ring.
  std::vector<ShapePolygon> polygons;
  /// Singular edges as (smaller index, larger index), sorted, without repeats.
  std::vector<std::array<uint32_t, 2>> singular_edges;
  /// Isolated points, sorted, without repeats.
  std::vector<uint32_t> isolated_points;
  /// Total area of the triangles (sum of the triangle areas, in doubles), in squared input units.
  double area = 0.0;
};

/// Assembles the polygons of `complex`'s triangles and copies its singular edges and isolated
/// points in canonical order. O(n log n) for n triangles.
///
/// Errors: InvalidArgument naming the item and index for an index >= points.size(), a triangle
/// that is not strictly counter-clockwise (exact orientation), a singular edge with equal end
/// points, and triangles that overlap (a directed edge in two triangles, or a boundary that does
/// not close into simple rings) — none of which a subset of one triangulation has.
absl::StatusOr<ShapeGeometry> AssembleShape(const ShapeComplex& complex);

/// One side of a shape's boundary: an edge of a complex triangle whose other side is not in the
/// complex, directed as that triangle runs along it (counter-clockwise), and its piece: any label
/// shared by exactly the triangles of one edge-connected piece.
struct ShapeBoundarySide {
  uint32_t from;
  uint32_t to;
  uint32_t piece;
};

/// The second half of AssembleShape, for callers that found the boundary elsewhere (a resident
/// family finds it where its tables live: gpu/alpha/resident_family.hpp): the rings traced from
/// `boundary` (any order), grouped into polygons by piece, with `area` (AssembleShape's: the
/// complex's triangle areas added in triangle order), and the singular edges and isolated points in
/// canonical order. The same ShapeGeometry as AssembleShape of the same complex; its overlap errors
/// as well.
absl::StatusOr<ShapeGeometry> ShapeFromBoundary(absl::Span<const Point2> points,
                                                std::vector<ShapeBoundarySide> boundary, double area,
                                                absl::Span<const std::array<uint32_t, 2>> singular_edges,
                                                absl::Span<const uint32_t> isolated_points);

// The writers print coordinates as their shortest decimal that reads back as the same double
// (core/io/number_text.hpp: "0.1", not %.17g's "0.10000000000000001"). They require every index of
// `shape` to be < points.size() (true of AssembleShape's result for the same points).

/// GeoJSON (RFC 7946): a FeatureCollection with up to three features, each present only when not
/// empty: a MultiPolygon (property "kind": "polygons", and "area"; rings closed, outer rings
/// counter-clockwise, holes clockwise, as RFC 7946 section 3.1.6 asks), a MultiLineString
/// ("singular_edges") and a MultiPoint ("isolated_points"). An empty shape gives an empty
/// FeatureCollection. Compact JSON written from an nlohmann-json document (core/io/json_text.hpp);
/// keys in the order named here ("type", "properties", "geometry"; "type", "coordinates").
std::string ShapeToGeoJson(const ShapeGeometry& shape, absl::Span<const Point2> points);

/// The shape's polygons as one GeoJSON MultiPolygon geometry (as ShapeToGeoJson writes it; empty
/// coordinates for a shape without polygons), for callers that put it in features of their own.
nlohmann::ordered_json ShapePolygonsGeoJson(const ShapeGeometry& shape, absl::Span<const Point2> points);

/// OGC WKT, the simplest type that holds the shape, so that a reader (GEOS, shapely, PostGIS) gets
/// a polygon where the shape is one:
/// - only polygons (always so in REGULARIZED mode, and in GENERAL mode without singular edges or
///   isolated points): `POLYGON ((...), ...)` for one polygon, `MULTIPOLYGON (((...)), ...)` for
///   several, `MULTIPOLYGON EMPTY` for none (the empty shape of either mode);
/// - with singular edges or isolated points (GENERAL mode only):
///   `GEOMETRYCOLLECTION (MULTIPOLYGON (...), MULTILINESTRING (...), MULTIPOINT (...))`, always in
///   that order and with the empty parts left out; the polygons stay a MULTIPOLYGON there, even
///   one, so that each part of the collection has one type.
/// Rings are closed (the first vertex repeated), outer rings counter-clockwise, holes clockwise.
std::string ShapeToWkt(const ShapeGeometry& shape, absl::Span<const Point2> points);

/// A standalone SVG document for a browser: the viewBox fits all of `points` (not only the shape's,
/// so that shapes of one point set at different alphas line up), y points up (north up), each
/// polygon is one path with fill-rule evenodd, singular edges are lines, isolated points small
/// circles. Coordinates are written relative to the points' bounding box, so that large offsets
/// keep their detail in a browser's single-precision renderer. A non-empty `description` (the
/// coordinates' CRS, for one) becomes the document's <desc>, XML-escaped.
std::string ShapeToSvg(const ShapeGeometry& shape, absl::Span<const Point2> points, absl::string_view description = {});

}  // namespace galpha
