// GDAL vector sources (GeoPackage, Shapefile, FlatGeobuf) written with GDAL's own API from known
// points, for the tests of the GDAL point reader (core/io/vector_points.hpp) and of alphactl. In a
// build without GDAL (GALPHA_WITH_GDAL=OFF) the writer is there too and refuses, so that the tests
// compile either way and skip.
#pragma once

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/base/point.hpp"

namespace galpha::testing {

/// Whether WriteVectorFile can write (the build has GDAL).
bool VectorWriterAvailable();

enum class VectorGeometry { kPoint, kMultiPoint, kLineString, kNone };

struct VectorFeature {
  VectorGeometry geometry = VectorGeometry::kPoint;
  std::vector<Point2> points;  // one for kPoint (none: POINT EMPTY), any for the others
};

struct VectorLayer {
  std::string name;
  std::vector<VectorFeature> features;
  /// "EPSG:32610", a PROJ string, or empty for no CRS.
  std::string crs;
};

/// Writes `layers` to `path` (replacing it) with GDAL driver `driver` ("GPKG", "ESRI Shapefile",
/// "FlatGeobuf"); a layer whose features are all points is a point layer, all multipoints a
/// multipoint layer, else of unknown (mixed) geometry type. Unimplemented without GDAL; GDAL's
/// message for its failures.
absl::Status WriteVectorFile(const std::string& path, const std::string& driver,
                             const std::vector<VectorLayer>& layers);

}  // namespace galpha::testing
