// vector_file_writer.hpp with GDAL's C++ API.
#include <memory>
#include <mutex>

#include "absl/strings/str_cat.h"
#include "cpl_error.h"
#include "gdal_priv.h"
#include "ogr_geometry.h"
#include "ogr_spatialref.h"
#include "ogrsf_frmts.h"
#include "tests/support/vector_file_writer.hpp"

namespace galpha::testing {
namespace {

absl::Status GdalError(const std::string& what) {
  return absl::InternalError(absl::StrCat(what, ": ", CPLGetLastErrorMsg()));
}

OGRwkbGeometryType LayerType(const VectorLayer& layer) {
  bool points = true, multipoints = true;
  for (const VectorFeature& f : layer.features) {
    points = points && f.geometry == VectorGeometry::kPoint;
    multipoints = multipoints && f.geometry == VectorGeometry::kMultiPoint;
  }
  if (points) return wkbPoint;
  return multipoints ? wkbMultiPoint : wkbUnknown;
}

std::unique_ptr<OGRGeometry> Geometry(const VectorFeature& feature) {
  switch (feature.geometry) {
    case VectorGeometry::kPoint: {
      if (feature.points.empty()) return std::make_unique<OGRPoint>();
      return std::make_unique<OGRPoint>(feature.points[0].x, feature.points[0].y);
    }
    case VectorGeometry::kMultiPoint: {
      auto multi = std::make_unique<OGRMultiPoint>();
      for (const Point2& p : feature.points) {
        OGRPoint point(p.x, p.y);
        multi->addGeometry(&point);
      }
      return multi;
    }
    case VectorGeometry::kLineString: {
      auto line = std::make_unique<OGRLineString>();
      for (const Point2& p : feature.points) line->addPoint(p.x, p.y);
      return line;
    }
    case VectorGeometry::kNone:
      break;
  }
  return nullptr;
}

}  // namespace

bool VectorWriterAvailable() { return true; }

absl::Status WriteVectorFile(const std::string& path, const std::string& driver_name,
                             const std::vector<VectorLayer>& layers) {
  static std::once_flag registered;
  std::call_once(registered, [] { GDALAllRegister(); });
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName(driver_name.c_str());
  if (driver == nullptr) return GdalError(absl::StrCat("no GDAL driver ", driver_name));
  CPLPushErrorHandler(CPLQuietErrorHandler);
  driver->Delete(path.c_str());  // a file of an earlier run, if any
  CPLPopErrorHandler();
  GDALDatasetUniquePtr dataset(driver->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  if (dataset == nullptr) return GdalError(absl::StrCat("cannot create ", path));
  for (const VectorLayer& spec : layers) {
    OGRSpatialReference srs;
    if (!spec.crs.empty()) {
      if (srs.SetFromUserInput(spec.crs.c_str()) != OGRERR_NONE) return GdalError(absl::StrCat("CRS ", spec.crs));
      srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    }
    OGRLayer* layer =
        dataset->CreateLayer(spec.name.c_str(), spec.crs.empty() ? nullptr : &srs, LayerType(spec), nullptr);
    if (layer == nullptr) return GdalError(absl::StrCat("cannot create layer ", spec.name));
    for (const VectorFeature& f : spec.features) {
      OGRFeatureUniquePtr feature(OGRFeature::CreateFeature(layer->GetLayerDefn()));
      if (std::unique_ptr<OGRGeometry> geometry = Geometry(f)) feature->SetGeometry(geometry.get());
      if (layer->CreateFeature(feature.get()) != OGRERR_NONE) return GdalError("cannot write a feature");
    }
  }
  // GDAL 3.6 has no Close() with a status: FlushCache, then the destructor writes the rest.
  CPLErrorReset();
  dataset->FlushCache(false);
  dataset.reset();
  if (CPLGetLastErrorType() >= CE_Failure) return GdalError(absl::StrCat("cannot finish ", path));
  return absl::OkStatus();
}

}  // namespace galpha::testing
