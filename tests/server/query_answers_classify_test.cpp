// The Classify stream against ClassifyAll of the in-process AlphaFamily: every simplex once, in
// canonical order, in chunks of at most kSimplicesPerChunk, after a summary with the counts,
// components and area; non-exterior-only and summary-only requests; bad thresholds refused.
#include "server/query_answers.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/family/classification_summary.hpp"
#include "core/geometry/shape.hpp"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/cached_family.hpp"
#include "tests/server/cached_family_fixture.hpp"
#include "tests/server/query_answers_fixture.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using testing::Drain;
using testing::Families;
using ::testing::HasSubstr;
using testing::LargeFamily;
using testing::MakeCachedFamily;
using testing::NamedFamily;
using testing::Rank;
using testing::ResolveOn;
using testing::Thresholds;

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
    triangles.emplace_back(triangle, classes.triangles[t]);
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
void CheckClassify(const std::shared_ptr<const CachedFamily>& cached, const AlphaFamily& family,
                   const v1::ClassifyRequest& request, size_t* chunks_out = nullptr) {
  SCOPED_TRACE(request.ShortDebugString());
  auto source = MakeClassifySource(cached, request);
  ASSERT_THAT(source, IsOk());
  const std::vector<v1::ClassifyResponse> messages = Drain(**source);
  ASSERT_FALSE(messages.empty());

  const int64_t level = ResolveOn(family, request.threshold())->level;
  const ClassifyMode mode = *ToClassifyMode(request.mode());
  const Classification classes = family.ClassifyAll(level, mode, *ToVertexRule(request.vertex_rule()));

  ASSERT_EQ(messages[0].part_case(), v1::ClassifyResponse::kSummary);
  const v1::ClassifySummary& summary = messages[0].summary();
  EXPECT_EQ(summary.level(), level);
  EXPECT_EQ(summary.alpha_sq(), ResolveOn(family, request.threshold())->alpha_sq);
  ExpectCountsEqual(summary.vertices(), Count(classes.vertices, &family.representative()));
  ExpectCountsEqual(summary.edges(), Count(classes.edges, nullptr));
  ExpectCountsEqual(summary.triangles(), Count(classes.triangles, nullptr));
  EXPECT_EQ(summary.components(), family.Components(level));
  EXPECT_EQ(summary.solid_components(), family.SolidComponents(level));
  const absl::StatusOr<ShapeGeometry> shape = AssembleShape(family.ComplexAt(level, mode));
  ASSERT_THAT(shape, IsOk());
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
    for (const v1::Threshold& threshold : Thresholds(*f.oracle)) {
      for (const v1::ClassifyMode mode : {v1::CLASSIFY_MODE_GENERAL, v1::CLASSIFY_MODE_REGULARIZED}) {
        for (const v1::VertexRule rule : {v1::VERTEX_RULE_REPORT, v1::VERTEX_RULE_CGAL}) {
          for (const bool non_exterior_only : {false, true}) {
            v1::ClassifyRequest request;
            *request.mutable_threshold() = threshold;
            request.set_mode(mode);
            request.set_vertex_rule(rule);
            request.set_non_exterior_only(non_exterior_only);
            CheckClassify(f.cached, *f.oracle, request);
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
  *request.mutable_threshold() = Rank(cached->host_family()->max_level() / 3);
  auto all = MakeClassifySource(cached, request);
  request.set_non_exterior_only(true);
  auto some = MakeClassifySource(cached, request);
  ASSERT_THAT(all, IsOk());
  ASSERT_THAT(some, IsOk());
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
    for (const v1::Threshold& threshold : Thresholds(*f.oracle)) {
      v1::ClassifyRequest request;
      *request.mutable_threshold() = threshold;
      request.set_summary_only(true);
      CheckClassify(f.cached, *f.oracle, request);
    }
  }
}

// A split answer: part k sends the chunks numbered k, k + P, ... of the whole answer, the summary
// in part 0 only; dealt back round-robin, the parts are the whole answer, message for message.
// 300,000 points: every kind spans several chunks (kSimplicesPerChunk), so that parts skip chunks
// within a kind, the filtered ones too.
TEST(QueryAnswersTest, ClassifyPartsDealtRoundRobinAreTheWholeAnswer) {
  const std::shared_ptr<const CachedFamily> cached = MakeCachedFamily(gen::Uniform(300000, 9), "uniform_300000");
  for (const bool non_exterior_only : {false, true}) {
    v1::ClassifyRequest request;
    *request.mutable_threshold() = Rank(cached->reader().max_level() / 2);
    request.set_non_exterior_only(non_exterior_only);
    auto whole_source = MakeClassifySource(cached, request);
    ASSERT_THAT(whole_source, IsOk());
    const std::vector<v1::ClassifyResponse> whole = Drain(**whole_source);
    ASSERT_GT(whole.size(), 8u) << "the test needs an answer of several chunks";
    for (const uint32_t parts : {2u, 3u, 5u, 64u}) {
      std::vector<std::vector<v1::ClassifyResponse>> answers(parts);
      for (uint32_t part = 0; part < parts; ++part) {
        request.set_part_index(part);
        request.set_part_count(parts);
        auto source = MakeClassifySource(cached, request);
        ASSERT_THAT(source, IsOk());
        answers[part] = Drain(**source);
        for (size_t m = 0; m < answers[part].size(); ++m) {
          EXPECT_EQ(answers[part][m].has_summary(), part == 0 && m == 0) << "part " << part << " message " << m;
        }
      }
      ASSERT_FALSE(answers[0].empty());
      std::vector<v1::ClassifyResponse> merged = {answers[0][0]};
      std::vector<size_t> next(parts, 0);
      next[0] = 1;
      for (uint64_t chunk = 0;; ++chunk) {
        const uint32_t part = static_cast<uint32_t>(chunk % parts);
        if (next[part] == answers[part].size()) break;
        merged.push_back(answers[part][next[part]++]);
      }
      for (uint32_t part = 0; part < parts; ++part) {
        EXPECT_EQ(next[part], answers[part].size()) << parts << " parts: part " << part << " sent chunks past the end";
      }
      ASSERT_EQ(merged.size(), whole.size()) << parts << " parts";
      for (size_t m = 0; m < whole.size(); ++m) {
        EXPECT_EQ(merged[m].SerializeAsString(), whole[m].SerializeAsString()) << parts << " parts, message " << m;
      }
    }
  }
}

TEST(QueryAnswersTest, ClassifyRefusesPartsItCannotSplit) {
  const std::shared_ptr<const CachedFamily>& cached = Families()[0].cached;
  v1::ClassifyRequest request;
  *request.mutable_threshold() = Rank(1);
  const auto refused = [&](uint32_t index, uint32_t count, bool summary_only, const std::string& says) {
    request.set_part_index(index);
    request.set_part_count(count);
    request.set_summary_only(summary_only);
    EXPECT_THAT(MakeClassifySource(cached, request).status(),
                StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr(says)))
        << index << " of " << count;
  };
  refused(0, kMaxClassifyParts + 1, false, "part_count 65 is over 64");
  refused(3, 3, false, "part_index 3 is not below part_count 3");
  refused(1, 0, false, "part_index 1 is not below part_count 1 (0: the whole answer)");
  refused(0, 2, true, "summary_only");
  request.set_part_index(kMaxClassifyParts - 1);
  request.set_part_count(kMaxClassifyParts);
  request.set_summary_only(false);
  EXPECT_THAT(MakeClassifySource(cached, request), IsOk());
}

// The parts of one answer share one classification while any of them holds it.
TEST(QueryAnswersTest, SharedClassificationIsComputedOnceWhileHeld) {
  const std::shared_ptr<const CachedFamily> cached = LargeFamily();
  const int64_t level = cached->reader().max_level() / 2;
  auto first = cached->SharedClassification(level, ClassifyMode::kGeneral, VertexRule::kReport);
  auto second = cached->SharedClassification(level, ClassifyMode::kGeneral, VertexRule::kReport);
  auto other = cached->SharedClassification(level, ClassifyMode::kRegularized, VertexRule::kReport);
  ASSERT_THAT(first, IsOk());
  ASSERT_THAT(second, IsOk());
  ASSERT_THAT(other, IsOk());
  EXPECT_EQ(first->get(), second->get());
  EXPECT_NE(first->get(), other->get());
  const Classification expected =
      cached->host_family()->ClassifyAll(level, ClassifyMode::kGeneral, VertexRule::kReport);
  EXPECT_EQ((*first)->vertices, expected.vertices);
  EXPECT_EQ((*first)->edges, expected.edges);
  EXPECT_EQ((*first)->triangles, expected.triangles);
  const std::weak_ptr<const Classification> released = *first;
  first->reset();
  second->reset();
  EXPECT_TRUE(released.expired()) << "no caller holds it: the family keeps no classification";
}

TEST(QueryAnswersTest, ClassifyRefusesBadThresholds) {
  const std::shared_ptr<const CachedFamily>& cached = Families()[0].cached;
  ASSERT_NE(cached, nullptr);
  v1::ClassifyRequest request;
  EXPECT_THAT(MakeClassifySource(cached, request).status(), StatusIs(absl::StatusCode::kInvalidArgument));
  *request.mutable_threshold() = Rank(cached->host_family()->max_level() + 1);
  EXPECT_THAT(MakeClassifySource(cached, request).status(), StatusIs(absl::StatusCode::kInvalidArgument));
}

// The service sums the cached family's area terms (CachedFamily::TriangleAreaTerms); alphactl
// gathers the points per classification: the same counts and the same double at every level.
TEST(QueryAnswersTest, SummaryFromCachedAreaTermsIsTheSameDouble) {
  for (const NamedFamily& named : Families()) {
    const AlphaFamily& family = *named.oracle;
    const std::vector<double>& terms = named.cached->TriangleAreaTerms();
    ASSERT_EQ(terms.size(), family.triangles().size()) << named.name;
    for (int64_t level = 0; level <= family.max_level(); level += std::max<int64_t>(1, family.max_level() / 7)) {
      for (ClassifyMode mode : {ClassifyMode::kGeneral, ClassifyMode::kRegularized}) {
        const Classification classes = family.ClassifyAll(level, mode, VertexRule::kReport);
        const ClassificationSummary gathered = SummarizeClassification(family, classes);
        const ClassificationSummary summed = SummarizeClassification(family.representative(), terms, classes);
        EXPECT_EQ(summed.interior_area, gathered.interior_area) << named.name << " level " << level;
        EXPECT_EQ(summed.vertices, gathered.vertices);
        EXPECT_EQ(summed.edges, gathered.edges);
        EXPECT_EQ(summed.triangles, gathered.triangles);
      }
    }
  }
}

// The summary packs the interior terms on every core before one thread adds them: the sum must
// still be the interior terms added one at a time in triangle order (what AssembleShape gives), on
// any number of threads (the blocks follow the thread count).
TEST(QueryAnswersTest, SummaryAreaAddsTheInteriorTermsInTriangleOrderOnAnyThreadCount) {
  const int threads_before = omp_get_max_threads();
  for (const NamedFamily& named : Families()) {
    const AlphaFamily& family = *named.oracle;
    const std::vector<double>& terms = named.cached->TriangleAreaTerms();
    for (int64_t level = 0; level <= family.max_level(); level += std::max<int64_t>(1, family.max_level() / 5)) {
      const Classification classes = family.ClassifyAll(level, ClassifyMode::kRegularized, VertexRule::kReport);
      double in_order = 0.0;
      for (size_t t = 0; t < classes.triangles.size(); ++t) {
        if (classes.triangles[t] == SimplexClass::kInterior) in_order += terms[t];
      }
      for (int threads : {1, 2, 3, 7, 16}) {
        omp_set_num_threads(threads);
        EXPECT_EQ(SummarizeClassification(family.representative(), terms, classes).interior_area, in_order)
            << named.name << " level " << level << ", " << threads << " threads";
        EXPECT_EQ(SummarizeClassification(family, classes).interior_area, in_order)
            << named.name << " level " << level << ", " << threads << " threads";
      }
      omp_set_num_threads(threads_before);
    }
  }
}

TEST(QueryAnswersTest, ClassifyRefusesASimplexEncodingTheEnumDoesNotDefine) {
  const std::shared_ptr<const CachedFamily>& cached = Families()[0].cached;
  v1::ClassifyRequest request;
  *request.mutable_threshold() = Rank(1);
  for (int encoding : {0, 1, 2, 3}) {
    request.set_simplex_encoding(static_cast<v1::SimplexEncoding>(encoding));
    EXPECT_THAT(MakeClassifySource(cached, request).status(), IsOk()) << encoding;
  }
  request.set_simplex_encoding(static_cast<v1::SimplexEncoding>(4));
  const absl::Status refused = MakeClassifySource(cached, request).status();
  EXPECT_THAT(refused, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(refused.message().find("simplex_encoding 4 is not a SimplexEncoding"), std::string::npos)
      << refused.message();
}

TEST(QueryAnswersTest, ClassifyChunksNeverExceedTheLimit) {
  const std::shared_ptr<const CachedFamily> cached = LargeFamily();
  ASSERT_NE(cached, nullptr);
  ASSERT_GT(cached->host_family()->edges().size(), size_t{kSimplicesPerChunk}) << "the test needs several edge chunks";
  for (const int64_t rank : {cached->host_family()->max_level() / 2, cached->host_family()->max_level()}) {
    for (const bool non_exterior_only : {false, true}) {
      v1::ClassifyRequest request;
      *request.mutable_threshold() = Rank(rank);
      request.set_non_exterior_only(non_exterior_only);
      size_t chunks = 0;
      CheckClassify(cached, *cached->host_family(), request, &chunks);
      // Every simplex is sent, or (at rank K) none is exterior: edges take two chunks.
      if (!non_exterior_only || rank == cached->host_family()->max_level()) {
        EXPECT_GE(chunks, 4u) << "vertices, edges in two chunks, triangles";
      }
    }
  }
}

}  // namespace
}  // namespace galpha::server
