// Built without PROJ (GALPHA_WITH_PROJ=OFF): every CRS operation refuses, naming the option.
#include "core/io/coordinate_system.hpp"

namespace galpha {

namespace {

absl::Status NoProj() {
  return absl::FailedPreconditionError(
      "this build has no PROJ (GALPHA_WITH_PROJ=OFF): coordinate reference systems cannot be read; give --crs none "
      "to use the coordinates as planar ones");
}

}  // namespace

absl::StatusOr<CrsInfo> DescribeCrs(absl::string_view /*definition*/) { return NoProj(); }

absl::StatusOr<LocalMetres> ProjectToLocalMetres(const CrsInfo& /*crs*/, absl::Span<const Point2> /*points*/) {
  return NoProj();
}

absl::StatusOr<std::vector<Point2>> ToWgs84LonLat(const CrsInfo& /*crs*/, absl::Span<const Point2> /*points*/) {
  return NoProj();
}

}  // namespace galpha
