// The families and thresholds of query_answers_fixture.hpp.
#include "tests/server/query_answers_fixture.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include "tests/server/cached_family_fixture.hpp"
#include "tests/support/point_generators.hpp"

namespace galpha::server::testing {

std::vector<Point2> OneLine(size_t n, uint64_t seed) {
  std::vector<Point2> points;
  for (size_t i = 0; i < n; ++i) points.push_back({static_cast<double>(i), 2.0 * static_cast<double>(i) + 1.0});
  std::mt19937_64 random(seed);
  std::shuffle(points.begin(), points.end(), random);
  return points;
}

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
    for (const auto& [name, points] : inputs) {
      std::shared_ptr<const CachedFamily> host = MakeCachedFamily(points, name);
      std::shared_ptr<const AlphaFamily> oracle(host, host->host_family());
      built->push_back({name, host, oracle});
      built->push_back({name + "/resident", MakeCachedFamily(points, name, /*resident=*/true), oracle});
    }
    return built;
  }();
  return *families;
}

std::shared_ptr<const CachedFamily> LargeFamily() {
  static const std::shared_ptr<const CachedFamily> family = MakeCachedFamily(gen::Uniform(50000, 8), "uniform_50000");
  return family;
}

absl::StatusOr<ResolvedLevel> ResolveOn(const AlphaFamily& family, const v1::Threshold& threshold) {
  // A reader that does not own the family: it lives as long as the caller's reference.
  const HostFamilyReader reader(std::shared_ptr<const AlphaFamily>(&family, [](const AlphaFamily*) {}));
  return ResolveLevel(reader, threshold);
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
v1::Threshold Ratio(double ratio) {
  v1::Threshold t;
  t.set_ratio(ratio);
  return t;
}

std::vector<v1::Threshold> Thresholds(const AlphaFamily& family) {
  const int64_t k = family.max_level();
  const auto& s = family.spectrum();
  std::vector<v1::Threshold> out = {Rank(0),
                                    Rank(k),
                                    AlphaSq(-1.0),
                                    AlphaSq(0.0),
                                    AlphaSq(std::numeric_limits<double>::infinity()),
                                    Alpha(0.0),
                                    Alpha(std::numeric_limits<double>::infinity()),
                                    Ratio(0.0),
                                    Ratio(0.5),
                                    Ratio(1.0)};
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

}  // namespace galpha::server::testing
