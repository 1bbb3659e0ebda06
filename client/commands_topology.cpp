// alphactl persistence and holes: the persistence diagram of the alpha filtration
// (core/family/persistence.hpp) and the holes of the shape at a threshold
// (core/geometry/shape_holes.hpp), computed by the embedded engine or asked of a server (the remote
// halves are in commands_remote.cpp), written by client/topology_output.
#include <cstdio>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/commands.hpp"
#include "client/topology_output.hpp"
#include "core/family/canonical_order.hpp"
#include "core/family/persistence.hpp"
#include "core/geometry/shape.hpp"
#include "core/geometry/shape_holes.hpp"
#include "gpu/alpha/persistence_engine.hpp"

namespace galpha::alphactl {

absl::StatusOr<PersistenceArgs> ParsePersistenceArgs(const CommandLine& line) {
  PersistenceArgs out;
  if (const std::string* text = line.Find("dimension")) {
    auto dimension = ParseInteger("dimension", *text, 0);
    if (!dimension.ok()) return dimension.status();
    if (*dimension > 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("--dimension ", *dimension, ": a planar alpha complex has classes in dimensions 0 and 1 only"));
    }
    out.dimensions = {*dimension == 0, *dimension == 1};
  }
  if (const std::string* text = line.Find("min-persistence")) {
    auto value = ParseFiniteDouble("min-persistence", *text);
    if (!value.ok()) return value.status();
    if (*value < 0) return absl::InvalidArgumentError(absl::StrCat("--min-persistence '", *text, "' is negative"));
    out.min_persistence = *value;
  }
  if (const std::string* text = line.Find("format")) {
    auto format = ParsePersistenceFormat(*text);
    if (!format.ok()) return format.status();
    out.format = *format;
  }
  return out;
}

int RunPersistence(Args args) {
  auto common = ParseCommon("persistence", args, {"dimension", "min-persistence", "format"});
  if (!common.ok()) return UsageError(common.status());
  auto options = ParsePersistenceArgs(common->line);
  if (!options.ok()) return UsageError(options.status());
  if (!common->server.empty()) return RemotePersistence(*common, *options);
  size_t input_points = 0;
  auto family = LoadFamily(*common, &input_points);
  if (!family.ok()) return Failure(family.status());
  // On the GPU when the family was built there (gpu/alpha/persistence_engine.hpp).
  auto diagram = PersistenceDiagramOf(*family);
  if (!diagram.ok()) return Failure(diagram.status());

  std::vector<PersistenceRow> rows;
  for (const PersistencePair& p : diagram->pairs) {
    if (!options->dimensions[p.dimension] || !PersistsAtLeast(*family, p, options->min_persistence)) continue;
    PersistenceRow row;
    row.dimension = p.dimension;
    row.birth_rank = p.birth_rank;
    row.death_rank = p.essential() ? -1 : static_cast<int64_t>(p.death_rank);
    row.birth = RankValue(*family, p.birth_rank);
    row.death = RankValue(*family, p.death_rank);
    const PairVertices vertices = VerticesOf(*family, p);
    row.creator.assign(vertices.creator.begin(), vertices.creator.begin() + p.dimension + 1);
    if (!p.essential()) row.killer.assign(vertices.killer.begin(), vertices.killer.begin() + p.dimension + 2);
    rows.push_back(std::move(row));
  }
  if (!WritePersistence(rows, options->format, stdout)) {
    return Failure(absl::DataLossError("persistence: writing to standard output failed"));
  }
  return kExitOk;
}

absl::StatusOr<HolesArgs> ParseHolesArgs(const CommandLine& line) {
  HolesArgs out;
  auto threshold = ParseThreshold(line);
  if (!threshold.ok()) return threshold.status();
  out.threshold = *threshold;
  if (const std::string* text = line.Find("min-area")) {
    auto value = ParseFiniteDouble("min-area", *text);
    if (!value.ok()) return value.status();
    if (*value < 0) return absl::InvalidArgumentError(absl::StrCat("--min-area '", *text, "' is negative"));
    out.min_area = *value;
  }
  if (const std::string* text = line.Find("format")) {
    auto format = ParseHolesFormat(*text);
    if (!format.ok()) return format.status();
    out.format = *format;
  }
  return out;
}

int RunHoles(Args args) {
  auto common = ParseCommon("holes", args, {"alpha-sq", "alpha", "rank", "ratio", "min-area", "format"});
  if (!common.ok()) return UsageError(common.status());
  auto options = ParseHolesArgs(common->line);
  if (!options.ok()) return UsageError(options.status());
  if (!common->server.empty()) return RemoteHoles(*common, *options);
  size_t input_points = 0;
  FramedPoints frame;
  auto family = LoadFamily(*common, &input_points, &frame);
  if (!family.ok()) return Failure(family.status());
  auto threshold = ResolveThreshold(*family, options->threshold);
  if (!threshold.ok()) return ArgumentError(threshold.status());
  // The polygons are the same in both modes: holes are rings of the regularized shape.
  auto shape = AssembleShape(family->ComplexAt(threshold->level, ClassifyMode::kRegularized));
  if (!shape.ok()) return Failure(shape.status());
  // Areas in the computation's units (metres for a geographic CRS); rings in the format's.
  const std::vector<ShapeHole> holes = ListHoles(*shape, family->points(), options->min_area);
  auto points = OutputPoints(frame, options->format == HolesFormat::kGeoJson);
  if (!points.ok()) return Failure(points.status());
  if (!WriteHoles(holes, *points, options->format, stdout)) {
    return Failure(absl::DataLossError("holes: writing to standard output failed"));
  }
  return kExitOk;
}

}  // namespace galpha::alphactl
