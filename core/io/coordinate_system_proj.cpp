#include <proj.h>
#include <proj_experimental.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.hpp"
#include "core/io/coordinate_system.hpp"
#include "core/io/number_text.hpp"

namespace galpha {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;

struct ContextDeleter {
  void operator()(PJ_CONTEXT* context) const { proj_context_destroy(context); }
};
struct PjDeleter {
  void operator()(PJ* object) const { proj_destroy(object); }
};
using Context = std::unique_ptr<PJ_CONTEXT, ContextDeleter>;
using Pj = std::unique_ptr<PJ, PjDeleter>;

/// One context per call: PROJ objects are not shared between threads, and calls are rare (one a
/// build) next to the transformations they run.
Context NewContext() {
  Context context(proj_context_create());
  proj_log_level(context.get(), PJ_LOG_NONE);  // errors come back as statuses, not on stderr
  return context;
}

std::string LastError(PJ_CONTEXT* context) {
  const int code = proj_context_errno(context);
  return code == 0 ? std::string("no reason given") : std::string(proj_context_errno_string(context, code));
}

/// The definition as a message quotes it: WKT can run to kilobytes.
std::string Quoted(absl::string_view definition) {
  constexpr size_t kShown = 80;
  if (definition.size() <= kShown) return absl::StrCat("'", definition, "'");
  return absl::StrCat("'", definition.substr(0, kShown), "...'");
}

const char* TypeName(PJ_TYPE type) {
  switch (type) {
    case PJ_TYPE_GEOCENTRIC_CRS:
      return "a geocentric CRS (x, y, z from the Earth's centre)";
    case PJ_TYPE_VERTICAL_CRS:
      return "a vertical CRS (heights)";
    case PJ_TYPE_TEMPORAL_CRS:
      return "a temporal CRS";
    default:
      return "not a horizontal CRS";
  }
}

struct Horizontal {
  Pj crs;
  bool geographic = false;
};

/// The horizontal CRS of `definition`, as a 2D CRS.
absl::StatusOr<Horizontal> HorizontalCrs(PJ_CONTEXT* context, absl::string_view definition) {
  Pj object(proj_create(context, std::string(definition).c_str()));
  if (!object) {
    return absl::InvalidArgumentError(
        absl::StrCat("CRS ", Quoted(definition), " is not understood by PROJ: ", LastError(context)));
  }
  if (proj_is_crs(object.get()) == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(Quoted(definition), " is not a CRS (PROJ reads it as a coordinate operation)"));
  }
  // A bound CRS (a CRS with its transformation to WGS84) stands for its source; a compound CRS
  // (horizontal + vertical, as LAS files state them) for its horizontal part.
  for (int unwrap = 0; unwrap < 4; ++unwrap) {
    const PJ_TYPE type = proj_get_type(object.get());
    if (type == PJ_TYPE_BOUND_CRS) {
      object.reset(proj_get_source_crs(context, object.get()));
    } else if (type == PJ_TYPE_COMPOUND_CRS) {
      object.reset(proj_crs_get_sub_crs(context, object.get(), 0));
    } else {
      break;
    }
    if (!object) return absl::InvalidArgumentError(absl::StrCat("CRS ", Quoted(definition), " has no horizontal part"));
  }
  Horizontal out;
  switch (proj_get_type(object.get())) {
    case PJ_TYPE_GEOGRAPHIC_3D_CRS:
      object.reset(proj_crs_demote_to_2D(context, nullptr, object.get()));
      if (!object) {
        return absl::InvalidArgumentError(
            absl::StrCat("CRS ", Quoted(definition), " cannot be taken in 2D: ", LastError(context)));
      }
      out.geographic = true;
      break;
    case PJ_TYPE_GEOGRAPHIC_2D_CRS:
      out.geographic = true;
      break;
    case PJ_TYPE_PROJECTED_CRS:
    case PJ_TYPE_ENGINEERING_CRS:
      break;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("CRS ", Quoted(definition), " is ", TypeName(proj_get_type(object.get())),
                       ": galpha needs a geographic (longitude/latitude) or a projected CRS"));
  }
  out.crs = std::move(object);
  return out;
}

/// Radians per unit of the CRS's first axis (degrees: pi / 180).
double AngularUnit(PJ_CONTEXT* context, const PJ* crs) {
  Pj system(proj_crs_get_coordinate_system(context, crs));
  double radians_per_unit = kDegree;
  if (system) {
    proj_cs_get_axis_info(context, system.get(), 0, nullptr, nullptr, nullptr, &radians_per_unit, nullptr, nullptr,
                          nullptr);
  }
  return radians_per_unit > 0 ? radians_per_unit : kDegree;
}

/// Runs `operation` (normalized to x = longitude/easting first) over the non-empty `points` in place.
/// InvalidArgument naming the first point that did not transform.
absl::Status Transform(PJ_CONTEXT* context, PJ* operation, std::vector<Point2>* points, absl::string_view what) {
  Pj normalized(proj_normalize_for_visualization(context, operation));
  if (!normalized) return absl::InternalError(absl::StrCat(what, ": PROJ cannot order the axes: ", LastError(context)));
  const std::vector<Point2> input = *points;  // for the message of a point that fails
  proj_trans_generic(normalized.get(), PJ_FWD, &(*points)[0].x, sizeof(Point2), points->size(), &(*points)[0].y,
                     sizeof(Point2), points->size(), nullptr, 0, 0, nullptr, 0, 0);
  for (size_t i = 0; i < points->size(); ++i) {
    const Point2& p = (*points)[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      return absl::InvalidArgumentError(absl::StrCat(what, ": point ", i, " (", ShortestDouble(input[i].x), ", ",
                                                     ShortestDouble(input[i].y), ") cannot be transformed by PROJ"));
    }
  }
  return absl::OkStatus();
}

/// The centre of a set of longitudes (degrees): the middle of the shortest arc that holds them
/// all, and that arc's length.
std::pair<double, double> LongitudeCentre(std::vector<double> longitudes) {
  for (double& lon : longitudes) lon -= 360.0 * std::floor((lon + 180.0) / 360.0);  // to [-180, 180)
  std::sort(longitudes.begin(), longitudes.end());
  // The largest gap between neighbours on the circle: the arc is its complement.
  double gap = longitudes.front() + 360.0 - longitudes.back();
  double start = longitudes.front();
  for (size_t i = 1; i < longitudes.size(); ++i) {
    if (longitudes[i] - longitudes[i - 1] > gap) {
      gap = longitudes[i] - longitudes[i - 1];
      start = longitudes[i];
    }
  }
  const double arc = 360.0 - gap;
  double centre = start + arc / 2;
  centre -= 360.0 * std::floor((centre + 180.0) / 360.0);
  return {centre, arc};
}

/// Angular distance in degrees between two points of the sphere (haversine: stable for small ones).
double AngularDistance(double lat1, double lon1, double lat2, double lon2) {
  const double dlat = (lat2 - lat1) * kDegree, dlon = (lon2 - lon1) * kDegree;
  const double h = std::sin(dlat / 2) * std::sin(dlat / 2) +
                   std::cos(lat1 * kDegree) * std::cos(lat2 * kDegree) * std::sin(dlon / 2) * std::sin(dlon / 2);
  return 2 * std::asin(std::min(1.0, std::sqrt(h))) / kDegree;
}

}  // namespace

absl::StatusOr<CrsInfo> DescribeCrs(absl::string_view definition) {
  Context context = NewContext();
  GALPHA_ASSIGN_OR_RETURN(Horizontal horizontal, HorizontalCrs(context.get(), definition));
  CrsInfo info;
  info.definition = std::string(definition);
  const char* name = proj_get_name(horizontal.crs.get());
  info.name = name != nullptr ? name : "";
  const char* authority = proj_get_id_auth_name(horizontal.crs.get(), 0);
  const char* code = proj_get_id_code(horizontal.crs.get(), 0);
  if (authority != nullptr && code != nullptr) info.id = absl::StrCat(authority, ":", code);
  info.geographic = horizontal.geographic;
  return info;
}

absl::StatusOr<LocalMetres> ProjectToLocalMetres(const CrsInfo& crs, absl::Span<const Point2> points) {
  Context context = NewContext();
  PJ_CONTEXT* ctx = context.get();
  GALPHA_ASSIGN_OR_RETURN(Horizontal horizontal, HorizontalCrs(ctx, crs.definition));
  if (!horizontal.geographic) {
    return absl::InvalidArgumentError(absl::StrCat("CRS '", crs.name, "' is not geographic: it is used as it is"));
  }
  LocalMetres out;
  if (points.empty()) return out;
  // Degrees of every point (the CRS may count in grads or radians), checked as angles.
  const double to_degrees = AngularUnit(ctx, horizontal.crs.get()) / kDegree;
  const std::string hint = absl::StrCat(" (x is longitude and y latitude in CRS '", crs.name,
                                        "'; if the coordinates are in another CRS, name it with --crs, or give "
                                        "--crs none for planar coordinates)");
  std::vector<double> longitudes(points.size());
  double lat_min = 90, lat_max = -90;
  for (size_t i = 0; i < points.size(); ++i) {
    const double lon = points[i].x * to_degrees, lat = points[i].y * to_degrees;
    if (!std::isfinite(lon) || !std::isfinite(lat) || std::abs(lat) > 90.0 + 1e-9 || std::abs(lon) > 540.0) {
      return absl::InvalidArgumentError(absl::StrCat("point ", i, " (", ShortestDouble(points[i].x), ", ",
                                                     ShortestDouble(points[i].y), ") is not a longitude and latitude",
                                                     hint));
    }
    longitudes[i] = lon;
    lat_min = std::min(lat_min, lat);
    lat_max = std::max(lat_max, lat);
  }
  auto [lon0, arc] = LongitudeCentre(longitudes);
  double lat0 = (lat_min + lat_max) / 2;
  if (arc > 180.0) {
    // Around a pole: all on one side of the equator, centred on the pole; otherwise too wide.
    if (lat_min > 0 || lat_max < 0) {
      lat0 = lat_min > 0 ? 90.0 : -90.0;
      lon0 = 0.0;
    } else {
      return absl::InvalidArgumentError(absl::StrCat(
          "the set spans ", arc,
          " degrees of longitude and both hemispheres: galpha computes a geographic set in "
          "one azimuthal equidistant projection about its centre, which holds at most a hemisphere; split the set, "
          "or give it in a projected CRS"));
    }
  }
  for (size_t i = 0; i < points.size(); ++i) {
    out.radius_degrees =
        std::max(out.radius_degrees, AngularDistance(lat0, lon0, points[i].y * to_degrees, points[i].x * to_degrees));
  }
  if (out.radius_degrees > 90.0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the set reaches ", out.radius_degrees, " degrees from its centre (", lat0, ", ", lon0,
        "): galpha computes a geographic set in one azimuthal equidistant projection about its centre, which holds "
        "at most 90 degrees; split the set, or give it in a projected CRS"));
  }
  Pj conversion(
      proj_create_conversion_azimuthal_equidistant(ctx, lat0, lon0, 0.0, 0.0, "Degree", kDegree, "metre", 1.0));
  Pj system(proj_create_cartesian_2D_cs(ctx, PJ_CART2D_EASTING_NORTHING, "metre", 1.0));
  Pj local(conversion && system ? proj_create_projected_crs(ctx, "galpha local azimuthal equidistant",
                                                            horizontal.crs.get(), conversion.get(), system.get())
                                : nullptr);
  Pj operation(local ? proj_create_crs_to_crs_from_pj(ctx, horizontal.crs.get(), local.get(), nullptr, nullptr)
                     : nullptr);
  if (!operation) {
    return absl::InternalError(
        absl::StrCat("PROJ cannot make the local projection of CRS '", crs.name, "': ", LastError(ctx)));
  }
  out.points.assign(points.begin(), points.end());
  GALPHA_RETURN_IF_ERROR(Transform(ctx, operation.get(), &out.points, "the local projection"));
  const char* text = proj_as_proj_string(ctx, local.get(), PJ_PROJ_5, nullptr);
  out.projection = text != nullptr ? text : "";
  return out;
}

absl::StatusOr<std::vector<Point2>> ToWgs84LonLat(const CrsInfo& crs, absl::Span<const Point2> points) {
  Context context = NewContext();
  PJ_CONTEXT* ctx = context.get();
  GALPHA_ASSIGN_OR_RETURN(Horizontal horizontal, HorizontalCrs(ctx, crs.definition));
  Pj wgs84(proj_create(ctx, "OGC:CRS84"));
  if (!wgs84) return absl::InternalError(absl::StrCat("PROJ does not know OGC:CRS84: ", LastError(ctx)));
  std::vector<Point2> out(points.begin(), points.end());
  if (proj_is_equivalent_to_with_ctx(ctx, horizontal.crs.get(), wgs84.get(),
                                     PJ_COMP_EQUIVALENT_EXCEPT_AXIS_ORDER_GEOGCRS) != 0) {
    return out;  // already WGS84 longitude/latitude: the input doubles, unchanged
  }
  Pj operation(proj_create_crs_to_crs_from_pj(ctx, horizontal.crs.get(), wgs84.get(), nullptr, nullptr));
  if (!operation) {
    return absl::InvalidArgumentError(
        absl::StrCat("PROJ has no transformation from CRS '", crs.name, "' to WGS84: ", LastError(ctx)));
  }
  if (!out.empty()) GALPHA_RETURN_IF_ERROR(Transform(ctx, operation.get(), &out, "the transformation to WGS84"));
  return out;
}

}  // namespace galpha
