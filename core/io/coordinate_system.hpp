// Coordinate reference systems of point sets, through PROJ: what a CRS is (geographic or planar),
// the local metric projection a geographic set is computed in, and longitude/latitude on WGS84 for
// GeoJSON (RFC 7946). Semantics: docs/design.md, "Coordinate reference systems".
//
// Coordinates are always taken in the traditional GIS order, x = longitude or easting and
// y = latitude or northing, whatever axis order the CRS's definition states (EPSG:4326 states
// latitude first; files and users give longitude first).
//
// Without GALPHA_WITH_PROJ every function refuses (FailedPrecondition, naming the build option).
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"

namespace galpha {

/// A CRS as PROJ understands it.
struct CrsInfo {
  /// As given (by a file or a user): "EPSG:4326", OGC WKT, a PROJ string, PROJJSON.
  std::string definition;
  /// PROJ's name of its horizontal part: "WGS 84", "NAD83 / UTM zone 10N".
  std::string name;
  /// "AUTHORITY:CODE" where PROJ knows one ("EPSG:32610"), else empty.
  std::string id;
  /// Longitude and latitude (angles): the set is projected for the computation. Otherwise the
  /// CRS is planar (projected or engineering) and the coordinates are used as they are.
  bool geographic = false;
};

/// "coordinates in CRS NAME (ID)", as an SVG's <desc> names the CRS of its coordinates.
inline std::string CoordinatesLabel(const CrsInfo& crs) {
  return crs.id.empty() ? "coordinates in CRS " + crs.name : "coordinates in CRS " + crs.name + " (" + crs.id + ")";
}

/// The horizontal CRS of `definition` (a compound CRS's first part, a bound CRS's source).
/// InvalidArgument when PROJ does not read it as a CRS, or when it has no horizontal part that is
/// geographic or planar (geocentric, vertical, temporal).
absl::StatusOr<CrsInfo> DescribeCrs(absl::string_view definition);

/// A geographic set's coordinates for the computation.
struct LocalMetres {
  /// Easting and northing in metres of `projection`, point for point.
  std::vector<Point2> points;
  /// The local projection, as a PROJ string: an azimuthal equidistant projection on the CRS's own
  /// ellipsoid, centred on the set (the middle of its latitude range and of the shortest
  /// longitude arc that holds it, across the antimeridian where that is shorter; a pole for a set
  /// around one).
  std::string projection;
  /// The largest angular distance of a point from the centre, in degrees: the projection's scale
  /// error across the set is below 1 / cos of it (about 0.5% at 10 degrees).
  double radius_degrees = 0.0;
};

/// Projects the points of geographic `crs` (x longitude, y latitude, in its angular unit) to
/// LocalMetres. InvalidArgument naming the point for a latitude outside -90..90, a longitude
/// outside -540..540 or a non-finite coordinate (with a hint: the CRS may be wrong), and for a
/// set that does not fit in one hemisphere about its centre (more than 90 degrees from it).
absl::StatusOr<LocalMetres> ProjectToLocalMetres(const CrsInfo& crs, absl::Span<const Point2> points);

/// The points of `crs` as longitude and latitude in degrees on WGS84 (OGC:CRS84), GeoJSON's only
/// CRS. Points already in WGS84 longitude/latitude (EPSG:4326, OGC:CRS84) are returned unchanged,
/// bit for bit. InvalidArgument naming the first point PROJ cannot transform.
absl::StatusOr<std::vector<Point2>> ToWgs84LonLat(const CrsInfo& crs, absl::Span<const Point2> points);

}  // namespace galpha
