// BuildBatch through the real server: many sets in one stream give the families their sets give
// alone (the oracles: the in-process engine on the CPU backend for the summary's counts, and the
// same sets built one by one with Build on a second server for the spectra), under the handles of
// their points; a malformed set fails the whole call naming it, with nothing built; a set whose
// build alone fails answers its own error while the others are built and cached.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <random>
#include <string>
#include <vector>

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
using galpha::testing::StatusIs;
using testing::ClientOf;
using ::testing::HasSubstr;
using testing::Header;
using testing::LocalFamily;
using testing::ScrapeMetric;
using testing::SpectrumRemote;
using testing::StartServer;
using testing::TestServerOptions;

struct NamedSet {
  std::string name;
  std::vector<Point2> points;
  std::vector<double> weights;
};

/// Sets of every kind a GIS layer holds, degenerate ones and an empty one included.
std::vector<NamedSet> Sets() {
  std::vector<NamedSet> sets = {
      {"uniform", gen::Uniform(1000, 1), {}},
      {"grid", gen::Grid(900, 2), {}},
      {"two-lines", gen::TwoLines(500, 3), {}},
      {"duplicates", gen::WithDuplicates(700, 4), {}},
      {"empty", {}, {}},
      {"circle", gen::Circle(300, 5), {}},
      {"one", {{0.5, 0.5}}, {}},
      {"uniform-again", gen::Uniform(1000, 1), {}},
      // Over BuildBatchReactor's host-core size: built on the slot while the others are built on
      // the host's cores.
      {"large", gen::Uniform(30000, 8), {}},
  };
  NamedSet weighted{"weighted", gen::Uniform(400, 6), {}};
  std::mt19937_64 random(7);
  for (size_t i = 0; i < weighted.points.size(); ++i)
    weighted.weights.push_back(static_cast<double>(random() % 100) * 1e-6);
  sets.push_back(std::move(weighted));
  return sets;
}

std::vector<client::BatchSet> Batch(const std::vector<NamedSet>& sets) {
  std::vector<client::BatchSet> batch;
  batch.reserve(sets.size());
  for (const NamedSet& set : sets) batch.push_back({set.name, set.points, set.weights});
  return batch;
}

/// A Build stream's message as a BuildBatch stream's: the same bytes (proto: BuildBatchRequest).
v1::BuildBatchRequest AsBatch(const v1::BuildRequest& message) {
  v1::BuildBatchRequest out;
  EXPECT_TRUE(out.ParseFromString(message.SerializeAsString()));
  return out;
}

/// Streams `messages` as one BuildBatch call: its status, and its answers' sets in `answers`.
absl::Status RawBatch(client::AlphaClient& client, const std::vector<v1::BuildRequest>& messages,
                      std::vector<v1::BatchedBuild>* answers = nullptr) {
  grpc::ClientContext context;
  client.PrepareContext(&context);
  auto stream = client.stub().BuildBatch(&context);
  for (const v1::BuildRequest& message : messages) {
    if (!stream->Write(AsBatch(message))) break;
  }
  stream->WritesDone();
  v1::BuildBatchResponse page;
  while (stream->Read(&page)) {
    if (answers != nullptr) answers->insert(answers->end(), page.sets().begin(), page.sets().end());
  }
  return client::FromGrpc(stream->Finish());
}

v1::BuildRequest NamedHeader(const std::string& name, uint64_t expected) {
  v1::BuildRequest header = Header(expected);
  header.mutable_header()->set_name(name);
  return header;
}

v1::BuildRequest PointsOf(const std::vector<Point2>& points) {
  v1::BuildRequest chunk;
  for (const Point2& p : points) {
    chunk.mutable_points()->add_coordinates(p.x);
    chunk.mutable_points()->add_coordinates(p.y);
  }
  return chunk;
}

class ServiceBatchPackingTest : public ::testing::TestWithParam<BatchPacking> {};

TEST_P(ServiceBatchPackingTest, ABatchGivesTheFamiliesItsSetsGiveAlone) {
  // The small unweighted sets packed into one build (on), or built one a host core (off).
  auto options = TestServerOptions();
  options.service.batch_packing = GetParam();
  auto server = StartServer(options);
  auto alone = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  ASSERT_NE(alone, nullptr);
  auto client = ClientOf(*server);
  auto alone_client = ClientOf(*alone);
  const std::vector<NamedSet> sets = Sets();
  for (client::PointEncoding encoding : {client::PointEncoding::kAuto, client::PointEncoding::kRaw}) {
    SCOPED_TRACE(encoding == client::PointEncoding::kAuto ? "auto encoding" : "raw encoding");
    client::BuildBatchCallOptions options;
    options.encoding = encoding;
    size_t progress = 0;
    options.progress = [&](size_t sent) { progress = sent; };
    auto answers = client->BuildBatch(Batch(sets), options);
    ASSERT_THAT(answers, IsOk());
    ASSERT_EQ(answers->size(), sets.size());
    EXPECT_EQ(progress, sets.size());
    for (size_t i = 0; i < sets.size(); ++i) {
      const NamedSet& set = sets[i];
      SCOPED_TRACE(set.name);
      const auto& answer = (*answers)[i];
      ASSERT_THAT(answer, IsOk());
      const bool weighted = !set.weights.empty() && !set.points.empty();
      EXPECT_EQ(answer->handle,
                weighted ? WeightedPointSetHandle(set.points, set.weights) : PointSetHandle(set.points));
      EXPECT_EQ(answer->summary.name(), set.name);
      EXPECT_EQ(answer->summary.points(), set.points.size());
      // The second call finds every family; the first computes all but the repeated set.
      const bool again = encoding == client::PointEncoding::kRaw || set.name == "uniform-again";
      EXPECT_EQ(answer->cached, again);
      if (!weighted) {
        const AlphaFamily local = LocalFamily(set.points);
        EXPECT_EQ(answer->summary.triangles(), local.triangles().size());
        EXPECT_EQ(answer->summary.edges(), local.edges().size());
        EXPECT_EQ(answer->summary.spectrum_size(), local.spectrum().size());
      }
      // The same set through Build on another server: the same family, value for value.
      client::BuildCallOptions build;
      build.name = set.name;
      build.weights = set.weights;
      auto built = alone_client->Build(set.points, build);
      ASSERT_THAT(built, IsOk());
      EXPECT_EQ(built->handle, answer->handle);
      EXPECT_EQ(built->summary.triangles(), answer->summary.triangles());
      EXPECT_EQ(built->summary.spectrum_size(), answer->summary.spectrum_size());
      EXPECT_EQ(SpectrumRemote(*client, answer->handle, 100), SpectrumRemote(*alone_client, built->handle, 100));
    }
  }
  EXPECT_EQ(ScrapeMetric(*server, "galpha_rpcs_total{code=\"OK\",method=\"BuildBatch\"}"), 2.0);
  // Builds: packed, the seven small unweighted sets (the repeat is answered by its first) are one,
  // then the large set and the weighted one; one a core, nine.
  EXPECT_EQ(ScrapeMetric(*server, "galpha_build_seconds_count"), GetParam() == BatchPacking::kOn ? 3.0 : 9.0);
}

INSTANTIATE_TEST_SUITE_P(Packing, ServiceBatchPackingTest, ::testing::Values(BatchPacking::kOn, BatchPacking::kOff),
                         [](const ::testing::TestParamInfo<BatchPacking>& info) {
                           return info.param == BatchPacking::kOn ? std::string("packed") : std::string("one_a_core");
                         });

TEST(ServiceBatchTest, APackedSetPastItsOwnComparisonLimitFailsAloneAndTheOthersAreBuilt) {
  // A limit of 2,000 exact comparisons a set: a 4,000-point grid's exact ties need about 19,500,
  // uniform points none. The packed build passes the sets' summed limit and stops; its sets are
  // built again one by one, and only the grid answers the limit.
  auto options = TestServerOptions();
  options.service.batch_packing = BatchPacking::kOn;
  options.service.exact_comparisons.per_point = 0.5;
  options.service.exact_comparisons.floor = 2000;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  const auto grid = gen::Grid(4000, 31);
  auto answers = client->BuildBatch(std::vector<client::BatchSet>{
      {"uniform", gen::Uniform(3000, 30), {}}, {"grid", grid, {}}, {"uniform-too", gen::Uniform(2000, 32), {}}});
  ASSERT_THAT(answers, IsOk());
  ASSERT_EQ(answers->size(), 3u);
  EXPECT_THAT((*answers)[0], IsOk());
  EXPECT_THAT((*answers)[1].status(),
              StatusIs(absl::StatusCode::kResourceExhausted, HasSubstr("exact radius comparisons")));
  EXPECT_THAT((*answers)[2], IsOk());
  EXPECT_THAT(client->Describe(PointSetHandle(grid)).status(), StatusIs(absl::StatusCode::kNotFound));
  EXPECT_EQ(ScrapeMetric(*server, "galpha_builds_rejected_total{reason=\"exact_comparisons\"}"), 1.0);
}

TEST(ServiceBatchTest, AMalformedSetFailsTheWholeBatchNamingIt) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  const auto a = gen::Uniform(50, 11);
  const auto b = gen::Uniform(60, 12);
  // Set 1 announces more points than it carries.
  absl::Status status = RawBatch(*client, {NamedHeader("a", a.size()), PointsOf(a), NamedHeader("b", 70), PointsOf(b),
                                           NamedHeader("c", 0), PointsOf(a)});
  EXPECT_THAT(status,
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("set 1 ('b'): the stream ended after 60")));
  // So does the last set, whose end is the stream's.
  status = RawBatch(*client, {NamedHeader("a", a.size()), PointsOf(a), NamedHeader("last", 70), PointsOf(b)});
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("set 1 ('last')")));
  // An odd coordinate count in set 0.
  v1::BuildRequest odd = PointsOf(a);
  odd.mutable_points()->add_coordinates(1.0);
  status = RawBatch(*client, {NamedHeader("odd", 0), odd});
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("set 0 ('odd')")));
  // The client answers an empty batch itself, without a call.
  auto none = client->BuildBatch({});
  ASSERT_THAT(none, IsOk());
  EXPECT_TRUE(none->empty());
  // Points before any header, and no set at all.
  EXPECT_THAT(RawBatch(*client, {PointsOf(a)}),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("began with points")));
  EXPECT_THAT(RawBatch(*client, {}), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("carried no set")));
  // Nothing of the refused batches was built.
  EXPECT_THAT(client->Describe(PointSetHandle(a)).status(), StatusIs(absl::StatusCode::kNotFound));
  EXPECT_EQ(ScrapeMetric(*server, "galpha_cache_entries{tier=\"resident\"}"), 0.0);
  // A batch over the points limit together, though each set is under it.
  auto limits = TestServerOptions();
  limits.service.max_points_per_build = 100;
  auto limited = StartServer(limits);
  ASSERT_NE(limited, nullptr);
  auto limited_client = ClientOf(*limited);
  status = RawBatch(*limited_client, {NamedHeader("a", 0), PointsOf(gen::Uniform(60, 1)), NamedHeader("b", 0),
                                      PointsOf(gen::Uniform(60, 2))});
  EXPECT_THAT(status,
              StatusIs(absl::StatusCode::kResourceExhausted, HasSubstr("set 1 ('b'): the batch's sets hold 120")));
  EXPECT_EQ(ScrapeMetric(*limited, "galpha_builds_rejected_total{reason=\"points_per_build\"}"), 1.0);
}

TEST(ServiceBatchTest, ASetThatFailsAloneLeavesTheOthersBuilt) {
  // A cache that holds a small family but not a large one: the large set's build succeeds and
  // its family is refused by the cache (RESOURCE_EXHAUSTED, as Build answers it).
  const auto small = gen::Uniform(40, 21);
  const auto large = gen::Uniform(20000, 22);
  auto options = TestServerOptions();
  options.service.cache_bytes = 200000;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  auto answers = client->BuildBatch(std::vector<client::BatchSet>{
      {"small", small, {}}, {"large", large, {}}, {"small-too", gen::Uniform(30, 23), {}}});
  ASSERT_THAT(answers, IsOk());
  ASSERT_EQ(answers->size(), 3u);
  EXPECT_THAT((*answers)[0], IsOk());
  EXPECT_THAT((*answers)[1].status(), StatusIs(absl::StatusCode::kResourceExhausted, HasSubstr("cache")));
  EXPECT_THAT((*answers)[2], IsOk());
  EXPECT_THAT(client->Describe(PointSetHandle(small)), IsOk());
  EXPECT_THAT(client->Describe(PointSetHandle(large)).status(), StatusIs(absl::StatusCode::kNotFound));
  EXPECT_EQ(ScrapeMetric(*server, "galpha_builds_rejected_total{reason=\"cache_bytes\"}"), 1.0);
}

TEST(ServiceBatchTest, SetsPastTheBatchDeadlineAreNotStarted) {
  // A time limit of about 1 ms plus 100 ms a set: the first large set (built on the slot, for a
  // second or more) runs past it and stops at a phase boundary; the two after it are
  // answered without being started. Two refusals: the set stopped, and the batch's unstarted rest.
  auto options = TestServerOptions();
  options.service.build_time.multiple = 1e-9;
  options.service.build_time.floor = std::chrono::milliseconds(1);
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  std::vector<std::vector<Point2>> points;
  std::vector<client::BatchSet> batch;
  // Sets whose build takes a second or more on the test's backend (a GPU builds 200,000 points
  // in milliseconds).
  const size_t n = testing::TestBackend() == "cuda" ? 20'000'000 : 200'000;
  for (uint64_t i = 0; i < 3; ++i) points.push_back(gen::Uniform(n, 50 + i));
  for (size_t i = 0; i < 3; ++i) batch.push_back({"large-" + std::to_string(i), points[i], {}});
  auto answers = client->BuildBatch(batch);
  ASSERT_THAT(answers, IsOk());
  ASSERT_EQ(answers->size(), 3u);
  EXPECT_THAT((*answers)[0].status(),
              StatusIs(absl::StatusCode::kDeadlineExceeded, HasSubstr("during this set's build")));
  for (size_t i = 1; i < 3; ++i) {
    EXPECT_THAT((*answers)[i].status(),
                StatusIs(absl::StatusCode::kDeadlineExceeded, HasSubstr("before this set was built")));
    EXPECT_THAT(client->Describe(PointSetHandle(points[i])).status(), StatusIs(absl::StatusCode::kNotFound));
  }
  EXPECT_EQ(ScrapeMetric(*server, "galpha_builds_rejected_total{reason=\"build_time\"}"), 2.0);
}

TEST(ServiceBatchTest, AnswersComeInPagesOfAThousandSets) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  std::vector<std::vector<Point2>> points;
  std::vector<v1::BuildRequest> messages;
  for (size_t i = 0; i < 2500; ++i) {
    points.push_back(gen::Uniform(3 + i % 5, 1000 + i));
    messages.push_back(NamedHeader("set-" + std::to_string(i), points.back().size()));
    messages.push_back(PointsOf(points.back()));
  }
  grpc::ClientContext context;
  client->PrepareContext(&context);
  auto stream = client->stub().BuildBatch(&context);
  for (const v1::BuildRequest& message : messages) ASSERT_TRUE(stream->Write(AsBatch(message)));
  stream->WritesDone();
  std::vector<uint64_t> firsts;
  size_t sets = 0;
  v1::BuildBatchResponse page;
  while (stream->Read(&page)) {
    firsts.push_back(page.first_set());
    EXPECT_EQ(page.set_count(), 2500u);
    for (const v1::BatchedBuild& answer : page.sets()) {
      ASSERT_EQ(answer.code(), 0) << answer.message();
      EXPECT_EQ(answer.result().handle(), PointSetHandle(points[sets]));
      EXPECT_EQ(answer.result().summary().name(), "set-" + std::to_string(sets));
      ++sets;
    }
  }
  ASSERT_THAT(client::FromGrpc(stream->Finish()), IsOk());
  EXPECT_EQ(firsts, (std::vector<uint64_t>{0, 1000, 2000}));
  EXPECT_EQ(sets, 2500u);
}

}  // namespace
}  // namespace galpha::server
