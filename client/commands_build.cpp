// The commands about a build itself: triangulate (the Delaunay step alone), spectrum, bench.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.hpp"
#include "client/point_input.hpp"
#include "client/text_output.hpp"
#include "gpu/triangulation/delaunay.hpp"
#include "nlohmann/json.hpp"

namespace galpha::alphactl {

int RunTriangulate(Args args) {
  auto common = ParseCommon("triangulate", args, {});
  if (!common.ok()) return UsageError(common.status());
  if (!common->server.empty()) {
    return UsageError(absl::InvalidArgumentError(
        "triangulate runs locally only: a server builds whole families (use summary or bench with --server)"));
  }
  TriangulateOptions options;
  options.backend = common->backend;

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

  size_t hull_edges = 0;
  for (const auto& n : tri->neighbors) {
    for (int32_t x : n) hull_edges += x == Triangulation::kNoNeighbor ? 1 : 0;
  }
  if (tri->triangles.empty()) hull_edges = tri->edges.size();
  // Milliseconds to the microsecond: a clock's noise needs no more digits.
  auto ms = [](double seconds) { return std::round(seconds * 1e6) / 1e3; };
  double total = 0.0;
  nlohmann::ordered_json stages = nlohmann::ordered_json::object();
  for (const auto& s : tri->stage_times) {
    stages[s.stage] = ms(s.seconds);
    total += s.seconds;
  }
  const nlohmann::ordered_json json = {
      {"file", common->file},
      {"points", points->size()},
      {"distinct_points", tri->num_unique},
      {"duplicates", points->size() - tri->num_unique},
      {"hidden_points", weighted ? nlohmann::ordered_json(tri->hidden.size()) : nlohmann::ordered_json(nullptr)},
      {"triangles", tri->triangles.size()},
      {"edges", tri->edges.size()},
      {"hull_edges", hull_edges},
      {"backend", BackendName(tri->backend)},
      {"peak_memory_bytes", tri->peak_memory_bytes},
      {"total_ms", ms(total)},
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
