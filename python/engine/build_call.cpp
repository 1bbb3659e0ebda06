#include "python/engine/build_call.hpp"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"
#include "core/io/coordinate_system.hpp"
#include "core/io/molecule_points.hpp"
#include "core/io/point_formats.hpp"
#include "core/io/point_set_handle.hpp"
#include "core/io/vector_points.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "python/engine/engine_error.hpp"
#include "python/engine/numpy_arrays.hpp"

namespace py = pybind11;

namespace galpha::python {
namespace {

static_assert(sizeof(Point2) == 2 * sizeof(double), "Point2 is two packed doubles: an (N, 2) array is N points");

// forcecast: a float32, integer or non-contiguous input is converted (one copy, by NumPy); a
// C-contiguous float64 array is used as it is.
using PointArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

PointArray AsPointArray(const py::object& points) {
  PointArray array = PointArray::ensure(points);
  if (!array) {
    PyErr_Clear();
    throw StatusError(absl::InvalidArgumentError(
        absl::StrCat("points must be an (N, 2) array of numbers, got ", std::string(py::str(py::type::of(points))))));
  }
  if (array.ndim() != 2 || array.shape(1) != 2) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < array.ndim(); ++d) absl::StrAppend(&shape, d ? ", " : "", array.shape(d));
    absl::StrAppend(&shape, array.ndim() == 1 ? ",)" : ")");
    throw StatusError(absl::InvalidArgumentError(absl::StrCat("points must have shape (N, 2), got ", shape)));
  }
  return array;
}

using WeightArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Weights as a 1-D float64 array of `n` values (forcecast, as the points).
WeightArray AsWeightArray(const py::object& weights, size_t n) {
  WeightArray array = WeightArray::ensure(weights);
  if (!array) {
    PyErr_Clear();
    throw StatusError(absl::InvalidArgumentError(
        absl::StrCat("weights must be an (N,) array of numbers, got ", std::string(py::str(py::type::of(weights))))));
  }
  if (array.ndim() != 1 || static_cast<size_t>(array.shape(0)) != n) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < array.ndim(); ++d) absl::StrAppend(&shape, d ? ", " : "", array.shape(d));
    absl::StrAppend(&shape, array.ndim() == 1 ? ",)" : ")");
    throw StatusError(
        absl::InvalidArgumentError(absl::StrCat("weights must have shape (", n, ",): one per point, got ", shape)));
  }
  return array;
}

absl::Span<const Point2> PointsOf(const PointArray& array) {
  return {reinterpret_cast<const Point2*>(array.data()), static_cast<size_t>(array.shape(0))};
}

Backend ParseBackend(const std::string& backend) {
  if (backend == "auto") return Backend::kAuto;
  if (backend == "cpu") return Backend::kCpu;
  if (backend == "cuda") return Backend::kCuda;
  throw StatusError(
      absl::InvalidArgumentError(absl::StrCat("unknown backend '", backend, "' (expected auto, cpu or cuda)")));
}

// What the engine's callbacks share with the caller: the first Python exception raised in them.
// The engine cannot carry a Python exception through its own code, so a callback that meets one
// keeps it, and cancelled() then answers true: the build stops at its next check and the caller
// re-raises the kept exception instead of the engine's Cancelled status.
struct PythonCallbacks {
  py::object progress;
  std::optional<py::error_already_set> error;
};

/// Python runs signal handlers only when the interpreter runs: the engine asks between phases,
/// so that Ctrl-C stops a long build (KeyboardInterrupt from the default SIGINT handler).
std::function<bool()> CancelledBySignal(PythonCallbacks* callbacks) {
  return [callbacks] {
    py::gil_scoped_acquire gil;
    if (!callbacks->error && PyErr_CheckSignals() != 0) callbacks->error.emplace();
    return callbacks->error.has_value();
  };
}

/// `call()` (returning an absl::StatusOr<T>) with the GIL released; its error raised as
/// EngineError once the GIL is held again.
template <class T, class Call>
T WithoutGil(Call&& call) {
  absl::StatusOr<T> result = absl::UnknownError("not run");
  {
    py::gil_scoped_release release;
    result = call();
  }
  if (!result.ok()) throw StatusError(result.status());
  return *std::move(result);
}

/// An (N, 2) float64 array holding `points`.
py::array_t<double> PointsArray(const std::vector<Point2>& points) {
  std::vector<double> flat(2 * points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    flat[2 * i] = points[i].x;
    flat[2 * i + 1] = points[i].y;
  }
  return ArrayFromVector(std::move(flat), {static_cast<py::ssize_t>(points.size()), 2});
}

}  // namespace

std::shared_ptr<const FamilyState> BuildFamily(const py::object& points, const py::object& weights,
                                               const std::string& backend, const py::object& progress,
                                               const std::string& name) {
  const PointArray array = AsPointArray(points);
  const absl::Span<const Point2> span = PointsOf(array);
  WeightArray weight_array;
  absl::Span<const double> weight_span;
  if (!weights.is_none()) {
    weight_array = AsWeightArray(weights, span.size());
    weight_span = {weight_array.data(), static_cast<size_t>(weight_array.shape(0))};
  }
  if (!progress.is_none() && !PyCallable_Check(progress.ptr())) {
    throw StatusError(absl::InvalidArgumentError("progress must be None or a callable (phase, fraction)"));
  }

  PythonCallbacks callbacks{progress, std::nullopt};
  BuildOptions options;
  options.backend = ParseBackend(backend);
  if (!progress.is_none()) {
    options.progress = [&callbacks](std::string_view phase, double fraction) {
      py::gil_scoped_acquire gil;
      if (callbacks.error) return;
      try {
        callbacks.progress(py::str(phase.data(), phase.size()), fraction);
      } catch (py::error_already_set& e) {
        callbacks.error = std::move(e);
      }
    };
  }
  options.cancelled = CancelledBySignal(&callbacks);

  std::optional<absl::StatusOr<AlphaFamily>> built;
  {
    py::gil_scoped_release release;
    built.emplace(weights.is_none() ? BuildAlphaFamily(span, options)
                                    : BuildWeightedAlphaFamily(span, weight_span, options));
  }
  if (callbacks.error) throw std::move(*callbacks.error);
  return std::make_shared<const FamilyState>(ValueOrThrow(*std::move(built)), name);
}

std::vector<std::shared_ptr<const FamilyState>> BuildFamilies(const py::object& points, const py::object& set_begin,
                                                              const std::string& backend,
                                                              const std::vector<std::string>& names) {
  const PointArray array = AsPointArray(points);
  const absl::Span<const Point2> span = PointsOf(array);
  using OffsetArray = py::array_t<int64_t, py::array::c_style | py::array::forcecast>;
  const OffsetArray offsets = OffsetArray::ensure(set_begin);
  if (!offsets || offsets.ndim() != 1 || static_cast<size_t>(offsets.shape(0)) != names.size() + 1) {
    PyErr_Clear();
    throw StatusError(absl::InvalidArgumentError(
        absl::StrCat("set_begin must be a 1-D array of ", names.size() + 1, " offsets (one more than the names)")));
  }
  std::vector<uint32_t> begin(names.size() + 1);
  for (size_t s = 0; s < begin.size(); ++s) {
    const int64_t offset = offsets.at(static_cast<py::ssize_t>(s));
    if (offset < 0 || static_cast<uint64_t>(offset) > span.size()) {
      throw StatusError(absl::InvalidArgumentError(
          absl::StrCat("set offset ", s, " is ", offset, ", outside 0..", span.size(), " (the points given)")));
    }
    begin[s] = static_cast<uint32_t>(offset);
  }
  PythonCallbacks callbacks{py::none(), std::nullopt};
  BuildOptions options;
  options.backend = ParseBackend(backend);
  options.cancelled = CancelledBySignal(&callbacks);
  std::optional<absl::StatusOr<AlphaFamilies>> built;
  {
    py::gil_scoped_release release;
    built.emplace(BuildAlphaFamilies(span, begin, options));
  }
  if (callbacks.error) throw std::move(*callbacks.error);
  AlphaFamilies families = ValueOrThrow(*std::move(built));
  std::vector<std::shared_ptr<const FamilyState>> out;
  out.reserve(families.families.size());
  for (size_t s = 0; s < families.families.size(); ++s) {
    out.push_back(std::make_shared<const FamilyState>(std::move(families.families[s]), names[s]));
  }
  return out;
}

std::string HandleOf(const py::object& points) {
  const PointArray array = AsPointArray(points);
  const absl::Span<const Point2> span = PointsOf(array);
  py::gil_scoped_release release;
  return PointSetHandle(span);
}

py::dict FrameOf(const std::string& crs, const py::object& points) {
  const PointArray array = AsPointArray(points);
  const absl::Span<const Point2> span = PointsOf(array);
  py::dict out;
  const CrsInfo info = ValueOrThrow(DescribeCrs(crs));
  out["name"] = info.name;
  out["id"] = info.id.empty() ? py::object(py::none()) : py::object(py::str(info.id));
  out["geographic"] = info.geographic;
  out["points"] = py::none();
  out["projection"] = py::none();
  if (!info.geographic) return out;
  LocalMetres local = WithoutGil<LocalMetres>([&] { return ProjectToLocalMetres(info, span); });
  out["points"] = PointsArray(local.points);
  out["projection"] = local.projection;
  return out;
}

py::dict ReadPointFile(const std::string& path, const std::string& layer, const py::object& plane,
                       const py::object& slab, uint64_t max_points) {
  std::string extension = absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  // A structure may be gzip-compressed: its format is the extension before ".gz".
  if (extension == ".gz") extension = absl::AsciiStrToLower(std::filesystem::path(path).stem().extension().string());
  const bool molecule = IsMoleculeExtension(extension), vector = IsVectorPointsExtension(extension);
  std::optional<std::string> plane_text, slab_text;
  if (!plane.is_none()) plane_text = py::cast<std::string>(plane);
  if (!slab.is_none()) slab_text = py::cast<std::string>(slab);
  if ((plane_text || slab_text) && !molecule) {
    throw StatusError(absl::InvalidArgumentError(absl::StrCat(
        "plane and slab apply to PDB and mmCIF structures (.pdb, .ent, .cif, .mmcif), not to '", path, "'")));
  }
  if (!layer.empty() && !vector) {
    throw StatusError(absl::InvalidArgumentError(absl::StrCat(
        "layer applies to Shapefiles, GeoPackages and FlatGeobuf files (.shp, .gpkg, .fgb), not to '", path, "'")));
  }
  const MoleculeSection section =
      ValueOrThrow(ParseMoleculeSection(plane_text ? &*plane_text : nullptr, slab_text ? &*slab_text : nullptr));
  std::vector<double> radii;
  GeoreferencedPoints read = WithoutGil<GeoreferencedPoints>([&]() -> absl::StatusOr<GeoreferencedPoints> {
    absl::StatusOr<GeoreferencedPoints> result = molecule ? ReadMoleculePoints(path, section, max_points, &radii)
                                                 : vector ? ReadVectorPoints(path, layer, max_points)
                                                          : ReadGeoreferencedPointsFile(path);
    if (result.ok() && result->points.size() > max_points) {
      return absl::ResourceExhaustedError(absl::StrCat("points file '", path, "' has ", result->points.size(),
                                                       " points: more than max_points, ", max_points));
    }
    return result;
  });
  py::dict out;
  out["points"] = PointsArray(read.points);
  out["crs"] = read.crs ? py::object(py::str(*read.crs)) : py::object(py::none());
  if (molecule) {
    py::array_t<double> radius_array(static_cast<py::ssize_t>(radii.size()));
    std::copy(radii.begin(), radii.end(), radius_array.mutable_data());
    out["radii"] = std::move(radius_array);
  } else {
    out["radii"] = py::none();
  }
  return out;
}

}  // namespace galpha::python
