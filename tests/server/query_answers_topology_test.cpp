// Betti curves, holes in summaries and optimal alpha, and the persistence stream against the
// in-process family and its diagram (core/family/persistence.hpp): every pair once, in order, with
// its simplices named by sorted vertices, chunked, filtered by dimension and minimum persistence;
// bad requests refused.
#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/family/canonical_order.hpp"
#include "core/family/persistence.hpp"
#include "gtest/gtest.h"
#include "server/persistence_answers.hpp"
#include "server/query_answers.hpp"
#include "tests/server/cached_family_fixture.hpp"
#include "tests/server/query_answers_fixture.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using testing::Drain;
using testing::Families;
using testing::LargeFamily;
using testing::NamedFamily;
using testing::Thresholds;

TEST(QueryAnswersTopologyTest, BettiAtAThresholdAndOverARange) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    const AlphaFamily& family = *f.oracle;
    for (const v1::Threshold& threshold : Thresholds(family)) {
      v1::BettiRequest request;
      *request.mutable_threshold() = threshold;
      const absl::StatusOr<v1::BettiResponse> response = AnswerBetti(f.cached->reader(), request);
      ASSERT_THAT(response, IsOk());
      ASSERT_EQ(response->holes_size(), 1);
      const int64_t level = response->first_level();
      EXPECT_EQ(response->components(0), family.Components(level));
      EXPECT_EQ(response->holes(0), family.Holes(level, ClassifyMode::kGeneral));
      EXPECT_EQ(response->regularized_components(0), family.RegularizedComponents(level));
      EXPECT_EQ(response->regularized_holes(0), family.Holes(level, ClassifyMode::kRegularized));
    }
    v1::BettiRequest request;
    request.mutable_ranks()->set_first(0);
    request.mutable_ranks()->set_last(family.max_level());
    const absl::StatusOr<v1::BettiResponse> response = AnswerBetti(f.cached->reader(), request);
    ASSERT_THAT(response, IsOk());
    ASSERT_EQ(response->components_size(), family.max_level() + 1);
    for (int64_t level = 0; level <= family.max_level(); ++level) {
      const int i = static_cast<int>(level);
      EXPECT_EQ(response->components(i), family.Components(level));
      EXPECT_EQ(response->holes(i), family.Holes(level, ClassifyMode::kGeneral));
      EXPECT_EQ(response->regularized_components(i), family.RegularizedComponents(level));
      EXPECT_EQ(response->regularized_holes(i), family.Holes(level, ClassifyMode::kRegularized));
    }
    request.mutable_ranks()->set_last(family.max_level() + 1);
    EXPECT_THAT(AnswerBetti(f.cached->reader(), request).status(), StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_THAT(AnswerBetti(f.cached->reader(), v1::BettiRequest()).status(),
                StatusIs(absl::StatusCode::kInvalidArgument));
  }
}

// The smallest rank with at most one component and at most N holes, from the family's curves.
TEST(QueryAnswersTopologyTest, OptimalAlphaWithAHoleBound) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    const AlphaFamily& family = *f.oracle;
    for (uint32_t holes : {0u, 1u, 5u}) {
      v1::OptimalAlphaRequest request;
      request.set_max_components(1);
      request.set_max_holes(holes);
      const absl::StatusOr<v1::OptimalAlphaResponse> response = AnswerOptimalAlpha(f.cached->reader(), request);
      ASSERT_THAT(response, IsOk());
      const std::optional<int64_t> regularized = family.OptimalLevelRegularized(1, holes);
      ASSERT_EQ(response->has_regularized(), regularized.has_value());
      if (regularized) {
        EXPECT_EQ(response->regularized().rank(), *regularized);
        EXPECT_EQ(response->regularized().holes(), family.Holes(*regularized, ClassifyMode::kRegularized));
        EXPECT_LE(response->regularized().holes(), holes);
      }
      const std::optional<int64_t> general = family.OptimalLevelGeneral(1, holes);
      ASSERT_EQ(response->has_general(), general.has_value());
      if (general) {
        EXPECT_EQ(response->general().rank(), *general);
        EXPECT_LE(response->general().holes(), holes);
        EXPECT_LE(response->general().components(), 1u);
        // The smallest such level: the one before fails a bound.
        if (*general > 0) {
          EXPECT_TRUE(family.Components(*general - 1) > 1 ||
                      family.Holes(*general - 1, ClassifyMode::kGeneral) > holes);
        }
      }
    }
  }
}

// Every pair of the diagram in the stream, in order, named by its sorted vertices.
TEST(QueryAnswersTopologyTest, PersistenceStreamsTheDiagram) {
  std::vector<NamedFamily> families = Families();
  families.push_back(
      {"large", LargeFamily(), std::shared_ptr<const AlphaFamily>(LargeFamily(), LargeFamily()->host_family())});
  for (const NamedFamily& f : families) {
    SCOPED_TRACE(f.name);
    const AlphaFamily& family = *f.oracle;
    const absl::StatusOr<PersistenceDiagram> diagram = ComputePersistence(family);
    ASSERT_THAT(diagram, IsOk());
    auto source = MakePersistenceSource(f.cached, v1::PersistenceRequest());
    ASSERT_THAT(source, IsOk());
    const std::vector<v1::PersistenceResponse> messages = Drain(**source);
    size_t next = 0;
    uint32_t last_dimension = 0;
    for (const v1::PersistenceResponse& m : messages) {
      ASSERT_GT(m.birth_rank_size(), 0) << "no empty chunks";
      ASSERT_LE(m.birth_rank_size(), static_cast<int>(kPersistencePairsPerChunk));
      ASSERT_GE(m.dimension(), last_dimension);
      last_dimension = m.dimension();
      const int arity = static_cast<int>(m.dimension()) + 1;
      ASSERT_EQ(m.creator_vertices_size(), m.birth_rank_size() * arity);
      ASSERT_EQ(m.killer_vertices_size(), m.birth_rank_size() * (arity + 1));
      for (int i = 0; i < m.birth_rank_size(); ++i, ++next) {
        ASSERT_LT(next, diagram->pairs.size());
        const PersistencePair& p = diagram->pairs[next];
        ASSERT_EQ(m.dimension(), p.dimension);
        EXPECT_EQ(m.birth_rank(i), p.birth_rank);
        EXPECT_EQ(m.death_rank(i), p.essential() ? -1 : static_cast<int64_t>(p.death_rank));
        EXPECT_EQ(m.birth_alpha_sq(i), RankValue(family, p.birth_rank));
        EXPECT_EQ(m.death_alpha_sq(i), RankValue(family, p.death_rank));
        std::vector<uint32_t> creator(m.creator_vertices().begin() + i * arity,
                                      m.creator_vertices().begin() + (i + 1) * arity);
        std::vector<uint32_t> killer(m.killer_vertices().begin() + i * (arity + 1),
                                     m.killer_vertices().begin() + (i + 1) * (arity + 1));
        if (p.dimension == 0) {
          EXPECT_EQ(creator, std::vector<uint32_t>{p.creator});
          if (p.essential()) {
            EXPECT_EQ(killer, std::vector<uint32_t>(2, 0xFFFFFFFFu));
          } else {
            const auto e = SortedEdge(family.edges()[p.killer]);
            EXPECT_EQ(killer, std::vector<uint32_t>(e.begin(), e.end()));
          }
        } else {
          const auto e = SortedEdge(family.edges()[p.creator]);
          EXPECT_EQ(creator, std::vector<uint32_t>(e.begin(), e.end()));
          ASSERT_FALSE(p.essential());
          const auto t = SortedTriangle(family.triangles()[p.killer]);
          EXPECT_EQ(killer, std::vector<uint32_t>(t.begin(), t.end()));
        }
      }
    }
    EXPECT_EQ(next, diagram->pairs.size());
  }
}

TEST(QueryAnswersTopologyTest, PersistenceFiltersByDimensionAndPersistence) {
  const std::shared_ptr<const CachedFamily> cached = LargeFamily();
  const AlphaFamily& family = *cached->host_family();
  const absl::StatusOr<PersistenceDiagram> diagram = ComputePersistence(family);
  ASSERT_THAT(diagram, IsOk());
  // The median finite persistence of H1: about half the holes pass.
  std::vector<double> lengths;
  for (size_t i = diagram->dimension_begin[1]; i < diagram->dimension_begin[2]; ++i) {
    const PersistencePair& p = diagram->pairs[i];
    lengths.push_back(RankValue(family, p.death_rank) - RankValue(family, p.birth_rank));
  }
  ASSERT_GT(lengths.size(), 100u);
  std::nth_element(lengths.begin(), lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2), lengths.end());
  const double median = lengths[lengths.size() / 2];
  v1::PersistenceRequest request;
  request.add_dimensions(1);
  request.set_min_persistence(median);
  auto source = MakePersistenceSource(cached, request);
  ASSERT_THAT(source, IsOk());
  // The bound is compared with the exact difference of the published values.
  auto exact_length = [](double birth, double death) -> mpq_class { return mpq_class(death) - mpq_class(birth); };
  size_t listed = 0;
  for (const v1::PersistenceResponse& m : Drain(**source)) {
    ASSERT_EQ(m.dimension(), 1u);
    for (int i = 0; i < m.birth_rank_size(); ++i) {
      ASSERT_GE(exact_length(m.birth_alpha_sq(i), m.death_alpha_sq(i)), mpq_class(median));
      ++listed;
    }
  }
  size_t expected = 0;
  for (size_t i = diagram->dimension_begin[1]; i < diagram->dimension_begin[2]; ++i) {
    const PersistencePair& p = diagram->pairs[i];
    expected += exact_length(RankValue(family, p.birth_rank), RankValue(family, p.death_rank)) >= mpq_class(median);
  }
  EXPECT_EQ(listed, expected);
  EXPECT_GT(expected, 0u);
  EXPECT_LT(expected, lengths.size());

  // Dimension 0 alone: every H0 pair, the essential one included, whatever the bound.
  v1::PersistenceRequest h0;
  h0.add_dimensions(0);
  h0.set_min_persistence(std::numeric_limits<double>::infinity());
  auto h0_source = MakePersistenceSource(cached, h0);
  ASSERT_THAT(h0_source, IsOk());
  size_t essential = 0;
  for (const v1::PersistenceResponse& m : Drain(**h0_source)) {
    ASSERT_EQ(m.dimension(), 0u);
    for (int i = 0; i < m.death_rank_size(); ++i) essential += m.death_rank(i) == -1;
  }
  EXPECT_EQ(essential, 1u);

  v1::PersistenceRequest bad;
  bad.add_dimensions(2);
  EXPECT_THAT(MakePersistenceSource(cached, bad).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("dimension 2")));
  v1::PersistenceRequest negative;
  negative.set_min_persistence(-1);
  EXPECT_THAT(MakePersistenceSource(cached, negative).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, ::testing::HasSubstr("min_persistence")));
  negative.set_min_persistence(std::nan(""));
  EXPECT_THAT(MakePersistenceSource(cached, negative).status(), StatusIs(absl::StatusCode::kInvalidArgument));
}

// A 12 x 12 integer grid without a 3 x 3 block: at alpha_sq 0.5 every unit square is in, and the
// block leaves one octagonal hole (a 4 x 4 square less the four corner triangles that are in at
// 0.5: area 14); min_hole_area fills it above 14.
TEST(QueryAnswersTopologyTest, ShapeFillsHolesBelowMinHoleArea) {
  std::vector<Point2> points;
  for (int i = 0; i < 12; ++i) {
    for (int j = 0; j < 12; ++j) {
      if (i >= 4 && i <= 6 && j >= 4 && j <= 6) continue;
      points.push_back({static_cast<double>(i), static_cast<double>(j)});
    }
  }
  const std::shared_ptr<const CachedFamily> cached = testing::MakeCachedFamily(points, "holed grid");
  ASSERT_NE(cached, nullptr);
  auto wkt = [&](double min_hole_area) -> std::string {
    v1::ShapeRequest request;
    *request.mutable_threshold() = testing::AlphaSq(0.5);
    request.set_mode(v1::CLASSIFY_MODE_REGULARIZED);
    request.set_format(v1::SHAPE_FORMAT_WKT);
    request.set_min_hole_area(min_hole_area);
    auto source = MakeShapeSource(cached, request);
    if (!source.ok()) return std::string(source.status().message());
    std::string text;
    for (const v1::ShapeResponse& m : Drain(**source)) text += m.text();
    return text;
  };
  const std::string kept = wkt(0), also_kept = wkt(14), filled = wkt(14.5);
  EXPECT_EQ(kept.rfind("POLYGON ((", 0), 0u) << kept;
  EXPECT_NE(kept.find("), ("), std::string::npos) << "one hole ring: " << kept;
  EXPECT_EQ(also_kept, kept);
  EXPECT_EQ(filled.find("), ("), std::string::npos) << "no hole ring: " << filled;
  EXPECT_EQ(
      cached->host_family()->Holes(cached->host_family()->LevelForAlphaSq(0.5).value(), ClassifyMode::kRegularized),
      1u);
  EXPECT_NE(wkt(-1).find("min_hole_area"), std::string::npos);
  EXPECT_NE(wkt(std::nan("")).find("min_hole_area"), std::string::npos);
}

}  // namespace
}  // namespace galpha::server
