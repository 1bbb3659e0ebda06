// Weighted point sets through the real server (BuildHeader.weighted): the family the server builds
// from (x, y, w) uploads is the local weighted family (the oracle: BuildWeightedAlphaFamily on the
// CPU backend, itself checked against CGAL in weighted_family_cgal_test), under a handle that
// covers the weights; its hidden points are counted and reported EXTERIOR; and the compact tier
// keeps the weights, so that a demoted weighted family is rebuilt as it was.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "core/family/classification_summary.hpp"
#include "core/family/threshold.hpp"
#include "core/io/point_set_handle.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "tests/server/service_test_calls.hpp"
#include "tests/server/service_test_support.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using testing::ClientOf;
using testing::ScrapeMetric;
using testing::StartServer;
using testing::TestServerOptions;

/// Squared radii up to about the squared spacing of `n` uniform points in the unit square, so that
/// disks overlap and light points between heavy neighbours are hidden; a few negative.
std::vector<double> Weights(size_t n, uint32_t seed) {
  std::mt19937_64 random(seed);
  std::vector<double> weights(n);
  const double spacing_sq = 1.0 / static_cast<double>(n);
  for (double& w : weights) w = static_cast<double>(random() % 1000) / 1000.0 * spacing_sq - 0.1 * spacing_sq;
  return weights;
}

AlphaFamily LocalWeightedFamily(const std::vector<Point2>& points, const std::vector<double>& weights) {
  BuildOptions options;
  options.backend = Backend::kCpu;
  auto family = BuildWeightedAlphaFamily(points, weights, options);
  EXPECT_THAT(family, IsOk());
  return *std::move(family);
}

std::array<uint64_t, 4> Counts(const v1::ClassCounts& counts) {
  return {counts.exterior(), counts.singular(), counts.regular(), counts.interior()};
}

/// The server's ClassifySummary at `threshold` and the vertices it reports EXTERIOR.
struct RemoteClasses {
  v1::ClassifySummary summary;
  std::set<uint32_t> exterior_vertices;
};

RemoteClasses ClassifyRemote(client::AlphaClient& client, const std::string& handle, const v1::Threshold& threshold) {
  v1::ClassifyRequest request;
  request.set_handle(handle);
  *request.mutable_threshold() = threshold;
  RemoteClasses out;
  EXPECT_THAT(client.Classify(request,
                              [&](const v1::ClassifyResponse& message) {
                                if (message.has_summary()) out.summary = message.summary();
                                if (!message.has_chunk() || message.chunk().kind() != v1::SIMPLEX_KIND_VERTEX) {
                                  return absl::OkStatus();
                                }
                                const v1::SimplexChunk& chunk = message.chunk();
                                for (size_t i = 0; i < chunk.classes().size(); ++i) {
                                  if (static_cast<unsigned char>(chunk.classes()[i]) == v1::SIMPLEX_CLASS_EXTERIOR) {
                                    out.exterior_vertices.insert(chunk.vertex_indices(static_cast<int>(i)));
                                  }
                                }
                                return absl::OkStatus();
                              }),
              IsOk());
  return out;
}

// Decimal coordinates (X / 10^6) and weights (X / 10^9), as files of atoms and sites hold them:
// the client sends them as scaled integers, the weights with their own w_scale. The last point is
// a lighter copy of the first's position: a point of its own, hidden.
TEST(ServiceTest, WeightedBuildAnswersAsTheLocalWeightedFamily) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  std::vector<Point2> points = gen::Uniform(3000, 31);
  for (Point2& p : points) p = {std::round(p.x * 1e6) / 1e6, std::round(p.y * 1e6) / 1e6};
  std::vector<double> weights = Weights(points.size(), 32);
  for (double& w : weights) w = std::round(w * 1e9) / 1e9;
  points.push_back(points.front());
  weights.push_back((std::round(weights.front() * 1e9) - 1000) / 1e9);
  const AlphaFamily local = LocalWeightedFamily(points, weights);
  const std::vector<uint32_t> hidden = local.HiddenPoints();
  ASSERT_FALSE(hidden.empty()) << "the weights must hide points for this test to mean anything";

  client::BuildCallOptions options;
  options.weights = weights;
  auto built = client->Build(points, options);
  ASSERT_THAT(built, IsOk());
  EXPECT_EQ(built->handle, WeightedPointSetHandle(points, weights));
  EXPECT_LT(built->upload_bytes, 12 * points.size()) << "scaled integers, not raw triples (24 bytes a point)";
  EXPECT_TRUE(built->summary.weighted());
  EXPECT_EQ(built->summary.hidden_points(), hidden.size());
  EXPECT_EQ(built->summary.spectrum_size(), local.spectrum().size());
  EXPECT_EQ(testing::SpectrumRemote(*client, built->handle, 1000),
            std::vector<double>(local.spectrum().begin(), local.spectrum().end()));

  // Classes at rank 0 (hidden points are its only EXTERIOR vertices), below every disk (level -1:
  // nothing), and at two ranks, against the local classification.
  std::vector<v1::Threshold> thresholds(4);
  thresholds[0].set_rank(0);
  thresholds[1].set_alpha_sq(local.min_alpha_sq() * 2 - 1.0);
  thresholds[2].set_rank(static_cast<int64_t>(local.spectrum().size() / 3));
  thresholds[3].set_rank(static_cast<int64_t>(local.spectrum().size() * 2 / 3));
  for (const v1::Threshold& threshold : thresholds) {
    SCOPED_TRACE(threshold.ShortDebugString());
    const RemoteClasses remote = ClassifyRemote(*client, built->handle, threshold);
    Threshold t;
    t.kind = threshold.has_rank() ? Threshold::Kind::kRank : Threshold::Kind::kAlphaSq;
    t.rank = threshold.rank();
    t.value = threshold.alpha_sq();
    auto level = ResolveThreshold(local, t);
    ASSERT_THAT(level, IsOk());
    EXPECT_EQ(remote.summary.level(), level->level);
    const ClassificationSummary counts =
        SummarizeClassification(local, local.ClassifyAll(level->level, ClassifyMode::kGeneral, VertexRule::kReport));
    EXPECT_EQ(Counts(remote.summary.vertices()), counts.vertices);
    EXPECT_EQ(Counts(remote.summary.edges()), counts.edges);
    EXPECT_EQ(Counts(remote.summary.triangles()), counts.triangles);
    EXPECT_EQ(remote.summary.components(), local.Components(level->level));
  }
  const RemoteClasses rank0 = ClassifyRemote(*client, built->handle, thresholds[0]);
  std::set<uint32_t> hidden_firsts;  // Classify lists first occurrences (uniform points have no duplicates)
  for (const uint32_t v : hidden) hidden_firsts.insert(local.representative()[v]);
  EXPECT_EQ(rank0.exterior_vertices, hidden_firsts);
  EXPECT_EQ(hidden.back(), points.size() - 1) << "the lighter point at the first one's position";

  // The client's check before an upload finds the weighted handle: no upload.
  auto again = client->Build(points, options);
  ASSERT_THAT(again, IsOk());
  EXPECT_TRUE(again->cached);
  EXPECT_FALSE(again->uploaded);
  // The same coordinates without weights are another family.
  auto unweighted = client->Build(points);
  ASSERT_THAT(unweighted, IsOk());
  EXPECT_NE(unweighted->handle, built->handle);
  EXPECT_FALSE(unweighted->summary.weighted());
  EXPECT_EQ(unweighted->summary.hidden_points(), 0u);
  // A weight count other than the points' is refused before anything is sent.
  options.weights = absl::MakeConstSpan(weights).subspan(1);
  EXPECT_THAT(client->Build(points, options).status(),
              galpha::testing::StatusIs(absl::StatusCode::kInvalidArgument,
                                        ::testing::HasSubstr("3001 points need 3001 weights, not 3000")));
}

TEST(ServiceTest, DemotedWeightedFamilyIsRebuiltWithItsWeights) {
  const std::vector<Point2> a = gen::Uniform(3000, 33), b = gen::Uniform(3000, 34);
  const std::vector<double> weights = Weights(a.size(), 35);
  client::BuildCallOptions weighted;
  weighted.weights = weights;
  size_t one_family = 0;
  {
    auto probe = StartServer(TestServerOptions());
    ASSERT_NE(probe, nullptr);
    auto first = ClientOf(*probe)->Build(a, weighted);
    auto second = ClientOf(*probe)->Build(b);
    ASSERT_THAT(first, IsOk());
    ASSERT_THAT(second, IsOk());
    one_family = std::max(first->summary.family_bytes(), second->summary.family_bytes());
  }
  ServerOptions server_options = TestServerOptions();
  server_options.service.cache_bytes = one_family * 3 / 2;  // one family resident at a time
  auto server = StartServer(server_options);
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  auto first = client->Build(a, weighted);
  ASSERT_THAT(first, IsOk());
  v1::Threshold rank;
  rank.set_rank(40);
  const RemoteClasses before = ClassifyRemote(*client, first->handle, rank);
  ASSERT_THAT(client->Build(b), IsOk());
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_demotions_total"), 1.0);
  // The compact entry holds the points and their weights: 24 bytes each.
  EXPECT_GE(ScrapeMetric(*server, "galpha_cache_bytes{tier=\"compact\"}"), 24.0 * static_cast<double>(a.size()));

  const RemoteClasses after = ClassifyRemote(*client, first->handle, rank);  // promotes: a rebuild
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_promotions_total"), 1.0);
  EXPECT_EQ(after.summary.SerializeAsString(), before.summary.SerializeAsString());
  EXPECT_EQ(after.exterior_vertices, before.exterior_vertices);
  auto described = client->Describe(first->handle);
  ASSERT_THAT(described, IsOk());
  EXPECT_TRUE(described->summary().weighted());
  EXPECT_EQ(described->summary().hidden_points(), first->summary.hidden_points());
  EXPECT_GT(first->summary.hidden_points(), 0u);
}

}  // namespace
}  // namespace galpha::server
