// alphactl shape --group-by: one shape per group of points (issue "Speak GIS": a hull per feature
// class, cluster or region). Each group is framed (its own local projection for a geographic
// CRS) and shaped on its own; the families are built here in one packed build
// (BuildAlphaFamilies), or, with --server, by the server from one BuildBatch call.
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/commands.hpp"
#include "client/text_output.hpp"
#include "core/base/status_macros.hpp"
#include "core/geometry/shape.hpp"
#include "core/geometry/shape_holes.hpp"
#include "core/io/json_text.hpp"
#include "gpu/alpha/alpha_engine.hpp"

namespace galpha::alphactl {

int RunGroupedShape(const CommonArgs& common, const ThresholdArg& threshold, const std::string& format,
                    double min_hole_area) {
  if (common.input.weights != InputOptions::Weights::kNone) {
    return UsageError(absl::InvalidArgumentError(
        "--group-by reads groups without weights: build a weighted set's shape without --group-by"));
  }
  if (format != "geojson" && format != "wkt") {
    return UsageError(absl::InvalidArgumentError("--group-by writes geojson or wkt (one shape per group), not svg"));
  }
  GeoreferencedPoints read;
  try {
    auto result = ReadInputPointsAndCrs(common.file, common.input);
    if (!result.ok()) return Failure(result.status());
    read = *std::move(result);
  } catch (const std::exception& e) {
    return Failure(absl::DataLossError(absl::StrCat("points file '", common.file, "' cannot be read: ", e.what())));
  }
  // Each group framed on its own (its own local projection for a geographic CRS).
  const auto groups = GroupsOf(read.groups);
  std::vector<std::string> names;
  std::vector<FramedPoints> frames;
  for (const auto& [group, indices] : groups) {
    names.push_back(group ? absl::StrCat("group '", *group, "'") : std::string("the group without a value"));
    std::vector<Point2> subset;
    subset.reserve(indices.size());
    for (uint32_t i : indices) subset.push_back(read.points[i]);
    auto frame = FramePoints(common, std::move(subset), read.crs);
    if (!frame.ok())
      return Failure(absl::Status(frame.status().code(), absl::StrCat(names.back(), ": ", frame.status().message())));
    frames.push_back(*std::move(frame));
  }
  // Each group's level, squared alpha and shape: built here, or by the server in one BuildBatch
  // call.
  std::vector<RemoteSetShape> shapes;
  if (!common.server.empty()) {
    std::vector<absl::Span<const Point2>> sets;
    sets.reserve(frames.size());
    for (const FramedPoints& frame : frames) sets.emplace_back(frame.Computed());
    auto remote = RemoteSetShapes(common, names, sets, threshold, min_hole_area);
    if (!remote.ok()) {
      return absl::IsInvalidArgument(remote.status()) ? ArgumentError(remote.status()) : Failure(remote.status());
    }
    shapes = *std::move(remote);
  } else {
    // Every group's family in one packed build (BuildAlphaFamilies: each the family of its group
    // alone); when it fails, the groups are built one by one, so that the error names its group.
    std::vector<Point2> all;
    std::vector<uint32_t> set_begin{0};
    for (const FramedPoints& frame : frames) {
      all.insert(all.end(), frame.Computed().begin(), frame.Computed().end());
      set_begin.push_back(static_cast<uint32_t>(all.size()));
    }
    BuildOptions options;
    options.backend = common.backend;
    absl::StatusOr<AlphaFamilies> packed = BuildAlphaFamilies(all, set_begin, options);
    all = {};
    for (size_t g = 0; g < groups.size(); ++g) {
      const std::string& name = names[g];
      absl::StatusOr<AlphaFamily> family = packed.ok() ? absl::StatusOr<AlphaFamily>(std::move(packed->families[g]))
                                                       : BuildFamily(common, frames[g].Computed(), /*weights=*/{});
      if (!family.ok())
        return Failure(absl::Status(family.status().code(), absl::StrCat(name, ": ", family.status().message())));
      auto level = ResolveThreshold(*family, threshold);
      if (!level.ok())
        return ArgumentError(absl::Status(level.status().code(), absl::StrCat(name, ": ", level.status().message())));
      auto shape = AssembleShape(family->ComplexAt(level->level, ClassifyMode::kRegularized));
      if (!shape.ok()) return Failure(shape.status());
      // Areas in the computation's units (square metres for a geographic CRS).
      if (min_hole_area > 0) FillHolesSmallerThan(&*shape, family->points(), min_hole_area);
      shapes.push_back({level->level, level->alpha_sq, *std::move(shape)});
    }
  }
  ChunkedWriter out(stdout);
  nlohmann::ordered_json features = nlohmann::ordered_json::array();
  for (size_t g = 0; g < groups.size(); ++g) {
    const auto& [group, indices] = groups[g];
    const RemoteSetShape& shape = shapes[g];
    auto points = OutputPoints(frames[g], format == "geojson");
    if (!points.ok()) return Failure(points.status());
    if (format == "wkt") {
      out.Append(absl::StrCat(group.value_or(""), "\t", ShapeToWkt(shape.shape, *points), "\n"));
      continue;
    }
    nlohmann::ordered_json properties = {{"group", group ? nlohmann::ordered_json(*group) : nlohmann::ordered_json()},
                                         {"points", indices.size()},
                                         {"level", shape.level},
                                         {"alpha_sq", shape.alpha_sq},
                                         {"area", shape.shape.area}};
    features.push_back({{"type", "Feature"},
                        {"properties", std::move(properties)},
                        {"geometry", ShapePolygonsGeoJson(shape.shape, *points)}});
  }
  if (format == "geojson") {
    out.Append(JsonText({{"type", "FeatureCollection"}, {"features", std::move(features)}}));
    out.Append('\n');
  }
  return FinishOutput(out);
}

}  // namespace galpha::alphactl
