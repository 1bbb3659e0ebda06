// vector_points.hpp with GDAL (GALPHA_WITH_GDAL=ON): the C++ API of Debian's libgdal.
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "core/io/vector_points.hpp"
#include "cpl_error.h"
#include "gdal_priv.h"
#include "ogr_geometry.h"
#include "ogr_spatialref.h"
#include "ogrsf_frmts.h"

namespace galpha {
namespace {

// The GDAL driver of each extension: a file is opened only as what its name says.
const char* DriverOf(absl::string_view extension) {
  if (extension == ".shp") return "ESRI Shapefile";
  if (extension == ".gpkg") return "GPKG";
  if (extension == ".fgb") return "FlatGeobuf";
  return nullptr;
}

/// GDAL reports problems to a process-wide handler that prints them on stderr; while one of these
/// lives, this thread's are kept quiet instead (their text comes back in our statuses).
class QuietGdalErrors {
 public:
  QuietGdalErrors() {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  QuietGdalErrors(const QuietGdalErrors&) = delete;
  QuietGdalErrors& operator=(const QuietGdalErrors&) = delete;
  ~QuietGdalErrors() { CPLPopErrorHandler(); }

  /// ": GDAL says ..." when GDAL left a message, else "".
  static std::string Said() {
    const std::string message = CPLGetLastErrorMsg();
    return message.empty() ? std::string() : absl::StrCat(" (GDAL: ", message, ")");
  }
};

// "EPSG:32610" when GDAL knows the CRS's authority code, else its WKT2.
std::optional<std::string> CrsOf(OGRLayer& layer) {
  const OGRSpatialReference* srs = layer.GetSpatialRef();
  if (srs == nullptr) return std::nullopt;
  // A GeoPackage layer without a CRS references srs_id 0 or -1, the "undefined" geographic and
  // Cartesian entries its specification requires, which GDAL reports under these names.
  const char* name = srs->GetName();
  if (name != nullptr &&
      (absl::string_view(name) == "Undefined geographic SRS" || absl::string_view(name) == "Undefined Cartesian SRS")) {
    return std::nullopt;
  }
  const char* authority = srs->GetAuthorityName(nullptr);
  const char* code = srs->GetAuthorityCode(nullptr);
  if (authority != nullptr && code != nullptr) return absl::StrCat(authority, ":", code);
  char* wkt = nullptr;
  const char* const options[] = {"FORMAT=WKT2", nullptr};
  std::optional<std::string> crs;
  if (srs->exportToWkt(&wkt, options) == OGRERR_NONE && wkt != nullptr && *wkt != '\0') crs = std::string(wkt);
  CPLFree(wkt);
  return crs;
}

std::string LayerNames(GDALDataset& dataset) {
  std::string names;
  for (OGRLayer* layer : dataset.GetLayers())
    absl::StrAppend(&names, names.empty() ? "'" : ", '", layer->GetName(), "'");
  return names;
}

}  // namespace

bool VectorPointsAvailable() { return true; }

absl::StatusOr<GeoreferencedPoints> ReadVectorPoints(const std::string& path, const std::string& layer_name,
                                                     uint64_t max_points, const std::string& group_field) {
  static std::once_flag registered;
  std::call_once(registered, [] { GDALAllRegister(); });
  const std::string named = absl::StrCat("points file '", path, "'");
  const std::string extension = absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  const char* driver = DriverOf(extension);
  if (driver == nullptr) {
    return absl::InvalidArgumentError(absl::StrCat(named,
                                                   ": not a Shapefile, GeoPackage or FlatGeobuf file (.shp, "
                                                   ".gpkg, .fgb)"));
  }

  QuietGdalErrors quiet;
  const char* const drivers[] = {driver, nullptr};
  GDALDatasetUniquePtr dataset(
      GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, drivers, nullptr, nullptr));
  if (dataset == nullptr) {
    return absl::InvalidArgumentError(absl::StrCat("cannot open ", named, " as ", driver, QuietGdalErrors::Said()));
  }
  OGRLayer* layer = nullptr;
  if (layer_name.empty()) {
    if (dataset->GetLayerCount() == 0) return absl::InvalidArgumentError(absl::StrCat(named, " has no layers"));
    layer = dataset->GetLayer(0);
  } else {
    layer = dataset->GetLayerByName(layer_name.c_str());
    if (layer == nullptr) {
      return absl::InvalidArgumentError(
          absl::StrCat(named, " has no layer '", layer_name, "' (its layers: ", LayerNames(*dataset), ")"));
    }
  }
  const std::string source = absl::StrCat(named, ", layer '", layer->GetName(), "'");

  int group_index = -1;
  if (!group_field.empty()) {
    const OGRFeatureDefn* definition = layer->GetLayerDefn();
    group_index = definition->GetFieldIndex(group_field.c_str());
    if (group_index < 0) {
      std::string fields;
      for (int i = 0; i < definition->GetFieldCount(); ++i) {
        absl::StrAppend(&fields, i ? ", " : "", definition->GetFieldDefn(i)->GetNameRef());
      }
      return absl::InvalidArgumentError(absl::StrCat(source, " has no field '", group_field,
                                                     "' (its fields: ", fields.empty() ? "none" : fields, ")"));
    }
  }
  GeoreferencedPoints out;
  out.crs = CrsOf(*layer);
  std::optional<std::string> group;  // the current feature's
  const auto take = [&](const OGRPoint& point) -> absl::Status {
    if (point.IsEmpty()) return absl::OkStatus();
    if (out.points.size() == max_points) {
      return absl::ResourceExhaustedError(absl::StrCat(source, ": more than ", max_points, " points, the limit"));
    }
    out.points.push_back({point.getX(), point.getY()});
    if (group_index >= 0) out.groups.push_back(group);
    return absl::OkStatus();
  };
  layer->ResetReading();
  CPLErrorReset();  // what opening said is not a read error
  for (OGRFeatureUniquePtr feature(layer->GetNextFeature()); feature != nullptr;
       feature.reset(layer->GetNextFeature())) {
    const OGRGeometry* geometry = feature->GetGeometryRef();
    if (geometry == nullptr) continue;  // unlocated
    if (group_index >= 0) {
      group = feature->IsFieldSetAndNotNull(group_index)
                  ? std::optional<std::string>(feature->GetFieldAsString(group_index))
                  : std::nullopt;
    }
    const OGRwkbGeometryType type = wkbFlatten(geometry->getGeometryType());
    if (type == wkbPoint) {
      if (absl::Status s = take(*geometry->toPoint()); !s.ok()) return s;
    } else if (type == wkbMultiPoint) {
      for (const OGRPoint* point : *geometry->toMultiPoint()) {
        if (absl::Status s = take(*point); !s.ok()) return s;
      }
    } else {
      return absl::InvalidArgumentError(absl::StrCat(source, ": feature ", feature->GetFID(), " is a ",
                                                     OGRGeometryTypeToName(geometry->getGeometryType()),
                                                     "; only points and multipoints are read"));
    }
  }
  if (CPLGetLastErrorType() >= CE_Failure) {
    return absl::DataLossError(absl::StrCat("cannot read ", source, QuietGdalErrors::Said()));
  }
  return out;
}

}  // namespace galpha
