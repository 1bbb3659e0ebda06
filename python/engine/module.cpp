// galpha._engine: the embedded engine for the galpha Python package (python/src/galpha/_local.py
// adapts it to the package's types). Every error is galpha._engine.EngineError with the absl code.
#include <string>
#include <utility>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "gpu/system/backend.hpp"
#include "python/engine/build_call.hpp"
#include "python/engine/engine_error.hpp"
#include "python/engine/family_binding.hpp"
#include "python/engine/simplex_sections_binding.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_engine, module) {
  module.doc() = "The galpha engine in this process: build(points) -> Family; handle(points).";
  galpha::python::RegisterEngineError(module);
  galpha::python::RegisterFamily(module);
  galpha::python::RegisterSimplexSectionReader(module);
  module.def(
      "build",
      [](const py::object& points, const std::string& backend, const py::object& progress, const std::string& name,
         const py::object& weights) {
        return galpha::python::FamilyObject(galpha::python::BuildFamily(points, weights, backend, progress, name));
      },
      py::arg("points"), py::arg("backend") = "auto", py::arg("progress") = py::none(), py::arg("name") = "",
      py::arg("weights") = py::none(),
      "Builds the exact alpha family of an (N, 2) float64 array (used without a copy when C-contiguous) on "
      "backend 'auto', 'cpu' or 'cuda', with the GIL released; with weights (N numbers, squared radii) the "
      "weighted family. progress(phase, fraction) is called after each phase; Ctrl-C or an exception in "
      "progress stops the build between phases and is raised.");
  module.def(
      "build_many",
      [](const py::object& points, const py::object& set_begin, const std::vector<std::string>& names,
         const std::string& backend) {
        std::vector<galpha::python::FamilyObject> families;
        for (auto& state : galpha::python::BuildFamilies(points, set_begin, backend, names)) {
          families.emplace_back(std::move(state));
        }
        return families;
      },
      py::arg("points"), py::arg("set_begin"), py::arg("names"), py::arg("backend") = "auto",
      "Builds the exact alpha families of many point sets in one packed build: set s is "
      "points[set_begin[s]:set_begin[s + 1]] of an (N, 2) float64 array, labelled names[s]; each family equals "
      "build()'s of the set alone. Unweighted; the GIL is released; Ctrl-C stops the build between phases.");
  module.def("handle", &galpha::python::HandleOf, py::arg("points"),
             "The content handle of an (N, 2) float64 array, as the server and the C++ client compute it.");
  module.def("frame", &galpha::python::FrameOf, py::arg("crs"), py::arg("points"),
             "The CRS `crs` (EPSG:4326, WKT, a PROJ string) as PROJ reads it, and for a geographic CRS the local "
             "projection (metres) of the (N, 2) longitude/latitude array that galpha computes in.");
  module.def("read_points", &galpha::python::ReadPointFile, py::arg("path"), py::arg("layer") = "",
             py::arg("plane") = py::none(), py::arg("slab") = py::none(), py::arg("max_points") = 100000000,
             "The points of a point file (alphactl's formats) and the CRS it states: {'points', 'crs'}.");
  module.def("cuda_available", &galpha::CudaBackendAvailable,
             "Whether this build has the CUDA backend and a GPU is visible now.");
}
