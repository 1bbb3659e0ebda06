// BuildAlphaFamilies: many sets' families built in one packed build must give, set by set, every
// table BuildAlphaFamily gives for the set alone on the same backend (BuildAlphaFamily itself is
// checked against CGAL, GUDHI and brute force in the other family tests): the mesh, the spectrum
// bit for bit and the simplex naming each rank, every interval, the master list, the component,
// hole and area curves with their scale. Inputs: every generator at sizes from 0 to a thousand,
// the shared degenerate sets and chains, sets whose radii tie exactly across sets (copies of one
// grid, of one lattice nudged by ulps), very different magnitudes, and hundreds of small sets.
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "core/family/alpha_family.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gtest/gtest.h"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/family_tables.hpp"
#include "tests/support/packed_sets.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::IsOk;
using testing::SetsToPack;
using testing::StatusIs;

/// Every table of two families of one set, and the backend their reports name.
void ExpectSameFamily(const AlphaFamily& got, const AlphaFamily& want) {
  testing::ExpectSameFamilyTables(got, want);
  EXPECT_EQ(got.report().backend, want.report().backend);
}

class PackedFamiliesTest : public testing::BackendTest {
 protected:
  BuildOptions Options() const {
    BuildOptions options;
    options.backend = GetParam();
    return options;
  }

  /// Builds the sets' families together, then checks each against BuildAlphaFamily of it alone.
  void ExpectEqualToEachAlone(const SetsToPack& sets) {
    absl::StatusOr<AlphaFamilies> packed = BuildAlphaFamilies(sets.points, sets.set_begin, Options());
    ASSERT_THAT(packed.status(), IsOk());
    ASSERT_EQ(packed->families.size(), sets.names.size());
    EXPECT_EQ(packed->report.backend, BackendName(GetParam()));
    EXPECT_EQ(packed->built_alone, 0u);  // the docs' claim: no input measured leaves one
    for (size_t s = 0; s < sets.names.size(); ++s) {
      SCOPED_TRACE("set " + std::to_string(s) + ": " + sets.names[s]);
      absl::StatusOr<AlphaFamily> alone = BuildAlphaFamily(sets.Set(s), Options());
      ASSERT_THAT(alone.status(), IsOk());
      ExpectSameFamily(packed->families[s], *alone);
      if (HasFailure()) return;  // one set's report is enough
    }
  }
};

TEST_P(PackedFamiliesTest, EveryGeneratorAtEverySizeEqualsItsSetAlone) {
  ExpectEqualToEachAlone(testing::SetsOfEveryGenerator({0, 1, 2, 3, 4, 7, 50, 333, 1000}));
}

TEST_P(PackedFamiliesTest, DegenerateSetsAndChainsEqualTheirSetAlone) {
  ExpectEqualToEachAlone(testing::DegenerateSetsAndChains());
}

TEST_P(PackedFamiliesTest, SetsWithoutAMeshEqualTheirSetAlone) { ExpectEqualToEachAlone(testing::SetsWithoutAMesh()); }

TEST_P(PackedFamiliesTest, SetsOfThreePointsEqualTheirSetAlone) {
  ExpectEqualToEachAlone(testing::SetsOfThreePoints());
}

TEST_P(PackedFamiliesTest, RadiiTiedExactlyAcrossSetsEqualTheirSetAlone) {
  // Copies of one grid (identical, and moved by exact translations) and of one lattice nudged by
  // ulps: the packed spectrum's runs of exact and near ties mix many sets, repaired together.
  SetsToPack sets;
  const std::vector<Point2> grid = gen::Grid(900, 2);
  const std::vector<Point2> lattice = gen::UlpLattice(900, 3);
  for (int copy = 0; copy < 12; ++copy) {
    std::vector<Point2> moved = grid;
    for (Point2& p : moved) p = {p.x + 64.0 * copy, p.y - 32.0 * copy};
    sets.Add("grid copy " + std::to_string(copy), copy % 3 == 0 ? grid : moved);
    sets.Add("ulp lattice copy " + std::to_string(copy), lattice);
  }
  ExpectEqualToEachAlone(sets);
}

TEST_P(PackedFamiliesTest, SetsOfVeryDifferentMagnitudesEachMeasureAsAlone) {
  // Each set's area scale (its own box) and filters' scaling.
  ExpectEqualToEachAlone(testing::SetsOfVeryDifferentMagnitudes());
}

TEST_P(PackedFamiliesTest, HundredsOfSmallSetsEqualTheirSetsAlone) {
  ExpectEqualToEachAlone(testing::SmallSetsOfEveryKind(400));
}

TEST_P(PackedFamiliesTest, OneSetCountsTheComparisonsOfItsBuildAlone) {
  // With one set, the packed spectrum is the set's own: the build's counts of exact comparisons
  // are its build alone's (the grid ties exactly, the lattice nearly).
  for (const std::vector<Point2>& points : {gen::Grid(2000, 1), gen::UlpLattice(2000, 2)}) {
    const std::vector<uint32_t> set_begin{0, static_cast<uint32_t>(points.size())};
    absl::StatusOr<AlphaFamilies> packed = BuildAlphaFamilies(points, set_begin, Options());
    absl::StatusOr<AlphaFamily> alone = BuildAlphaFamily(points, Options());
    ASSERT_THAT(packed.status(), IsOk());
    ASSERT_THAT(alone.status(), IsOk());
    const ComparisonCounts& got = packed->report.comparisons;
    const ComparisonCounts& want = alone->report().comparisons;
    EXPECT_EQ(got.filter, want.filter);
    EXPECT_EQ(got.bounded_exact, want.bounded_exact);
    EXPECT_EQ(got.cpu_fallback, want.cpu_fallback);
    EXPECT_GT(got.bounded_exact, 0u);
  }
}

TEST_P(PackedFamiliesTest, NoPointsAtAllGiveEmptyFamilies) {
  const std::vector<uint32_t> set_begin{0, 0, 0};
  absl::StatusOr<AlphaFamilies> packed = BuildAlphaFamilies({}, set_begin, Options());
  ASSERT_THAT(packed.status(), IsOk());
  ASSERT_EQ(packed->families.size(), 2u);
  absl::StatusOr<AlphaFamily> empty = BuildAlphaFamily({}, Options());
  ASSERT_THAT(empty.status(), IsOk());
  for (const AlphaFamily& f : packed->families) ExpectSameFamily(f, *empty);
}

TEST_P(PackedFamiliesTest, BadInputAndOptionsAreRefusedByName) {
  const std::vector<Point2> points = gen::Uniform(10, 1);
  EXPECT_THAT(BuildAlphaFamilies(points, std::vector<uint32_t>{0, 4, 9}, Options()).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "set offsets: the last is 9, not the 10 points given"));
  std::vector<Point2> with_nan = points;
  with_nan[7].x = std::numeric_limits<double>::infinity();
  const absl::Status bad = BuildAlphaFamilies(with_nan, std::vector<uint32_t>{0, 3, 5, 10}, Options()).status();
  EXPECT_EQ(bad.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(std::string(bad.message()).rfind("set 2: point 2 is not finite", 0), 0u) << bad.message();
  BuildOptions persistence = Options();
  persistence.persistence = true;
  EXPECT_THAT(BuildAlphaFamilies(points, std::vector<uint32_t>{0, 10}, persistence).status(),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       "a packed build of many sets does not compute persistence diagrams: build the sets one by one"));
}

TEST_P(PackedFamiliesTest, TheLimitOfExactComparisonsBoundsAllTheSets) {
  // Two lattices nudged by ulps need thousands of exact comparisons together; a limit of 100
  // stops the build, named as that limit.
  SetsToPack sets;
  sets.Add("lattice", gen::UlpLattice(3000, 1));
  sets.Add("lattice again", gen::UlpLattice(3000, 2));
  BuildOptions limited = Options();
  limited.max_exact_comparisons = 100;
  const absl::Status stopped = BuildAlphaFamilies(sets.points, sets.set_begin, limited).status();
  EXPECT_TRUE(IsExactComparisonLimit(stopped)) << stopped;
}

TEST_P(PackedFamiliesTest, ACancelledBuildStopsAndSaysWhere) {
  SetsToPack sets;
  sets.Add("uniform", gen::Uniform(2000, 1));
  sets.Add("grid", gen::Grid(2000, 2));
  BuildOptions options = Options();
  std::vector<std::string> phases;
  options.progress = [&](std::string_view phase, double) { phases.emplace_back(phase); };
  options.cancelled = [&] { return !phases.empty(); };  // after the triangulation
  EXPECT_THAT(
      BuildAlphaFamilies(sets.points, sets.set_begin, options).status(),
      StatusIs(absl::StatusCode::kCancelled, "build of 2 sets of 4000 points cancelled after the triangulation"));
  options.cancelled = nullptr;
  phases.clear();
  ASSERT_THAT(BuildAlphaFamilies(sets.points, sets.set_begin, options).status(), IsOk());
  EXPECT_EQ(phases, (std::vector<std::string>{"triangulation", "alpha", "split"}));
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(PackedFamiliesTest);

}  // namespace
}  // namespace galpha
