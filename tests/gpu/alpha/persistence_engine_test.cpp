// The engine's persistence diagram (gpu/alpha/persistence_engine.hpp: spanning forests and the
// elder rule by parallel rounds) against the host's union-finds in filtration order
// (core/family/persistence.cpp, itself checked against GUDHI by persistence_gudhi_test), pair for
// pair: every generator, degenerate sets (ties, collinear, duplicates, tiny sets), weighted
// families; with the forests' slow tails paired on the host (the default) and with every round on
// the backend, on both backends. Families are built on the CPU, so the CUDA instance compares the
// CUDA diagram with the host's on the very same family.
#include <cstdint>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/family/alpha_family.hpp"
#include "core/family/persistence.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gpu/alpha/persistence_engine.hpp"
#include "gtest/gtest.h"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::IsOk;

BuildOptions OnCpu() {
  BuildOptions options;
  options.backend = Backend::kCpu;
  return options;
}

std::string Show(const PersistencePair& p) {
  std::ostringstream out;
  out << "{dim " << p.dimension << ", birth " << p.birth_rank << ", death " << p.death_rank << ", creator " << p.creator
      << ", killer " << p.killer << "}";
  return out.str();
}

class PersistenceEngineTest : public testing::BackendTest {
 protected:
  static void ExpectSame(const PersistenceDiagram& engine, const PersistenceDiagram& host) {
    for (int d = 0; d < 3; ++d) EXPECT_EQ(engine.dimension_begin[d], host.dimension_begin[d]) << "dimension " << d;
    ASSERT_EQ(engine.pairs.size(), host.pairs.size());
    size_t mismatches = 0;
    for (size_t i = 0; i < host.pairs.size() && mismatches < 5; ++i) {
      if (engine.pairs[i] != host.pairs[i]) {
        ADD_FAILURE() << "pair " << i << ": engine " << Show(engine.pairs[i]) << ", host " << Show(host.pairs[i]);
        ++mismatches;
      }
    }
  }

  void ExpectSameAsHost(const AlphaFamily& family, const std::string& where) {
    SCOPED_TRACE(where);
    const absl::StatusOr<PersistenceDiagram> host = ComputePersistence(family);
    ASSERT_THAT(host, IsOk());
    for (const bool host_finish : {true, false}) {
      SCOPED_TRACE(host_finish ? "tails on the host" : "every round on the backend");
      PersistenceOptions options;
      options.backend = GetParam();
      options.host_finish = host_finish;
      PersistenceReport report;
      const absl::StatusOr<PersistenceDiagram> engine = ComputePersistenceOnBackend(family, options, &report);
      ASSERT_THAT(engine, IsOk());
      EXPECT_FALSE(report.stage_times.empty());
      if (!host_finish) {
        EXPECT_EQ(report.forests[0].host_finished_edges, 0u);
        EXPECT_EQ(report.forests[1].host_finished_edges, 0u);
      }
      ExpectSame(*engine, *host);
    }
  }

  void ExpectSameAsHost(const std::vector<Point2>& points, const std::string& where) {
    absl::StatusOr<AlphaFamily> family = BuildAlphaFamily(points, OnCpu());
    ASSERT_THAT(family, IsOk()) << where;
    ExpectSameAsHost(*family, where);
  }
};

TEST_P(PersistenceEngineTest, EveryGenerator) {
  for (const gen::NamedGenerator& generator : gen::AllDistributions()) {
    for (const size_t n : {size_t{200}, size_t{5000}}) {
      for (const uint64_t seed : {1u, 2u}) {
        ExpectSameAsHost(generator.generate(n, seed),
                         generator.name + " n " + std::to_string(n) + " seed " + std::to_string(seed));
        if (HasFatalFailure()) return;
      }
    }
  }
}

TEST_P(PersistenceEngineTest, DegenerateSets) {
  // The grid's births tie everywhere, and ties are broken by canonical position, which makes the
  // forests' weights increase along rows and columns: the rounds' slowest case.
  for (const gen::NamedPoints& set : gen::SmallDegenerateSets()) ExpectSameAsHost(set.points, set.name);
}

// BuildOptions::persistence: the diagram computed in the build, from the family's arrays where they
// lie (device memory on CUDA), is the host's; and PersistenceDiagramOf answers with it.
TEST_P(PersistenceEngineTest, ComputedInTheBuild) {
  for (const gen::NamedGenerator& generator : gen::AllDistributions()) {
    SCOPED_TRACE(generator.name);
    BuildOptions options;
    options.backend = GetParam();
    options.persistence = true;
    absl::StatusOr<AlphaFamily> family = BuildAlphaFamily(generator.generate(4000, 5), options);
    ASSERT_THAT(family, IsOk());
    ASSERT_NE(family->persistence(), nullptr);
    bool timed = false;
    for (const StageTime& stage : family->report().stage_times) timed |= stage.stage == "persistence_h1";
    EXPECT_TRUE(timed) << "the build's stages name the diagram's";
    const absl::StatusOr<PersistenceDiagram> host = ComputePersistence(*family);
    ASSERT_THAT(host, IsOk());
    ExpectSame(*family->persistence(), *host);
    const absl::StatusOr<PersistenceDiagram> answered = PersistenceDiagramOf(*family);
    ASSERT_THAT(answered, IsOk());
    ExpectSame(*answered, *host);
    // The curves' general forest doubles as the diagram's primal forest in such a build: its
    // curves are the plain build's.
    options.persistence = false;
    absl::StatusOr<AlphaFamily> plain = BuildAlphaFamily(generator.generate(4000, 5), options);
    ASSERT_THAT(plain, IsOk());
    EXPECT_EQ(family->ranks().components, plain->ranks().components);
    EXPECT_EQ(family->ranks().holes, plain->ranks().holes);
    EXPECT_EQ(family->ranks().regularized_components, plain->ranks().regularized_components);
    EXPECT_EQ(family->ranks().regularized_holes, plain->ranks().regularized_holes);
    EXPECT_EQ(family->ranks().solid_components, plain->ranks().solid_components);
  }
  std::vector<Point2> points = gen::Uniform(3000, 4);
  std::vector<double> weights(points.size());
  for (size_t i = 0; i < weights.size(); ++i) weights[i] = 1e-4 * static_cast<double>(i % 7);
  BuildOptions options;
  options.backend = GetParam();
  options.persistence = true;
  absl::StatusOr<AlphaFamily> weighted = BuildWeightedAlphaFamily(points, weights, options);
  ASSERT_THAT(weighted, IsOk());
  ASSERT_NE(weighted->persistence(), nullptr);
  const absl::StatusOr<PersistenceDiagram> host = ComputePersistence(*weighted);
  ASSERT_THAT(host, IsOk());
  ExpectSame(*weighted->persistence(), *host);
  // Without the option the family has none.
  absl::StatusOr<AlphaFamily> plain = BuildAlphaFamily(points, OnCpu());
  ASSERT_THAT(plain, IsOk());
  EXPECT_EQ(plain->persistence(), nullptr);
}

TEST_P(PersistenceEngineTest, WeightedFamilies) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> weight(-0.0004, 0.0004);
  for (const size_t n : {size_t{300}, size_t{6000}}) {
    const std::vector<Point2> points = gen::Uniform(n, 3);
    std::vector<double> weights(points.size());
    for (double& w : weights) w = weight(rng);
    absl::StatusOr<AlphaFamily> family = BuildWeightedAlphaFamily(points, weights, OnCpu());
    ASSERT_THAT(family, IsOk());
    ExpectSameAsHost(*family, "weighted uniform n " + std::to_string(n));
  }
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(PersistenceEngineTest);

}  // namespace
}  // namespace galpha
