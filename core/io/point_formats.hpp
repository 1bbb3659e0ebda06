// Point files in the formats users bring (docs/design.md, "Formats"), next to the raw `.bin` format
// of point_io.hpp: delimited text (CSV, TSV, whitespace), NumPy `.npy` arrays and GeoJSON (LAS in
// las_reader.hpp, GDAL vector sources in vector_points.hpp). Nothing is deduplicated or validated
// for finiteness here: the engine's validation layer does that, naming the point's index (its row
// among the data rows).
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/base/point.hpp"
#include "core/io/georeferenced_points.hpp"

namespace galpha {

/// Parses delimited text: one point per line, x and y the first two fields, fields separated by
/// the line's first comma, semicolon or tab (empty fields count), or else by runs of spaces. Empty
/// lines and lines starting with '#' are skipped. The first non-skipped line is a header when one
/// of its first two fields is not a number. Further fields are ignored. O(size).
///
/// Errors: InvalidArgument naming `source` and the 1-based line number of a line that has fewer
/// than two fields or whose x or y is not a number.
absl::StatusOr<std::vector<Point2>> ParsePointsText(absl::string_view text, const std::string& source);

/// Parses the bytes of a NumPy `.npy` file (format versions 1-3) holding a float64 array of shape
/// (N, 2), in C or Fortran order, either byte order. O(N).
///
/// Errors naming `source`: InvalidArgument for a missing magic string, a malformed header, another
/// dtype or shape; DataLoss when the data is shorter or longer than the header says.
absl::StatusOr<std::vector<Point2>> ParsePointsNpy(absl::string_view bytes, const std::string& source);

/// Parses GeoJSON (RFC 7946): a FeatureCollection, Feature, GeometryCollection, Point or
/// MultiPoint; points are taken in document order, the third coordinate (altitude) ignored, features
/// with a null geometry (unlocated) skipped. O(size).
///
/// Errors: InvalidArgument naming `source` and, for content, the place in the document (as
/// `features[3].geometry`): invalid JSON (with its byte offset), a geometry that is not a Point or
/// MultiPoint (other geometries are refused rather than skipped, so that no data is lost
/// silently), a position that is not an array of two or three numbers.
absl::StatusOr<std::vector<Point2>> ParsePointsGeoJson(absl::string_view text, const std::string& source);

/// ParsePointsGeoJson with the document's CRS: "OGC:CRS84" (RFC 7946: WGS84 longitude and
/// latitude, always), or the name of a 2008-style "crs" member ({"type": "name", "properties":
/// {"name": "urn:ogc:def:crs:EPSG::3857"}}, or {"type": "EPSG", "properties": {"code": 3857}}),
/// which GDAL still writes for other CRSs. InvalidArgument for a "crs" member of another form.
/// With a `group_property`, each point's group is its feature's property of that name (strings as
/// they are, other values as their JSON text; nullopt for null, a missing property or a bare
/// geometry); InvalidArgument when no feature has the property at all (a misspelt name).
absl::StatusOr<GeoreferencedPoints> ParseGeoreferencedGeoJson(absl::string_view text, const std::string& source,
                                                              const std::string& group_property = "");

/// ParsePointsText for weighted points: x, y and the weight are the first three fields of a record
/// (a header when one of them is not a number). Errors name the line, as ParsePointsText's.
absl::StatusOr<GeoreferencedPoints> ParseWeightedPointsText(absl::string_view text, const std::string& source);

/// ParsePointsNpy for weighted points: a float64 array of shape (N, 3), rows (x, y, weight).
absl::StatusOr<GeoreferencedPoints> ParseWeightedPointsNpy(absl::string_view bytes, const std::string& source);

/// ParseGeoreferencedGeoJson with a weight per point: the number in its feature's property
/// `weight_property` (a JSON number, or a string holding one; every point of a MultiPoint takes its
/// feature's). InvalidArgument names the first point (in document order) without one.
absl::StatusOr<GeoreferencedPoints> ParseWeightedGeoJson(absl::string_view text, const std::string& source,
                                                         const std::string& weight_property);

/// Reads a point file, choosing the format by extension: `.bin` (raw, point_io.hpp), `.npy`,
/// `.geojson` or `.json`, `.las` (las_reader.hpp), anything else as delimited text
/// except the formats refused by name: `.laz` (compressed LAS) and the GDAL vector sources of
/// vector_points.hpp (`.shp`, `.gpkg`, `.fgb`: InvalidArgument; ReadVectorPoints reads them). Errors
/// name the file: NotFound when it does not exist, the errno-derived code when it cannot be read, and
/// the parsers' errors above.
absl::StatusOr<std::vector<Point2>> ReadPointsFile(const std::string& path);

/// ReadPointsFile with the CRS the file states: a LAS file's (las_reader.hpp), a GeoJSON
/// document's (ParseGeoreferencedGeoJson); nullopt for the formats that state none.
absl::StatusOr<GeoreferencedPoints> ReadGeoreferencedPointsFile(const std::string& path);

/// Reads a weighted point file (GeoreferencedPoints::weights set, one per point, as stored: the
/// caller decides whether they are radii or squared radii): `.bin` with the weighted flag
/// (point_io.hpp), `.npy` (N, 3), GeoJSON with `weight_property` (required for GeoJSON and
/// refused for the others), anything else as delimited text (x, y, weight). LAS and GDAL sources
/// hold no weights: InvalidArgument. Errors name the file, as ReadPointsFile's.
absl::StatusOr<GeoreferencedPoints> ReadWeightedPointsFile(const std::string& path,
                                                           const std::string& weight_property = "");

}  // namespace galpha
