// vector_points.hpp in a build without GDAL (GALPHA_WITH_GDAL=OFF): every file is refused.
#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/io/vector_points.hpp"

namespace galpha {

bool VectorPointsAvailable() { return false; }

absl::StatusOr<GeoreferencedPoints> ReadVectorPoints(const std::string& path, const std::string& /*layer*/,
                                                     uint64_t /*max_points*/, const std::string& /*group_field*/) {
  return absl::InvalidArgumentError(
      absl::StrCat("points file '", path,
                   "': this build has no GDAL, which Shapefiles, GeoPackages and FlatGeobuf files are read with "
                   "(rebuild with libgdal-dev installed and -DGALPHA_WITH_GDAL=ON)"));
}

}  // namespace galpha
