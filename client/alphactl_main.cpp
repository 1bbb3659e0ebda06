// alphactl: galpha on the command line, working locally with no server (the embedded engine).
//
//   alphactl triangulate FILE.bin [--backend=auto|cpu|cuda]
//
// prints one JSON object summarising the Delaunay triangulation of the points in FILE.bin.
// Errors are one line on standard error and a non-zero exit status.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "core/point_formats.hpp"
#include "gpu/delaunay.hpp"

namespace {

constexpr char kUsage[] =
    "usage: alphactl triangulate FILE [--backend=auto|cpu|cuda]\n"
    "  FILE: .bin (little-endian uint64 N, then N pairs of float64 x, y), .npy (float64, N x 2),\n"
    "        .geojson/.json (Point, MultiPoint), or delimited text (CSV, TSV, whitespace:\n"
    "        x and y first, optional header line)\n";

// A JSON string literal for `text` (quotes, backslashes and control characters escaped).
std::string JsonString(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", static_cast<unsigned>(c));
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

absl::StatusOr<galpha::Backend> ParseBackend(const std::string& name) {
  if (name == "auto") return galpha::Backend::kAuto;
  if (name == "cpu") return galpha::Backend::kCpu;
  if (name == "cuda") return galpha::Backend::kCuda;
  return absl::InvalidArgumentError(absl::StrCat("unknown backend '", name, "' (expected auto, cpu or cuda)"));
}

int Fail(const std::string& message) {
  std::fprintf(stderr, "alphactl: %s\n", message.c_str());
  return 1;
}

int Triangulate(const std::vector<std::string>& args) {
  std::string file;
  galpha::TriangulateOptions options;
  for (const std::string& arg : args) {
    if (arg.rfind("--backend=", 0) == 0) {
      auto backend = ParseBackend(arg.substr(std::strlen("--backend=")));
      if (!backend.ok()) return Fail(std::string(backend.status().message()));
      options.backend = *backend;
    } else if (!arg.empty() && arg[0] == '-') {
      return Fail(absl::StrCat("unknown option '", arg, "'\n", kUsage));
    } else if (file.empty()) {
      file = arg;
    } else {
      return Fail(absl::StrCat("unexpected argument '", arg, "'\n", kUsage));
    }
  }
  if (file.empty()) return Fail(absl::StrCat("missing FILE\n", kUsage));

  auto points = galpha::ReadPointsFile(file);
  if (!points.ok()) return Fail(std::string(points.status().message()));
  auto tri = galpha::Triangulate(*points, options);
  if (!tri.ok()) return Fail(std::string(tri.status().message()));

  size_t hull_edges = 0;
  for (const auto& n : tri->neighbors) {
    for (int32_t x : n) hull_edges += x == galpha::Triangulation::kNoNeighbor ? 1 : 0;
  }
  if (tri->triangles.empty()) hull_edges = tri->edges.size();
  double total = 0.0;
  std::string stages;
  for (const auto& s : tri->stage_times) {
    absl::StrAppend(&stages, stages.empty() ? "" : ", ", "\"", s.stage, "\": ", s.seconds * 1e3);
    total += s.seconds;
  }
  std::printf(
      "{\"file\": %s, \"points\": %zu, \"distinct_points\": %u, \"duplicates\": %zu, "
      "\"triangles\": %zu, \"edges\": %zu, \"hull_edges\": %zu, \"backend\": \"%s\", "
      "\"peak_memory_bytes\": %zu, \"total_ms\": %.3f, \"stage_ms\": {%s}}\n",
      JsonString(file).c_str(), points->size(), tri->num_unique, points->size() - tri->num_unique, tri->triangles.size(),
      tri->edges.size(), hull_edges, galpha::BackendName(tri->backend), tri->peak_memory_bytes, total * 1e3,
      stages.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::fputs(kUsage, args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "triangulate") return Triangulate({args.begin() + 1, args.end()});
  return Fail(absl::StrCat("unknown command '", args[0], "'\n", kUsage));
}
