// The commands that query one family: classify, summary, shape, masterlist, optimal. Each checks its
// whole command line before reading FILE, so a usage error costs no build.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/commands.hpp"
#include "client/text_output.hpp"
#include "core/family/area_ratio.hpp"
#include "core/family/canonical_order.hpp"
#include "core/family/classification_summary.hpp"
#include "core/geometry/shape.hpp"
#include "core/geometry/shape_holes.hpp"
#include "nlohmann/json.hpp"

namespace galpha::alphactl {

int RunClassify(Args args) {
  auto common =
      ParseCommon("classify", args, {"alpha-sq", "alpha", "rank", "ratio", "mode", "vertex-rule", "answer-encoding"});
  if (!common.ok()) return UsageError(common.status());
  auto options = ParseClassifyArgs(common->line, !common->server.empty());
  if (!options.ok()) return UsageError(options.status());
  if (!common->server.empty()) return RemoteClassify(*common, *options);
  size_t input_points = 0;
  FramedPoints frame;
  auto family = LoadFamily(*common, &input_points, &frame);
  if (!family.ok()) return Failure(family.status());
  auto threshold = ResolveThreshold(*family, options->threshold);
  if (!threshold.ok()) return ArgumentError(threshold.status());

  const Classification classes = family->ClassifyAll(threshold->level, options->mode, options->rule);
  ChunkedWriter out(stdout);
  const auto& representative = family->representative();
  for (uint32_t v = 0; v < classes.vertices.size(); ++v) {
    if (representative[v] != v) continue;
    AppendSimplex<1>(out, 'v', {v});
    out.Append(' ');
    out.Append(SimplexClassName(classes.vertices[v]));
    out.Append('\n');
  }
  const CanonicalOrders orders = ComputeCanonicalOrders(*family);
  for (size_t i = 0; i < orders.edge_order.size(); ++i) {
    AppendSimplex<2>(out, 'e', {orders.edge_vertices[2 * i], orders.edge_vertices[2 * i + 1]});
    out.Append(' ');
    out.Append(SimplexClassName(classes.edges[orders.edge_order[i]]));
    out.Append('\n');
  }
  for (size_t i = 0; i < orders.triangle_order.size(); ++i) {
    AppendSimplex<3>(
        out, 't',
        {orders.triangle_vertices[3 * i], orders.triangle_vertices[3 * i + 1], orders.triangle_vertices[3 * i + 2]});
    out.Append(' ');
    out.Append(SimplexClassName(classes.triangles[orders.triangle_order[i]]));
    out.Append('\n');
  }
  return FinishOutput(out);
}

namespace {

/// A weighted family's hidden points (input indices, ascending); null for an unweighted one.
nlohmann::ordered_json HiddenPointsJson(const AlphaFamily& family) {
  if (!family.weighted()) return nullptr;
  return family.HiddenPoints();
}

}  // namespace

int RunSummary(Args args) {
  auto common = ParseCommon("summary", args, {"alpha-sq", "alpha", "rank", "ratio", "mode", "vertex-rule"});
  if (!common.ok()) return UsageError(common.status());
  auto options = ParseClassifyArgs(common->line);
  if (!options.ok()) return UsageError(options.status());
  if (!common->server.empty()) return RemoteSummary(*common, *options);
  size_t input_points = 0;
  FramedPoints frame;
  auto family = LoadFamily(*common, &input_points, &frame);
  if (!family.ok()) return Failure(family.status());
  auto threshold = ResolveThreshold(*family, options->threshold);
  if (!threshold.ok()) return ArgumentError(threshold.status());

  const Classification classes = family->ClassifyAll(threshold->level, options->mode, options->rule);
  const ClassificationSummary counts = SummarizeClassification(*family, classes);

  const int64_t level = threshold->level;
  const nlohmann::ordered_json json = {{"file", common->file},
                                       {"points", input_points},
                                       {"distinct_points", family->num_unique()},
                                       {"duplicates", family->num_duplicates()},
                                       {"hidden_points", HiddenPointsJson(*family)},
                                       {"spectrum_size", family->spectrum().size()},
                                       {"level", level},
                                       {"alpha_sq", threshold->alpha_sq},
                                       {"mode", ModeName(options->mode)},
                                       {"vertex_rule", VertexRuleName(options->rule)},
                                       {"vertices", ClassCountsJson(counts.vertices)},
                                       {"edges", ClassCountsJson(counts.edges)},
                                       {"triangles", ClassCountsJson(counts.triangles)},
                                       {"components", family->Components(level)},
                                       {"solid_components", family->SolidComponents(level)},
                                       {"holes", family->Holes(level, options->mode)},
                                       {"interior_area", counts.interior_area},
                                       {"hull_area", HullAreaApprox(*family)},
                                       {"crs", CrsJson(frame)},
                                       {"backend", family->report().backend}};
  std::fputs(JsonLine(json).c_str(), stdout);
  return kExitOk;
}

int RunShape(Args args) {
  auto common =
      ParseCommon("shape", args, {"alpha-sq", "alpha", "rank", "ratio", "mode", "format", "min-hole-area", "group-by"});
  if (!common.ok()) return UsageError(common.status());
  auto threshold_arg = ParseThreshold(common->line);
  if (!threshold_arg.ok()) return UsageError(threshold_arg.status());
  auto mode = ParseMode(common->line);
  if (!mode.ok()) return UsageError(mode.status());
  const std::string* format = common->line.Find("format");
  if (format == nullptr) return UsageError(absl::InvalidArgumentError("shape: missing --format geojson|wkt|svg"));
  if (*format != "geojson" && *format != "wkt" && *format != "svg") {
    return UsageError(
        absl::InvalidArgumentError(absl::StrCat("unknown --format '", *format, "' (expected geojson, wkt or svg)")));
  }
  double min_hole_area = 0.0;
  if (const std::string* text = common->line.Find("min-hole-area")) {
    auto value = ParseFiniteDouble("min-hole-area", *text);
    if (!value.ok()) return UsageError(value.status());
    if (*value < 0)
      return UsageError(absl::InvalidArgumentError(absl::StrCat("--min-hole-area '", *text, "' is negative")));
    min_hole_area = *value;
  }
  if (const std::string* column = common->line.Find("group-by")) {
    if (column->empty()) return UsageError(absl::InvalidArgumentError("--group-by needs a column's name"));
    if (*mode == ClassifyMode::kGeneral && common->line.Find("mode") != nullptr) {
      return UsageError(
          absl::InvalidArgumentError("--group-by writes each group's regularized shape (its polygons): "
                                     "leave out --mode general"));
    }
    common->input.group_by = *column;
    return RunGroupedShape(*common, *threshold_arg, *format, min_hole_area);
  }
  if (!common->server.empty()) return RemoteShape(*common, *threshold_arg, *mode, *format, min_hole_area);
  size_t input_points = 0;
  FramedPoints frame;
  auto family = LoadFamily(*common, &input_points, &frame);
  if (!family.ok()) return Failure(family.status());
  auto threshold = ResolveThreshold(*family, *threshold_arg);
  if (!threshold.ok()) return ArgumentError(threshold.status());

  auto shape = AssembleShape(family->ComplexAt(threshold->level, *mode));
  if (!shape.ok()) return Failure(shape.status());
  // Areas in the computation's units (metres for a geographic CRS); coordinates in the format's.
  if (min_hole_area > 0) FillHolesSmallerThan(&*shape, family->points(), min_hole_area);
  auto points = OutputPoints(frame, *format == "geojson");
  if (!points.ok()) return Failure(points.status());
  std::string text = *format == "geojson" ? ShapeToGeoJson(*shape, *points)
                     : *format == "wkt"   ? ShapeToWkt(*shape, *points)
                                          : ShapeToSvg(*shape, *points, CrsLabel(frame));
  if (text.empty() || text.back() != '\n') text += '\n';
  ChunkedWriter out(stdout);
  out.Append(text);
  return FinishOutput(out);
}

int RunMasterList(Args args) {
  auto common = ParseCommon("masterlist", args, {"rank"});
  if (!common.ok()) return UsageError(common.status());
  const std::string* rank_text = common->line.Find("rank");
  if (rank_text == nullptr) return UsageError(absl::InvalidArgumentError("masterlist: missing --rank K"));
  auto rank = ParseInteger("rank", *rank_text, 0);
  if (!rank.ok()) return UsageError(rank.status());
  if (!common->server.empty()) return RemoteMasterList(*common, *rank);
  size_t input_points = 0;
  auto family = LoadFamily(*common, &input_points);
  if (!family.ok()) return Failure(family.status());
  if (absl::Status s = CheckMasterListRank(*rank, family->max_level()); !s.ok()) return ArgumentError(s);

  ChunkedWriter out(stdout);
  for (const MasterEntry& entry : family->MasterList(*rank)) {
    switch (entry.kind()) {
      case SimplexKind::kVertex:
        AppendSimplex<1>(out, 'v', {entry.id()});
        break;
      case SimplexKind::kEdge: {
        const auto& edge = family->edges()[entry.id()];
        AppendSimplex<2>(out, 'e', {std::min(edge[0], edge[1]), std::max(edge[0], edge[1])});
        break;
      }
      case SimplexKind::kTriangle: {
        std::array<uint32_t, 3> tri = family->triangles()[entry.id()];
        std::sort(tri.begin(), tri.end());
        AppendSimplex(out, 't', tri);
        break;
      }
    }
    out.Append(' ');
    out.Append(EndpointName(entry.endpoint()));
    out.Append('\n');
  }
  return FinishOutput(out);
}

int RunOptimal(Args args) {
  auto common = ParseCommon("optimal", args, {"components", "holes"});
  if (!common.ok()) return UsageError(common.status());
  const std::string* text = common->line.Find("components");
  if (text == nullptr) return UsageError(absl::InvalidArgumentError("optimal: missing --components N"));
  auto components = ParseInteger("components", *text, 1);
  if (!components.ok()) return UsageError(components.status());
  std::optional<int64_t> holes;
  if (const std::string* holes_text = common->line.Find("holes")) {
    auto parsed = ParseInteger("holes", *holes_text, 0);
    if (!parsed.ok()) return UsageError(parsed.status());
    holes = *parsed;
  }
  if (!common->server.empty()) return RemoteOptimal(*common, *components, holes);
  size_t input_points = 0;
  auto family = LoadFamily(*common, &input_points);
  if (!family.ok()) return Failure(family.status());

  // Counts are 32-bit: "at most N" for any larger N means the same as for the largest count.
  const uint32_t n = static_cast<uint32_t>(std::min<int64_t>(*components, std::numeric_limits<uint32_t>::max()));
  const std::optional<uint32_t> max_holes = holes ? std::optional<uint32_t>(static_cast<uint32_t>(std::min<int64_t>(
                                                        *holes, std::numeric_limits<uint32_t>::max())))
                                                  : std::nullopt;
  nlohmann::ordered_json json = {{"components", *components}};
  if (holes) json["holes"] = *holes;
  json["regularized"] = nullptr;
  json["general"] = nullptr;
  if (const std::optional<int64_t> level = family->OptimalLevelRegularized(n, max_holes)) {
    json["regularized"] = {{"rank", *level},
                           {"alpha_sq", PublishedAlphaSq(*family, *level)},
                           {"solid_components", family->SolidComponents(*level)},
                           {"holes", family->Holes(*level, ClassifyMode::kRegularized)}};
  }
  if (const std::optional<int64_t> level = family->OptimalLevelGeneral(n, max_holes)) {
    json["general"] = {{"rank", *level},
                       {"alpha_sq", PublishedAlphaSq(*family, *level)},
                       {"components", family->Components(*level)},
                       {"holes", family->Holes(*level, ClassifyMode::kGeneral)}};
  }
  std::fputs(JsonLine(json).c_str(), stdout);
  return kExitOk;
}

}  // namespace galpha::alphactl
