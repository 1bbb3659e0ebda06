#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <iterator>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.hpp"
#include "gpu/alpha/alpha_engine.hpp"

namespace galpha::alphactl {

namespace {

/// Inputs at least this large report their build phases on stderr.
constexpr size_t kProgressMinPoints = 100000;

// Scripts read one line per error: a message never spans lines.
std::string OneLine(absl::string_view message) {
  std::string line(message);
  for (char& c : line) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return line;
}

}  // namespace

int UsageError(const absl::Status& status) {
  std::fprintf(stderr, "alphactl: %s (see 'alphactl --help')\n", OneLine(status.message()).c_str());
  return kExitUsage;
}

int ArgumentError(const absl::Status& status) {
  std::fprintf(stderr, "alphactl: %s\n", OneLine(status.message()).c_str());
  return kExitUsage;
}

int Failure(const absl::Status& status) {
  std::fprintf(stderr, "alphactl: %s\n", OneLine(status.message()).c_str());
  return kExitFailure;
}

absl::StatusOr<CommonArgs> ParseCommon(absl::string_view command, Args args,
                                       absl::Span<const absl::string_view> allowed) {
  std::vector<absl::string_view> names(allowed.begin(), allowed.end());
  names.insert(names.end(), std::begin(kGlobalOptions), std::end(kGlobalOptions));
  auto line = ParseCommandLine(command, args, names);
  if (!line.ok()) return line.status();
  CommonArgs common;
  if (line->positional.empty()) return absl::InvalidArgumentError(absl::StrCat(command, ": missing FILE"));
  if (line->positional.size() > 1) {
    return absl::InvalidArgumentError(absl::StrCat(command, ": unexpected argument '", line->positional[1], "'"));
  }
  common.file = line->positional[0];
  auto backend = ParseBackend(*line);
  if (!backend.ok()) return backend.status();
  common.backend = *backend;
  auto max_points = ParseMaxPoints(*line);
  if (!max_points.ok()) return max_points.status();
  common.input.max_points = *max_points;
  if (const std::string* layer = line->Find("layer")) {
    if (layer->empty()) return absl::InvalidArgumentError("--layer needs a layer's name");
    common.input.layer = *layer;
  }
  if (const std::string* server = line->Find("server")) {
    if (server->empty()) return absl::InvalidArgumentError("--server needs HOST:PORT");
    if (line->Find("backend") != nullptr) {
      return absl::InvalidArgumentError(
          "--backend applies to local builds; with --server the server picks its backend");
    }
    common.server = *server;
  }
  if (const std::string* ca = line->Find("tls-ca")) {
    if (common.server.empty()) return absl::InvalidArgumentError("--tls-ca needs --server");
    common.tls_ca_file = *ca;
  }
  if (const std::string* encoding = line->Find("encoding")) {
    if (common.server.empty()) return absl::InvalidArgumentError("--encoding needs --server");
    if (*encoding != "auto" && *encoding != "raw") {
      return absl::InvalidArgumentError(absl::StrCat("unknown --encoding '", *encoding, "' (expected auto or raw)"));
    }
    common.raw_upload = *encoding == "raw";
  }
  common.line = *std::move(line);
  return common;
}

absl::StatusOr<ClassifyArgs> ParseClassifyArgs(const CommandLine& line) {
  ClassifyArgs parsed;
  auto threshold = ParseThreshold(line);
  if (!threshold.ok()) return threshold.status();
  parsed.threshold = *threshold;
  auto mode = ParseMode(line);
  if (!mode.ok()) return mode.status();
  parsed.mode = *mode;
  auto rule = ParseVertexRule(line);
  if (!rule.ok()) return rule.status();
  parsed.rule = *rule;
  return parsed;
}

absl::StatusOr<std::vector<Point2>> ReadPoints(const CommonArgs& common) {
  try {
    return ReadInputPoints(common.file, common.input);
  } catch (const std::exception& e) {
    return absl::DataLossError(absl::StrCat("points file '", common.file, "' cannot be read: ", e.what()));
  }
}

absl::StatusOr<AlphaFamily> BuildFamily(const CommonArgs& common, const std::vector<Point2>& points) {
  BuildOptions options;
  options.backend = common.backend;
  if (points.size() >= kProgressMinPoints) {
    const auto start = std::chrono::steady_clock::now();
    options.progress = [start](std::string_view phase, double fraction) {
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::fprintf(stderr, "alphactl: %.*s done (%.0f%%, %.2f s)\n", static_cast<int>(phase.size()), phase.data(),
                   fraction * 100.0, seconds);
    };
  }
  return BuildAlphaFamily(points, options);
}

absl::StatusOr<AlphaFamily> LoadFamily(const CommonArgs& common, size_t* input_points) {
  auto points = ReadPoints(common);
  if (!points.ok()) return points.status();
  *input_points = points->size();
  return BuildFamily(common, *points);
}

absl::Status CheckThresholdRank(int64_t rank, int64_t k) {
  if (rank >= 0 && rank <= k) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat("--rank ", rank, " is outside 0..", k, " (the spectrum has ", k, " values)"));
}

absl::Status CheckMasterListRank(int64_t rank, int64_t k) {
  if (rank >= 1 && rank <= k) return absl::OkStatus();
  if (k == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("--rank ", rank, " is out of range: the spectrum is empty, the master list has no ranks"));
  }
  return absl::InvalidArgumentError(
      absl::StrCat("--rank ", rank, " is outside 1..", k, " (the spectrum has ", k, " values)"));
}

absl::StatusOr<ResolvedThreshold> ResolveThreshold(const AlphaFamily& family, const ThresholdArg& threshold) {
  Threshold resolved_from;
  switch (threshold.kind) {
    case ThresholdArg::Kind::kRank:
      if (absl::Status s = CheckThresholdRank(threshold.rank, family.max_level()); !s.ok()) return s;
      resolved_from.kind = Threshold::Kind::kRank;
      resolved_from.rank = threshold.rank;
      break;
    case ThresholdArg::Kind::kAlphaSq:
      resolved_from.kind = Threshold::Kind::kAlphaSq;
      resolved_from.value = threshold.value;
      break;
    case ThresholdArg::Kind::kAlpha:
      resolved_from.kind = Threshold::Kind::kAlpha;
      resolved_from.value = threshold.value;
      break;
    case ThresholdArg::Kind::kRatio:
      resolved_from.kind = Threshold::Kind::kRatio;
      resolved_from.value = threshold.value;
      break;
  }
  return ::galpha::ResolveThreshold(family, resolved_from);
}

int PrintBenchTable(const std::string& file, size_t input_points, uint64_t distinct_points, int64_t repeat,
                    size_t first_measure, const std::vector<std::pair<std::string, std::string>>& rows) {
  size_t name_width = std::string("stage").size(), value_width = std::string("ms").size();
  for (const auto& [name, value] : rows) {
    name_width = std::max(name_width, name.size());
    value_width = std::max(value_width, value.size());
  }
  const int nw = static_cast<int>(name_width), vw = static_cast<int>(value_width);
  std::string table = absl::StrFormat("# %s: %zu points, %u distinct, best of %d build%s\n", file, input_points,
                                      distinct_points, repeat, repeat == 1 ? "" : "s");
  absl::StrAppendFormat(&table, "%-*s  %*s\n", nw, "stage", vw, "ms");
  for (size_t i = 0; i < rows.size(); ++i) {
    if (i == first_measure) absl::StrAppendFormat(&table, "%-*s  %*s\n", nw, "measure", vw, "value");
    absl::StrAppendFormat(&table, "%-*s  %*s\n", nw, rows[i].first, vw, rows[i].second);
  }
  std::fputs(table.c_str(), stdout);
  return kExitOk;
}

}  // namespace galpha::alphactl
