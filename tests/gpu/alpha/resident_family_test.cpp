// ResidentAlphaFamily (gpu/alpha/resident_family.hpp) against the family in host memory built on the
// same backend (AlphaFamily, itself checked against CGAL and brute force): every query answered
// where the tables live equals AlphaFamily's, and ToHostFamily() is the same family array for
// array. Every generator, degenerate and tiny sets, weighted families; on both backends (the CUDA
// instance reads the tables from device memory).
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/family/alpha_family.hpp"
#include "core/family/area_ratio.hpp"
#include "core/family/persistence.hpp"
#include "core/family/threshold.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gpu/alpha/resident_family.hpp"
#include "gtest/gtest.h"
#include "tests/support/backend_fixture.hpp"
#include "tests/support/family_tables.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using testing::AsVector;
using testing::IsOk;
using testing::PackedEntries;

std::vector<uint64_t> Packed(const std::vector<MasterEntry>& entries) {
  std::vector<uint64_t> out;
  out.reserve(entries.size());
  for (const MasterEntry& e : entries) out.push_back(e.packed());
  return out;
}

class ResidentFamilyTest : public testing::BackendTest {
 protected:
  BuildOptions Options() const {
    BuildOptions options;
    options.backend = GetParam();
    return options;
  }

  /// Thresholds that probe the exact resolution: spectrum values, their neighbouring doubles, the
  /// radii of those, and the edges of the domain.
  static std::vector<double> ProbeValues(const AlphaFamily& host) {
    std::vector<double> values = {0.0,
                                  -0.0,
                                  -1.0,
                                  1e-300,
                                  1e300,
                                  std::numeric_limits<double>::infinity(),
                                  -std::numeric_limits<double>::infinity(),
                                  std::nan("")};
    const HostVector<double>& spectrum = host.spectrum();
    const size_t step = std::max<size_t>(1, spectrum.size() / 60);
    for (size_t i = 0; i < spectrum.size(); i += step) {
      const double d = spectrum[i];
      values.push_back(d);
      values.push_back(std::nextafter(d, -HUGE_VAL));
      values.push_back(std::nextafter(d, HUGE_VAL));
    }
    if (!spectrum.empty()) values.push_back(spectrum[spectrum.size() - 1]);
    return values;
  }

  void ExpectSameAnswers(const AlphaFamily& host, const ResidentAlphaFamily& resident, const std::string& where) {
    SCOPED_TRACE(where);
    ASSERT_EQ(resident.max_level(), host.max_level());
    EXPECT_EQ(resident.num_unique(), host.num_unique());
    EXPECT_EQ(resident.SolidLevel(), host.SolidLevel());
    EXPECT_EQ(resident.min_alpha_sq(), host.min_alpha_sq());
    EXPECT_EQ(resident.comparisons().filter, host.report().comparisons.filter);
    EXPECT_EQ(resident.comparisons().bounded_exact, host.report().comparisons.bounded_exact);
    EXPECT_EQ(resident.comparisons().cpu_fallback, host.report().comparisons.cpu_fallback);
    const int64_t k = host.max_level();
    if (!host.points().empty()) {
      EXPECT_GT(resident.ResidentBytes(), 0u);
    }

    // Thresholds resolve to the same levels (or the same errors).
    for (const double value : ProbeValues(host)) {
      SCOPED_TRACE("threshold " + std::to_string(value));
      const absl::StatusOr<int64_t> sq = resident.LevelForAlphaSq(value);
      const absl::StatusOr<int64_t> host_sq = host.LevelForAlphaSq(value);
      ASSERT_EQ(sq.status().code(), host_sq.status().code());
      if (host_sq.ok()) {
        EXPECT_EQ(*sq, *host_sq);
      }
      const absl::StatusOr<int64_t> lower = resident.RankLowerBound(value);
      ASSERT_THAT(lower, IsOk());
      EXPECT_EQ(*lower, host.RankLowerBound(value));
      for (const double alpha : {value, value > 0 ? std::sqrt(value) : value,
                                 value > 0 ? std::nextafter(std::sqrt(value), HUGE_VAL) : value}) {
        const absl::StatusOr<int64_t> r = resident.LevelForAlpha(alpha);
        const absl::StatusOr<int64_t> h = host.LevelForAlpha(alpha);
        ASSERT_EQ(r.status().code(), h.status().code()) << "alpha " << alpha;
        if (h.ok()) {
          EXPECT_EQ(*r, *h) << "alpha " << alpha;
        }
      }
    }
    for (const int64_t rank : {int64_t{-1}, int64_t{0}, k / 2, k, k + 1}) {
      EXPECT_EQ(resident.LevelForRank(rank).status().code(), host.LevelForRank(rank).status().code());
    }

    // Classification at levels across the range, in every mode and vertex rule.
    std::vector<int64_t> levels = {-1, 0, 1, k / 7, k / 3, k / 2, (2 * k) / 3, k - 1, k};
    for (const int64_t level : levels) {
      for (const ClassifyMode mode : {ClassifyMode::kGeneral, ClassifyMode::kRegularized}) {
        for (const VertexRule rule : {VertexRule::kReport, VertexRule::kCgal}) {
          const absl::StatusOr<Classification> r = resident.ClassifyAll(level, mode, rule);
          ASSERT_THAT(r, IsOk());
          const Classification h = host.ClassifyAll(level, mode, rule);
          EXPECT_EQ(r->vertices, h.vertices) << "level " << level;
          EXPECT_EQ(r->edges, h.edges) << "level " << level;
          EXPECT_EQ(r->triangles, h.triangles) << "level " << level;
          if (rule == VertexRule::kReport) {
            // The shape's complex from the resident classes is the host family's.
            const ShapeComplex from_classes = ComplexFromClasses(resident.points(), resident.representative(),
                                                                 resident.triangles(), resident.edges(), *r, mode);
            const ShapeComplex expected = host.ComplexAt(level, mode);
            EXPECT_EQ(from_classes.triangles, expected.triangles) << "level " << level;
            EXPECT_EQ(from_classes.singular_edges, expected.singular_edges) << "level " << level;
            EXPECT_EQ(from_classes.isolated_points, expected.isolated_points) << "level " << level;
            // The shape from the boundary found where the tables live is AssembleShape's, to the
            // area's last bit.
            const absl::StatusOr<ShapeGeometry> shape = resident.ShapeAt(level, mode);
            const absl::StatusOr<ShapeGeometry> assembled = AssembleShape(expected);
            ASSERT_THAT(shape, IsOk());
            ASSERT_THAT(assembled, IsOk());
            ASSERT_EQ(shape->polygons.size(), assembled->polygons.size()) << "level " << level;
            for (size_t p = 0; p < shape->polygons.size(); ++p) {
              EXPECT_EQ(shape->polygons[p].outer, assembled->polygons[p].outer) << "level " << level;
              EXPECT_EQ(shape->polygons[p].holes, assembled->polygons[p].holes) << "level " << level;
            }
            EXPECT_EQ(shape->singular_edges, assembled->singular_edges) << "level " << level;
            EXPECT_EQ(shape->isolated_points, assembled->isolated_points) << "level " << level;
            EXPECT_EQ(shape->area, assembled->area) << "level " << level;
          }
        }
      }
    }

    // The curves at every level (and beyond both ends).
    for (int64_t level = -1; level <= k + 1; level += (k > 400 ? 7 : 1)) {
      const absl::StatusOr<TopologyAtLevel> at = resident.TopologyAt(level);
      ASSERT_THAT(at, IsOk());
      ASSERT_EQ(at->components, host.Components(level)) << "level " << level;
      ASSERT_EQ(at->solid_components, host.SolidComponents(level)) << "level " << level;
      ASSERT_EQ(at->regularized_components, host.RegularizedComponents(level)) << "level " << level;
      ASSERT_EQ(at->holes, host.Holes(level, ClassifyMode::kGeneral)) << "level " << level;
      ASSERT_EQ(at->regularized_holes, host.Holes(level, ClassifyMode::kRegularized)) << "level " << level;
    }

    // The curves over ranges in one read, the area curve and the published values.
    const absl::StatusOr<std::vector<TopologyAtLevel>> range = resident.TopologyBetween(-2, k + 2);
    ASSERT_THAT(range, IsOk());
    ASSERT_EQ(range->size(), static_cast<size_t>(k + 5));
    for (int64_t level = -2; level <= k + 2; ++level) {
      const TopologyAtLevel& at = (*range)[static_cast<size_t>(level + 2)];
      ASSERT_EQ(at.components, host.Components(level)) << "level " << level;
      ASSERT_EQ(at.solid_components, host.SolidComponents(level)) << "level " << level;
      ASSERT_EQ(at.regularized_components, host.RegularizedComponents(level)) << "level " << level;
      ASSERT_EQ(at.holes, host.Holes(level, ClassifyMode::kGeneral)) << "level " << level;
      ASSERT_EQ(at.regularized_holes, host.Holes(level, ClassifyMode::kRegularized)) << "level " << level;
    }
    for (const auto& [first, last] : {std::pair<int64_t, int64_t>{k + 3, k + 5}, {-5, -1}, {-1, 0}, {k, k + 1}}) {
      const absl::StatusOr<std::vector<TopologyAtLevel>> part = resident.TopologyBetween(first, last);
      ASSERT_THAT(part, IsOk());
      ASSERT_EQ(part->size(), static_cast<size_t>(last - first + 1));
      for (int64_t level = first; level <= last; ++level) {
        EXPECT_EQ((*part)[static_cast<size_t>(level - first)].components, host.Components(level)) << "level " << level;
        EXPECT_EQ((*part)[static_cast<size_t>(level - first)].holes, host.Holes(level, ClassifyMode::kGeneral))
            << "level " << level;
      }
    }
    for (const int64_t level : {int64_t{-1}, int64_t{0}, k / 2, k, k + 1}) {
      const absl::StatusOr<double> area = resident.RegularizedAreaApprox(level);
      ASSERT_THAT(area, IsOk());
      EXPECT_EQ(*area, RegularizedAreaApprox(host, level)) << "level " << level;
      if (level <= k) {
        const absl::StatusOr<double> published = resident.PublishedAlphaSq(level);
        ASSERT_THAT(published, IsOk());
        EXPECT_EQ(*published, PublishedAlphaSq(host, level)) << "level " << level;
      }
    }
    // Area ratios: fixed ones, and each sampled level's own ratio with its neighbouring doubles,
    // which the certified curve cannot decide (the exact areas do, from the downloaded tables).
    std::vector<double> ratios = {0.0, 1e-300, 0.1, 0.5, 0.9, 1.0};
    const double hull = HullAreaApprox(host);
    if (hull > 0.0) {
      for (int64_t level = 1; level <= k; level += std::max<int64_t>(1, k / 12)) {
        const double own = RegularizedAreaApprox(host, level) / hull;
        for (const double ratio : {own, std::nextafter(own, 0.0), std::nextafter(own, 2.0)}) {
          if (ratio <= 1.0) ratios.push_back(ratio);
        }
      }
    }
    AreaCurveReader host_curve;
    host_curve.max_level = k;
    host_curve.complete = host.ranks().area_units.size() == static_cast<size_t>(k) + 1;
    host_curve.error_units = host.ranks().area_scale.error_units;
    host_curve.units_at = [&host](int64_t level) -> absl::StatusOr<uint64_t> {
      return host.ranks().area_units[static_cast<size_t>(level)];
    };
    for (const double ratio : ratios) {
      const absl::StatusOr<int64_t> level = resident.LevelForAreaRatio(ratio);
      ASSERT_THAT(level, IsOk()) << "ratio " << ratio;
      EXPECT_EQ(*level, *LevelForAreaRatio(host, ratio)) << "ratio " << ratio;
      const absl::StatusOr<AreaRatioBracket> bracket = BracketAreaRatio(host_curve, ratio);
      ASSERT_THAT(bracket, IsOk());
      if (!bracket->decided()) ++undecided_ratios_;
    }
    EXPECT_EQ(resident.LevelForAreaRatio(1.5).status().code(), absl::StatusCode::kInvalidArgument);

    const absl::StatusOr<std::vector<uint32_t>> begins = resident.MasterBegins(0, k + 2);
    ASSERT_THAT(begins, IsOk());
    EXPECT_EQ(*begins, AsVector(host.ranks().master_begin));
    EXPECT_FALSE(resident.MasterBegins(0, k + 3).ok());
    const absl::StatusOr<std::vector<MasterEntry>> all = resident.MasterEntries(0, host.ranks().master.size());
    ASSERT_THAT(all, IsOk());
    EXPECT_EQ(Packed(*all), PackedEntries(host.ranks().master));
    EXPECT_EQ(resident.MasterEntries(0, host.ranks().master.size() + 1).status().code(), absl::StatusCode::kOutOfRange);

    // Optimal levels.
    for (const uint32_t n : {0u, 1u, 2u, 5u, 100u}) {
      for (const std::optional<uint32_t> holes :
           {std::optional<uint32_t>(), std::optional<uint32_t>(0u), std::optional<uint32_t>(3u)}) {
        const absl::StatusOr<std::optional<int64_t>> general = resident.OptimalLevelGeneral(n, holes);
        ASSERT_THAT(general, IsOk());
        EXPECT_EQ(*general, host.OptimalLevelGeneral(n, holes)) << "n " << n;
        const absl::StatusOr<std::optional<int64_t>> regularized = resident.OptimalLevelRegularized(n, holes);
        ASSERT_THAT(regularized, IsOk());
        EXPECT_EQ(*regularized, host.OptimalLevelRegularized(n, holes)) << "n " << n;
      }
    }

    // Master list and spectrum slices.
    for (int64_t rank = -1; rank <= k + 1; rank += (k > 400 ? 13 : 1)) {
      const absl::StatusOr<std::vector<MasterEntry>> entries = resident.MasterList(rank);
      ASSERT_THAT(entries, IsOk());
      const absl::Span<const MasterEntry> h = host.MasterList(rank);
      ASSERT_EQ(Packed(*entries), Packed(std::vector<MasterEntry>(h.begin(), h.end()))) << "rank " << rank;
    }
    const absl::StatusOr<std::vector<double>> whole = resident.Spectrum(0, k);
    ASSERT_THAT(whole, IsOk());
    EXPECT_EQ(*whole, AsVector(host.spectrum()));
    const absl::StatusOr<std::vector<double>> tail = resident.Spectrum(k - 3, 100);
    ASSERT_THAT(tail, IsOk());
    EXPECT_EQ(tail->size(), static_cast<size_t>(std::min<int64_t>(k, 3)));

    // The persistence diagram where the tables live, pair for pair the host union-finds' (the
    // oracle: core/family/persistence.cpp).
    const absl::StatusOr<PersistenceDiagram> diagram = resident.Persistence();
    ASSERT_THAT(diagram, IsOk());
    const absl::StatusOr<PersistenceDiagram> expected = ComputePersistence(host);
    ASSERT_THAT(expected, IsOk());
    for (int d = 0; d < 3; ++d) EXPECT_EQ(diagram->dimension_begin[d], expected->dimension_begin[d]) << d;
    ASSERT_EQ(diagram->pairs.size(), expected->pairs.size());
    for (size_t i = 0; i < expected->pairs.size(); ++i) {
      ASSERT_TRUE(diagram->pairs[i] == expected->pairs[i]) << "pair " << i;
    }

    // The same family, array for array, once downloaded.
    const absl::StatusOr<AlphaFamily> downloaded = resident.ToHostFamily();
    ASSERT_THAT(downloaded, IsOk());
    testing::ExpectSameFamilyTables(*downloaded, host);
  }

  void ExpectSameAsHost(const std::vector<Point2>& points, const std::string& where) {
    const absl::StatusOr<AlphaFamily> host = BuildAlphaFamily(points, Options());
    ASSERT_THAT(host, IsOk()) << where;
    const absl::StatusOr<ResidentAlphaFamily> resident = BuildResidentAlphaFamily(points, Options());
    ASSERT_THAT(resident, IsOk()) << where;
    ExpectSameAnswers(*host, *resident, where);
  }

  /// Ratios the certified curve left to the exact areas (the resident family's download path).
  int undecided_ratios_ = 0;
};

TEST_P(ResidentFamilyTest, EveryGenerator) {
  for (const gen::NamedGenerator& generator : gen::AllDistributions()) {
    for (const size_t n : {size_t{300}, size_t{4000}}) {
      ExpectSameAsHost(generator.generate(n, 3), generator.name + " n " + std::to_string(n));
      if (HasFatalFailure()) return;
    }
  }
  EXPECT_GT(undecided_ratios_, 0) << "no ratio reached the exact areas";
}

TEST_P(ResidentFamilyTest, DegenerateAndTinySets) {
  for (const gen::NamedPoints& set : gen::SmallDegenerateSets()) {
    ExpectSameAsHost(set.points, set.name);
    if (HasFatalFailure()) return;
  }
}

TEST_P(ResidentFamilyTest, WeightedFamilies) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> weight(-0.0004, 0.0004);
  for (const size_t n : {size_t{300}, size_t{5000}}) {
    const std::vector<Point2> points = gen::Uniform(n, 5);
    std::vector<double> weights(points.size());
    for (double& w : weights) w = weight(rng);
    // Some points hidden: a few heavy weights.
    for (size_t i = 0; i < weights.size(); i += 97) weights[i] = 0.003;
    const absl::StatusOr<AlphaFamily> host = BuildWeightedAlphaFamily(points, weights, Options());
    ASSERT_THAT(host, IsOk());
    ASSERT_FALSE(host->HiddenPoints().empty()) << "the heavy weights hide points";
    const absl::StatusOr<ResidentAlphaFamily> resident = BuildWeightedResidentAlphaFamily(points, weights, Options());
    ASSERT_THAT(resident, IsOk());
    EXPECT_TRUE(resident->weighted());
    ExpectSameAnswers(*host, *resident, "weighted uniform n " + std::to_string(n));
  }
  const std::vector<Point2> points = gen::Uniform(10, 1);
  EXPECT_EQ(BuildWeightedResidentAlphaFamily(points, std::vector<double>(9, 0.0), Options()).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST_P(ResidentFamilyTest, BadInputIsRefusedAsByTheHostBuild) {
  const std::vector<Point2> bad = {{0, 0}, {std::nan(""), 1}, {2, 2}};
  const absl::StatusOr<ResidentAlphaFamily> resident = BuildResidentAlphaFamily(bad, Options());
  const absl::StatusOr<AlphaFamily> host = BuildAlphaFamily(bad, Options());
  ASSERT_FALSE(host.ok());
  EXPECT_EQ(resident.status(), host.status());
  if (GetParam() == Backend::kCuda) {
    // A resident family owns its stream: a caller's stream is refused, not ignored.
    BuildOptions options = Options();
    int not_a_stream = 0;
    options.cuda_stream = &not_a_stream;
    const absl::StatusOr<ResidentAlphaFamily> refused = BuildResidentAlphaFamily(gen::Uniform(10, 1), options);
    EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(refused.status().message().find("cuda_stream"), std::string::npos) << refused.status();
  }
}

GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(ResidentFamilyTest);

}  // namespace
}  // namespace galpha
