// Point layers of GDAL vector sources: ESRI Shapefiles (.shp), GeoPackages (.gpkg) and FlatGeobuf
// (.fgb), read through GDAL's C++ API. GDAL is optional (GALPHA_WITH_GDAL): a build without it
// has the same functions, which refuse every file saying so. Its own library, galpha_vector_io,
// so that only what reads these files (alphactl) links GDAL.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/georeferenced_points.hpp"

namespace galpha {

/// Whether this build reads vector sources (it was built with GDAL).
bool VectorPointsAvailable();

/// Whether `extension` (lower case, with its dot: ".gpkg") names a format ReadVectorPoints reads
/// (in a build with GDAL; without, it refuses them by name).
inline bool IsVectorPointsExtension(absl::string_view extension) {
  return extension == ".shp" || extension == ".gpkg" || extension == ".fgb";
}

/// Reads the points of layer `layer` (empty: the first layer) of the vector source at `path`, the
/// format chosen by its extension (IsVectorPointsExtension): each feature's Point, or each point of
/// its MultiPoint, in the layer's feature order; features without a geometry, or with an empty one,
/// are skipped (unlocated); Z and M are ignored. `crs` is the layer's CRS as "AUTHORITY:CODE" when
/// GDAL knows its code, else its WKT (WKT2), nullopt when it has none. O(features).
///
/// Errors name the file: InvalidArgument when this build has no GDAL, when GDAL cannot open the
/// file as its extension's format (GDAL's message attached), when the source has no layers or no
/// layer `layer` (the layers are listed), or for a feature of another geometry type (its FID and
/// type named: other geometries are refused rather than skipped, so that no data is lost
/// silently); ResourceExhausted as soon as more than `max_points` points have been read. With a
/// `group_field`, each point's group is its feature's value of that field as text (nullopt where
/// it is null or unset); InvalidArgument, listing the fields, when the layer has no such field.
absl::StatusOr<GeoreferencedPoints> ReadVectorPoints(const std::string& path, const std::string& layer = "",
                                                     uint64_t max_points = std::numeric_limits<uint64_t>::max(),
                                                     const std::string& group_field = "");

}  // namespace galpha
