#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <iterator>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.hpp"
#include "core/base/status_macros.hpp"
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

int FinishOutput(ChunkedWriter& out) {
  if (!out.Finish()) return Failure(absl::UnavailableError("cannot write to standard output"));
  return kExitOk;
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
  if (line->Find("plane") != nullptr || line->Find("slab") != nullptr) {
    auto section = ParseMoleculeSection(line->Find("plane"), line->Find("slab"));
    if (!section.ok()) return section.status();
    common.input.section = *std::move(section);
    common.input.molecule_options = true;
  }
  if (const std::string* crs = line->Find("crs")) {
    if (crs->empty()) return absl::InvalidArgumentError("--crs needs a CRS (as EPSG:4326), or none");
    common.crs = *crs;
  }
  if (const std::string* weights = line->Find("weights")) {
    if (*weights == "radius") {
      common.input.weights = InputOptions::Weights::kRadius;
    } else if (*weights == "squared") {
      common.input.weights = InputOptions::Weights::kSquared;
    } else {
      return absl::InvalidArgumentError(
          absl::StrCat("--weights is radius or squared (what the third value of a point is), not '", *weights, "'"));
    }
  }
  if (const std::string* probe = line->Find("probe")) {
    if (common.input.weights != InputOptions::Weights::kRadius) {
      return absl::InvalidArgumentError("--probe grows radii: it needs --weights radius");
    }
    double value = 0.0;
    if (!absl::SimpleAtod(*probe, &value) || !std::isfinite(value) || value < 0.0) {
      return absl::InvalidArgumentError(
          absl::StrCat("--probe is a radius, a finite number >= 0 (1.4 for water), not '", *probe, "'"));
    }
    common.input.probe = value;
  }
  if (const std::string* property = line->Find("weight-property")) {
    if (property->empty()) return absl::InvalidArgumentError("--weight-property needs a property's name");
    common.input.weight_property = *property;
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

absl::StatusOr<ClassifyArgs> ParseClassifyArgs(const CommandLine& line, bool remote) {
  ClassifyArgs parsed;
  if (const std::string* encoding = line.Find("answer-encoding")) {
    if (!remote) return absl::InvalidArgumentError("--answer-encoding needs --server");
    if (*encoding == "raw") {
      parsed.answer_encoding = AnswerEncoding::kRaw;
    } else if (*encoding == "delta") {
      parsed.answer_encoding = AnswerEncoding::kDelta;
    } else if (*encoding == "zstd") {
      parsed.answer_encoding = AnswerEncoding::kDeltaZstd;
    } else {
      return absl::InvalidArgumentError(
          absl::StrCat("unknown --answer-encoding '", *encoding, "' (expected raw, delta or zstd)"));
    }
  }
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

absl::StatusOr<std::vector<Point2>> ReadPoints(const CommonArgs& common, std::vector<double>* weights) {
  try {
    if (common.input.weights == InputOptions::Weights::kNone) return ReadInputPoints(common.file, common.input);
    GALPHA_ASSIGN_OR_RETURN(GeoreferencedPoints read, ReadInputPointsAndCrs(common.file, common.input));
    *weights = std::move(read.weights);
    return std::move(read.points);
  } catch (const std::exception& e) {
    return absl::DataLossError(absl::StrCat("points file '", common.file, "' cannot be read: ", e.what()));
  }
}

absl::StatusOr<AlphaFamily> BuildFamily(const CommonArgs& common, const std::vector<Point2>& points,
                                        const std::vector<double>& weights) {
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
  if (!weights.empty()) return BuildWeightedAlphaFamily(points, weights, options);
  return BuildAlphaFamily(points, options);
}

absl::StatusOr<FramedPoints> FramePoints(const CommonArgs& common, std::vector<Point2> input,
                                         const std::optional<std::string>& stated) {
  FramedPoints frame;
  frame.input = std::move(input);
  const std::optional<std::string> definition =
      common.crs ? (*common.crs == "none" ? std::nullopt : common.crs) : stated;
  if (!definition) return frame;
  absl::StatusOr<CrsInfo> crs = DescribeCrs(*definition);
  if (!crs.ok()) {
    return absl::Status(crs.status().code(),
                        absl::StrCat(common.crs ? "--crs: " : absl::StrCat("the CRS '", common.file, "' states: "),
                                     crs.status().message(), common.crs ? "" : " (--crs overrides it)"));
  }
  frame.crs = *std::move(crs);
  if (frame.crs->geographic) {
    absl::StatusOr<LocalMetres> local = ProjectToLocalMetres(*frame.crs, frame.input);
    if (!local.ok()) {
      return absl::Status(local.status().code(),
                          absl::StrCat("points file '", common.file, "': ", local.status().message()));
    }
    frame.projected = std::move(local->points);
    frame.projection = std::move(local->projection);
  }
  return frame;
}

absl::StatusOr<FramedPoints> ReadFramedPoints(const CommonArgs& common) {
  GeoreferencedPoints read;
  try {
    GALPHA_ASSIGN_OR_RETURN(read, ReadInputPointsAndCrs(common.file, common.input));
  } catch (const std::exception& e) {
    return absl::DataLossError(absl::StrCat("points file '", common.file, "' cannot be read: ", e.what()));
  }
  GALPHA_ASSIGN_OR_RETURN(FramedPoints frame, FramePoints(common, std::move(read.points), read.crs));
  if (!read.weights.empty() && frame.crs && frame.crs->geographic) {
    // A weight is a squared length in the units of the coordinates: degrees are none, and the
    // local projection would change distances without changing the weights.
    return absl::InvalidArgumentError(
        absl::StrCat("points file '", common.file, "': --weights needs planar coordinates, and its CRS (",
                     frame.crs->name, ") is geographic: project the points (and the radii) to a metric CRS first"));
  }
  frame.weights = std::move(read.weights);
  return frame;
}

absl::StatusOr<std::vector<Point2>> OutputPoints(const FramedPoints& frame, bool geojson) {
  if (!geojson || !frame.crs) return frame.input;
  return ToWgs84LonLat(*frame.crs, frame.input);
}

nlohmann::ordered_json CrsJson(const FramedPoints& frame) {
  if (!frame.crs) return nullptr;
  return {{"name", frame.crs->name},
          {"id", frame.crs->id.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(frame.crs->id)},
          {"geographic", frame.crs->geographic},
          {"computed_in", frame.crs->geographic ? nlohmann::ordered_json(frame.projection) : nullptr}};
}

std::string CrsLabel(const FramedPoints& frame) { return frame.crs ? CoordinatesLabel(*frame.crs) : std::string(); }

absl::StatusOr<AlphaFamily> LoadFamily(const CommonArgs& common, size_t* input_points, FramedPoints* frame) {
  GALPHA_ASSIGN_OR_RETURN(FramedPoints read, ReadFramedPoints(common));
  *input_points = read.input.size();
  absl::StatusOr<AlphaFamily> family = BuildFamily(common, read.Computed(), read.weights);
  if (frame != nullptr) *frame = std::move(read);
  return family;
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

std::vector<std::pair<std::optional<std::string>, std::vector<uint32_t>>> GroupsOf(
    const std::vector<std::optional<std::string>>& values) {
  std::vector<std::pair<std::optional<std::string>, std::vector<uint32_t>>> groups;
  std::map<std::optional<std::string>, size_t> position;
  for (uint32_t i = 0; i < values.size(); ++i) {
    auto [it, added] = position.emplace(values[i], groups.size());
    if (added) groups.emplace_back(values[i], std::vector<uint32_t>());
    groups[it->second].second.push_back(i);
  }
  return groups;
}

}  // namespace galpha::alphactl
