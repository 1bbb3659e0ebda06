// galpha._engine.build and .handle: points from NumPy to the engine. The points cross without a
// copy when they are a C-contiguous (N, 2) float64 array (galpha::Point2 is two doubles); the
// engine runs with the GIL released and copies them into the family, which owns all it needs.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include "python/engine/family_state.hpp"

namespace galpha::python {

/// Builds the family of `points` (anything NumPy turns into an (N, 2) float64 array) on `backend`
/// ("auto", "cpu" or "cuda"), labelled `name`; with `weights` (None, or N numbers: each point's
/// squared radius) the weighted family. `progress`, when not None, is called as
/// progress(phase, fraction) after each engine phase, with the GIL. Between phases the build
/// checks for signals: Ctrl-C (or any exception from `progress`) stops it, frees what it held and
/// raises that exception. Engine errors raise EngineError.
std::shared_ptr<const FamilyState> BuildFamily(const pybind11::object& points, const pybind11::object& weights,
                                               const std::string& backend, const pybind11::object& progress,
                                               const std::string& name);

/// Builds the families of many point sets in one packed build (BuildAlphaFamilies): set s is
/// points[set_begin[s]:set_begin[s + 1]] (`set_begin`: a 1-D array of S + 1 offsets from 0 to N),
/// labelled names[s]; each family equals BuildFamily's of the set alone. Unweighted. Ctrl-C stops
/// the build between phases, as BuildFamily's; engine errors raise EngineError.
std::vector<std::shared_ptr<const FamilyState>> BuildFamilies(const pybind11::object& points,
                                                              const pybind11::object& set_begin,
                                                              const std::string& backend,
                                                              const std::vector<std::string>& names);

/// The content handle of `points` (core/io/point_set_handle.hpp), hashed with the GIL released.
std::string HandleOf(const pybind11::object& points);

/// The frame `points` are computed in under CRS `crs` (core/io/coordinate_system.hpp): a dict of
/// name, id (None if PROJ knows none), geographic, and for a geographic CRS points (their local
/// projection, an (N, 2) float64 array in metres) and projection (its PROJ string), else None for
/// both. EngineError for an unknown CRS or points that are not longitudes and latitudes.
pybind11::dict FrameOf(const std::string& crs, const pybind11::object& points);

/// The points of a file in alphactl's formats, by extension (.bin, .npy, GeoJSON, .las,
/// .shp/.gpkg/.fgb with `layer`, .pdb/.cif (also .gz) with `plane` and `slab` (None: the
/// defaults), delimited text), read with the GIL released by core/io's readers: a dict of points
/// (an (N, 2) float64 array) and crs (the CRS the file states, or None). EngineError as the
/// readers' errors; ResourceExhausted over `max_points`.
pybind11::dict ReadPointFile(const std::string& path, const std::string& layer, const pybind11::object& plane,
                             const pybind11::object& slab, uint64_t max_points);

}  // namespace galpha::python
