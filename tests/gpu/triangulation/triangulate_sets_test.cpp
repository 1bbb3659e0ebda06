// TriangulateSets: many sets packed into one build must give, set by set, exactly what Triangulate
// gives for the set alone on the same backend (Triangulate itself is checked against CGAL and by
// exact validation in delaunay_test and delaunay_cgal_test): the same triangles in the same order,
// neighbours, edges, representatives. Inputs: every generator at sizes from 0 to thousands, the
// shared degenerate sets, sets of very different magnitudes in one call, and thousands of small
// sets.
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "gpu/triangulation/delaunay.hpp"
#include "gtest/gtest.h"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/packed_sets.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::IsOk;
using testing::SetsToPack;
using testing::StatusIs;

class TriangulateSetsTest : public testing::BackendTest {
 protected:
  TriangulateOptions Options() const {
    TriangulateOptions options;
    options.backend = GetParam();
    return options;
  }

  /// Packs the sets, then checks every set's triangulation against Triangulate of it alone.
  void ExpectEqualToEachAlone(const SetsToPack& sets) {
    absl::StatusOr<TriangulatedSets> packed = TriangulateSets(sets.points, sets.set_begin, Options());
    ASSERT_THAT(packed.status(), IsOk());
    ASSERT_EQ(packed->sets.size(), sets.names.size());
    EXPECT_EQ(packed->backend, GetParam());
    // The claim the docs make: no input measured leaves a set to be built alone.
    EXPECT_EQ(packed->built_alone, 0u);
    for (size_t s = 0; s < sets.names.size(); ++s) {
      SCOPED_TRACE("set " + std::to_string(s) + ": " + sets.names[s]);
      absl::StatusOr<Triangulation> alone = Triangulate(sets.Set(s), Options());
      ASSERT_THAT(alone.status(), IsOk());
      const Triangulation& got = packed->sets[s];
      EXPECT_EQ(got.points, alone->points);
      EXPECT_EQ(got.representative, alone->representative);
      EXPECT_EQ(got.num_unique, alone->num_unique);
      EXPECT_EQ(got.triangles, alone->triangles);
      EXPECT_EQ(got.neighbors, alone->neighbors);
      EXPECT_EQ(got.tri_edge_begin, alone->tri_edge_begin);
      EXPECT_EQ(got.edges, alone->edges);
      EXPECT_TRUE(got.hidden.empty());
      if (HasFailure()) return;  // one set's report is enough
    }
  }
};

TEST_P(TriangulateSetsTest, EveryGeneratorAtEverySizeEqualsItsSetAlone) {
  ExpectEqualToEachAlone(testing::SetsOfEveryGenerator({0, 1, 2, 3, 4, 7, 50, 333, 2000}));
}

TEST_P(TriangulateSetsTest, DegenerateSetsEqualTheirSetAlone) {
  ExpectEqualToEachAlone(testing::DegenerateSetsAndChains());
}

TEST_P(TriangulateSetsTest, SetsWithoutAMeshEqualTheirSetAlone) {
  // No set has a mesh: the packed build writes chains only.
  ExpectEqualToEachAlone(testing::SetsWithoutAMesh());
}

TEST_P(TriangulateSetsTest, SetsOfThreePointsEqualTheirSetAlone) {
  ExpectEqualToEachAlone(testing::SetsOfThreePoints());
}

TEST_P(TriangulateSetsTest, SetsOfVeryDifferentMagnitudesEachScaleAsAlone) {
  // Each set's power of two (the floating filters' scaling) is its own.
  ExpectEqualToEachAlone(testing::SetsOfVeryDifferentMagnitudes());
}

TEST_P(TriangulateSetsTest, ThousandsOfSmallSetsEqualTheirSetsAlone) {
  ExpectEqualToEachAlone(testing::SmallSetsOfEveryKind(1500));
}

TEST_P(TriangulateSetsTest, NoPointsAtAllGiveEmptySets) {
  const std::vector<uint32_t> set_begin{0, 0, 0};
  absl::StatusOr<TriangulatedSets> packed = TriangulateSets({}, set_begin, Options());
  ASSERT_THAT(packed.status(), IsOk());
  ASSERT_EQ(packed->sets.size(), 2u);
  for (const Triangulation& t : packed->sets) {
    EXPECT_TRUE(t.points.empty());
    EXPECT_TRUE(t.triangles.empty());
    EXPECT_TRUE(t.edges.empty());
    EXPECT_EQ(t.num_unique, 0u);
  }
}

TEST_P(TriangulateSetsTest, BadOffsetsAndPointsAreRefusedByName) {
  const std::vector<Point2> points = gen::Uniform(10, 1);
  EXPECT_THAT(TriangulateSets(points, std::vector<uint32_t>{}, Options()).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "set offsets: none given (at least the 0 that ends them)"));
  EXPECT_THAT(TriangulateSets(points, std::vector<uint32_t>{1, 10}, Options()).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "set offsets: the first is 1, not 0"));
  EXPECT_THAT(TriangulateSets(points, std::vector<uint32_t>{0, 4, 9}, Options()).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "set offsets: the last is 9, not the 10 points given"));
  EXPECT_THAT(TriangulateSets(points, std::vector<uint32_t>{0, 6, 4, 10}, Options()).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "set offsets: set 1 ends at 4 before it begins at 6"));
  std::vector<Point2> with_nan = points;
  with_nan[7].y = std::numeric_limits<double>::quiet_NaN();
  const absl::Status nan = TriangulateSets(with_nan, std::vector<uint32_t>{0, 3, 5, 10}, Options()).status();
  EXPECT_EQ(nan.code(), absl::StatusCode::kInvalidArgument);
  // The set, then ValidatePoints' message for the set's own index of the point (7 - 5 = 2).
  EXPECT_EQ(std::string(nan.message()).rfind("set 2: point 2 is not finite", 0), 0u) << nan.message();
  // More sets than the Hilbert keys can keep apart (all of them empty).
  const std::vector<uint32_t> too_many(size_t{kMaxTriangulatedSets} + 2, 0);
  EXPECT_THAT(TriangulateSets({}, too_many, Options()).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "4194305 sets: at most 4194304 in one call"));
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(TriangulateSetsTest);

}  // namespace
}  // namespace galpha
