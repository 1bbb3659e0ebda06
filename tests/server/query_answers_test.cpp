// The service's answers against the in-process AlphaFamily as the oracle, on families built on the
// CPU backend from every kind of input the service must handle (uniform, a grid, duplicates, two
// crossing lines, one line, and 0, 1, 2 points): thresholds resolved to the family's levels, the
// Classify stream reproducing ClassifyAll in canonical order, the master list, spectrum pages,
// component curves, optimal alpha, and the shape in every format.
#include "server/query_answers.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/family/classification_summary.hpp"
#include "core/geometry/shape.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gtest/gtest.h"
#include "server/cached_family.hpp"
#include "tests/server/cached_family_fixture.hpp"
#include "tests/support/point_generators.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;

struct NamedFamily {
  std::string name;
  std::shared_ptr<const CachedFamily> cached;
};

std::shared_ptr<const CachedFamily> Build(const std::vector<Point2>& points, const std::string& name) {
  return testing::MakeCachedFamily(points, name);
}

// Points (i, 2i + 1) in shuffled order: exactly collinear, so edges only.
std::vector<Point2> OneLine(size_t n, uint64_t seed) {
  std::vector<Point2> points;
  for (size_t i = 0; i < n; ++i) points.push_back({static_cast<double>(i), 2.0 * static_cast<double>(i) + 1.0});
  std::mt19937_64 random(seed);
  std::shuffle(points.begin(), points.end(), random);
  return points;
}

// The families every test runs on, built once.
const std::vector<NamedFamily>& Families() {
  static const std::vector<NamedFamily>* families = [] {
    const std::vector<std::pair<std::string, std::vector<Point2>>> inputs = {
        {"uniform_2000", gen::Uniform(2000, 1)},
        {"grid_400", gen::Grid(400, 2)},
        {"duplicates_1000", gen::WithDuplicates(1000, 3)},
        {"two_lines_200", gen::TwoLines(200, 4)},
        {"one_line_50", OneLine(50, 5)},
        {"empty", {}},
        {"one_point", gen::Uniform(1, 6)},
        {"two_points", gen::Uniform(2, 7)},
        {"two_equal_points", {{0.25, 0.5}, {0.25, 0.5}}},
    };
    auto* built = new std::vector<NamedFamily>();
    for (const auto& [name, points] : inputs) built->push_back({name, Build(points, name)});
    return built;
  }();
  return *families;
}

// Enough points that every kind of Classify chunk, and the master list, span several messages.
std::shared_ptr<const CachedFamily> LargeFamily() {
  static const std::shared_ptr<const CachedFamily> family = Build(gen::Uniform(50000, 8), "uniform_50000");
  return family;
}

v1::Threshold Rank(int64_t rank) {
  v1::Threshold t;
  t.set_rank(rank);
  return t;
}
v1::Threshold AlphaSq(double alpha_sq) {
  v1::Threshold t;
  t.set_alpha_sq(alpha_sq);
  return t;
}
v1::Threshold Alpha(double alpha) {
  v1::Threshold t;
  t.set_alpha(alpha);
  return t;
}

// Thresholds of every kind that hit interesting levels of `family`.
std::vector<v1::Threshold> Thresholds(const AlphaFamily& family) {
  const int64_t k = family.max_level();
  const auto& s = family.spectrum();
  std::vector<v1::Threshold> out = {Rank(0), Rank(k), AlphaSq(-1.0), AlphaSq(0.0),
                                    AlphaSq(std::numeric_limits<double>::infinity()), Alpha(0.0),
                                    Alpha(std::numeric_limits<double>::infinity())};
  if (k >= 1) {
    out.push_back(Rank(1));
    out.push_back(Rank(k / 2 + 1));
    out.push_back(AlphaSq(s[static_cast<size_t>(k / 3)]));
    out.push_back(AlphaSq(std::nextafter(s[static_cast<size_t>(k / 3)], 0.0)));
    out.push_back(Alpha(std::sqrt(s[static_cast<size_t>(k / 4)])));
  }
  if (k >= 2) {
    const size_t i = static_cast<size_t>(k / 2);
    out.push_back(AlphaSq(0.5 * (s[i - 1] + s[i])));
  }
  return out;
}

template <typename Message>
std::vector<Message> Drain(ChunkSource<Message>& source) {
  std::vector<Message> messages;
  Message message;
  while (source.Next(&message)) {
    messages.push_back(message);
    if (messages.size() > 100000) {
      ADD_FAILURE() << "the source does not end";
      break;
    }
  }
  EXPECT_FALSE(source.Next(&message)) << "a finished source stays finished";
  return messages;
}

// ---- ResolveLevel ---------------------------------------------------------------------------------

TEST(QueryAnswersTest, ResolveLevelMatchesTheFamily) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = f.cached->family();
    const int64_t k = family.max_level();
    for (int64_t rank = 0; rank <= k; rank += std::max<int64_t>(1, k / 50)) {
      const absl::StatusOr<ResolvedLevel> resolved = ResolveLevel(family, Rank(rank));
      ASSERT_TRUE(resolved.ok()) << resolved.status();
      EXPECT_EQ(resolved->level, *family.LevelForRank(rank));
      EXPECT_EQ(resolved->alpha_sq, rank == 0 ? 0.0 : family.spectrum()[static_cast<size_t>(rank - 1)]);
    }
    for (const v1::Threshold& threshold : Thresholds(family)) {
      SCOPED_TRACE(threshold.ShortDebugString());
      const absl::StatusOr<ResolvedLevel> resolved = ResolveLevel(family, threshold);
      ASSERT_TRUE(resolved.ok()) << resolved.status();
      switch (threshold.value_case()) {
        case v1::Threshold::kRank:
          EXPECT_EQ(resolved->level, *family.LevelForRank(threshold.rank()));
          break;
        case v1::Threshold::kAlphaSq:
          EXPECT_EQ(resolved->level, *family.LevelForAlphaSq(threshold.alpha_sq()));
          EXPECT_EQ(resolved->alpha_sq, threshold.alpha_sq());
          break;
        case v1::Threshold::kAlpha:
          EXPECT_EQ(resolved->level, *family.LevelForAlpha(threshold.alpha()));
          EXPECT_EQ(resolved->alpha_sq, threshold.alpha() * threshold.alpha());
          break;
        case v1::Threshold::VALUE_NOT_SET:
          FAIL();
      }
    }
    // Every spectrum value, as alpha_sq, resolves to its own rank (exact comparison).
    for (int64_t rank = 1; rank <= k; rank += std::max<int64_t>(1, k / 50)) {
      const absl::StatusOr<ResolvedLevel> resolved =
          ResolveLevel(family, AlphaSq(family.spectrum()[static_cast<size_t>(rank - 1)]));
      ASSERT_TRUE(resolved.ok());
      EXPECT_EQ(resolved->level, *family.LevelForAlphaSq(family.spectrum()[static_cast<size_t>(rank - 1)]));
    }
  }
}

TEST(QueryAnswersTest, ResolveLevelRefusesBadThresholds) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = f.cached->family();
    const int64_t k = family.max_level();
    const absl::StatusOr<ResolvedLevel> none = ResolveLevel(family, v1::Threshold());
    EXPECT_TRUE(absl::IsInvalidArgument(none.status())) << none.status();
    const absl::StatusOr<ResolvedLevel> beyond = ResolveLevel(family, Rank(k + 1));
    EXPECT_TRUE(absl::IsInvalidArgument(beyond.status())) << beyond.status();
    EXPECT_NE(beyond.status().message().find(absl::StrCat(k + 1)), absl::string_view::npos) << beyond.status();
    EXPECT_TRUE(absl::IsInvalidArgument(ResolveLevel(family, Rank(-1)).status()));
    EXPECT_TRUE(absl::IsInvalidArgument(ResolveLevel(family, AlphaSq(std::nan(""))).status()));
    EXPECT_TRUE(absl::IsInvalidArgument(ResolveLevel(family, Alpha(std::nan(""))).status()));
    EXPECT_TRUE(absl::IsInvalidArgument(ResolveLevel(family, Alpha(-1.0)).status()));
  }
}

TEST(QueryAnswersTest, EnumConversions) {
  EXPECT_EQ(ToClassifyMode(v1::CLASSIFY_MODE_UNSPECIFIED), ClassifyMode::kGeneral);
  EXPECT_EQ(ToClassifyMode(v1::CLASSIFY_MODE_GENERAL), ClassifyMode::kGeneral);
  EXPECT_EQ(ToClassifyMode(v1::CLASSIFY_MODE_REGULARIZED), ClassifyMode::kRegularized);
  EXPECT_EQ(ToVertexRule(v1::VERTEX_RULE_UNSPECIFIED), VertexRule::kReport);
  EXPECT_EQ(ToVertexRule(v1::VERTEX_RULE_REPORT), VertexRule::kReport);
  EXPECT_EQ(ToVertexRule(v1::VERTEX_RULE_CGAL), VertexRule::kCgal);
}

TEST(QueryAnswersTest, BuildSummaryDescribesTheFamily) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = f.cached->family();
    v1::BuildSummary summary;
    FillBuildSummary(*f.cached, &summary);
    EXPECT_EQ(summary.name(), f.name);
    EXPECT_EQ(summary.points(), family.points().size());
    EXPECT_EQ(summary.distinct_points(), family.num_unique());
    EXPECT_EQ(summary.duplicates(), family.num_duplicates());
    EXPECT_EQ(summary.distinct_points() + summary.duplicates(), summary.points());
    EXPECT_EQ(summary.triangles(), family.triangles().size());
    EXPECT_EQ(summary.edges(), family.edges().size());
    EXPECT_EQ(summary.spectrum_size(), family.spectrum().size());
    EXPECT_EQ(summary.backend(), family.report().backend);
    EXPECT_EQ(summary.family_bytes(), f.cached->bytes());
    EXPECT_EQ(static_cast<size_t>(summary.stage_times_size()), family.report().stage_times.size());
  }
}

// ---- Classify -------------------------------------------------------------------------------------

// One simplex as the stream names it: kind, sorted vertex indices, class byte.
using StreamedSimplex = std::tuple<int, std::vector<uint32_t>, int>;

int ClassByte(SimplexClass c) { return static_cast<int>(c) + 1; }

// What the Classify stream must carry after its summary, from ClassifyAll.
std::vector<StreamedSimplex> ExpectedSimplices(const AlphaFamily& family, const Classification& classes,
                                               bool non_exterior_only) {
  auto sent = [&](SimplexClass c) { return !(non_exterior_only && c == SimplexClass::kExterior); };
  std::vector<StreamedSimplex> out;
  for (uint32_t v = 0; v < family.points().size(); ++v) {
    if (family.representative()[v] == v && sent(classes.vertices[v])) {
      out.emplace_back(v1::SIMPLEX_KIND_VERTEX, std::vector<uint32_t>{v}, ClassByte(classes.vertices[v]));
    }
  }
  std::vector<std::pair<std::array<uint32_t, 2>, SimplexClass>> edges;
  for (uint32_t e = 0; e < family.edges().size(); ++e) {
    const auto& edge = family.edges()[e];
    edges.push_back({{std::min(edge[0], edge[1]), std::max(edge[0], edge[1])}, classes.edges[e]});
  }
  std::sort(edges.begin(), edges.end());
  for (const auto& [edge, c] : edges) {
    if (sent(c)) out.emplace_back(v1::SIMPLEX_KIND_EDGE, std::vector<uint32_t>{edge[0], edge[1]}, ClassByte(c));
  }
  std::vector<std::pair<std::array<uint32_t, 3>, SimplexClass>> triangles;
  for (uint32_t t = 0; t < family.triangles().size(); ++t) {
    std::array<uint32_t, 3> triangle = family.triangles()[t];
    std::sort(triangle.begin(), triangle.end());
    triangles.push_back({triangle, classes.triangles[t]});
  }
  std::sort(triangles.begin(), triangles.end());
  for (const auto& [triangle, c] : triangles) {
    if (sent(c)) {
      out.emplace_back(v1::SIMPLEX_KIND_TRIANGLE, std::vector<uint32_t>{triangle[0], triangle[1], triangle[2]},
                       ClassByte(c));
    }
  }
  return out;
}

// Counts per class of ClassifyAll, as ClassCounts (vertices: distinct points only).
v1::ClassCounts Count(const std::vector<SimplexClass>& classes, const HostVector<uint32_t>* representative) {
  std::array<uint64_t, 4> counts{};
  for (uint32_t i = 0; i < classes.size(); ++i) {
    if (representative == nullptr || (*representative)[i] == i) ++counts[static_cast<size_t>(classes[i])];
  }
  v1::ClassCounts out;
  out.set_exterior(counts[0]);
  out.set_singular(counts[1]);
  out.set_regular(counts[2]);
  out.set_interior(counts[3]);
  return out;
}

void ExpectCountsEqual(const v1::ClassCounts& got, const v1::ClassCounts& expected) {
  EXPECT_EQ(got.exterior(), expected.exterior());
  EXPECT_EQ(got.singular(), expected.singular());
  EXPECT_EQ(got.regular(), expected.regular());
  EXPECT_EQ(got.interior(), expected.interior());
}

// Runs one Classify request against the family and checks every message.
void CheckClassify(const std::shared_ptr<const CachedFamily>& cached, const v1::ClassifyRequest& request,
                   size_t* chunks_out = nullptr) {
  SCOPED_TRACE(request.ShortDebugString());
  const AlphaFamily& family = cached->family();
  auto source = MakeClassifySource(cached, request);
  ASSERT_TRUE(source.ok()) << source.status();
  const std::vector<v1::ClassifyResponse> messages = Drain(**source);
  ASSERT_FALSE(messages.empty());

  const int64_t level = ResolveLevel(family, request.threshold())->level;
  const ClassifyMode mode = ToClassifyMode(request.mode());
  const Classification classes = family.ClassifyAll(level, mode, ToVertexRule(request.vertex_rule()));

  ASSERT_EQ(messages[0].part_case(), v1::ClassifyResponse::kSummary);
  const v1::ClassifySummary& summary = messages[0].summary();
  EXPECT_EQ(summary.level(), level);
  EXPECT_EQ(summary.alpha_sq(), ResolveLevel(family, request.threshold())->alpha_sq);
  ExpectCountsEqual(summary.vertices(), Count(classes.vertices, &family.representative()));
  ExpectCountsEqual(summary.edges(), Count(classes.edges, nullptr));
  ExpectCountsEqual(summary.triangles(), Count(classes.triangles, nullptr));
  EXPECT_EQ(summary.components(), family.Components(level));
  EXPECT_EQ(summary.solid_components(), family.SolidComponents(level));
  const absl::StatusOr<ShapeGeometry> shape = AssembleShape(family.ComplexAt(level, mode));
  ASSERT_TRUE(shape.ok()) << shape.status();
  EXPECT_EQ(summary.interior_area(), shape->area) << "the interior area is the shape's area";

  if (request.summary_only()) {
    EXPECT_EQ(messages.size(), 1u);
    return;
  }
  std::vector<StreamedSimplex> streamed;
  std::array<size_t, 4> chunks_of_kind{};
  int last_kind = v1::SIMPLEX_KIND_VERTEX;
  for (size_t m = 1; m < messages.size(); ++m) {
    ASSERT_EQ(messages[m].part_case(), v1::ClassifyResponse::kChunk) << "message " << m;
    const v1::SimplexChunk& chunk = messages[m].chunk();
    const int kind = chunk.kind();
    ASSERT_GE(kind, last_kind) << "kinds come in order vertex, edge, triangle";
    ASSERT_LE(kind, v1::SIMPLEX_KIND_TRIANGLE);
    last_kind = kind;
    ++chunks_of_kind[static_cast<size_t>(kind)];
    const size_t arity = static_cast<size_t>(kind);  // SIMPLEX_KIND_VERTEX = 1, EDGE = 2, TRIANGLE = 3
    const size_t simplices = chunk.classes().size();
    EXPECT_GT(simplices, 0u) << "no empty chunks";
    EXPECT_LE(simplices, kSimplicesPerChunk);
    ASSERT_EQ(static_cast<size_t>(chunk.vertex_indices_size()), arity * simplices);
    for (size_t i = 0; i < simplices; ++i) {
      std::vector<uint32_t> indices(chunk.vertex_indices().begin() + static_cast<int>(i * arity),
                                    chunk.vertex_indices().begin() + static_cast<int>((i + 1) * arity));
      streamed.emplace_back(kind, std::move(indices), static_cast<int>(chunk.classes()[i]));
    }
  }
  if (chunks_out != nullptr) *chunks_out = messages.size() - 1;
  const std::vector<StreamedSimplex> expected = ExpectedSimplices(family, classes, request.non_exterior_only());
  // Every chunk but the last of its kind is full.
  std::array<size_t, 4> expected_of_kind{};
  for (const StreamedSimplex& simplex : expected) ++expected_of_kind[static_cast<size_t>(std::get<0>(simplex))];
  for (size_t kind = 1; kind <= 3; ++kind) {
    EXPECT_EQ(chunks_of_kind[kind], (expected_of_kind[kind] + kSimplicesPerChunk - 1) / kSimplicesPerChunk)
        << "chunks of kind " << kind;
  }
  ASSERT_EQ(streamed.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    if (streamed[i] != expected[i]) {
      ADD_FAILURE() << "simplex " << i << " differs: kind " << std::get<0>(streamed[i]) << " vs "
                    << std::get<0>(expected[i]) << ", class " << std::get<2>(streamed[i]) << " vs "
                    << std::get<2>(expected[i]);
      break;
    }
  }
}

TEST(QueryAnswersTest, ClassifyStreamsEverySimplexInOrder) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    for (const v1::Threshold& threshold : Thresholds(f.cached->family())) {
      for (const v1::ClassifyMode mode : {v1::CLASSIFY_MODE_GENERAL, v1::CLASSIFY_MODE_REGULARIZED}) {
        for (const v1::VertexRule rule : {v1::VERTEX_RULE_REPORT, v1::VERTEX_RULE_CGAL}) {
          for (const bool non_exterior_only : {false, true}) {
            v1::ClassifyRequest request;
            *request.mutable_threshold() = threshold;
            request.set_mode(mode);
            request.set_vertex_rule(rule);
            request.set_non_exterior_only(non_exterior_only);
            CheckClassify(f.cached, request);
          }
        }
      }
    }
  }
}

TEST(QueryAnswersTest, ClassifyNonExteriorOnlyDropsExactlyTheExterior) {
  const std::shared_ptr<const CachedFamily>& cached = Families()[0].cached;
  ASSERT_NE(cached, nullptr);
  v1::ClassifyRequest request;
  *request.mutable_threshold() = Rank(cached->family().max_level() / 3);
  auto all = MakeClassifySource(cached, request);
  request.set_non_exterior_only(true);
  auto some = MakeClassifySource(cached, request);
  ASSERT_TRUE(all.ok() && some.ok());
  const auto all_messages = Drain(**all);
  const auto some_messages = Drain(**some);
  size_t all_sent = 0, exterior = 0, some_sent = 0;
  for (size_t m = 1; m < all_messages.size(); ++m) {
    for (const char c : all_messages[m].chunk().classes()) {
      ++all_sent;
      exterior += c == v1::SIMPLEX_CLASS_EXTERIOR;
    }
  }
  for (size_t m = 1; m < some_messages.size(); ++m) {
    for (const char c : some_messages[m].chunk().classes()) {
      ++some_sent;
      EXPECT_NE(c, v1::SIMPLEX_CLASS_EXTERIOR);
    }
  }
  EXPECT_GT(exterior, 0u) << "the test needs exterior simplices at this rank";
  EXPECT_EQ(some_sent, all_sent - exterior);
  EXPECT_EQ(all_messages[0].SerializeAsString(), some_messages[0].SerializeAsString())
      << "the summary still counts every class";
}

TEST(QueryAnswersTest, ClassifySummaryOnlySendsOneMessage) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    for (const v1::Threshold& threshold : Thresholds(f.cached->family())) {
      v1::ClassifyRequest request;
      *request.mutable_threshold() = threshold;
      request.set_summary_only(true);
      CheckClassify(f.cached, request);
    }
  }
}

TEST(QueryAnswersTest, ClassifyRefusesBadThresholds) {
  const std::shared_ptr<const CachedFamily>& cached = Families()[0].cached;
  ASSERT_NE(cached, nullptr);
  v1::ClassifyRequest request;
  EXPECT_TRUE(absl::IsInvalidArgument(MakeClassifySource(cached, request).status()));
  *request.mutable_threshold() = Rank(cached->family().max_level() + 1);
  EXPECT_TRUE(absl::IsInvalidArgument(MakeClassifySource(cached, request).status()));
}

TEST(QueryAnswersTest, ClassifyChunksNeverExceedTheLimit) {
  const std::shared_ptr<const CachedFamily> cached = LargeFamily();
  ASSERT_NE(cached, nullptr);
  ASSERT_GT(cached->family().edges().size(), size_t{kSimplicesPerChunk}) << "the test needs several edge chunks";
  for (const int64_t rank : {cached->family().max_level() / 2, cached->family().max_level()}) {
    for (const bool non_exterior_only : {false, true}) {
      v1::ClassifyRequest request;
      *request.mutable_threshold() = Rank(rank);
      request.set_non_exterior_only(non_exterior_only);
      size_t chunks = 0;
      CheckClassify(cached, request, &chunks);
      // Every simplex is sent, or (at rank K) none is exterior: edges take two chunks.
      if (!non_exterior_only || rank == cached->family().max_level()) {
        EXPECT_GE(chunks, 4u) << "vertices, edges in two chunks, triangles";
      }
    }
  }
}

// ---- MasterList -----------------------------------------------------------------------------------

// One master-list entry as the stream names it: rank, kind byte, endpoint byte, sorted indices.
using StreamedEntry = std::tuple<uint64_t, int, int, std::vector<uint32_t>>;

std::vector<StreamedEntry> ExpectedMasterList(const AlphaFamily& family, int64_t first, int64_t last) {
  std::vector<StreamedEntry> out;
  for (int64_t rank = first; rank <= last; ++rank) {
    for (const MasterEntry& entry : family.MasterList(rank)) {
      std::vector<uint32_t> indices;
      switch (entry.kind()) {
        case SimplexKind::kVertex:
          indices.push_back(entry.id());
          break;
        case SimplexKind::kEdge:
          for (const uint32_t v : family.edges()[entry.id()]) indices.push_back(v);
          break;
        case SimplexKind::kTriangle:
          for (const uint32_t v : family.triangles()[entry.id()]) indices.push_back(v);
          break;
      }
      std::sort(indices.begin(), indices.end());
      out.emplace_back(static_cast<uint64_t>(rank), static_cast<int>(entry.kind()) + 1,
                       static_cast<int>(entry.endpoint()) + 1, std::move(indices));
    }
  }
  return out;
}

void CheckMasterList(const std::shared_ptr<const CachedFamily>& cached, int64_t first, int64_t last_field) {
  SCOPED_TRACE(absl::StrCat("ranks ", first, "..", last_field));
  const int64_t last = last_field == 0 ? first : last_field;
  v1::MasterListRequest request;
  request.set_first_rank(first);
  request.set_last_rank(last_field);
  auto source = MakeMasterListSource(cached, request);
  ASSERT_TRUE(source.ok()) << source.status();
  std::vector<StreamedEntry> streamed;
  const std::vector<v1::MasterListResponse> messages = Drain(**source);
  for (const v1::MasterListResponse& message : messages) {
    const size_t entries = static_cast<size_t>(message.ranks_size());
    EXPECT_GT(entries, 0u);
    EXPECT_LE(entries, kMasterEntriesPerChunk);
    ASSERT_EQ(message.kinds().size(), entries);
    ASSERT_EQ(message.endpoints().size(), entries);
    int position = 0;
    for (size_t i = 0; i < entries; ++i) {
      const int kind = message.kinds()[i];
      ASSERT_GE(kind, v1::SIMPLEX_KIND_VERTEX);
      ASSERT_LE(kind, v1::SIMPLEX_KIND_TRIANGLE);
      ASSERT_LE(position + kind, message.vertex_indices_size());
      std::vector<uint32_t> indices(message.vertex_indices().begin() + position,
                                    message.vertex_indices().begin() + position + kind);
      position += kind;
      streamed.emplace_back(message.ranks(static_cast<int>(i)), kind, static_cast<int>(message.endpoints()[i]),
                            std::move(indices));
    }
    EXPECT_EQ(position, message.vertex_indices_size());
  }
  const std::vector<StreamedEntry> expected = ExpectedMasterList(cached->family(), first, last);
  EXPECT_EQ(messages.size(), (expected.size() + kMasterEntriesPerChunk - 1) / kMasterEntriesPerChunk)
      << "every message but the last is full";
  ASSERT_EQ(streamed.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    if (streamed[i] != expected[i]) {
      ADD_FAILURE() << "entry " << i << " differs: rank " << std::get<0>(streamed[i]) << " vs "
                    << std::get<0>(expected[i]);
      break;
    }
  }
}

TEST(QueryAnswersTest, MasterListReproducesTheFamilysList) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const int64_t k = f.cached->family().max_level();
    if (k == 0) continue;
    CheckMasterList(f.cached, 1, 0);
    CheckMasterList(f.cached, k, 0);
    CheckMasterList(f.cached, 1, k);
    CheckMasterList(f.cached, (k + 1) / 2, std::min(k, (k + 1) / 2 + 5));
    CheckMasterList(f.cached, k, k);
  }
}

TEST(QueryAnswersTest, MasterListOfALargeFamilySpansSeveralMessages) {
  const std::shared_ptr<const CachedFamily> cached = LargeFamily();
  ASSERT_NE(cached, nullptr);
  ASSERT_GT(cached->family().ranks().master.size(), 2 * size_t{kMasterEntriesPerChunk});
  CheckMasterList(cached, 1, cached->family().max_level());
}

TEST(QueryAnswersTest, MasterListRefusesBadRanges) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const int64_t k = f.cached->family().max_level();
    std::vector<std::pair<int64_t, int64_t>> bad = {{0, 0}, {0, 1}, {-1, 0}, {k + 1, 0}, {k + 1, k + 1},
                                                    {1, k + 1}, {2, 1}};
    if (k >= 2) bad.push_back({k, k - 1});  // reversed (k - 1 = 0 would mean "first alone")
    for (const auto& [first, last] : bad) {
      SCOPED_TRACE(absl::StrCat(first, "..", last));
      v1::MasterListRequest request;
      request.set_first_rank(first);
      request.set_last_rank(last);
      const auto source = MakeMasterListSource(f.cached, request);
      EXPECT_TRUE(absl::IsInvalidArgument(source.status())) << source.status();
    }
  }
}

TEST(QueryAnswersTest, MasterListOfAnEmptySpectrumIsRefused) {
  size_t checked = 0;
  for (const NamedFamily& f : Families()) {
    ASSERT_NE(f.cached, nullptr);
    if (f.cached->family().max_level() != 0) continue;
    SCOPED_TRACE(f.name);
    ++checked;
    for (const int64_t first : {int64_t{0}, int64_t{1}, int64_t{2}}) {
      v1::MasterListRequest request;
      request.set_first_rank(first);
      const auto source = MakeMasterListSource(f.cached, request);
      EXPECT_TRUE(absl::IsInvalidArgument(source.status())) << source.status();
      EXPECT_NE(source.status().message().find("empty"), absl::string_view::npos) << source.status();
    }
  }
  EXPECT_GE(checked, 2u) << "the empty and one-point families have no spectrum";
}

// ---- Spectrum -------------------------------------------------------------------------------------

TEST(QueryAnswersTest, SpectrumPagesConcatenateToTheSpectrum) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = f.cached->family();
    const int64_t k = family.max_level();
    for (const uint32_t page_size : {1u, 7u, 1000u, 0u, kMaxSpectrumPage}) {
      SCOPED_TRACE(page_size);
      std::vector<double> all;
      v1::SpectrumRequest request;
      request.set_page_size(page_size);
      request.set_first_rank(1);
      for (int pages = 0;; ++pages) {
        ASSERT_LT(pages, 100000) << "next_rank never reaches 0";
        const absl::StatusOr<v1::SpectrumResponse> page = AnswerSpectrum(family, request);
        ASSERT_TRUE(page.ok()) << page.status();
        EXPECT_EQ(page->first_rank(), request.first_rank());
        EXPECT_EQ(page->spectrum_size(), k);
        const int64_t size = page->alpha_sq_size();
        EXPECT_LE(size, page_size == 0 ? int64_t{kDefaultSpectrumPage} : int64_t{page_size});
        all.insert(all.end(), page->alpha_sq().begin(), page->alpha_sq().end());
        if (page->next_rank() == 0) {
          EXPECT_EQ(request.first_rank() + size - 1, k) << "the last page reaches rank K";
          break;
        }
        EXPECT_EQ(page->next_rank(), request.first_rank() + size);
        EXPECT_GT(size, 0);
        request.set_first_rank(page->next_rank());
      }
      EXPECT_EQ(all, family.spectrum());
    }
    // Without a start: from rank 1, 65536 values per page.
    const absl::StatusOr<v1::SpectrumResponse> whole = AnswerSpectrum(family, v1::SpectrumRequest());
    ASSERT_TRUE(whole.ok()) << whole.status();
    EXPECT_EQ(whole->first_rank(), 1);
    EXPECT_EQ(std::vector<double>(whole->alpha_sq().begin(), whole->alpha_sq().end()), family.spectrum());
    EXPECT_EQ(whole->next_rank(), 0);
    // K + 1: an empty page at the end.
    v1::SpectrumRequest past;
    past.set_first_rank(k + 1);
    const absl::StatusOr<v1::SpectrumResponse> empty = AnswerSpectrum(family, past);
    ASSERT_TRUE(empty.ok()) << empty.status();
    EXPECT_EQ(empty->alpha_sq_size(), 0);
    EXPECT_EQ(empty->next_rank(), 0);
    EXPECT_EQ(empty->first_rank(), k + 1);
  }
}

TEST(QueryAnswersTest, SpectrumFromAtLeastAlphaSq) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = f.cached->family();
    const int64_t k = family.max_level();
    const auto& s = family.spectrum();
    std::vector<double> values = {-1.0, 0.0, 1e-300, std::numeric_limits<double>::infinity(), 1e300};
    for (int64_t rank = 1; rank <= k; rank += std::max<int64_t>(1, k / 7)) {
      const double v = s[static_cast<size_t>(rank - 1)];
      values.push_back(v);
      values.push_back(std::nextafter(v, 0.0));
      values.push_back(std::nextafter(v, std::numeric_limits<double>::infinity()));
    }
    for (const double x : values) {
      SCOPED_TRACE(x);
      v1::SpectrumRequest request;
      request.set_at_least_alpha_sq(x);
      request.set_page_size(5);
      const absl::StatusOr<v1::SpectrumResponse> page = AnswerSpectrum(family, request);
      ASSERT_TRUE(page.ok()) << page.status();
      const int64_t first = family.RankLowerBound(x);
      EXPECT_EQ(page->first_rank(), first);
      const int64_t end = std::min<int64_t>(k, first + 4);
      ASSERT_EQ(page->alpha_sq_size(), std::max<int64_t>(0, end - first + 1));
      for (int i = 0; i < page->alpha_sq_size(); ++i) {
        EXPECT_EQ(page->alpha_sq(i), s[static_cast<size_t>(first - 1 + i)]);
      }
      EXPECT_EQ(page->next_rank(), end < k ? end + 1 : 0);
    }
  }
}

TEST(QueryAnswersTest, SpectrumRefusesBadRequests) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = f.cached->family();
    const int64_t k = family.max_level();
    for (const int64_t first : {int64_t{0}, int64_t{-1}, k + 2}) {
      v1::SpectrumRequest request;
      request.set_first_rank(first);
      EXPECT_TRUE(absl::IsInvalidArgument(AnswerSpectrum(family, request).status())) << first;
    }
    v1::SpectrumRequest too_large;
    too_large.set_page_size(kMaxSpectrumPage + 1);
    const auto refused = AnswerSpectrum(family, too_large);
    EXPECT_TRUE(absl::IsInvalidArgument(refused.status())) << refused.status();
    v1::SpectrumRequest nan;
    nan.set_at_least_alpha_sq(std::nan(""));
    EXPECT_TRUE(absl::IsInvalidArgument(AnswerSpectrum(family, nan).status()));
  }
}

// ---- Components / OptimalAlpha --------------------------------------------------------------------

TEST(QueryAnswersTest, ComponentsAtAThresholdAndOverARange) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = f.cached->family();
    const int64_t k = family.max_level();
    for (const v1::Threshold& threshold : Thresholds(family)) {
      SCOPED_TRACE(threshold.ShortDebugString());
      v1::ComponentsRequest request;
      *request.mutable_threshold() = threshold;
      const absl::StatusOr<v1::ComponentsResponse> response = AnswerComponents(family, request);
      ASSERT_TRUE(response.ok()) << response.status();
      const int64_t level = ResolveLevel(family, threshold)->level;
      EXPECT_EQ(response->first_level(), level);
      ASSERT_EQ(response->components_size(), 1);
      ASSERT_EQ(response->solid_components_size(), 1);
      EXPECT_EQ(response->components(0), family.Components(level));
      EXPECT_EQ(response->solid_components(0), family.SolidComponents(level));
    }
    const std::vector<std::pair<int64_t, int64_t>> ranges = {{0, k}, {0, 0}, {k, k}, {k / 2, std::min(k, k / 2 + 3)}};
    for (const auto& [first, last] : ranges) {
      SCOPED_TRACE(absl::StrCat(first, "..", last));
      v1::ComponentsRequest request;
      request.mutable_ranks()->set_first(first);
      request.mutable_ranks()->set_last(last);
      const absl::StatusOr<v1::ComponentsResponse> response = AnswerComponents(family, request);
      ASSERT_TRUE(response.ok()) << response.status();
      EXPECT_EQ(response->first_level(), first);
      ASSERT_EQ(response->components_size(), last - first + 1);
      ASSERT_EQ(response->solid_components_size(), last - first + 1);
      for (int64_t level = first; level <= last; ++level) {
        EXPECT_EQ(response->components(static_cast<int>(level - first)), family.Components(level)) << level;
        EXPECT_EQ(response->solid_components(static_cast<int>(level - first)), family.SolidComponents(level))
            << level;
      }
    }
  }
}

TEST(QueryAnswersTest, ComponentsRefusesBadRequests) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = f.cached->family();
    const int64_t k = family.max_level();
    EXPECT_TRUE(absl::IsInvalidArgument(AnswerComponents(family, v1::ComponentsRequest()).status()));
    const std::vector<std::pair<int64_t, int64_t>> bad = {{-1, 0}, {0, k + 1}, {1, 0}, {k + 1, k + 1}, {-5, -1}};
    for (const auto& [first, last] : bad) {
      SCOPED_TRACE(absl::StrCat(first, "..", last));
      v1::ComponentsRequest request;
      request.mutable_ranks()->set_first(first);
      request.mutable_ranks()->set_last(last);
      const auto response = AnswerComponents(family, request);
      EXPECT_TRUE(absl::IsInvalidArgument(response.status())) << response.status();
    }
    v1::ComponentsRequest beyond;
    *beyond.mutable_threshold() = Rank(k + 1);
    EXPECT_TRUE(absl::IsInvalidArgument(AnswerComponents(family, beyond).status()));
    v1::ComponentsRequest no_value;
    no_value.mutable_threshold();  // a threshold with none of its three values
    EXPECT_TRUE(absl::IsInvalidArgument(AnswerComponents(family, no_value).status()));
  }
}

TEST(QueryAnswersTest, OptimalAlphaMatchesTheFamily) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = f.cached->family();
    for (const uint32_t n : {1u, 2u, 3u, 5u, 10u, 100u, 1000000u}) {
      SCOPED_TRACE(n);
      v1::OptimalAlphaRequest request;
      request.set_max_components(n);
      const absl::StatusOr<v1::OptimalAlphaResponse> response = AnswerOptimalAlpha(family, request);
      ASSERT_TRUE(response.ok()) << response.status();
      const auto published = [&](int64_t level) {
        return level == 0 ? 0.0 : family.spectrum()[static_cast<size_t>(level - 1)];
      };
      const std::optional<int64_t> regularized = family.OptimalLevelRegularized(n);
      ASSERT_EQ(response->has_regularized(), regularized.has_value());
      if (regularized) {
        EXPECT_EQ(response->regularized().rank(), *regularized);
        EXPECT_EQ(response->regularized().alpha_sq(), published(*regularized));
        EXPECT_EQ(response->regularized().components(), family.SolidComponents(*regularized));
        EXPECT_LE(response->regularized().components(), n);
      }
      const std::optional<int64_t> general = family.OptimalLevelGeneral(n);
      ASSERT_EQ(response->has_general(), general.has_value());
      if (general) {
        EXPECT_EQ(response->general().rank(), *general);
        EXPECT_EQ(response->general().alpha_sq(), published(*general));
        EXPECT_EQ(response->general().components(), family.Components(*general));
        EXPECT_LE(response->general().components(), n);
      }
    }
    const auto refused = AnswerOptimalAlpha(family, v1::OptimalAlphaRequest());
    EXPECT_TRUE(absl::IsInvalidArgument(refused.status())) << refused.status();
  }
}

// ---- Shape ----------------------------------------------------------------------------------------

TEST(QueryAnswersTest, ShapeTextFormatsMatchTheWriters) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = f.cached->family();
    for (const v1::Threshold& threshold : Thresholds(family)) {
      for (const v1::ClassifyMode mode : {v1::CLASSIFY_MODE_GENERAL, v1::CLASSIFY_MODE_REGULARIZED}) {
        SCOPED_TRACE(absl::StrCat(threshold.ShortDebugString(), " mode ", mode));
        const int64_t level = ResolveLevel(family, threshold)->level;
        const absl::StatusOr<ShapeGeometry> shape = AssembleShape(family.ComplexAt(level, ToClassifyMode(mode)));
        ASSERT_TRUE(shape.ok()) << shape.status();
        const std::pair<v1::ShapeFormat, std::string> formats[] = {
            {v1::SHAPE_FORMAT_GEOJSON, ShapeToGeoJson(*shape, family.points())},
            {v1::SHAPE_FORMAT_WKT, ShapeToWkt(*shape, family.points())},
            {v1::SHAPE_FORMAT_SVG, ShapeToSvg(*shape, family.points())},
        };
        for (const auto& [format, expected] : formats) {
          SCOPED_TRACE(v1::ShapeFormat_Name(format));
          v1::ShapeRequest request;
          *request.mutable_threshold() = threshold;
          request.set_mode(mode);
          request.set_format(format);
          auto source = MakeShapeSource(f.cached, request);
          ASSERT_TRUE(source.ok()) << source.status();
          std::string text;
          for (const v1::ShapeResponse& piece : Drain(**source)) {
            ASSERT_EQ(piece.part_case(), v1::ShapeResponse::kText);
            EXPECT_FALSE(piece.text().empty());
            EXPECT_LE(piece.text().size(), kShapeTextBytesPerChunk);
            text += piece.text();
          }
          EXPECT_EQ(text, expected);
        }
      }
    }
  }
}

TEST(QueryAnswersTest, ShapeTextOfALargeFamilySpansSeveralPieces) {
  const std::shared_ptr<const CachedFamily> cached = LargeFamily();
  ASSERT_NE(cached, nullptr);
  const AlphaFamily& family = cached->family();
  v1::ShapeRequest request;
  *request.mutable_threshold() = Rank(family.max_level() / 3);
  request.set_format(v1::SHAPE_FORMAT_GEOJSON);
  const absl::StatusOr<ShapeGeometry> shape =
      AssembleShape(family.ComplexAt(ResolveLevel(family, request.threshold())->level, ClassifyMode::kGeneral));
  ASSERT_TRUE(shape.ok()) << shape.status();
  const std::string expected = ShapeToGeoJson(*shape, family.points());
  ASSERT_GT(expected.size(), kShapeTextBytesPerChunk) << "the test needs a text of several pieces";
  auto source = MakeShapeSource(cached, request);
  ASSERT_TRUE(source.ok()) << source.status();
  const std::vector<v1::ShapeResponse> pieces = Drain(**source);
  EXPECT_EQ(pieces.size(), (expected.size() + kShapeTextBytesPerChunk - 1) / kShapeTextBytesPerChunk);
  std::string text;
  for (const v1::ShapeResponse& piece : pieces) {
    EXPECT_LE(piece.text().size(), kShapeTextBytesPerChunk);
    text += piece.text();
  }
  EXPECT_EQ(text, expected);
}

// Element by element: GCC 12's -Wnonnull misfires on vector::assign from a RepeatedField's pointers.
std::vector<uint32_t> ToVector(const google::protobuf::RepeatedField<uint32_t>& field) {
  std::vector<uint32_t> out;
  out.reserve(static_cast<size_t>(field.size()));
  for (const uint32_t v : field) out.push_back(v);
  return out;
}

// The ShapeGeometry that RINGS pieces carry, put back together.
ShapeGeometry JoinRings(const std::vector<v1::ShapeResponse>& pieces) {
  ShapeGeometry shape;
  for (size_t i = 0; i < pieces.size(); ++i) {
    EXPECT_EQ(pieces[i].part_case(), v1::ShapeResponse::kRings);
    const v1::ShapeRings& rings = pieces[i].rings();
    if (i == 0) {
      shape.area = rings.area();
    } else {
      EXPECT_EQ(rings.area(), 0.0) << "the area is in the first piece only";
    }
    for (const v1::ShapePolygon& polygon : rings.polygons()) {
      ShapePolygon out;
      out.outer = ToVector(polygon.outer());
      for (const v1::Ring& hole : polygon.holes()) out.holes.push_back(ToVector(hole.vertex_indices()));
      shape.polygons.push_back(std::move(out));
    }
    EXPECT_EQ(rings.singular_edges_size() % 2, 0);
    for (int e = 0; e + 1 < rings.singular_edges_size(); e += 2) {
      shape.singular_edges.push_back({rings.singular_edges(e), rings.singular_edges(e + 1)});
    }
    for (const uint32_t v : rings.isolated_points()) shape.isolated_points.push_back(v);
  }
  return shape;
}

void ExpectSameGeometry(const ShapeGeometry& got, const ShapeGeometry& expected) {
  EXPECT_EQ(got.area, expected.area);
  ASSERT_EQ(got.polygons.size(), expected.polygons.size());
  for (size_t p = 0; p < expected.polygons.size(); ++p) {
    EXPECT_EQ(got.polygons[p].outer, expected.polygons[p].outer) << "polygon " << p;
    EXPECT_EQ(got.polygons[p].holes, expected.polygons[p].holes) << "polygon " << p;
  }
  EXPECT_EQ(got.singular_edges, expected.singular_edges);
  EXPECT_EQ(got.isolated_points, expected.isolated_points);
}

TEST(QueryAnswersTest, ShapeRingsReproduceTheGeometry) {
  size_t with_holes = 0, with_singular = 0, with_isolated = 0;
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = f.cached->family();
    for (const v1::Threshold& threshold : Thresholds(family)) {
      for (const v1::ClassifyMode mode : {v1::CLASSIFY_MODE_GENERAL, v1::CLASSIFY_MODE_REGULARIZED}) {
        SCOPED_TRACE(absl::StrCat(threshold.ShortDebugString(), " mode ", mode));
        const int64_t level = ResolveLevel(family, threshold)->level;
        const absl::StatusOr<ShapeGeometry> shape = AssembleShape(family.ComplexAt(level, ToClassifyMode(mode)));
        ASSERT_TRUE(shape.ok()) << shape.status();
        v1::ShapeRequest request;
        *request.mutable_threshold() = threshold;
        request.set_mode(mode);
        request.set_format(v1::SHAPE_FORMAT_RINGS);
        auto source = MakeShapeSource(f.cached, request);
        ASSERT_TRUE(source.ok()) << source.status();
        const std::vector<v1::ShapeResponse> pieces = Drain(**source);
        ASSERT_GE(pieces.size(), 1u) << "even an empty shape sends its area";
        ExpectSameGeometry(JoinRings(pieces), *shape);
        for (const ShapePolygon& polygon : shape->polygons) with_holes += !polygon.holes.empty();
        with_singular += !shape->singular_edges.empty();
        with_isolated += !shape->isolated_points.empty();
      }
    }
  }
  // The inputs must exercise every part of the geometry, or the comparison proves little.
  EXPECT_GT(with_holes, 0u);
  EXPECT_GT(with_singular, 0u);
  EXPECT_GT(with_isolated, 0u);
}

TEST(QueryAnswersTest, ShapeRingsOfALargeFamily) {
  const std::shared_ptr<const CachedFamily> cached = LargeFamily();
  ASSERT_NE(cached, nullptr);
  const AlphaFamily& family = cached->family();
  for (const int64_t rank : {family.max_level() / 3, family.max_level() / 10}) {
    SCOPED_TRACE(rank);
    v1::ShapeRequest request;
    *request.mutable_threshold() = Rank(rank);
    request.set_format(v1::SHAPE_FORMAT_RINGS);
    const absl::StatusOr<ShapeGeometry> shape = AssembleShape(family.ComplexAt(rank, ClassifyMode::kGeneral));
    ASSERT_TRUE(shape.ok()) << shape.status();
    auto source = MakeShapeSource(cached, request);
    ASSERT_TRUE(source.ok()) << source.status();
    ExpectSameGeometry(JoinRings(Drain(**source)), *shape);
  }
}

TEST(QueryAnswersTest, ShapeRefusesBadRequests) {
  const std::shared_ptr<const CachedFamily>& cached = Families()[0].cached;
  ASSERT_NE(cached, nullptr);
  v1::ShapeRequest request;
  *request.mutable_threshold() = Rank(1);
  const auto unspecified = MakeShapeSource(cached, request);
  EXPECT_TRUE(absl::IsInvalidArgument(unspecified.status())) << unspecified.status();

  request.set_format(v1::SHAPE_FORMAT_WKT);
  request.clear_threshold();
  EXPECT_TRUE(absl::IsInvalidArgument(MakeShapeSource(cached, request).status()));
  *request.mutable_threshold() = Rank(cached->family().max_level() + 1);
  EXPECT_TRUE(absl::IsInvalidArgument(MakeShapeSource(cached, request).status()));
  request.set_format(static_cast<v1::ShapeFormat>(99));
  *request.mutable_threshold() = Rank(1);
  EXPECT_TRUE(absl::IsInvalidArgument(MakeShapeSource(cached, request).status()));
}

}  // namespace
}  // namespace galpha::server
