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
  SetsToPack sets;
  uint64_t seed = 1;
  for (const gen::NamedGenerator& g : gen::AllDistributions()) {
    for (const size_t n : {0, 1, 2, 3, 4, 7, 50, 333, 2000}) {
      sets.Add(g.name + " n=" + std::to_string(n), g.generate(n, seed++));
    }
  }
  ExpectEqualToEachAlone(sets);
}

TEST_P(TriangulateSetsTest, DegenerateSetsEqualTheirSetAlone) {
  SetsToPack sets;
  for (const gen::NamedPoints& p : gen::SmallDegenerateSets()) sets.Add(p.name, p.points);
  // Sets on one line (a chain, no mesh) between sets with meshes, and a set of one point repeated.
  std::vector<Point2> line, diagonal;
  for (int i = 0; i < 40; ++i) line.push_back({0.25 * i, 3.0});
  for (int i = 0; i < 25; ++i) diagonal.push_back({i * 1.0, i * 2.0 + 1.0});
  sets.Add("horizontal line", line);
  sets.Add("uniform", gen::Uniform(500, 9));
  sets.Add("diagonal line", diagonal);
  sets.Add("one point four times", std::vector<Point2>(4, Point2{2.0, -1.0}));
  ExpectEqualToEachAlone(sets);
}

TEST_P(TriangulateSetsTest, SetsWithoutAMeshEqualTheirSetAlone) {
  // No set has a mesh (every one on a line, or of at most two distinct points): the packed build
  // writes chains only.
  SetsToPack sets;
  std::vector<Point2> vertical, repeated_pair;
  for (int i = 0; i < 30; ++i) vertical.push_back({-2.0, 0.125 * (i % 17) + i});
  for (int i = 0; i < 9; ++i) repeated_pair.push_back(i % 2 == 0 ? Point2{1.0, 1.0} : Point2{3.0, -5.0});
  sets.Add("vertical line", vertical);
  sets.Add("empty", {});
  sets.Add("two points, repeated", repeated_pair);
  sets.Add("one point", {Point2{0.5, 0.5}});
  ExpectEqualToEachAlone(sets);
}

TEST_P(TriangulateSetsTest, SetsOfThreePointsEqualTheirSetAlone) {
  // Every set is its first triangle: nothing is left to insert in any set.
  SetsToPack sets;
  for (int s = 0; s < 50; ++s) {
    const double d = 1.0 + s;
    sets.Add("triangle " + std::to_string(s), {Point2{0.0, 0.0}, Point2{d, s % 2 == 0 ? 0.0 : 1.0}, Point2{0.0, d}});
  }
  ExpectEqualToEachAlone(sets);
}

TEST_P(TriangulateSetsTest, SetsOfVeryDifferentMagnitudesEachScaleAsAlone) {
  // Each set's power of two (the floating filters' scaling) is its own: a set of tiny coordinates
  // beside one offset by 1e15 and one of ordinary ones.
  SetsToPack sets;
  sets.Add("tiny", gen::Tiny(800, 3));
  sets.Add("huge offset 1e15", gen::HugeOffset(800, 4, 1e15));
  sets.Add("uniform", gen::Uniform(800, 5));
  sets.Add("tiny again", gen::Tiny(300, 6));
  sets.Add("the same uniform points shifted", [] {
    std::vector<Point2> p = gen::Uniform(800, 5);
    for (Point2& q : p) q = {q.x + 1024.0, q.y - 4096.0};
    return p;
  }());
  ExpectEqualToEachAlone(sets);
}

TEST_P(TriangulateSetsTest, ThousandsOfSmallSetsEqualTheirSetsAlone) {
  // A batch as issue 20's users send it: many features of a few hundred points, every kind.
  SetsToPack sets;
  const std::vector<gen::NamedGenerator> generators = gen::AllDistributions();
  for (uint32_t s = 0; s < 1500; ++s) {
    const gen::NamedGenerator& g = generators[s % generators.size()];
    const size_t n = 20 + (s * 37) % 280;
    sets.Add(g.name + " n=" + std::to_string(n), g.generate(n, 1000 + s));
  }
  ExpectEqualToEachAlone(sets);
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
