#include "python/engine/family_answers.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/family/area_ratio.hpp"
#include "core/family/canonical_order.hpp"
#include "core/family/persistence.hpp"
#include "gpu/alpha/persistence_engine.hpp"

namespace galpha::python {
namespace {

// classes[order[i]] in wire numbers, for every i: the classes in the canonical order. Parallel:
// at a million points these gathers are most of a classification's cost after ClassifyAll.
std::vector<uint8_t> GatherClasses(const std::vector<SimplexClass>& classes, const std::vector<uint32_t>& order) {
  std::vector<uint8_t> out(order.size());
  const auto n = static_cast<int64_t>(order.size());
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < n; ++i) out[static_cast<size_t>(i)] = WireClass(classes[order[static_cast<size_t>(i)]]);
  return out;
}

// The non-exterior simplices of one kind, in the canonical order: `arity` indices each.
void KeepNonExterior(const std::vector<SimplexClass>& classes, const std::vector<uint32_t>& order,
                     const std::vector<uint32_t>& vertices_in_order, size_t arity, std::vector<uint32_t>* kept,
                     std::vector<uint8_t>* kept_classes) {
  for (size_t i = 0; i < order.size(); ++i) {
    const SimplexClass c = classes[order[i]];
    if (c == SimplexClass::kExterior) continue;
    kept->insert(kept->end(), vertices_in_order.begin() + static_cast<std::ptrdiff_t>(i * arity),
                 vertices_in_order.begin() + static_cast<std::ptrdiff_t>((i + 1) * arity));
    kept_classes->push_back(WireClass(c));
  }
}

// One pair as server/persistence_answers.cpp's PersistenceSource lists it.
void AppendPair(const AlphaFamily& family, const PersistencePair& p, double birth, double death,
                PersistencePairs* out) {
  out->birth_rank.push_back(p.birth_rank);
  out->death_rank.push_back(p.essential() ? -1 : static_cast<int64_t>(p.death_rank));
  out->birth_alpha_sq.push_back(birth);
  out->death_alpha_sq.push_back(death);
  const PairVertices vertices = VerticesOf(family, p);
  out->creator_vertices.insert(out->creator_vertices.end(), vertices.creator.begin(),
                               vertices.creator.begin() + p.dimension + 1);
  out->killer_vertices.insert(out->killer_vertices.end(), vertices.killer.begin(),
                              vertices.killer.begin() + p.dimension + 2);
}

}  // namespace

absl::StatusOr<Threshold::Kind> ParseThresholdKind(absl::string_view kind) {
  if (kind == "alpha_sq") return Threshold::Kind::kAlphaSq;
  if (kind == "alpha") return Threshold::Kind::kAlpha;
  if (kind == "rank") return Threshold::Kind::kRank;
  if (kind == "ratio") return Threshold::Kind::kRatio;
  return absl::InvalidArgumentError(
      absl::StrCat("unknown threshold kind '", kind, "': give alpha_sq, alpha, rank or ratio"));
}

absl::StatusOr<ClassifyMode> ParseMode(absl::string_view mode) {
  if (mode == "general") return ClassifyMode::kGeneral;
  if (mode == "regularized") return ClassifyMode::kRegularized;
  return absl::InvalidArgumentError(absl::StrCat("mode '", mode, "' is not a mode (general or regularized)"));
}

absl::StatusOr<VertexRule> ParseVertexRule(absl::string_view rule) {
  if (rule == "report") return VertexRule::kReport;
  if (rule == "cgal") return VertexRule::kCgal;
  return absl::InvalidArgumentError(absl::StrCat("vertex_rule '", rule, "' is not a vertex rule (report or cgal)"));
}

absl::StatusOr<ClassifyAnswer> AnswerClassify(const FamilyState& state, const Threshold& threshold, ClassifyMode mode,
                                              VertexRule rule, bool non_exterior_only, bool summary_only) {
  const AlphaFamily& family = state.family();
  ClassifyAnswer answer;
  auto level = ResolveLevel(family, threshold);
  if (!level.ok()) return level.status();
  answer.level = *level;
  const Classification classes = family.ClassifyAll(level->level, mode, rule);
  answer.counts = SummarizeClassification(family, classes);
  answer.components = family.Components(level->level);
  answer.solid_components = family.SolidComponents(level->level);
  answer.holes = family.Holes(level->level, mode);
  answer.hull_area = HullAreaApprox(family);
  answer.summary_only = summary_only;
  if (summary_only) return answer;

  const std::vector<uint32_t>& distinct = state.DistinctVertices();
  if (!non_exterior_only) {
    answer.vertex_classes = GatherClasses(classes.vertices, distinct);
    answer.edge_classes = GatherClasses(classes.edges, state.EdgeOrder());
    answer.triangle_classes = GatherClasses(classes.triangles, state.TriangleOrder());
    return answer;
  }
  answer.filtered = true;
  KeepNonExterior(classes.vertices, distinct, distinct, 1, &answer.vertices, &answer.vertex_classes);
  KeepNonExterior(classes.edges, state.EdgeOrder(), state.EdgeVerticesInOrder(), 2, &answer.edges,
                  &answer.edge_classes);
  KeepNonExterior(classes.triangles, state.TriangleOrder(), state.TriangleVerticesInOrder(), 3, &answer.triangles,
                  &answer.triangle_classes);
  return answer;
}

absl::StatusOr<ShapeGeometry> AnswerShape(const AlphaFamily& family, const Threshold& threshold, ClassifyMode mode,
                                          double min_hole_area) {
  auto level = ResolveLevel(family, threshold);
  if (!level.ok()) return level.status();
  // The service's check and message (server/query_answers.cpp, MakeShapeSource), after the
  // threshold's as there.
  if (std::isnan(min_hole_area) || min_hole_area < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("min_hole_area ", min_hole_area, " is not an area: give 0 (keep every hole) or more"));
  }
  auto shape = AssembleShape(family.ComplexAt(level->level, mode));
  if (!shape.ok()) return shape.status();
  if (min_hole_area > 0) FillHolesSmallerThan(&*shape, family.points(), min_hole_area);
  return shape;
}

absl::StatusOr<std::vector<ShapeHole>> AnswerHoles(const AlphaFamily& family, const Threshold& threshold,
                                                   double min_area) {
  if (std::isnan(min_area) || min_area < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("min_area ", min_area, " is not an area: give 0 (every hole) or more"));
  }
  // The polygons are the same in both modes: holes are rings of the regularized shape.
  auto shape = AnswerShape(family, threshold, ClassifyMode::kRegularized);
  if (!shape.ok()) return shape.status();
  return ListHoles(*shape, family.points(), min_area);
}

absl::StatusOr<std::pair<size_t, size_t>> AnswerSpectrumRange(const AlphaFamily& family, int64_t first_rank,
                                                              int64_t count) {
  const int64_t k = family.max_level();
  if (first_rank < 1 || first_rank > k + 1) {
    return absl::InvalidArgumentError(absl::StrCat("first_rank ", first_rank, " is outside 1..", k + 1));
  }
  if (count < 0) return absl::InvalidArgumentError(absl::StrCat("count ", count, " is negative"));
  const int64_t end = first_rank - 1 + std::min(count, k - (first_rank - 1));  // one past the last position
  return std::pair<size_t, size_t>{static_cast<size_t>(first_rank - 1), static_cast<size_t>(end)};
}

absl::StatusOr<int64_t> AnswerRankLowerBound(const AlphaFamily& family, double alpha_sq) {
  if (std::isnan(alpha_sq)) return absl::InvalidArgumentError("at_least_alpha_sq is NaN");
  return family.RankLowerBound(alpha_sq);
}

absl::StatusOr<MasterListAnswer> AnswerMasterList(const AlphaFamily& family, int64_t first_rank, int64_t last_rank) {
  const int64_t k = family.max_level();
  const int64_t first = first_rank;
  const int64_t last = last_rank == 0 ? first : last_rank;
  if (k == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("rank ", first, " is out of range: the spectrum is empty, the master list has no ranks"));
  }
  if (first < 1 || first > k) {
    return absl::InvalidArgumentError(
        absl::StrCat("first_rank ", first, " is outside 1..", k, " (the spectrum has ", k, " values)"));
  }
  if (last < first || last > k) {
    return absl::InvalidArgumentError(absl::StrCat("last_rank ", last, " is outside ", first, "..", k));
  }
  const auto& begin = family.ranks().master_begin;
  const auto& master = family.ranks().master;
  const size_t from = begin[static_cast<size_t>(first)], to = begin[static_cast<size_t>(last) + 1];
  MasterListAnswer answer;
  answer.ranks.reserve(to - from);
  answer.kinds.reserve(to - from);
  answer.endpoints.reserve(to - from);
  answer.vertex_indices.reserve(3 * (to - from));
  int64_t rank = first;
  for (size_t i = from; i < to; ++i) {
    while (i >= begin[static_cast<size_t>(rank) + 1]) ++rank;
    const MasterEntry entry = master[i];
    answer.ranks.push_back(rank);
    answer.kinds.push_back(static_cast<uint8_t>(static_cast<int>(entry.kind()) + 1));
    answer.endpoints.push_back(static_cast<uint8_t>(static_cast<int>(entry.endpoint()) + 1));
    switch (entry.kind()) {
      case SimplexKind::kVertex:
        answer.vertex_indices.push_back(entry.id());
        break;
      case SimplexKind::kEdge: {
        const auto& e = family.edges()[entry.id()];
        answer.vertex_indices.push_back(std::min(e[0], e[1]));
        answer.vertex_indices.push_back(std::max(e[0], e[1]));
        break;
      }
      case SimplexKind::kTriangle:
        for (uint32_t v : SortedTriangle(family.triangles()[entry.id()])) answer.vertex_indices.push_back(v);
        break;
    }
  }
  return answer;
}

absl::StatusOr<ComponentsAnswer> AnswerComponents(const AlphaFamily& family, int64_t first_level, int64_t last_level) {
  const int64_t k = family.max_level();
  if (first_level < 0 || last_level > k || last_level < first_level) {
    return absl::InvalidArgumentError(
        absl::StrCat("rank range ", first_level, "..", last_level, " is not within 0..", k, " (first <= last)"));
  }
  ComponentsAnswer answer;
  answer.first_level = first_level;
  answer.components.reserve(static_cast<size_t>(last_level - first_level + 1));
  answer.solid_components.reserve(static_cast<size_t>(last_level - first_level + 1));
  for (int64_t level = first_level; level <= last_level; ++level) {
    answer.components.push_back(family.Components(level));
    answer.solid_components.push_back(family.SolidComponents(level));
  }
  return answer;
}

absl::StatusOr<BettiAnswer> AnswerBetti(const AlphaFamily& family, int64_t first_level, int64_t last_level) {
  const int64_t k = family.max_level();
  if (first_level < 0 || last_level > k || last_level < first_level) {
    return absl::InvalidArgumentError(
        absl::StrCat("rank range ", first_level, "..", last_level, " is not within 0..", k, " (first <= last)"));
  }
  BettiAnswer answer;
  answer.first_level = first_level;
  const auto n = static_cast<size_t>(last_level - first_level + 1);
  answer.components.reserve(n);
  answer.holes.reserve(n);
  answer.regularized_components.reserve(n);
  answer.regularized_holes.reserve(n);
  for (int64_t level = first_level; level <= last_level; ++level) {
    answer.components.push_back(family.Components(level));
    answer.holes.push_back(family.Holes(level, ClassifyMode::kGeneral));
    answer.regularized_components.push_back(family.RegularizedComponents(level));
    answer.regularized_holes.push_back(family.Holes(level, ClassifyMode::kRegularized));
  }
  return answer;
}

absl::StatusOr<OptimalAnswer> AnswerOptimal(const AlphaFamily& family, int64_t max_components,
                                            std::optional<int64_t> max_holes) {
  constexpr int64_t kMaxWire = std::numeric_limits<uint32_t>::max();
  if (max_components < 1) return absl::InvalidArgumentError("max_components must be at least 1");
  if (max_components > kMaxWire) {
    return absl::InvalidArgumentError(absl::StrCat("max_components ", max_components, " exceeds ", kMaxWire));
  }
  if (max_holes && (*max_holes < 0 || *max_holes > kMaxWire)) {
    return absl::InvalidArgumentError(absl::StrCat("max_holes ", *max_holes, " is outside 0..", kMaxWire));
  }
  const auto n = static_cast<uint32_t>(max_components);
  const std::optional<uint32_t> holes =
      max_holes ? std::optional<uint32_t>(static_cast<uint32_t>(*max_holes)) : std::nullopt;
  OptimalAnswer answer;
  // Components as the service reports them: solid ones in the regularized sense (CGAL's).
  if (const std::optional<int64_t> level = family.OptimalLevelRegularized(n, holes)) {
    answer.regularized = OptimalLevel{*level, PublishedAlphaSq(family, *level), family.SolidComponents(*level),
                                      family.Holes(*level, ClassifyMode::kRegularized)};
  }
  if (const std::optional<int64_t> level = family.OptimalLevelGeneral(n, holes)) {
    answer.general = OptimalLevel{*level, PublishedAlphaSq(family, *level), family.Components(*level),
                                  family.Holes(*level, ClassifyMode::kGeneral)};
  }
  return answer;
}

absl::StatusOr<std::array<PersistencePairs, 2>> AnswerPersistence(const FamilyState& state,
                                                                  const std::vector<int64_t>& dimensions,
                                                                  double min_persistence) {
  std::array<bool, 2> wanted = {dimensions.empty(), dimensions.empty()};
  for (int64_t d : dimensions) {
    if (d < 0 || d > 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("dimension ", d, " has no classes: a planar alpha complex has H0 (0) and H1 (1) only"));
    }
    wanted[static_cast<size_t>(d)] = true;
  }
  if (std::isnan(min_persistence) || min_persistence < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("min_persistence ", min_persistence, " is not a length: give 0 or more"));
  }
  const AlphaFamily& family = state.family();
  // On the GPU when the family was built there (gpu/alpha/persistence_engine.hpp).
  absl::StatusOr<PersistenceDiagram> diagram = PersistenceDiagramOf(family, state.EdgeOrder(), state.TriangleOrder());
  if (!diagram.ok()) return diagram.status();
  std::array<PersistencePairs, 2> answer;
  for (size_t d = 0; d < 2; ++d) {
    if (!wanted[d]) continue;
    for (size_t i = diagram->dimension_begin[d]; i < diagram->dimension_begin[d + 1]; ++i) {
      const PersistencePair& p = diagram->pairs[i];
      if (!PersistsAtLeast(family, p, min_persistence)) continue;
      AppendPair(family, p, RankValue(family, p.birth_rank), RankValue(family, p.death_rank), &answer[d]);
    }
  }
  return answer;
}

}  // namespace galpha::python
