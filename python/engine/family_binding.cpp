#include "python/engine/family_binding.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "absl/strings/str_cat.h"
#include "python/engine/engine_error.hpp"
#include "python/engine/family_answers.hpp"
#include "python/engine/numpy_arrays.hpp"

namespace py = pybind11;

namespace galpha::python {
namespace {

using StatePtr = std::shared_ptr<const FamilyState>;

// (kind, value) as the caller gives a threshold: a rank must be an integer (Python's or NumPy's),
// the radii any real number.
Threshold ThresholdOf(const std::string& kind, const py::object& value) {
  Threshold threshold;
  threshold.kind = ValueOrThrow(ParseThresholdKind(kind));
  if (threshold.kind == Threshold::Kind::kRank) {
    py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
    if (!index) {
      PyErr_Clear();
      throw StatusError(absl::InvalidArgumentError(
          absl::StrCat("a rank must be an integer, got ", std::string(py::str(py::repr(value))))));
    }
    int overflow = 0;
    threshold.rank = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
    if (overflow != 0) {
      throw StatusError(absl::InvalidArgumentError(
          absl::StrCat("rank ", std::string(py::str(index)), " is outside the 64-bit integers")));
    }
    return threshold;
  }
  threshold.value = PyFloat_AsDouble(value.ptr());
  if (threshold.value == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();
    throw StatusError(absl::InvalidArgumentError(
        absl::StrCat(kind, " must be a real number, got ", std::string(py::str(py::repr(value))))));
  }
  return threshold;
}

py::tuple CountsTuple(const std::array<uint64_t, 4>& counts) {
  return py::make_tuple(counts[0], counts[1], counts[2], counts[3]);
}

py::dict SummaryDict(const FamilyState& state) {
  const AlphaFamily& family = state.family();
  const BuildReport& report = family.report();
  py::dict stage_times;
  for (const StageTime& stage : report.stage_times) stage_times[py::str(stage.stage)] = stage.seconds;
  py::dict comparisons;
  comparisons["filter"] = report.comparisons.filter;
  comparisons["device_exact"] = report.comparisons.bounded_exact;
  comparisons["cpu_fallback"] = report.comparisons.cpu_fallback;
  py::dict summary;
  summary["name"] = state.name();
  summary["points"] = family.points().size();
  summary["distinct_points"] = family.num_unique();
  summary["duplicates"] = family.num_duplicates();
  summary["triangles"] = family.triangles().size();
  summary["edges"] = family.edges().size();
  summary["spectrum_size"] = family.spectrum().size();
  summary["weighted"] = family.weighted();
  summary["hidden_points"] = family.HiddenPoints().size();
  summary["backend"] = report.backend;
  summary["stage_times"] = stage_times;
  summary["comparisons"] = comparisons;
  summary["peak_memory_bytes"] = report.peak_memory_bytes;
  summary["family_bytes"] = state.bytes();
  return summary;
}

py::dict ClassifyDict(ClassifyAnswer answer, const StatePtr& state) {
  py::dict out;
  out["level"] = answer.level.level;
  out["alpha_sq"] = answer.level.alpha_sq;
  out["vertex_counts"] = CountsTuple(answer.counts.vertices);
  out["edge_counts"] = CountsTuple(answer.counts.edges);
  out["triangle_counts"] = CountsTuple(answer.counts.triangles);
  out["components"] = answer.components;
  out["solid_components"] = answer.solid_components;
  out["holes"] = answer.holes;
  out["interior_area"] = answer.counts.interior_area;
  out["hull_area"] = answer.hull_area;
  if (answer.summary_only) {
    out["vertices"] = py::array_t<uint32_t>(std::vector<py::ssize_t>{0});
    out["edges"] = py::array_t<uint32_t>(std::vector<py::ssize_t>{0, 2});
    out["triangles"] = py::array_t<uint32_t>(std::vector<py::ssize_t>{0, 3});
  } else if (answer.filtered) {
    const auto e = static_cast<py::ssize_t>(answer.edges.size() / 2);
    const auto t = static_cast<py::ssize_t>(answer.triangles.size() / 3);
    out["vertices"] = ArrayFromVector(std::move(answer.vertices));
    out["edges"] = ArrayFromVector(std::move(answer.edges), {e, 2});
    out["triangles"] = ArrayFromVector(std::move(answer.triangles), {t, 3});
  } else {
    // Every simplex: the family's canonical arrays themselves, shared by every classification.
    const auto& vertices = state->DistinctVertices();
    const auto& edges = state->EdgeVerticesInOrder();
    const auto& triangles = state->TriangleVerticesInOrder();
    out["vertices"] = ReadOnlyView(vertices.data(), {static_cast<py::ssize_t>(vertices.size())}, state);
    out["edges"] = ReadOnlyView(edges.data(), {static_cast<py::ssize_t>(edges.size() / 2), 2}, state);
    out["triangles"] = ReadOnlyView(triangles.data(), {static_cast<py::ssize_t>(triangles.size() / 3), 3}, state);
  }
  out["vertex_classes"] = ArrayFromVector(std::move(answer.vertex_classes));
  out["edge_classes"] = ArrayFromVector(std::move(answer.edge_classes));
  out["triangle_classes"] = ArrayFromVector(std::move(answer.triangle_classes));
  return out;
}

py::dict ShapeDict(ShapeGeometry shape) {
  py::list polygons;
  for (ShapePolygon& polygon : shape.polygons) {
    py::list holes;
    for (std::vector<uint32_t>& hole : polygon.holes) holes.append(ArrayFromVector(std::move(hole)));
    polygons.append(py::make_tuple(ArrayFromVector(std::move(polygon.outer)), holes));
  }
  std::vector<uint32_t> singular;
  singular.reserve(2 * shape.singular_edges.size());
  for (const auto& e : shape.singular_edges) singular.insert(singular.end(), e.begin(), e.end());
  const auto k = static_cast<py::ssize_t>(shape.singular_edges.size());
  py::dict out;
  out["polygons"] = polygons;
  out["singular_edges"] = ArrayFromVector(std::move(singular), {k, 2});
  out["isolated_points"] = ArrayFromVector(std::move(shape.isolated_points));
  out["area"] = shape.area;
  return out;
}

py::object OptimalTuple(const std::optional<OptimalLevel>& level) {
  if (!level) return py::none();
  return py::make_tuple(level->rank, level->alpha_sq, level->components, level->holes);
}

py::dict PairsDict(PersistencePairs pairs, py::ssize_t dimension) {
  const auto n = static_cast<py::ssize_t>(pairs.birth_rank.size());
  py::dict out;
  out["birth_rank"] = ArrayFromVector(std::move(pairs.birth_rank));
  out["death_rank"] = ArrayFromVector(std::move(pairs.death_rank));
  out["birth"] = ArrayFromVector(std::move(pairs.birth_alpha_sq));
  out["death"] = ArrayFromVector(std::move(pairs.death_alpha_sq));
  out["creator"] = ArrayFromVector(std::move(pairs.creator_vertices), {n, dimension + 1});
  out["killer"] = ArrayFromVector(std::move(pairs.killer_vertices), {n, dimension + 2});
  return out;
}

}  // namespace

std::shared_ptr<const FamilyState> FamilyObject::state() const {
  if (!state_) throw StatusError(absl::NotFoundError("the family was released"));
  return state_;
}

bool FamilyObject::Release() {
  const bool held = state_ != nullptr;
  state_.reset();
  return held;
}

void RegisterFamily(py::module_& module) {
  py::class_<FamilyObject>(module, "Family", "A built alpha family (galpha._engine.build); answers as NumPy arrays.")
      .def_property_readonly(
          "handle",
          [](const FamilyObject& self) {
            const StatePtr state = self.state();
            py::gil_scoped_release release;
            return state->Handle();
          },
          "The content handle of the family's points: 'sha256-' and 64 hex digits.")
      .def(
          "hidden_points",
          [](const FamilyObject& self) {
            std::vector<uint32_t> hidden = self.state()->family().HiddenPoints();
            const auto n = static_cast<py::ssize_t>(hidden.size());
            return ArrayFromVector(std::move(hidden), {n});
          },
          "Input indices of the points a weighted family hides (no vertex of the regular triangulation), "
          "ascending, as uint32; empty for an unweighted family.")
      .def(
          "summary", [](const FamilyObject& self) { return SummaryDict(*self.state()); },
          "What the build produced and measured: a dict with the fields of galpha.BuildSummary but 'cached'.")
      .def(
          "spectrum",
          [](const FamilyObject& self, int64_t first_rank, std::optional<int64_t> count) {
            const StatePtr state = self.state();
            const auto& spectrum = state->family().spectrum();
            const int64_t n = count.value_or(static_cast<int64_t>(spectrum.size()));
            const auto [begin, end] = ValueOrThrow(AnswerSpectrumRange(state->family(), first_rank, n));
            return ReadOnlyView(spectrum.data() + begin, {static_cast<py::ssize_t>(end - begin)}, state);
          },
          py::arg("first_rank") = 1, py::arg("count") = py::none(),
          "Spectrum values (alpha_sq) of ranks first_rank .. first_rank + count - 1, clipped at K (count None: "
          "through K); a read-only float64 view.")
      .def(
          "rank_lower_bound",
          [](const FamilyObject& self, double alpha_sq) {
            return ValueOrThrow(AnswerRankLowerBound(self.state()->family(), alpha_sq));
          },
          py::arg("alpha_sq"), "The first rank whose exact threshold is >= alpha_sq (K + 1 when none is).")
      .def(
          "classify",
          [](const FamilyObject& self, const std::string& kind, const py::object& value, const std::string& mode,
             const std::string& vertex_rule, bool non_exterior_only, bool summary_only) {
            const StatePtr state = self.state();
            const Threshold threshold = ThresholdOf(kind, value);
            const ClassifyMode parsed_mode = ValueOrThrow(ParseMode(mode));
            const VertexRule rule = ValueOrThrow(ParseVertexRule(vertex_rule));
            std::optional<absl::StatusOr<ClassifyAnswer>> answer;
            {
              py::gil_scoped_release release;
              answer.emplace(AnswerClassify(*state, threshold, parsed_mode, rule, non_exterior_only, summary_only));
            }
            return ClassifyDict(ValueOrThrow(*std::move(answer)), state);
          },
          py::arg("kind"), py::arg("value"), py::arg("mode") = "general", py::arg("vertex_rule") = "report",
          py::arg("non_exterior_only") = false, py::arg("summary_only") = false,
          "Every simplex's class at one threshold (kind 'alpha_sq', 'alpha' or 'rank'), as the service's Classify: "
          "a dict of the counts and the arrays of galpha.Classification.")
      .def(
          "shape_rings",
          [](const FamilyObject& self, const std::string& kind, const py::object& value, const std::string& mode,
             double min_hole_area) {
            const StatePtr state = self.state();
            const Threshold threshold = ThresholdOf(kind, value);
            const ClassifyMode parsed_mode = ValueOrThrow(ParseMode(mode));
            std::optional<absl::StatusOr<ShapeGeometry>> shape;
            {
              py::gil_scoped_release release;
              shape.emplace(AnswerShape(state->family(), threshold, parsed_mode, min_hole_area));
            }
            return ShapeDict(ValueOrThrow(*std::move(shape)));
          },
          py::arg("kind"), py::arg("value"), py::arg("mode") = "general", py::arg("min_hole_area") = 0.0,
          "The alpha shape at one threshold by input indices: polygons as (outer, [holes]), singular_edges (k, 2), "
          "isolated_points, area; holes with an area below min_hole_area filled (their area joins the shape's), as "
          "the service's Shape fills them.")
      .def(
          "holes",
          [](const FamilyObject& self, const std::string& kind, const py::object& value, double min_area) {
            const StatePtr state = self.state();
            const Threshold threshold = ThresholdOf(kind, value);
            std::optional<absl::StatusOr<std::vector<ShapeHole>>> answer;
            {
              py::gil_scoped_release release;
              answer.emplace(AnswerHoles(state->family(), threshold, min_area));
            }
            std::vector<ShapeHole> holes = ValueOrThrow(*std::move(answer));
            py::list out;
            for (ShapeHole& hole : holes) {
              // Counter-clockwise, as alphactl holes prints the ring (AssembleShape writes it clockwise).
              std::reverse(hole.ring.begin(), hole.ring.end());
              out.append(py::make_tuple(hole.polygon, ArrayFromVector(std::move(hole.ring)), hole.area));
            }
            return out;
          },
          py::arg("kind"), py::arg("value"), py::arg("min_area") = 0.0,
          "The holes of the regularized shape at one threshold with an area of at least min_area, largest first, as "
          "alphactl holes lists them: a list of (polygon index, ring uint32 counter-clockwise and open, area).")
      .def(
          "master_list",
          [](const FamilyObject& self, int64_t first_rank, int64_t last_rank) {
            const StatePtr state = self.state();
            std::optional<absl::StatusOr<MasterListAnswer>> answer;
            {
              py::gil_scoped_release release;
              answer.emplace(AnswerMasterList(state->family(), first_rank, last_rank));
            }
            MasterListAnswer list = ValueOrThrow(*std::move(answer));
            py::dict out;
            out["ranks"] = ArrayFromVector(std::move(list.ranks));
            out["kinds"] = ArrayFromVector(std::move(list.kinds));
            out["endpoints"] = ArrayFromVector(std::move(list.endpoints));
            out["vertex_indices"] = ArrayFromVector(std::move(list.vertex_indices));
            return out;
          },
          py::arg("first_rank"), py::arg("last_rank") = 0,
          "Master-list entries of ranks first_rank .. last_rank (0: first_rank alone): ranks, kinds, endpoints, "
          "vertex_indices.")
      .def(
          "components",
          [](const FamilyObject& self, int64_t first_level, int64_t last_level) {
            ComponentsAnswer answer = ValueOrThrow(AnswerComponents(self.state()->family(), first_level, last_level));
            py::dict out;
            out["first_level"] = answer.first_level;
            out["components"] = ArrayFromVector(std::move(answer.components));
            out["solid_components"] = ArrayFromVector(std::move(answer.solid_components));
            return out;
          },
          py::arg("first_level"), py::arg("last_level"),
          "Components and solid components at levels first_level .. last_level (0..K, inclusive).")
      .def(
          "betti",
          [](const FamilyObject& self, int64_t first_level, int64_t last_level) {
            const StatePtr state = self.state();
            std::optional<absl::StatusOr<BettiAnswer>> answer;
            {
              py::gil_scoped_release release;
              answer.emplace(AnswerBetti(state->family(), first_level, last_level));
            }
            BettiAnswer betti = ValueOrThrow(*std::move(answer));
            py::dict out;
            out["first_level"] = betti.first_level;
            out["components"] = ArrayFromVector(std::move(betti.components));
            out["holes"] = ArrayFromVector(std::move(betti.holes));
            out["regularized_components"] = ArrayFromVector(std::move(betti.regularized_components));
            out["regularized_holes"] = ArrayFromVector(std::move(betti.regularized_holes));
            return out;
          },
          py::arg("first_level"), py::arg("last_level"),
          "b0 and b1 of the general and the regularized complex at levels first_level .. last_level (0..K, "
          "inclusive): components, holes, regularized_components, regularized_holes.")
      .def(
          "optimal",
          [](const FamilyObject& self, int64_t max_components, std::optional<int64_t> max_holes) {
            const StatePtr state = self.state();
            std::optional<absl::StatusOr<OptimalAnswer>> answer;
            {
              py::gil_scoped_release release;
              answer.emplace(AnswerOptimal(state->family(), max_components, max_holes));
            }
            const OptimalAnswer optimal = ValueOrThrow(*std::move(answer));
            py::dict out;
            out["regularized"] = OptimalTuple(optimal.regularized);
            out["general"] = OptimalTuple(optimal.general);
            return out;
          },
          py::arg("max_components"), py::arg("max_holes") = py::none(),
          "The smallest rank with at most max_components components (and at most max_holes holes when given): "
          "{'regularized', 'general'}, each (rank, alpha_sq, components, holes) or None.")
      .def(
          "persistence",
          [](const FamilyObject& self, const std::vector<int64_t>& dimensions, double min_persistence) {
            const StatePtr state = self.state();
            std::optional<absl::StatusOr<std::array<PersistencePairs, 2>>> answer;
            {
              py::gil_scoped_release release;
              answer.emplace(AnswerPersistence(*state, dimensions, min_persistence));
            }
            std::array<PersistencePairs, 2> pairs = ValueOrThrow(*std::move(answer));
            return py::make_tuple(PairsDict(std::move(pairs[0]), 0), PairsDict(std::move(pairs[1]), 1));
          },
          py::arg("dimensions"), py::arg("min_persistence") = 0.0,
          "The persistence diagram as the service's Persistence lists it: a tuple of two dicts (H0, H1) of "
          "birth_rank, death_rank (-1: essential), birth, death (alpha_sq; inf: essential), creator (n, d + 1) and "
          "killer (n, d + 2) vertices; dimensions not asked for (empty: both) are empty.")
      .def("release", &FamilyObject::Release, "Drops the family (arrays already returned stay valid); True when held.")
      .def("__repr__", [](const FamilyObject& self) {
        try {
          const StatePtr state = self.state();
          return absl::StrCat("<galpha._engine.Family of ", state->family().points().size(),
                              " points, K=", state->family().max_level(), ">");
        } catch (const StatusError&) {
          return std::string("<galpha._engine.Family (released)>");
        }
      });
}

}  // namespace galpha::python
