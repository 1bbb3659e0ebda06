// The commands about a build itself: triangulate (the Delaunay step alone), spectrum, bench.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.hpp"
#include "client/point_input.hpp"
#include "client/text_output.hpp"
#include "gpu/triangulation/delaunay.hpp"
#include "nlohmann/json.hpp"

namespace galpha::alphactl {

namespace {

// Milliseconds to the microsecond: a clock's noise needs no more digits.
double Milliseconds(double seconds) { return std::round(seconds * 1e6) / 1e3; }

/// The hull edges of a triangulation: edges with one triangle, or every edge of a chain.
size_t HullEdges(const Triangulation& t) {
  if (t.triangles.empty()) return t.edges.size();
  size_t hull_edges = 0;
  for (const auto& n : t.neighbors) {
    for (int32_t x : n) hull_edges += x == Triangulation::kNoNeighbor ? 1 : 0;
  }
  return hull_edges;
}

/// The stage times as a JSON object, and their sum into *total (seconds).
nlohmann::ordered_json StageJson(const std::vector<StageTime>& stage_times, double* total) {
  nlohmann::ordered_json stages = nlohmann::ordered_json::object();
  for (const auto& s : stage_times) {
    stages[s.stage] = Milliseconds(s.seconds);
    *total += s.seconds;
  }
  return stages;
}

/// triangulate --group-by: every group's triangulation from one packed build (TriangulateSets),
/// one JSON line with each group's counts and the build's times.
int RunGroupedTriangulate(const CommonArgs& common, const TriangulateOptions& options) {
  if (common.input.weights != InputOptions::Weights::kNone) {
    return UsageError(absl::InvalidArgumentError(
        "--group-by triangulates unweighted groups: triangulate a weighted set without --group-by"));
  }
  absl::StatusOr<GeoreferencedPoints> read;
  try {
    read = ReadInputPointsAndCrs(common.file, common.input);
  } catch (const std::exception& e) {
    read = absl::DataLossError(absl::StrCat("points file '", common.file, "' cannot be read: ", e.what()));
  }
  if (!read.ok()) return Failure(read.status());
  const auto groups = GroupsOf(read->groups);
  std::vector<Point2> points;
  points.reserve(read->points.size());
  std::vector<uint32_t> set_begin{0};
  for (const auto& [group, indices] : groups) {
    for (const uint32_t i : indices) points.push_back(read->points[i]);
    set_begin.push_back(static_cast<uint32_t>(points.size()));
  }
  auto sets = TriangulateSets(points, set_begin, options);
  if (!sets.ok()) {
    // The engine names a set by its index: name its group instead.
    const std::string message(sets.status().message());
    size_t set = 0;
    if (message.rfind("set ", 0) == 0 && absl::SimpleAtoi(message.substr(4, message.find(':') - 4), &set) &&
        set < groups.size()) {
      const std::string name =
          groups[set].first ? absl::StrCat("group '", *groups[set].first, "'") : "the group without a value";
      return Failure(absl::Status(sets.status().code(), absl::StrCat(name, message.substr(message.find(':')))));
    }
    return Failure(sets.status());
  }
  nlohmann::ordered_json per_group = nlohmann::ordered_json::array();
  for (size_t g = 0; g < groups.size(); ++g) {
    const Triangulation& t = sets->sets[g];
    per_group.push_back(
        {{"group", groups[g].first ? nlohmann::ordered_json(*groups[g].first) : nlohmann::ordered_json()},
         {"points", t.points.size()},
         {"distinct_points", t.num_unique},
         {"duplicates", t.points.size() - t.num_unique},
         {"triangles", t.triangles.size()},
         {"edges", t.edges.size()},
         {"hull_edges", HullEdges(t)}});
  }
  double total = 0.0;
  nlohmann::ordered_json stages = StageJson(sets->stage_times, &total);
  const nlohmann::ordered_json json = {{"file", common.file},
                                       {"points", points.size()},
                                       {"groups", std::move(per_group)},
                                       {"backend", BackendName(sets->backend)},
                                       {"built_alone", sets->built_alone},
                                       {"peak_memory_bytes", sets->peak_memory_bytes},
                                       {"total_ms", Milliseconds(total)},
                                       {"stage_ms", std::move(stages)}};
  std::fputs(JsonLine(json).c_str(), stdout);
  return kExitOk;
}

}  // namespace

int RunTriangulate(Args args) {
  auto common = ParseCommon("triangulate", args, {"group-by"});
  if (!common.ok()) return UsageError(common.status());
  if (!common->server.empty()) {
    return UsageError(absl::InvalidArgumentError(
        "triangulate runs locally only: a server builds whole families (use summary or bench with --server)"));
  }
  TriangulateOptions options;
  options.backend = common->backend;
  if (const std::string* column = common->line.Find("group-by")) {
    if (column->empty()) return UsageError(absl::InvalidArgumentError("--group-by needs a column's name"));
    common->input.group_by = *column;
    return RunGroupedTriangulate(*common, options);
  }

  const bool weighted = common->input.weights != InputOptions::Weights::kNone;
  absl::StatusOr<GeoreferencedPoints> read;
  try {
    read = ReadInputPointsAndCrs(common->file, common->input);
  } catch (const std::exception& e) {
    read = absl::DataLossError(absl::StrCat("points file '", common->file, "' cannot be read: ", e.what()));
  }
  if (!read.ok()) return Failure(read.status());
  const std::vector<Point2>* points = &read->points;
  auto tri = weighted ? TriangulateWeighted(*points, read->weights, options) : Triangulate(*points, options);
  if (!tri.ok()) return Failure(tri.status());

  double total = 0.0;
  nlohmann::ordered_json stages = StageJson(tri->stage_times, &total);
  const nlohmann::ordered_json json = {
      {"file", common->file},
      {"points", points->size()},
      {"distinct_points", tri->num_unique},
      {"duplicates", points->size() - tri->num_unique},
      {"hidden_points", weighted ? nlohmann::ordered_json(tri->hidden.size()) : nlohmann::ordered_json(nullptr)},
      {"triangles", tri->triangles.size()},
      {"edges", tri->edges.size()},
      {"hull_edges", HullEdges(*tri)},
      {"backend", BackendName(tri->backend)},
      {"peak_memory_bytes", tri->peak_memory_bytes},
      {"total_ms", Milliseconds(total)},
      {"stage_ms", std::move(stages)}};
  std::fputs(JsonLine(json).c_str(), stdout);
  return kExitOk;
}

int RunSpectrum(Args args) {
  auto common = ParseCommon("spectrum", args, {});
  if (!common.ok()) return UsageError(common.status());
  if (!common->server.empty()) return RemoteSpectrum(*common);
  size_t input_points = 0;
  auto family = LoadFamily(*common, &input_points);
  if (!family.ok()) return Failure(family.status());
  ChunkedWriter out(stdout);
  for (const double alpha_sq : family->spectrum()) {
    out.AppendDouble(alpha_sq);
    out.Append('\n');
  }
  if (!out.Finish()) return Failure(absl::UnavailableError("cannot write to standard output"));
  return kExitOk;
}

int RunBench(Args args) {
  auto common = ParseCommon("bench", args, {"repeat"});
  if (!common.ok()) return UsageError(common.status());
  int64_t repeat = 1;
  if (const std::string* text = common->line.Find("repeat")) {
    auto parsed = ParseInteger("repeat", *text, 1);
    if (!parsed.ok()) return UsageError(parsed.status());
    repeat = *parsed;
  }
  if (!common->server.empty()) return RemoteBench(*common, repeat);

  // Read once: FILE may be a pipe. Best of `repeat` per stage, matched by name in the first
  // build's order; the total is the best build's sum (not the sum of the per-stage bests).
  std::vector<double> weights;
  auto points = ReadPoints(*common, &weights);
  if (!points.ok()) return Failure(points.status());
  const size_t input_points = points->size();
  std::vector<std::pair<std::string, double>> best;
  double best_total = 0.0;
  std::optional<AlphaFamily> family;
  for (int64_t run = 0; run < repeat; ++run) {
    auto built = BuildFamily(*common, *points, weights);
    if (!built.ok()) return Failure(built.status());
    double total = 0.0;
    for (const StageTime& s : built->report().stage_times) {
      total += s.seconds;
      auto it = std::find_if(best.begin(), best.end(), [&](const auto& b) { return b.first == s.stage; });
      if (it == best.end()) {
        best.emplace_back(s.stage, s.seconds);
      } else {
        it->second = std::min(it->second, s.seconds);
      }
    }
    best_total = run == 0 ? total : std::min(best_total, total);
    family.emplace(*std::move(built));
  }

  const BuildReport& report = family->report();
  std::vector<std::pair<std::string, std::string>> rows;
  rows.reserve(best.size() + 3);
  for (const auto& [stage, seconds] : best) rows.emplace_back(stage, absl::StrFormat("%.3f", seconds * 1e3));
  rows.emplace_back("total", absl::StrFormat("%.3f", best_total * 1e3));
  rows.emplace_back("peak_memory_bytes", absl::StrCat(report.peak_memory_bytes));
  rows.emplace_back("bytes_per_point",
                    absl::StrFormat("%.1f", input_points == 0 ? 0.0
                                                              : static_cast<double>(report.peak_memory_bytes) /
                                                                    static_cast<double>(input_points)));
  rows.emplace_back("comparisons_filter", absl::StrCat(report.comparisons.filter));
  rows.emplace_back("comparisons_bounded_exact", absl::StrCat(report.comparisons.bounded_exact));
  rows.emplace_back("comparisons_cpu_fallback", absl::StrCat(report.comparisons.cpu_fallback));
  rows.emplace_back("spectrum_size", absl::StrCat(family->spectrum().size()));
  rows.emplace_back("backend", report.backend);

  return PrintBenchTable(common->file, input_points, family->num_unique(), repeat, best.size() + 1, rows);
}

}  // namespace galpha::alphactl
