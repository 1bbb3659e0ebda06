// The real server, started in-process on loopback ports and driven through the client library:
// every RPC against the local engine as the oracle (Build, Spectrum, Classify, MasterList,
// Components, OptimalAlpha, Shape), on generated inputs and a real data set; Describe, Release and
// the cache.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "core/family/persistence.hpp"
#include "core/geometry/shape.hpp"
#include "core/io/coordinate_system.hpp"
#include "core/io/point_set_handle.hpp"
#include "nlohmann/json.hpp"
#include "tests/server/service_test_calls.hpp"
#include "tests/server/service_test_support.hpp"
#include "tests/support/data_files.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using testing::ClientOf;
using testing::LocalFamily;
using testing::SpectrumRemote;
using testing::StartServer;
using testing::TestServerOptions;

/// The Classify stream of `request` as (kind, indices..., class) rows, and its summary.
struct ClassifyAnswer {
  v1::ClassifySummary summary;
  std::vector<std::vector<uint32_t>> rows;  // arity indices then the class byte
};

absl::StatusOr<ClassifyAnswer> ClassifyRemote(client::AlphaClient& client, const v1::ClassifyRequest& request) {
  ClassifyAnswer answer;
  absl::Status status = client.Classify(request, [&](const v1::ClassifyResponse& message) {
    if (message.has_summary()) answer.summary = message.summary();
    if (message.has_chunk()) {
      const auto& chunk = message.chunk();
      const int arity = static_cast<int>(chunk.kind());
      for (size_t i = 0; i < chunk.classes().size(); ++i) {
        std::vector<uint32_t> row;
        row.reserve(static_cast<size_t>(arity) + 1);
        for (int k = 0; k < arity; ++k) row.push_back(chunk.vertex_indices(static_cast<int>(i) * arity + k));
        row.push_back(static_cast<uint8_t>(chunk.classes()[i]));
        answer.rows.push_back(row);
      }
    }
    return absl::OkStatus();
  });
  if (!status.ok()) return status;
  return answer;
}

/// The same rows from the local engine, in the service's order.
std::vector<std::vector<uint32_t>> ClassifyLocal(const AlphaFamily& family, int64_t level, ClassifyMode mode,
                                                 VertexRule rule) {
  const Classification classes = family.ClassifyAll(level, mode, rule);
  std::vector<std::vector<uint32_t>> rows;
  for (uint32_t v = 0; v < family.points().size(); ++v) {
    if (family.representative()[v] == v) rows.push_back({v, static_cast<uint32_t>(classes.vertices[v]) + 1});
  }
  std::vector<std::vector<uint32_t>> edges, triangles;
  for (uint32_t e = 0; e < family.edges().size(); ++e) {
    const auto& edge = family.edges()[e];
    edges.push_back(
        {std::min(edge[0], edge[1]), std::max(edge[0], edge[1]), static_cast<uint32_t>(classes.edges[e]) + 1});
  }
  for (uint32_t t = 0; t < family.triangles().size(); ++t) {
    std::array<uint32_t, 3> tri = family.triangles()[t];
    std::sort(tri.begin(), tri.end());
    triangles.push_back({tri[0], tri[1], tri[2], static_cast<uint32_t>(classes.triangles[t]) + 1});
  }
  std::sort(edges.begin(), edges.end());
  std::sort(triangles.begin(), triangles.end());
  rows.insert(rows.end(), edges.begin(), edges.end());
  rows.insert(rows.end(), triangles.begin(), triangles.end());
  return rows;
}

/// Compares everything the service answers about `points` with the local engine.
void ExpectServiceMatchesLocal(client::AlphaClient& client, const std::vector<Point2>& points,
                               const std::string& label) {
  SCOPED_TRACE(label);
  const AlphaFamily local = LocalFamily(points);
  client::BuildCallOptions call;
  call.name = label;
  auto built = client.Build(points, call);
  ASSERT_THAT(built, IsOk());
  EXPECT_EQ(built->handle, PointSetHandle(points));
  const v1::BuildSummary& summary = built->summary;
  EXPECT_EQ(summary.points(), points.size());
  EXPECT_EQ(summary.distinct_points(), local.num_unique());
  EXPECT_EQ(summary.duplicates(), local.num_duplicates());
  EXPECT_EQ(summary.triangles(), local.triangles().size());
  EXPECT_EQ(summary.edges(), local.edges().size());
  EXPECT_EQ(summary.spectrum_size(), local.spectrum().size());
  EXPECT_EQ(summary.backend(), testing::TestBackend());
  EXPECT_GT(summary.family_bytes(), 0u);

  EXPECT_EQ(SpectrumRemote(client, built->handle, 1000), local.spectrum());

  const int64_t k = local.max_level();
  for (const int64_t rank : {int64_t{0}, k / 3, k / 2, k}) {
    for (const auto mode : {v1::CLASSIFY_MODE_GENERAL, v1::CLASSIFY_MODE_REGULARIZED}) {
      v1::ClassifyRequest request;
      request.set_handle(built->handle);
      request.mutable_threshold()->set_rank(rank);
      request.set_mode(mode);
      request.set_vertex_rule(v1::VERTEX_RULE_CGAL);
      auto answer = ClassifyRemote(client, request);
      ASSERT_THAT(answer, IsOk());
      const ClassifyMode local_mode =
          mode == v1::CLASSIFY_MODE_GENERAL ? ClassifyMode::kGeneral : ClassifyMode::kRegularized;
      EXPECT_EQ(answer->rows, ClassifyLocal(local, rank, local_mode, VertexRule::kCgal)) << "rank " << rank;
      EXPECT_EQ(answer->summary.level(), rank);
      EXPECT_EQ(answer->summary.components(), local.Components(rank));
      EXPECT_EQ(answer->summary.solid_components(), local.SolidComponents(rank));
    }
  }

  if (k > 0) {
    v1::MasterListRequest request;
    request.set_handle(built->handle);
    request.set_first_rank(1);
    request.set_last_rank(k);
    std::vector<uint64_t> ranks;
    std::string kinds;
    absl::Status status = client.MasterList(request, [&](const v1::MasterListResponse& message) {
      ranks.insert(ranks.end(), message.ranks().begin(), message.ranks().end());
      kinds += message.kinds();
      return absl::OkStatus();
    });
    ASSERT_THAT(status, IsOk());
    std::vector<uint64_t> local_ranks;
    std::string local_kinds;
    for (int64_t r = 1; r <= k; ++r) {
      for (const MasterEntry& entry : local.MasterList(r)) {
        local_ranks.push_back(static_cast<uint64_t>(r));
        local_kinds += static_cast<char>(static_cast<int>(entry.kind()) + 1);
      }
    }
    EXPECT_EQ(ranks, local_ranks);
    EXPECT_EQ(kinds, local_kinds);
  }

  v1::ComponentsRequest components;
  components.set_handle(built->handle);
  components.mutable_ranks()->set_first(0);
  components.mutable_ranks()->set_last(k);
  auto curve = client.Components(components);
  ASSERT_THAT(curve, IsOk());
  ASSERT_EQ(curve->components_size(), k + 1);
  for (int64_t level = 0; level <= k; ++level) {
    EXPECT_EQ(curve->components(static_cast<int>(level)), local.Components(level));
    EXPECT_EQ(curve->solid_components(static_cast<int>(level)), local.SolidComponents(level));
  }

  v1::BettiRequest betti;
  betti.set_handle(built->handle);
  betti.mutable_ranks()->set_first(0);
  betti.mutable_ranks()->set_last(k);
  auto curves = client.Betti(betti);
  ASSERT_THAT(curves, IsOk());
  ASSERT_EQ(curves->holes_size(), k + 1);
  for (int64_t level = 0; level <= k; ++level) {
    const int i = static_cast<int>(level);
    EXPECT_EQ(curves->components(i), local.Components(level));
    EXPECT_EQ(curves->holes(i), local.Holes(level, ClassifyMode::kGeneral));
    EXPECT_EQ(curves->regularized_components(i), local.RegularizedComponents(level));
    EXPECT_EQ(curves->regularized_holes(i), local.Holes(level, ClassifyMode::kRegularized));
  }

  // The diagram over the wire: as many pairs per dimension as the local one lists.
  const absl::StatusOr<PersistenceDiagram> diagram = ComputePersistence(local);
  ASSERT_THAT(diagram, IsOk());
  v1::PersistenceRequest persistence;
  persistence.set_handle(built->handle);
  size_t pairs[2] = {0, 0};
  ASSERT_THAT(client.Persistence(persistence,
                                 [&](const v1::PersistenceResponse& m) {
                                   pairs[m.dimension()] += static_cast<size_t>(m.birth_rank_size());
                                   return absl::OkStatus();
                                 }),
              IsOk());
  EXPECT_EQ(pairs[0], diagram->dimension_begin[1]);
  EXPECT_EQ(pairs[1], diagram->dimension_begin[2] - diagram->dimension_begin[1]);

  v1::OptimalAlphaRequest optimal;
  optimal.set_handle(built->handle);
  optimal.set_max_components(1);
  auto best = client.OptimalAlpha(optimal);
  ASSERT_THAT(best, IsOk());
  EXPECT_EQ(best->has_regularized(), local.OptimalLevelRegularized(1).has_value());
  if (best->has_regularized()) {
    EXPECT_EQ(best->regularized().rank(), *local.OptimalLevelRegularized(1));
  }
  EXPECT_EQ(best->has_general(), local.OptimalLevelGeneral(1).has_value());
  if (best->has_general()) {
    EXPECT_EQ(best->general().rank(), *local.OptimalLevelGeneral(1));
  }

  v1::ShapeRequest shape;
  shape.set_handle(built->handle);
  shape.mutable_threshold()->set_rank(k / 2);
  shape.set_format(v1::SHAPE_FORMAT_GEOJSON);
  std::string text;
  absl::Status status = client.Shape(shape, [&](const v1::ShapeResponse& message) {
    text += message.text();
    return absl::OkStatus();
  });
  ASSERT_THAT(status, IsOk());
  auto local_shape = AssembleShape(local.ComplexAt(k / 2, ClassifyMode::kGeneral));
  ASSERT_THAT(local_shape, IsOk());
  EXPECT_EQ(text, ShapeToGeoJson(*local_shape, local.points()));
}

/// The GPS tracks (WGS84 longitude/latitude) as users send them.
std::vector<Point2> GpsTracks() {
  const std::string file = testdata::DataDir() + "/gps_tracks_slovenia_croatia.bin";
  std::ifstream in(file, std::ios::binary);
  uint64_t n = 0;
  in.read(reinterpret_cast<char*>(&n), sizeof n);
  std::vector<Point2> points(n);
  in.read(reinterpret_cast<char*>(points.data()), static_cast<std::streamsize>(n * sizeof(Point2)));
  EXPECT_TRUE(in.good()) << file;
  return points;
}

TEST(ServiceTest, EveryQueryMatchesTheLocalEngine) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  ExpectServiceMatchesLocal(*client, gen::Uniform(3000, 1), "uniform");
  ExpectServiceMatchesLocal(*client, gen::Grid(2500, 2), "grid");
  ExpectServiceMatchesLocal(*client, gen::WithDuplicates(2000, 3), "duplicates");
  ExpectServiceMatchesLocal(*client, gen::TwoLines(400, 4), "two lines");
  ExpectServiceMatchesLocal(*client, {{0.5, 0.25}}, "one point");
  ExpectServiceMatchesLocal(*client, {}, "no points");
  // A real data set, as users send them.
  ExpectServiceMatchesLocal(*client, GpsTracks(), "gps tracks");
}

// A Classify answer read in parts (ClientOptions::classify_parts, ClassifyRequest.part_count) is
// handed over as one call's, message for message, in every encoding, filtered or not. 300,000
// points: every kind spans several chunks. (The other tests read in the default parts: half the
// machine's cores, so one part on 2 cores.)
TEST(ServiceTest, ClassifyReadInPartsIsTheSameAnswer) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  const std::vector<Point2> points = gen::Uniform(300000, 21);
  std::vector<std::unique_ptr<client::AlphaClient>> clients;
  for (const uint32_t parts : {1u, 2u, 5u, 64u, 0u}) {  // 0: the default
    client::ClientOptions options;
    options.target = "127.0.0.1:" + std::to_string(server->port());
    options.classify_parts = parts;
    auto connected = client::AlphaClient::Connect(options);
    ASSERT_THAT(connected, IsOk());
    clients.push_back(*std::move(connected));
  }
  auto built = clients[0]->Build(points);
  ASSERT_THAT(built, IsOk());
  // The messages handed over, and the bytes that came down. A real split brings down the one
  // call's bytes exactly (the same messages); a server that ignored part_count, read in parts by
  // the client, would bring down P whole answers: the byte count tells the two apart.
  const auto messages_of = [&](client::AlphaClient& client, const v1::ClassifyRequest& request, uint64_t* bytes) {
    std::vector<std::string> messages;
    EXPECT_THAT(client.Classify(
                    request,
                    [&](const v1::ClassifyResponse& message) {
                      messages.push_back(message.SerializeAsString());
                      return absl::OkStatus();
                    },
                    bytes),
                IsOk());
    return messages;
  };
  for (const auto encoding : {v1::SIMPLEX_ENCODING_RAW, v1::SIMPLEX_ENCODING_DELTA, v1::SIMPLEX_ENCODING_DELTA_ZSTD}) {
    for (const bool non_exterior_only : {false, true}) {
      v1::ClassifyRequest request;
      request.set_handle(built->handle);
      request.mutable_threshold()->set_rank(static_cast<int64_t>(built->summary.spectrum_size() / 2));
      request.set_simplex_encoding(encoding);
      request.set_non_exterior_only(non_exterior_only);
      uint64_t whole_bytes = 0;
      const std::vector<std::string> whole = messages_of(*clients[0], request, &whole_bytes);
      ASSERT_GT(whole.size(), 8u) << "the test needs an answer of several chunks";
      for (size_t c = 1; c < clients.size(); ++c) {
        uint64_t bytes = 0;
        EXPECT_EQ(messages_of(*clients[c], request, &bytes), whole)
            << "encoding " << encoding << ", non_exterior_only " << non_exterior_only << ", client " << c;
        EXPECT_EQ(bytes, whole_bytes) << "client " << c << ": the server did not split the answer";
      }
    }
  }
  // A caller's error stops every part and is returned.
  v1::ClassifyRequest request;
  request.set_handle(built->handle);
  request.mutable_threshold()->set_rank(1);
  int seen = 0;
  EXPECT_THAT(clients[2]->Classify(request,
                                   [&](const v1::ClassifyResponse&) {
                                     return ++seen == 3 ? absl::AbortedError("enough") : absl::OkStatus();
                                   }),
              StatusIs(absl::StatusCode::kAborted));
  EXPECT_EQ(seen, 3);
  // Bad options are refused before any call.
  client::ClientOptions bad;
  bad.target = "127.0.0.1:" + std::to_string(server->port());
  bad.classify_parts = client::kMaxClassifyParts + 1;
  EXPECT_THAT(client::AlphaClient::Connect(bad), StatusIs(absl::StatusCode::kInvalidArgument));
}

TEST(ServiceTest, DescribeReleaseAndTheCache) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  const std::vector<Point2> points = gen::Uniform(1000, 7);
  client::BuildCallOptions no_skip;
  no_skip.name = "first";
  no_skip.skip_upload_if_cached = false;
  auto first = client->Build(points, no_skip);
  ASSERT_THAT(first, IsOk());
  EXPECT_FALSE(first->cached);
  EXPECT_TRUE(first->uploaded);
  EXPECT_EQ(first->summary.name(), "first");
  // The same points again under another name: a cache hit, nothing recomputed (the summary is the
  // first build's), answered with this call's own name, never the first caller's.
  client::BuildCallOptions second_call = no_skip;
  second_call.name = "second";
  auto again = client->Build(points, second_call);
  ASSERT_THAT(again, IsOk());
  EXPECT_TRUE(again->cached);
  EXPECT_EQ(again->handle, first->handle);
  EXPECT_EQ(again->summary.name(), "second");
  v1::BuildSummary first_unnamed = first->summary;
  first_unnamed.clear_name();
  v1::BuildSummary again_unnamed = again->summary;
  again_unnamed.clear_name();
  EXPECT_EQ(again_unnamed.SerializeAsString(), first_unnamed.SerializeAsString());
  // The client hashes locally and skips the upload.
  client::BuildCallOptions skip;
  skip.name = "third";
  auto skipped = client->Build(points, skip);
  ASSERT_THAT(skipped, IsOk());
  EXPECT_TRUE(skipped->cached);
  EXPECT_FALSE(skipped->uploaded);
  auto described = client->Describe(first->handle);
  ASSERT_THAT(described, IsOk());
  EXPECT_EQ(described->summary().name(), "") << "a name is its Build call's label; the family keeps none";
  EXPECT_EQ(server->service().cache().GetStats().resident.entries, 1u);

  auto released = client->Release(first->handle);
  ASSERT_THAT(released, IsOk());
  EXPECT_TRUE(released->released());
  EXPECT_THAT(client->Describe(first->handle).status(), StatusIs(absl::StatusCode::kNotFound));
  auto released_again = client->Release(first->handle);
  ASSERT_THAT(released_again, IsOk());
  EXPECT_FALSE(released_again->released());
}

}  // namespace
}  // namespace galpha::server

#ifdef GALPHA_WITH_PROJ
namespace galpha::server {
namespace {

/// Shape text of `handle` at `rank` in `format`.
std::string ShapeText(client::AlphaClient& client, const std::string& handle, int64_t rank, v1::ShapeFormat format) {
  v1::ShapeRequest request;
  request.set_handle(handle);
  request.mutable_threshold()->set_rank(rank);
  request.set_mode(v1::CLASSIFY_MODE_REGULARIZED);
  request.set_format(format);
  std::string text;
  EXPECT_THAT(client.Shape(request,
                           [&](const v1::ShapeResponse& m) {
                             text += m.text();
                             return absl::OkStatus();
                           }),
              IsOk());
  return text;
}

// BuildHeader.crs: the server builds the local projection of longitude/latitude (the oracle: the
// same projection in-process, then the local engine), under the handle of the projected points,
// and writes text geometry in the points as sent.
TEST(ServiceTest, HeaderCrsBuildsTheLocalProjection) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  const std::vector<Point2> gps = GpsTracks();
  absl::StatusOr<CrsInfo> wgs84 = DescribeCrs("EPSG:4326");
  ASSERT_THAT(wgs84, IsOk());
  absl::StatusOr<LocalMetres> local = ProjectToLocalMetres(*wgs84, gps);
  ASSERT_THAT(local, IsOk());

  client::BuildCallOptions options;
  options.crs = "EPSG:4326";
  absl::StatusOr<client::BuildResult> built = client->Build(gps, options);
  ASSERT_THAT(built, IsOk());
  EXPECT_EQ(built->handle, PointSetHandle(local->points));
  EXPECT_EQ(built->summary.projection(), local->projection);
  const AlphaFamily expected = LocalFamily(local->points);
  EXPECT_EQ(SpectrumRemote(*client, built->handle, 1000),
            std::vector<double>(expected.spectrum().begin(), expected.spectrum().end()));
  // GeoJSON and WKT name input points only, bit for bit (WGS84 already: GeoJSON copies them).
  const int64_t rank = expected.max_level() / 2;
  const nlohmann::json geojson =
      nlohmann::json::parse(ShapeText(*client, built->handle, rank, v1::SHAPE_FORMAT_GEOJSON));
  ASSERT_FALSE(geojson["features"].empty());
  std::set<std::pair<double, double>> sent;
  for (const Point2& p : gps) sent.emplace(p.x, p.y);
  size_t positions = 0;
  for (const auto& polygon : geojson["features"][0]["geometry"]["coordinates"]) {
    for (const auto& ring : polygon) {
      for (const auto& position : ring) {
        EXPECT_TRUE(sent.count({position[0].get<double>(), position[1].get<double>()})) << position;
        ++positions;
      }
    }
  }
  EXPECT_GT(positions, 3u);
  const std::string svg = ShapeText(*client, built->handle, rank, v1::SHAPE_FORMAT_SVG);
  EXPECT_NE(svg.find("<desc>coordinates in CRS WGS 84 (EPSG:4326)</desc>"), std::string::npos);
  // The area stays in square metres (the local engine's, on the projected points).
  EXPECT_EQ(geojson["features"][0]["properties"]["area"].get<double>(),
            AssembleShape(expected.ComplexAt(rank, ClassifyMode::kRegularized))->area);

  // The projected points sent without a CRS (what alphactl --crs uploads) are the same family.
  client::BuildCallOptions plain;
  plain.skip_upload_if_cached = false;
  absl::StatusOr<client::BuildResult> again = client->Build(local->points, plain);
  ASSERT_THAT(again, IsOk());
  EXPECT_EQ(again->handle, built->handle);
  EXPECT_TRUE(again->cached);

  // What PROJ cannot take is the caller's error.
  options.crs = "no such crs";
  EXPECT_THAT(client->Build(gps, options),
              StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("the header's crs")));
  options.crs = "EPSG:4326";
  EXPECT_THAT(client->Build(std::vector<Point2>{{500000, 4000000}, {500100, 4000000}, {500000, 4000100}}, options),
              StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("is not a longitude and latitude")));
}

}  // namespace
}  // namespace galpha::server
#endif  // GALPHA_WITH_PROJ
