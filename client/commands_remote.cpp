// alphactl's commands against a galpha server (--server HOST:PORT): the file is read and hashed
// locally, uploaded only when the server does not hold its handle yet, and every answer is printed
// in exactly the format of the local commands, so that scripts do not care where the work ran.
// The bearer token, when the server needs one, comes from the environment (GALPHA_TOKEN), never
// from the command line, where other users of the machine could read it.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.hpp"
#include "client/galpha_client.hpp"
#include "client/text_output.hpp"
#include "core/base/status_macros.hpp"
#include "core/geometry/shape.hpp"
#include "core/geometry/shape_holes.hpp"
#include "core/io/point_set_handle.hpp"
#include "nlohmann/json.hpp"

namespace galpha::alphactl {

namespace v1 = galpha::v1;

namespace {

constexpr size_t kProgressMinPoints = 100000;

/// A family on the server: the connection, the handle and its summary.
struct RemoteFamily {
  std::unique_ptr<client::AlphaClient> client;
  client::BuildResult build;
  size_t input_points = 0;
  /// FILE's points (read once: it may be a pipe) and their CRS: the server holds the computed
  /// ones; answers written here (holes, shapes in a CRS) take their coordinates from the input.
  FramedPoints frame;
};

absl::StatusOr<std::unique_ptr<client::AlphaClient>> ConnectTo(const CommonArgs& common) {
  client::ClientOptions options;
  options.target = common.server;
  if (const char* token = std::getenv("GALPHA_TOKEN")) options.bearer_token = token;
  if (!common.tls_ca_file.empty()) {
    std::ifstream in(common.tls_ca_file);
    if (!in) return absl::NotFoundError(absl::StrCat("cannot read the --tls-ca file '", common.tls_ca_file, "'"));
    std::stringstream pem;
    pem << in.rdbuf();
    options.tls_root_certs_pem = pem.str();
  }
  return client::AlphaClient::Connect(options);
}

absl::Status ServerError(const CommonArgs& common, const absl::Status& status) {
  return absl::Status(status.code(), absl::StrCat("server ", common.server, ": ", status.message()));
}

/// Reads FILE, then finds or builds its family on the server (progress on stderr for large files).
absl::StatusOr<RemoteFamily> OpenRemote(const CommonArgs& common, bool skip_upload_if_cached = true) {
  auto frame = ReadFramedPoints(common);
  if (!frame.ok()) return frame.status();
  // With a geographic CRS the server gets the local projection: the family is in metres.
  const std::vector<Point2>* points = &frame->Computed();
  RemoteFamily remote;
  remote.input_points = points->size();
  auto connected = ConnectTo(common);
  if (!connected.ok()) return connected.status();
  remote.client = *std::move(connected);
  client::BuildCallOptions options;
  options.name = common.file;
  options.skip_upload_if_cached = skip_upload_if_cached;
  options.weights = frame->weights;  // with --weights: the weighted family
  if (common.raw_upload) options.encoding = client::PointEncoding::kRaw;
  const bool verbose = points->size() >= kProgressMinPoints;
  const auto start = std::chrono::steady_clock::now();
  if (verbose) {
    options.progress = [start, total = points->size(), last = size_t{0}](uint64_t sent) mutable {
      // About ten lines per upload.
      if (sent != total && sent - last < total / 10) return;
      last = sent;
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::fprintf(stderr, "alphactl: uploaded %llu of %zu points (%.2f s)\n", static_cast<unsigned long long>(sent),
                   total, seconds);
    };
  }
  auto built = remote.client->Build(*points, options);
  if (!built.ok()) return ServerError(common, built.status());
  remote.build = *std::move(built);
  if (verbose) {
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::string upload =
        remote.build.uploaded
            ? absl::StrFormat("; %llu bytes of points sent, %.2f per point",
                              static_cast<unsigned long long>(remote.build.upload_bytes),
                              static_cast<double>(remote.build.upload_bytes) / std::max<double>(1.0, points->size()))
            : std::string();
    std::fprintf(stderr, "alphactl: %s on the server (%.2f s%s)\n",
                 remote.build.cached ? "family found" : "family built", seconds, upload.c_str());
  }
  remote.frame = *std::move(frame);
  return remote;
}

/// The proto threshold of a command-line threshold; a rank outside 0..K gives the local
/// command's error message (the summary knows K).
absl::StatusOr<v1::Threshold> ToThreshold(const ThresholdArg& threshold, uint64_t spectrum_size) {
  v1::Threshold out;
  const int64_t k = static_cast<int64_t>(spectrum_size);
  switch (threshold.kind) {
    case ThresholdArg::Kind::kRank:
      if (absl::Status s = CheckThresholdRank(threshold.rank, k); !s.ok()) return s;
      out.set_rank(threshold.rank);
      break;
    case ThresholdArg::Kind::kAlphaSq:
      out.set_alpha_sq(threshold.value);
      break;
    case ThresholdArg::Kind::kAlpha:
      out.set_alpha(threshold.value);
      break;
    case ThresholdArg::Kind::kRatio:
      out.set_ratio(threshold.value);
      break;
  }
  return out;
}

absl::StatusOr<v1::Threshold> ToThreshold(const ThresholdArg& threshold, const RemoteFamily& remote) {
  return ToThreshold(threshold, remote.build.summary.spectrum_size());
}

v1::ClassifyMode ToProto(ClassifyMode mode) {
  return mode == ClassifyMode::kRegularized ? v1::CLASSIFY_MODE_REGULARIZED : v1::CLASSIFY_MODE_GENERAL;
}

v1::VertexRule ToProto(VertexRule rule) {
  return rule == VertexRule::kCgal ? v1::VERTEX_RULE_CGAL : v1::VERTEX_RULE_REPORT;
}

/// classify's and summary's request: the family's handle and the command line's options.
absl::StatusOr<v1::ClassifyRequest> ClassifyRequestFor(const ClassifyArgs& options, const RemoteFamily& remote) {
  auto threshold = ToThreshold(options.threshold, remote);
  if (!threshold.ok()) return threshold.status();
  v1::ClassifyRequest request;
  request.set_handle(remote.build.handle);
  *request.mutable_threshold() = *threshold;
  request.set_mode(ToProto(options.mode));
  request.set_vertex_rule(ToProto(options.rule));
  return request;
}

/// A query's failure: INVALID_ARGUMENT is the user's (exit 2), anything else a failure (exit 1).
int QueryError(const CommonArgs& common, const absl::Status& status) {
  if (absl::IsInvalidArgument(status)) return ArgumentError(status);
  return Failure(ServerError(common, status));
}

std::array<uint64_t, 4> FromProto(const v1::ClassCounts& counts) {
  return {counts.exterior(), counts.singular(), counts.regular(), counts.interior()};
}

/// A weighted family's hidden points (input indices, ascending), as the local summary lists them;
/// null for an unweighted family. The server counts them (BuildSummary.hidden_points) and
/// Classify at rank 0 reports them as its EXTERIOR vertices, first occurrences only: their
/// duplicates (the same position and the same weight: a lighter point at a heavier one's
/// position is a point of its own, hidden, and listed) are found among FILE's weighted points.
/// Classify stops after the vertices.
absl::StatusOr<nlohmann::ordered_json> RemoteHiddenPoints(const RemoteFamily& remote) {
  const v1::BuildSummary& build = remote.build.summary;
  if (!build.weighted()) return nullptr;
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  if (build.hidden_points() == 0) return list;
  v1::ClassifyRequest request;
  request.set_handle(remote.build.handle);
  request.mutable_threshold()->set_rank(0);
  const std::vector<Point2>& points = remote.frame.Computed();
  const std::vector<double>& weights = remote.frame.weights;
  if (weights.size() != points.size()) {
    return absl::InternalError("the server holds a weighted family of points sent without weights");
  }
  // Compared as values (-0.0 equals 0.0), as the engine finds duplicates.
  std::set<std::tuple<double, double, double>> hidden_at;
  bool past_vertices = false;
  absl::Status status = remote.client->Classify(request, [&](const v1::ClassifyResponse& message) {
    if (!message.has_chunk()) return absl::OkStatus();
    const v1::SimplexChunk& chunk = message.chunk();
    if (chunk.kind() != v1::SIMPLEX_KIND_VERTEX) {
      past_vertices = true;
      return absl::CancelledError("the vertices are all here");  // ends the stream
    }
    if (static_cast<size_t>(chunk.vertex_indices_size()) != chunk.classes().size()) {
      return absl::DataLossError("a Classify chunk's indices and classes disagree in length");
    }
    for (size_t i = 0; i < chunk.classes().size(); ++i) {
      if (static_cast<unsigned char>(chunk.classes()[i]) != v1::SIMPLEX_CLASS_EXTERIOR) continue;
      const uint32_t v = chunk.vertex_indices(static_cast<int>(i));
      if (v >= points.size())
        return absl::DataLossError(absl::StrCat("Classify names vertex ", v, " of ", points.size()));
      hidden_at.emplace(points[v].x, points[v].y, weights[v]);
    }
    return absl::OkStatus();
  });
  if (!status.ok() && !past_vertices) return status;
  for (size_t i = 0; i < points.size(); ++i) {
    if (hidden_at.count({points[i].x, points[i].y, weights[i]}) != 0) list.push_back(i);
  }
  if (list.size() != build.hidden_points()) {
    return absl::DataLossError(absl::StrCat("the server counts ", build.hidden_points(),
                                            " hidden points; Classify at rank 0 gives ", list.size()));
  }
  return list;
}

}  // namespace

int RemoteSpectrum(const CommonArgs& common) {
  auto remote = OpenRemote(common);
  if (!remote.ok()) return Failure(remote.status());
  ChunkedWriter out(stdout);
  v1::SpectrumRequest request;
  request.set_handle(remote->build.handle);
  request.set_page_size(262144);
  int64_t next = 1;
  while (next != 0) {
    request.set_first_rank(next);
    auto page = remote->client->Spectrum(request);
    if (!page.ok()) return QueryError(common, page.status());
    for (const double alpha_sq : page->alpha_sq()) {
      out.AppendDouble(alpha_sq);
      out.Append('\n');
    }
    next = page->next_rank();
  }
  return FinishOutput(out);
}

int RemoteClassify(const CommonArgs& common, const ClassifyArgs& options) {
  auto remote = OpenRemote(common);
  if (!remote.ok()) return Failure(remote.status());
  auto request = ClassifyRequestFor(options, *remote);
  if (!request.ok()) return ArgumentError(request.status());
  // The client decodes every encoding to the same chunks: the output does not depend on it.
  request->set_simplex_encoding(options.answer_encoding == AnswerEncoding::kRaw     ? v1::SIMPLEX_ENCODING_RAW
                                : options.answer_encoding == AnswerEncoding::kDelta ? v1::SIMPLEX_ENCODING_DELTA
                                                                                    : v1::SIMPLEX_ENCODING_DELTA_ZSTD);
  ChunkedWriter out(stdout);
  absl::Status status = remote->client->Classify(*request, [&](const v1::ClassifyResponse& message) {
    if (!message.has_chunk()) return absl::OkStatus();
    const v1::SimplexChunk& chunk = message.chunk();
    const int arity = chunk.kind() == v1::SIMPLEX_KIND_VERTEX ? 1 : chunk.kind() == v1::SIMPLEX_KIND_EDGE ? 2 : 3;
    const char kind = "?vet"[arity];
    if (static_cast<size_t>(chunk.vertex_indices_size()) != chunk.classes().size() * static_cast<size_t>(arity)) {
      return absl::DataLossError("a Classify chunk's indices and classes disagree in length");
    }
    for (size_t i = 0; i < chunk.classes().size(); ++i) {
      const int code = static_cast<unsigned char>(chunk.classes()[i]);
      if (code < 1 || code > 4) return absl::DataLossError(absl::StrCat("unknown simplex class ", code));
      out.Append(kind);
      for (int k = 0; k < arity; ++k) {
        out.Append(' ');
        out.AppendUint(chunk.vertex_indices(static_cast<int>(i) * arity + k));
      }
      out.Append(' ');
      out.Append(SimplexClassName(static_cast<SimplexClass>(code - 1)));
      out.Append('\n');
    }
    return absl::OkStatus();
  });
  if (!status.ok()) return QueryError(common, status);
  return FinishOutput(out);
}

int RemoteSummary(const CommonArgs& common, const ClassifyArgs& options) {
  auto remote = OpenRemote(common);
  if (!remote.ok()) return Failure(remote.status());
  auto request = ClassifyRequestFor(options, *remote);
  if (!request.ok()) return ArgumentError(request.status());
  request->set_summary_only(true);
  v1::ClassifySummary summary;
  absl::Status status = remote->client->Classify(*request, [&](const v1::ClassifyResponse& message) {
    if (message.has_summary()) summary = message.summary();
    return absl::OkStatus();
  });
  if (!status.ok()) return QueryError(common, status);
  auto hidden = RemoteHiddenPoints(*remote);
  if (!hidden.ok()) return QueryError(common, hidden.status());
  const v1::BuildSummary& build = remote->build.summary;
  const nlohmann::ordered_json json = {{"file", common.file},
                                       {"points", remote->input_points},
                                       {"distinct_points", build.distinct_points()},
                                       {"duplicates", build.duplicates()},
                                       {"hidden_points", *std::move(hidden)},
                                       {"spectrum_size", build.spectrum_size()},
                                       {"level", summary.level()},
                                       {"alpha_sq", summary.alpha_sq()},
                                       {"mode", ModeName(options.mode)},
                                       {"vertex_rule", VertexRuleName(options.rule)},
                                       {"vertices", ClassCountsJson(FromProto(summary.vertices()))},
                                       {"edges", ClassCountsJson(FromProto(summary.edges()))},
                                       {"triangles", ClassCountsJson(FromProto(summary.triangles()))},
                                       {"components", summary.components()},
                                       {"solid_components", summary.solid_components()},
                                       {"holes", summary.holes()},
                                       {"interior_area", summary.interior_area()},
                                       {"hull_area", summary.hull_area()},
                                       {"crs", CrsJson(remote->frame)},
                                       {"backend", build.backend()}};
  std::fputs(JsonLine(json).c_str(), stdout);
  return kExitOk;
}

/// The shape a rings-format ShapeRequest answers, every index checked against the `n` points.
absl::StatusOr<ShapeGeometry> RingsOfShape(client::AlphaClient& client, size_t n, const v1::ShapeRequest& request) {
  ShapeGeometry shape;
  auto checked = [n](const auto& indices) -> absl::Status {
    for (uint32_t v : indices) {
      if (v >= n) return absl::DataLossError("shape: the server named a vertex beyond FILE's");
    }
    return absl::OkStatus();
  };
  GALPHA_RETURN_IF_ERROR(client.Shape(request, [&](const v1::ShapeResponse& m) -> absl::Status {
    const v1::ShapeRings& rings = m.rings();
    for (const v1::ShapePolygon& polygon : rings.polygons()) {
      GALPHA_RETURN_IF_ERROR(checked(polygon.outer()));
      ShapePolygon& out = shape.polygons.emplace_back();
      out.outer.assign(polygon.outer().begin(), polygon.outer().end());
      for (const v1::Ring& hole : polygon.holes()) {
        GALPHA_RETURN_IF_ERROR(checked(hole.vertex_indices()));
        out.holes.emplace_back(hole.vertex_indices().begin(), hole.vertex_indices().end());
      }
    }
    GALPHA_RETURN_IF_ERROR(checked(rings.singular_edges()));
    GALPHA_RETURN_IF_ERROR(checked(rings.isolated_points()));
    if (rings.singular_edges_size() % 2 != 0) return absl::DataLossError("shape: an odd number of edge indices");
    for (int i = 0; i + 1 < rings.singular_edges_size(); i += 2) {
      shape.singular_edges.push_back({rings.singular_edges(i), rings.singular_edges(i + 1)});
    }
    shape.isolated_points.insert(shape.isolated_points.end(), rings.isolated_points().begin(),
                                 rings.isolated_points().end());
    shape.area += rings.area();
    return absl::OkStatus();
  }));
  return shape;
}

int RemoteShape(const CommonArgs& common, const ThresholdArg& threshold_arg, ClassifyMode mode,
                const std::string& format, double min_hole_area) {
  auto remote = OpenRemote(common);
  if (!remote.ok()) return Failure(remote.status());
  auto threshold = ToThreshold(threshold_arg, *remote);
  if (!threshold.ok()) return ArgumentError(threshold.status());
  v1::ShapeRequest request;
  request.set_handle(remote->build.handle);
  *request.mutable_threshold() = *threshold;
  request.set_mode(ToProto(mode));
  request.set_format(format == "geojson" ? v1::SHAPE_FORMAT_GEOJSON
                     : format == "wkt"   ? v1::SHAPE_FORMAT_WKT
                                         : v1::SHAPE_FORMAT_SVG);
  request.set_min_hole_area(min_hole_area);
  if (remote->frame.crs) {
    // The server holds the computed (projected) points: the geometry is written here, in the
    // coordinates of the format (docs/design.md, "Coordinate reference systems").
    request.set_format(v1::SHAPE_FORMAT_RINGS);
    auto shape = RingsOfShape(*remote->client, remote->frame.input.size(), request);
    if (!shape.ok()) return QueryError(common, shape.status());
    auto points = OutputPoints(remote->frame, format == "geojson");
    if (!points.ok()) return Failure(points.status());
    std::string text = format == "geojson" ? ShapeToGeoJson(*shape, *points)
                       : format == "wkt"   ? ShapeToWkt(*shape, *points)
                                           : ShapeToSvg(*shape, *points, CrsLabel(remote->frame));
    if (text.empty() || text.back() != '\n') text += '\n';
    ChunkedWriter out(stdout);
    out.Append(text);
    return FinishOutput(out);
  }
  ChunkedWriter out(stdout);
  char last = '\n';
  bool any = false;
  absl::Status status = remote->client->Shape(request, [&](const v1::ShapeResponse& message) {
    if (!message.text().empty()) {
      out.Append(message.text());
      last = message.text().back();
      any = true;
    }
    return absl::OkStatus();
  });
  if (!status.ok()) return QueryError(common, status);
  if (!any || last != '\n') out.Append('\n');
  return FinishOutput(out);
}

namespace {

/// At most `bytes` of `text`, cut at a UTF-8 character boundary.
std::string Utf8Prefix(const std::string& text, size_t bytes) {
  if (text.size() <= bytes) return text;
  size_t end = bytes;
  while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
  return text.substr(0, end);
}

}  // namespace

absl::StatusOr<std::vector<RemoteSetShape>> RemoteSetShapes(const CommonArgs& common,
                                                            const std::vector<std::string>& names,
                                                            const std::vector<absl::Span<const Point2>>& sets,
                                                            const ThresholdArg& threshold, double min_hole_area) {
  // Batches of this many sets, each queried before the next goes up, so that a server whose cache
  // cannot hold every group's family at once still answers each while it holds it.
  constexpr size_t kSetsPerCall = 10000;
  constexpr size_t kMaxLabelBytes = 256;  // BuildHeader.name's limit
  GALPHA_ASSIGN_OR_RETURN(std::unique_ptr<client::AlphaClient> client, ConnectTo(common));
  client::BuildBatchCallOptions options;
  if (common.raw_upload) options.encoding = client::PointEncoding::kRaw;
  const auto named = [&](size_t i, const absl::Status& status) {
    return absl::Status(status.code(), absl::StrCat(names[i], ": ", status.message()));
  };
  std::vector<RemoteSetShape> shapes(sets.size());
  for (size_t first = 0; first < sets.size(); first += kSetsPerCall) {
    const size_t end = std::min(sets.size(), first + kSetsPerCall);
    std::vector<client::BatchSet> batch;
    batch.reserve(end - first);
    for (size_t i = first; i < end; ++i) batch.push_back({Utf8Prefix(names[i], kMaxLabelBytes), sets[i], {}});
    GALPHA_ASSIGN_OR_RETURN(std::vector<absl::StatusOr<client::BuildResult>> built, client->BuildBatch(batch, options));
    for (size_t i = first; i < end; ++i) {
      const absl::StatusOr<client::BuildResult>& set = built[i - first];
      if (!set.ok()) return named(i, set.status());
      auto at = ToThreshold(threshold, set->summary.spectrum_size());
      if (!at.ok()) return named(i, at.status());
      // The level and squared alpha the threshold resolves to, as the local command prints them.
      v1::ClassifyRequest classify;
      classify.set_handle(set->handle);
      *classify.mutable_threshold() = *at;
      classify.set_mode(v1::CLASSIFY_MODE_REGULARIZED);
      classify.set_summary_only(true);
      absl::Status status = client->Classify(classify, [&](const v1::ClassifyResponse& message) {
        if (message.has_summary()) {
          shapes[i].level = message.summary().level();
          shapes[i].alpha_sq = message.summary().alpha_sq();
        }
        return absl::OkStatus();
      });
      if (!status.ok()) return named(i, status);
      v1::ShapeRequest request;
      request.set_handle(set->handle);
      *request.mutable_threshold() = *at;
      request.set_mode(v1::CLASSIFY_MODE_REGULARIZED);
      request.set_format(v1::SHAPE_FORMAT_RINGS);
      request.set_min_hole_area(min_hole_area);
      auto shape = RingsOfShape(*client, sets[i].size(), request);
      if (!shape.ok()) return named(i, shape.status());
      shapes[i].shape = *std::move(shape);
    }
  }
  return shapes;
}

int RemoteMasterList(const CommonArgs& common, int64_t rank) {
  auto remote = OpenRemote(common);
  if (!remote.ok()) return Failure(remote.status());
  const int64_t k = static_cast<int64_t>(remote->build.summary.spectrum_size());
  if (absl::Status s = CheckMasterListRank(rank, k); !s.ok()) return ArgumentError(s);
  v1::MasterListRequest request;
  request.set_handle(remote->build.handle);
  request.set_first_rank(rank);
  ChunkedWriter out(stdout);
  absl::Status status = remote->client->MasterList(request, [&](const v1::MasterListResponse& message) {
    int index = 0;
    for (size_t i = 0; i < message.kinds().size(); ++i) {
      const int kind = static_cast<unsigned char>(message.kinds()[i]);
      const int endpoint = static_cast<unsigned char>(message.endpoints()[i]);
      if (kind < 1 || kind > 3 || endpoint < 1 || endpoint > 3 || index + kind > message.vertex_indices_size()) {
        return absl::DataLossError("a MasterList message is malformed");
      }
      out.Append("?vet"[kind]);
      for (int v = 0; v < kind; ++v) {
        out.Append(' ');
        out.AppendUint(message.vertex_indices(index++));
      }
      out.Append(' ');
      out.Append(EndpointName(static_cast<Endpoint>(endpoint - 1)));
      out.Append('\n');
    }
    return absl::OkStatus();
  });
  if (!status.ok()) return QueryError(common, status);
  return FinishOutput(out);
}

int RemoteOptimal(const CommonArgs& common, int64_t components, std::optional<int64_t> holes) {
  auto remote = OpenRemote(common);
  if (!remote.ok()) return Failure(remote.status());
  v1::OptimalAlphaRequest request;
  request.set_handle(remote->build.handle);
  request.set_max_components(
      static_cast<uint32_t>(std::min<int64_t>(components, std::numeric_limits<uint32_t>::max())));
  if (holes)
    request.set_max_holes(static_cast<uint32_t>(std::min<int64_t>(*holes, std::numeric_limits<uint32_t>::max())));
  auto answer = remote->client->OptimalAlpha(request);
  if (!answer.ok()) return QueryError(common, answer.status());
  nlohmann::ordered_json json = {{"components", components}};
  if (holes) json["holes"] = *holes;
  json["regularized"] = nullptr;
  json["general"] = nullptr;
  if (answer->has_regularized()) {
    json["regularized"] = {{"rank", answer->regularized().rank()},
                           {"alpha_sq", answer->regularized().alpha_sq()},
                           {"solid_components", answer->regularized().components()},
                           {"holes", answer->regularized().holes()}};
  }
  if (answer->has_general()) {
    json["general"] = {{"rank", answer->general().rank()},
                       {"alpha_sq", answer->general().alpha_sq()},
                       {"components", answer->general().components()},
                       {"holes", answer->general().holes()}};
  }
  std::fputs(JsonLine(json).c_str(), stdout);
  return kExitOk;
}

int RemoteBench(const CommonArgs& common, int64_t repeat) {
  // Each run releases the handle first, so that the server builds again instead of finding it.
  std::vector<std::pair<std::string, double>> best;
  double best_engine = 0.0, best_rpc = 0.0;
  v1::BuildSummary summary;
  // Read once: FILE may be a pipe.
  std::vector<double> weights;  // with --weights: the weighted family is built
  auto points = ReadPoints(common, &weights);
  if (!points.ok()) return Failure(points.status());
  const size_t input_points = points->size();
  const std::string handle = weights.empty() ? PointSetHandle(*points) : WeightedPointSetHandle(*points, weights);
  for (int64_t run = 0; run < repeat; ++run) {
    auto connected = ConnectTo(common);
    if (!connected.ok()) return Failure(connected.status());
    auto released = (*connected)->Release(handle);
    if (!released.ok()) return Failure(ServerError(common, released.status()));
    client::BuildCallOptions options;
    options.name = common.file;
    options.skip_upload_if_cached = false;
    options.weights = weights;
    if (common.raw_upload) options.encoding = client::PointEncoding::kRaw;
    const auto start = std::chrono::steady_clock::now();
    auto built = (*connected)->Build(*points, options);
    const double rpc = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!built.ok()) return Failure(ServerError(common, built.status()));
    summary = built->summary;
    double engine = 0.0;
    for (const v1::StageTime& s : summary.stage_times()) {
      engine += s.seconds();
      auto it = std::find_if(best.begin(), best.end(), [&](const auto& b) { return b.first == s.stage(); });
      if (it == best.end()) {
        best.emplace_back(s.stage(), s.seconds());
      } else {
        it->second = std::min(it->second, s.seconds());
      }
    }
    best_engine = run == 0 ? engine : std::min(best_engine, engine);
    best_rpc = run == 0 ? rpc : std::min(best_rpc, rpc);
  }
  std::vector<std::pair<std::string, std::string>> rows;
  rows.reserve(best.size() + 3);
  for (const auto& [stage, seconds] : best) rows.emplace_back(stage, absl::StrFormat("%.3f", seconds * 1e3));
  rows.emplace_back("total", absl::StrFormat("%.3f", best_engine * 1e3));
  rows.emplace_back("rpc_total", absl::StrFormat("%.3f", best_rpc * 1e3));
  rows.emplace_back("peak_memory_bytes", absl::StrCat(summary.peak_memory_bytes()));
  rows.emplace_back("bytes_per_point",
                    absl::StrFormat("%.1f", input_points == 0 ? 0.0
                                                              : static_cast<double>(summary.peak_memory_bytes()) /
                                                                    static_cast<double>(input_points)));
  rows.emplace_back("comparisons_filter", absl::StrCat(summary.comparisons().filter()));
  rows.emplace_back("comparisons_bounded_exact", absl::StrCat(summary.comparisons().device_exact()));
  rows.emplace_back("comparisons_cpu_fallback", absl::StrCat(summary.comparisons().cpu_fallback()));
  rows.emplace_back("spectrum_size", absl::StrCat(summary.spectrum_size()));
  rows.emplace_back("backend", summary.backend());
  return PrintBenchTable(common.file, input_points, summary.distinct_points(), repeat, best.size() + 2, rows);
}

int RemoteHoles(const CommonArgs& common, const HolesArgs& options) {
  auto remote = OpenRemote(common);
  if (!remote.ok()) return Failure(remote.status());
  auto threshold = ToThreshold(options.threshold, *remote);
  if (!threshold.ok()) return ArgumentError(threshold.status());
  v1::ShapeRequest request;
  request.set_handle(remote->build.handle);
  *request.mutable_threshold() = *threshold;
  request.set_mode(v1::CLASSIFY_MODE_REGULARIZED);
  request.set_format(v1::SHAPE_FORMAT_RINGS);
  // The rings arrive by polygon; their areas are measured here, from FILE's points, as locally.
  ShapeGeometry shape;
  const absl::Status status = remote->client->Shape(request, [&](const v1::ShapeResponse& m) {
    for (const v1::ShapePolygon& polygon : m.rings().polygons()) {
      ShapePolygon& out = shape.polygons.emplace_back();
      out.outer.assign(polygon.outer().begin(), polygon.outer().end());
      for (const v1::Ring& hole : polygon.holes()) {
        for (uint32_t v : hole.vertex_indices()) {
          if (v >= remote->frame.input.size()) {
            return absl::DataLossError("holes: the server named a vertex beyond FILE's");
          }
        }
        out.holes.emplace_back(hole.vertex_indices().begin(), hole.vertex_indices().end());
      }
    }
    return absl::OkStatus();
  });
  if (!status.ok()) return QueryError(common, status);
  const std::vector<ShapeHole> holes = ListHoles(shape, remote->frame.Computed(), options.min_area);
  auto points = OutputPoints(remote->frame, options.format == HolesFormat::kGeoJson);
  if (!points.ok()) return Failure(points.status());
  if (!WriteHoles(holes, *points, options.format, stdout)) {
    return Failure(absl::DataLossError("holes: writing to standard output failed"));
  }
  return kExitOk;
}

int RemotePersistence(const CommonArgs& common, const PersistenceArgs& options) {
  auto remote = OpenRemote(common);
  if (!remote.ok()) return Failure(remote.status());
  v1::PersistenceRequest request;
  request.set_handle(remote->build.handle);
  for (uint32_t d = 0; d < 2; ++d) {
    // Both dimensions: the default (an empty list).
    if (options.dimensions[d] && !(options.dimensions[0] && options.dimensions[1])) request.add_dimensions(d);
  }
  request.set_min_persistence(options.min_persistence);
  std::vector<PersistenceRow> rows;
  const absl::Status status = remote->client->Persistence(request, [&](const v1::PersistenceResponse& m) {
    if (m.dimension() > 1) {
      return absl::DataLossError(absl::StrCat("persistence: the server sent pairs of dimension ", m.dimension()));
    }
    const uint32_t arity = m.dimension() + 1;
    const auto n = static_cast<size_t>(m.birth_rank_size());
    if (m.death_rank_size() != m.birth_rank_size() || m.birth_alpha_sq_size() != m.birth_rank_size() ||
        m.death_alpha_sq_size() != m.birth_rank_size() ||
        static_cast<size_t>(m.creator_vertices().size()) != n * arity ||
        static_cast<size_t>(m.killer_vertices().size()) != n * (arity + 1)) {
      return absl::DataLossError("persistence: a message's columns disagree in length");
    }
    for (size_t i = 0; i < n; ++i) {
      PersistenceRow row;
      row.dimension = m.dimension();
      row.birth_rank = m.birth_rank(static_cast<int>(i));
      row.death_rank = m.death_rank(static_cast<int>(i));
      row.birth = m.birth_alpha_sq(static_cast<int>(i));
      row.death = m.death_alpha_sq(static_cast<int>(i));
      row.creator.assign(m.creator_vertices().begin() + static_cast<std::ptrdiff_t>(i * arity),
                         m.creator_vertices().begin() + static_cast<std::ptrdiff_t>((i + 1) * arity));
      if (row.death_rank >= 0) {
        row.killer.assign(m.killer_vertices().begin() + static_cast<std::ptrdiff_t>(i * (arity + 1)),
                          m.killer_vertices().begin() + static_cast<std::ptrdiff_t>((i + 1) * (arity + 1)));
      }
      rows.push_back(std::move(row));
    }
    return absl::OkStatus();
  });
  if (!status.ok()) return QueryError(common, status);
  if (!WritePersistence(rows, options.format, stdout)) {
    return Failure(absl::DataLossError("persistence: writing to standard output failed"));
  }
  return kExitOk;
}

}  // namespace galpha::alphactl
