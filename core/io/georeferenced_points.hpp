// Points read from a file that may state their coordinate reference system (LAS point clouds,
// GDAL vector sources): the points, and the CRS carried along as the file states it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/base/point.hpp"

namespace galpha {

/// The points of a georeferenced file and its CRS.
struct GeoreferencedPoints {
  /// In file order, x and y as stored (no reprojection, no axis swap).
  std::vector<Point2> points;
  /// The CRS as the file states it: OGC WKT, or "AUTHORITY:CODE" (as "EPSG:32610") where the
  /// reader knows the code; nullopt when the file states none. Carried, not interpreted.
  std::optional<std::string> crs;
  /// When a group column was asked for (alphactl --group-by): each point's value of it as text,
  /// point for point (nullopt where its feature has none or null); empty otherwise.
  std::vector<std::optional<std::string>> groups;
  /// Weighted input (ReadWeightedPointsFile and the weighted parsers): each point's weight as
  /// stored, point for point; empty otherwise.
  std::vector<double> weights;
};

}  // namespace galpha
