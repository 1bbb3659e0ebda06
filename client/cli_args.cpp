#include "client/cli_args.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <iterator>

#include "absl/strings/str_cat.h"
#include "client/point_input.hpp"
#include "core/io/input_validation.hpp"

namespace galpha::alphactl {

const char kUsage[] =
    "usage: alphactl [GLOBAL OPTIONS] COMMAND FILE [OPTIONS]\n"
    "Exact 2D alpha shapes of the points in FILE, computed locally, or by a galpha server (--server).\n"
    "\n"
    "commands:\n"
    "  triangulate FILE              the Delaunay triangulation's counts and stage times, one JSON line\n"
    "                              (with --weights, the regular triangulation and its hidden points)\n"
    "  triangulate FILE --group-by COLUMN\n"
    "                              each group's counts from one build of all the groups (unweighted)\n"
    "  spectrum FILE               the spectrum: one alpha_sq per line, ascending (shortest round-trip decimals)\n"
    "  classify FILE THRESHOLD [--mode general|regularized] [--vertex-rule report|cgal]\n"
    "           [--answer-encoding raw|delta|zstd]\n"
    "                              every simplex at THRESHOLD: 'v i CLASS' (one per distinct point),\n"
    "                              'e i j CLASS', 't i j k CLASS' (indices ascending), in that order;\n"
    "                              with --server, how the simplices come down (the same output):\n"
    "                              delta (default: varint differences, 2-bit classes, ~0.4x raw),\n"
    "                              zstd (delta compressed: slow links), raw (4-byte indices)\n"
    "  summary FILE THRESHOLD [--mode general|regularized] [--vertex-rule report|cgal]\n"
    "                              counts by class, components, holes (in the mode's complex) and\n"
    "                              interior area, one JSON line\n"
    "  shape FILE THRESHOLD --format geojson|wkt|svg [--mode general|regularized] [--min-hole-area A]\n"
    "                              the alpha shape as geometry (holes of area below A filled)\n"
    "  shape FILE THRESHOLD --group-by COLUMN --format geojson|wkt [--min-hole-area A]\n"
    "                              one regularized shape per value of a GeoJSON property or a GDAL\n"
    "                              field, each group built on its own: a FeatureCollection (group,\n"
    "                              points, level, alpha_sq, area), or 'VALUE<tab>WKT' lines\n"
    "  masterlist FILE --rank K    the master-list entries of rank K (1..K): 'v i MU_LOW|MU_HIGH',\n"
    "                              'e i j RHO|MU_LOW|MU_HIGH', 't i j k RHO'\n"
    "  optimal FILE --components N [--holes H]\n"
    "                              the smallest ranks with at most N components (and at most H holes),\n"
    "                              one JSON line (regularized: solid components with every point on a\n"
    "                              triangle, holes of the regularized complex)\n"
    "  persistence FILE [--dimension 0|1] [--min-persistence X] [--format text|csv|json|svg]\n"
    "                              the persistence diagram (H0: components, H1: holes), one class a line:\n"
    "                              'H<d> BIRTH DEATH BIRTH_RANK DEATH_RANK CREATOR KILLER' (simplices as\n"
    "                              vertices joined by '-'; 'inf' and '-' for a class that never dies);\n"
    "                              csv, JSON Lines, or an SVG plot; X: least death - birth (alpha_sq)\n"
    "  holes FILE THRESHOLD [--min-area A] [--format text|geojson]\n"
    "                              each hole of the shape of area A or more, largest first:\n"
    "                              'AREA POLYGON_INDEX POLYGON ((x y, ...))', or GeoJSON\n"
    "  bench FILE [--repeat R]     builds R times (default 1): best stage times in ms, total, peak\n"
    "                              memory, exact comparison counts, spectrum size, backend\n"
    "\n"
    "THRESHOLD, exactly one of:\n"
    "  --alpha-sq A                a squared radius (CGAL's and PostGIS's alpha), compared exactly\n"
    "  --alpha R                   a radius R >= 0 (R*R compared exactly)\n"
    "  --rank K                    the K-th spectrum value (0: the points alone)\n"
    "  --ratio F                   an area ratio 0 <= F <= 1 (PostGIS ST_ConcaveHull's target_percent):\n"
    "                              the smallest rank whose regularized area is >= F x the convex hull's\n"
    "                              (compared exactly; 1: the convex hull)\n"
    "\n"
    "GLOBAL OPTIONS, for every command, before or after it:\n"
    "  --backend auto|cpu|cuda     where the engine runs (default auto: CUDA when a GPU is visible)\n"
    "  --server HOST:PORT          run on a galpha server instead: FILE is hashed locally and uploaded\n"
    "                              only when the server does not hold it; same output (not triangulate)\n"
    "  --tls-ca FILE               with --server: talk TLS, trusting the PEM roots in FILE\n"
    "  --encoding auto|raw         with --server: how points go up (default auto: per chunk the smallest\n"
    "                              lossless encoding, scaled integers or float64, zstd-compressed;\n"
    "                              raw: 16-byte doubles, for servers older than encoded chunks)\n"
    "  --max-points N              read at most N points (default 100000000, a default server's limit;\n"
    "                              at most 1073741824, the engine's)\n"
    "  --layer NAME                the layer of a .shp, .gpkg or .fgb FILE to read (default: its first)\n"
    "  --plane xy|yz|zx            the plane a .pdb/.cif FILE's atoms are put in (default xy)\n"
    "  --slab MIN:MAX              a section: only atoms whose third coordinate (z for xy) is in\n"
    "                              [MIN, MAX] (angstrom); default: all atoms, projected\n"
    "  --crs CRS|none              the CRS of FILE's coordinates (EPSG:4326, WKT, a PROJ string), over\n"
    "                              the one FILE states (GeoJSON: WGS84; LAS, GDAL sources: theirs);\n"
    "                              none: planar coordinates. A geographic CRS (x longitude, y latitude)\n"
    "                              is computed in metres (alpha, areas) in a local projection; GeoJSON\n"
    "                              is written in WGS84 longitude/latitude, other formats in FILE's CRS\n"
    "  --weights radius|squared    weighted points (atoms, disks): every command but --group-by\n"
    "                              builds the weighted family, locally or with --server (the\n"
    "                              regular triangulation's alpha shapes; hidden points EXTERIOR).\n"
    "                              A point's third value is its radius (squared here, the weight)\n"
    "                              or its squared radius, which may be negative: the third field of\n"
    "                              text, the third column of .npy, weighted .bin, a GeoJSON\n"
    "                              property (--weight-property NAME), or for PDB and mmCIF atoms\n"
    "                              their elements' van der Waals radii (with radius)\n"
    "  --probe R                   with --weights radius: every radius grows by R before squaring\n"
    "                              (1.4 angstrom, a water probe: solvent-accessible disks)\n"
    "  -h, --help                  this text\n"
    "Options take their value as '--name VALUE' or '--name=VALUE'; '--' ends the options.\n"
    "--mode: general keeps singular simplices, regularized only what bounds or fills triangles.\n"
    "--vertex-rule: vertex classes from incident edges (report) or incident triangles (cgal).\n"
    "CLASS: EXTERIOR, SINGULAR, REGULAR or INTERIOR. Indices are input indices; a duplicate point\n"
    "is named by its first occurrence.\n"
    "\n"
    "FILE: .bin (little-endian uint64 N, then N pairs of float64 x, y), .npy (float64, N x 2),\n"
    "      .geojson/.json (Point, MultiPoint), .las (LAS 1.0-1.4 point clouds, uncompressed: x and\n"
    "      y of every point; .laz is refused), .pdb, .ent, .cif, .mmcif (also .gz: the atoms of the\n"
    "      first model, read with gemmi; --plane, --slab), .shp, .gpkg, .fgb (Shapefile,\n"
    "      GeoPackage, FlatGeobuf point layers, read with GDAL; --layer), or delimited text (CSV,\n"
    "      TSV, whitespace: x and y first, optional header line, at most 65536 bytes a line). A\n"
    "      regular file, or delimited text from a named pipe (mkfifo, /dev/stdin) or from '-',\n"
    "      standard input; devices, directories and sockets are refused.\n"
    "\n"
    "exit status: 0 success, 1 failure (unreadable file, bad input, more than --max-points), 2 usage\n"
    "error (including a rank outside the spectrum). Progress goes to standard error for 100000\n"
    "points or more.\n"
    "environment: GALPHA_TOKEN, the bearer token a server with authentication expects.\n";

// kUsage quotes these numbers.
static_assert(kDefaultMaxPoints == 100000000 && kMaxPoints == 1073741824 && kDefaultMaxLineBytes == 65536,
              "update kUsage");

const absl::string_view kGlobalOptions[12] = {"backend", "server", "tls-ca", "encoding", "max-points",      "layer",
                                              "crs",     "plane",  "slab",   "weights",  "weight-property", "probe"};

namespace {

bool IsGlobalOption(absl::string_view name) {
  return std::find(std::begin(kGlobalOptions), std::end(kGlobalOptions), name) != std::end(kGlobalOptions);
}

}  // namespace

absl::StatusOr<Invocation> SplitAtCommand(absl::Span<const std::string> argv) {
  Invocation invocation;
  size_t i = 0;
  for (; i < argv.size(); ++i) {
    const std::string& arg = argv[i];
    if (arg.size() < 2 || arg[0] != '-') break;  // the command ('-' alone is no option either)
    if (arg == "--") return absl::InvalidArgumentError("expected a command before '--'");
    const size_t equals = arg.find('=');
    const absl::string_view name = absl::string_view(arg).substr(0, equals);
    if (name.size() < 3 || name[1] != '-' || !IsGlobalOption(name.substr(2))) {
      std::string global;
      for (absl::string_view option : kGlobalOptions)
        absl::StrAppend(&global, global.empty() ? "" : ", ", "--", option);
      return absl::InvalidArgumentError(
          absl::StrCat("unknown option '", name, "' before the command (only ", global, " may come before it)"));
    }
    invocation.args.push_back(arg);
    if (equals != std::string::npos) continue;
    if (i + 1 == argv.size()) return absl::InvalidArgumentError(absl::StrCat("option ", name, " needs a value"));
    invocation.args.push_back(argv[++i]);
  }
  if (i == argv.size()) return absl::InvalidArgumentError("missing COMMAND");
  invocation.command = argv[i];
  invocation.args.insert(invocation.args.end(), argv.begin() + static_cast<std::ptrdiff_t>(i) + 1, argv.end());
  return invocation;
}

const std::string* CommandLine::Find(absl::string_view name) const {
  for (const auto& [option, value] : options) {
    if (option == name) return &value;
  }
  return nullptr;
}

absl::StatusOr<CommandLine> ParseCommandLine(absl::string_view command, absl::Span<const std::string> args,
                                             absl::Span<const absl::string_view> allowed) {
  CommandLine line;
  bool options_ended = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (options_ended || arg.size() < 2 || arg[0] != '-') {
      line.positional.push_back(arg);
      continue;
    }
    if (arg == "--") {
      options_ended = true;
      continue;
    }
    if (arg[1] != '-') {
      // A lone '-' is positional above; "-5" and "-x" are neither options nor files we expect.
      return absl::InvalidArgumentError(absl::StrCat(command, ": unknown option '", arg, "'"));
    }
    const size_t equals = arg.find('=');
    std::string name = arg.substr(2, equals == std::string::npos ? std::string::npos : equals - 2);
    bool known = false;
    for (absl::string_view a : allowed) known = known || a == name;
    if (!known) {
      return absl::InvalidArgumentError(absl::StrCat(command, ": unknown option '--", name, "'"));
    }
    std::string value;
    if (equals != std::string::npos) {
      value = arg.substr(equals + 1);
    } else if (i + 1 < args.size()) {
      value = args[++i];
    } else {
      return absl::InvalidArgumentError(absl::StrCat(command, ": option --", name, " needs a value"));
    }
    if (line.Find(name) != nullptr) {
      return absl::InvalidArgumentError(absl::StrCat(command, ": option --", name, " given twice"));
    }
    line.options.emplace_back(std::move(name), std::move(value));
  }
  return line;
}

absl::StatusOr<double> ParseFiniteDouble(absl::string_view option, const std::string& text) {
  auto bad = [&](absl::string_view why) {
    return absl::InvalidArgumentError(absl::StrCat("--", option, " '", text, "' is not ", why));
  };
  // strtod alone would skip leading spaces and accept "nan" and "inf".
  if (text.empty() || std::isspace(static_cast<unsigned char>(text[0]))) return bad("a number");
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return bad("a number");
  if (!std::isfinite(value)) return bad("a finite number");
  return value;
}

absl::StatusOr<int64_t> ParseInteger(absl::string_view option, const std::string& text, int64_t min_value) {
  int64_t value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec == std::errc::invalid_argument || ptr != end) {
    return absl::InvalidArgumentError(absl::StrCat("--", option, " '", text, "' is not an integer"));
  }
  if (ec == std::errc::result_out_of_range || value < min_value) {
    return absl::InvalidArgumentError(
        absl::StrCat("--", option, " '", text, "' is out of range (expected an integer >= ", min_value, ")"));
  }
  return value;
}

absl::StatusOr<ThresholdArg> ParseThreshold(const CommandLine& line) {
  std::vector<absl::string_view> given;
  for (const auto& [name, value] : line.options) {
    if (name == "alpha-sq" || name == "alpha" || name == "rank" || name == "ratio") given.emplace_back(name);
  }
  if (given.empty()) {
    return absl::InvalidArgumentError(
        "missing threshold: give one of --alpha-sq A, --alpha R, --rank K or --ratio F (an area ratio, 0..1)");
  }
  if (given.size() > 1) {
    return absl::InvalidArgumentError(absl::StrCat("give only one threshold, got --", given[0], " and --", given[1]));
  }
  ThresholdArg threshold;
  const std::string& text = *line.Find(given[0]);
  if (given[0] == "rank") {
    auto rank = ParseInteger("rank", text, 0);
    if (!rank.ok()) return rank.status();
    threshold.kind = ThresholdArg::Kind::kRank;
    threshold.rank = *rank;
    return threshold;
  }
  auto value = ParseFiniteDouble(given[0], text);
  if (!value.ok()) return value.status();
  threshold.value = *value;
  if (given[0] == "alpha-sq") {
    threshold.kind = ThresholdArg::Kind::kAlphaSq;
  } else if (given[0] == "ratio") {
    if (*value < 0 || *value > 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("--ratio '", text, "' is outside 0..1 (the share of the convex hull's area the shape covers)"));
    }
    threshold.kind = ThresholdArg::Kind::kRatio;
  } else {
    if (*value < 0) {
      return absl::InvalidArgumentError(absl::StrCat("--alpha '", text, "' is a radius and must be >= 0"));
    }
    threshold.kind = ThresholdArg::Kind::kAlpha;
  }
  return threshold;
}

absl::StatusOr<uint64_t> ParseMaxPoints(const CommandLine& line) {
  const std::string* text = line.Find("max-points");
  if (text == nullptr) return kDefaultMaxPoints;
  auto value = ParseInteger("max-points", *text, 1);
  if (!value.ok()) return value.status();
  if (static_cast<uint64_t>(*value) > kMaxPoints) {
    return absl::InvalidArgumentError(
        absl::StrCat("--max-points '", *text, "' is more than ", kMaxPoints, ", the most points the engine takes"));
  }
  return static_cast<uint64_t>(*value);
}

absl::StatusOr<Backend> ParseBackend(const CommandLine& line) {
  const std::string* name = line.Find("backend");
  if (name == nullptr || *name == "auto") return Backend::kAuto;
  if (*name == "cpu") return Backend::kCpu;
  if (*name == "cuda") return Backend::kCuda;
  return absl::InvalidArgumentError(absl::StrCat("unknown backend '", *name, "' (expected auto, cpu or cuda)"));
}

absl::StatusOr<ClassifyMode> ParseMode(const CommandLine& line) {
  const std::string* name = line.Find("mode");
  if (name == nullptr || *name == "general") return ClassifyMode::kGeneral;
  if (*name == "regularized") return ClassifyMode::kRegularized;
  return absl::InvalidArgumentError(absl::StrCat("unknown --mode '", *name, "' (expected general or regularized)"));
}

absl::StatusOr<VertexRule> ParseVertexRule(const CommandLine& line) {
  const std::string* name = line.Find("vertex-rule");
  if (name == nullptr || *name == "report") return VertexRule::kReport;
  if (*name == "cgal") return VertexRule::kCgal;
  return absl::InvalidArgumentError(absl::StrCat("unknown --vertex-rule '", *name, "' (expected report or cgal)"));
}

const char* ModeName(ClassifyMode mode) { return mode == ClassifyMode::kGeneral ? "general" : "regularized"; }

const char* VertexRuleName(VertexRule rule) { return rule == VertexRule::kReport ? "report" : "cgal"; }

}  // namespace galpha::alphactl
