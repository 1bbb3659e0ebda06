// alphactl's commands, each run on the words after its name and returning the exit status
// (cli_args.hpp: kExitOk, kExitFailure, kExitUsage), and what they share: loading a family with
// progress on standard error, resolving a threshold, one-line error reports.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"
#include "client/cli_args.hpp"
#include "client/point_input.hpp"
#include "client/text_output.hpp"
#include "client/topology_output.hpp"
#include "core/base/point.hpp"
#include "core/family/alpha_family.hpp"
#include "core/family/threshold.hpp"
#include "core/geometry/shape.hpp"
#include "core/io/coordinate_system.hpp"
#include "nlohmann/json.hpp"

namespace galpha::alphactl {

using Args = absl::Span<const std::string>;

int RunTriangulate(Args args);
int RunSpectrum(Args args);
int RunClassify(Args args);
int RunSummary(Args args);
int RunShape(Args args);
int RunMasterList(Args args);
int RunOptimal(Args args);
int RunBench(Args args);
int RunPersistence(Args args);
int RunHoles(Args args);

// ---- shared by the commands (command_support.cpp) ----

/// Prints "alphactl: MESSAGE (see 'alphactl --help')" on one line to stderr; returns kExitUsage.
int UsageError(const absl::Status& status);
/// A usage error that the help text would not fix (a rank outside this file's spectrum): prints
/// "alphactl: MESSAGE" on one line to stderr; returns kExitUsage.
int ArgumentError(const absl::Status& status);
/// Flushes `out`: kExitOk, or a Failure when standard output could not be written.
int FinishOutput(ChunkedWriter& out);
/// Prints "alphactl: MESSAGE" on one line to stderr; returns kExitFailure.
int Failure(const absl::Status& status);

/// What every command parses first: its options, its one FILE and the global options.
struct CommonArgs {
  CommandLine line;
  std::string file;
  Backend backend = Backend::kAuto;
  /// --server HOST:PORT: run against a galpha server instead of the embedded engine.
  std::string server;
  /// --tls-ca FILE: PEM roots; talk TLS to the server.
  std::string tls_ca_file;
  /// --encoding raw: send PointChunk doubles (servers older than EncodedPointChunk refuse the
  /// compact chunks that the default, auto, picks).
  bool raw_upload = false;
  /// How FILE is read: --max-points, --layer.
  InputOptions input;
  /// --crs: the CRS of FILE's coordinates, overriding the one the file states ("none": planar
  /// coordinates, no CRS, whatever the file states).
  std::optional<std::string> crs;
};
/// ParseCommandLine with `allowed` and kGlobalOptions, then exactly one positional FILE and valid
/// global options. --backend with --server, or --tls-ca without it, is a usage error.
absl::StatusOr<CommonArgs> ParseCommon(absl::string_view command, Args args,
                                       absl::Span<const absl::string_view> allowed);

/// How a server sends classify's simplices (--answer-encoding; the proto's SimplexEncoding).
enum class AnswerEncoding { kRaw, kDelta, kDeltaZstd };

/// classify's and summary's options after FILE.
struct ClassifyArgs {
  ThresholdArg threshold;
  ClassifyMode mode = ClassifyMode::kGeneral;
  VertexRule rule = VertexRule::kReport;
  /// classify --answer-encoding raw|delta|zstd (with --server only; default delta).
  AnswerEncoding answer_encoding = AnswerEncoding::kDelta;
};
/// `remote`: whether --server was given (--answer-encoding needs it).
absl::StatusOr<ClassifyArgs> ParseClassifyArgs(const CommandLine& line, bool remote = false);

/// persistence's options after FILE: --dimension 0|1 (default both), --min-persistence X >= 0
/// (alpha_sq units), --format text|csv|json|svg (default text).
struct PersistenceArgs {
  std::array<bool, 2> dimensions = {true, true};
  double min_persistence = 0.0;
  PersistenceFormat format = PersistenceFormat::kText;
};
absl::StatusOr<PersistenceArgs> ParsePersistenceArgs(const CommandLine& line);

/// holes' options after FILE: a THRESHOLD, --min-area A >= 0 (squared input units; default 0),
/// --format text|geojson (default text).
struct HolesArgs {
  ThresholdArg threshold;
  double min_area = 0.0;
  HolesFormat format = HolesFormat::kText;
};
absl::StatusOr<HolesArgs> ParseHolesArgs(const CommandLine& line);

/// ReadInputPoints of the command's FILE (read once: it may be a pipe), with an exception thrown
/// while reading (out of memory) reported as an error. With --weights the weights (squared radii)
/// go to *weights.
absl::StatusOr<std::vector<Point2>> ReadPoints(const CommonArgs& common, std::vector<double>* weights);

/// FILE's points and the frame the family is computed in (docs/design.md, "Coordinate reference
/// systems"): with a geographic CRS, the local projection of the points, in metres; otherwise
/// the points as read.
struct FramedPoints {
  /// As read: the coordinates of the output geometry (WKT, SVG, text rings).
  std::vector<Point2> input;
  /// The local projection of `input` (geographic CRS only; empty otherwise).
  std::vector<Point2> projected;
  /// The CRS in effect: --crs, else the one FILE states; nullopt for planar coordinates.
  std::optional<CrsInfo> crs;
  /// The local projection as a PROJ string (geographic CRS only).
  std::string projection;
  /// With --weights: each point's weight (squared radius, in the input's squared units); empty
  /// otherwise.
  std::vector<double> weights;

  /// What the family is built from, and what areas are measured in.
  const std::vector<Point2>& Computed() const { return crs && crs->geographic ? projected : input; }
};
/// Reads FILE and resolves its CRS. Errors: ReadPoints's, an unknown CRS (naming --crs or the
/// file), points that are not longitudes and latitudes of a geographic CRS.
absl::StatusOr<FramedPoints> ReadFramedPoints(const CommonArgs& common);
/// The frame of `input` under --crs, else the CRS `stated` by FILE (ReadFramedPoints after the
/// read; --group-by frames each group on its own, with a projection centred on it).
absl::StatusOr<FramedPoints> FramePoints(const CommonArgs& common, std::vector<Point2> input,
                                         const std::optional<std::string>& stated);
/// The coordinates a format is written in: for GeoJSON, WGS84 longitude/latitude where a CRS is
/// known (RFC 7946); otherwise, and for every other format, the input's.
absl::StatusOr<std::vector<Point2>> OutputPoints(const FramedPoints& frame, bool geojson);
/// The CRS in effect as a summary reports it: null, or name, id (null if none), geographic, and
/// the local projection the family was computed in (null for a planar CRS).
nlohmann::ordered_json CrsJson(const FramedPoints& frame);
/// "coordinates in CRS NAME (ID)", what an SVG's <desc> says; empty without a CRS.
std::string CrsLabel(const FramedPoints& frame);

/// Builds the family of `points` (weighted when `weights` is not empty) on the command's backend;
/// for 100000 points or more, reports each build phase on stderr.
absl::StatusOr<AlphaFamily> BuildFamily(const CommonArgs& common, const std::vector<Point2>& points,
                                        const std::vector<double>& weights);

/// ReadFramedPoints, then BuildFamily of the computed points. `input_points` receives the number of
/// points read, `frame` (when given) the points and their CRS.
absl::StatusOr<AlphaFamily> LoadFamily(const CommonArgs& common, size_t* input_points, FramedPoints* frame = nullptr);

/// A threshold resolved against a family (core/family/threshold.hpp).
using ResolvedThreshold = ::galpha::ResolvedThreshold;
/// core/family/threshold.hpp's resolution of --alpha-sq, --alpha or --rank, with a rank outside
/// 0..K reported in alphactl's words (naming --rank).
/// Errors (InvalidArgument, for ArgumentError).
absl::StatusOr<ResolvedThreshold> ResolveThreshold(const AlphaFamily& family, const ThresholdArg& threshold);

/// bench's table: a header line, then rows of (stage, ms) and, from row `first_measure` on,
/// (measure, value) under their own heading. Returns kExitOk.
int PrintBenchTable(const std::string& file, size_t input_points, uint64_t distinct_points, int64_t repeat,
                    size_t first_measure, const std::vector<std::pair<std::string, std::string>>& rows);

/// The checks of a --rank against a spectrum of `k` values, shared by the local and the remote
/// commands so that both print the same line: a threshold rank must be in 0..K, a master-list
/// rank in 1..K. OK, or InvalidArgument (for ArgumentError).
absl::Status CheckThresholdRank(int64_t rank, int64_t k);
absl::Status CheckMasterListRank(int64_t rank, int64_t k);

/// The points of each group (--group-by: a point's value of the column, or none), by input
/// index, in the order the groups first appear.
std::vector<std::pair<std::optional<std::string>, std::vector<uint32_t>>> GroupsOf(
    const std::vector<std::optional<std::string>>& values);

/// shape --group-by COLUMN: one regularized shape per group of FILE's points (their values of a
/// GeoJSON property or a GDAL layer's field), each built on its own (with --server: all in one
/// BuildBatch call), in the order the groups first appear: a GeoJSON FeatureCollection (one MultiPolygon feature per
/// group, properties group, points, level, alpha_sq, area) or, for wkt, one line per group: the value, a tab, the WKT.
int RunGroupedShape(const CommonArgs& common, const ThresholdArg& threshold, const std::string& format,
                    double min_hole_area);

// ---- the same commands against a server (commands_remote.cpp), same output formats ----

int RemoteSpectrum(const CommonArgs& common);
int RemoteClassify(const CommonArgs& common, const ClassifyArgs& options);
int RemoteSummary(const CommonArgs& common, const ClassifyArgs& options);
int RemoteShape(const CommonArgs& common, const ThresholdArg& threshold, ClassifyMode mode, const std::string& format,
                double min_hole_area);
int RemoteMasterList(const CommonArgs& common, int64_t rank);
int RemoteOptimal(const CommonArgs& common, int64_t components, std::optional<int64_t> holes);
int RemoteBench(const CommonArgs& common, int64_t repeat);
int RemotePersistence(const CommonArgs& common, const PersistenceArgs& options);
int RemoteHoles(const CommonArgs& common, const HolesArgs& options);

/// One set's regularized shape at a threshold, as the server answers it.
struct RemoteSetShape {
  int64_t level = 0;
  double alpha_sq = 0;
  ShapeGeometry shape;
};
/// shape --group-by --server: the sets (a name and the computed points each) built in one
/// BuildBatch call, then each one's level, squared alpha and regularized shape (holes smaller than
/// `min_hole_area` filled) at `threshold`. An error names the set by `names`' entry.
absl::StatusOr<std::vector<RemoteSetShape>> RemoteSetShapes(const CommonArgs& common,
                                                            const std::vector<std::string>& names,
                                                            const std::vector<absl::Span<const Point2>>& sets,
                                                            const ThresholdArg& threshold, double min_hole_area);

}  // namespace galpha::alphactl
