// The Shape stream against the in-process AlphaFamily's shape: GeoJSON, WKT and SVG equal to the
// writers' text in pieces of at most kShapeTextBytesPerChunk, RINGS reproducing the geometry; bad
// requests refused.
#include "server/query_answers.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/geometry/shape.hpp"
#include "gtest/gtest.h"
#include "server/cached_family.hpp"
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
using testing::Rank;
using testing::ResolveOn;
using testing::Thresholds;

// ---- Shape ----------------------------------------------------------------------------------------

TEST(QueryAnswersTest, ShapeTextFormatsMatchTheWriters) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = *f.oracle;
    for (const v1::Threshold& threshold : Thresholds(family)) {
      for (const v1::ClassifyMode mode : {v1::CLASSIFY_MODE_GENERAL, v1::CLASSIFY_MODE_REGULARIZED}) {
        SCOPED_TRACE(absl::StrCat(threshold.ShortDebugString(), " mode ", mode));
        const int64_t level = ResolveOn(family, threshold)->level;
        const absl::StatusOr<ShapeGeometry> shape = AssembleShape(family.ComplexAt(level, *ToClassifyMode(mode)));
        ASSERT_THAT(shape, IsOk());
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
          ASSERT_THAT(source, IsOk());
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
  const AlphaFamily& family = *cached->host_family();
  v1::ShapeRequest request;
  *request.mutable_threshold() = Rank(family.max_level() / 3);
  request.set_format(v1::SHAPE_FORMAT_GEOJSON);
  const absl::StatusOr<ShapeGeometry> shape =
      AssembleShape(family.ComplexAt(ResolveOn(family, request.threshold())->level, ClassifyMode::kGeneral));
  ASSERT_THAT(shape, IsOk());
  const std::string expected = ShapeToGeoJson(*shape, family.points());
  ASSERT_GT(expected.size(), kShapeTextBytesPerChunk) << "the test needs a text of several pieces";
  auto source = MakeShapeSource(cached, request);
  ASSERT_THAT(source, IsOk());
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
    const AlphaFamily& family = *f.oracle;
    for (const v1::Threshold& threshold : Thresholds(family)) {
      for (const v1::ClassifyMode mode : {v1::CLASSIFY_MODE_GENERAL, v1::CLASSIFY_MODE_REGULARIZED}) {
        SCOPED_TRACE(absl::StrCat(threshold.ShortDebugString(), " mode ", mode));
        const int64_t level = ResolveOn(family, threshold)->level;
        const absl::StatusOr<ShapeGeometry> shape = AssembleShape(family.ComplexAt(level, *ToClassifyMode(mode)));
        ASSERT_THAT(shape, IsOk());
        v1::ShapeRequest request;
        *request.mutable_threshold() = threshold;
        request.set_mode(mode);
        request.set_format(v1::SHAPE_FORMAT_RINGS);
        auto source = MakeShapeSource(f.cached, request);
        ASSERT_THAT(source, IsOk());
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
  const AlphaFamily& family = *cached->host_family();
  for (const int64_t rank : {family.max_level() / 3, family.max_level() / 10}) {
    SCOPED_TRACE(rank);
    v1::ShapeRequest request;
    *request.mutable_threshold() = Rank(rank);
    request.set_format(v1::SHAPE_FORMAT_RINGS);
    const absl::StatusOr<ShapeGeometry> shape = AssembleShape(family.ComplexAt(rank, ClassifyMode::kGeneral));
    ASSERT_THAT(shape, IsOk());
    auto source = MakeShapeSource(cached, request);
    ASSERT_THAT(source, IsOk());
    ExpectSameGeometry(JoinRings(Drain(**source)), *shape);
  }
}

TEST(QueryAnswersTest, ShapeRefusesBadRequests) {
  const std::shared_ptr<const CachedFamily>& cached = Families()[0].cached;
  ASSERT_NE(cached, nullptr);
  v1::ShapeRequest request;
  *request.mutable_threshold() = Rank(1);
  const auto unspecified = MakeShapeSource(cached, request);
  EXPECT_THAT(unspecified.status(), StatusIs(absl::StatusCode::kInvalidArgument));

  request.set_format(v1::SHAPE_FORMAT_WKT);
  request.clear_threshold();
  EXPECT_THAT(MakeShapeSource(cached, request).status(), StatusIs(absl::StatusCode::kInvalidArgument));
  *request.mutable_threshold() = Rank(cached->host_family()->max_level() + 1);
  EXPECT_THAT(MakeShapeSource(cached, request).status(), StatusIs(absl::StatusCode::kInvalidArgument));
  request.set_format(static_cast<v1::ShapeFormat>(99));
  *request.mutable_threshold() = Rank(1);
  EXPECT_THAT(MakeShapeSource(cached, request).status(), StatusIs(absl::StatusCode::kInvalidArgument));
}

}  // namespace
}  // namespace galpha::server
