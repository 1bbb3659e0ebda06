#include "tests/support/point_generators.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <unordered_set>
#include <utility>

namespace galpha::gen {
namespace {

constexpr double kPi = 3.14159265358979323846;

// `count` distinct integers drawn uniformly from [lo, hi], in random order.
std::vector<int64_t> DistinctIntegers(size_t count, int64_t lo, int64_t hi, std::mt19937_64& rng) {
  std::uniform_int_distribution<int64_t> pick(lo, hi);
  std::unordered_set<int64_t> seen;
  std::vector<int64_t> values;
  values.reserve(count);
  while (values.size() < count) {
    const int64_t v = pick(rng);
    if (seen.insert(v).second) values.push_back(v);
  }
  return values;
}

// `count` distinct pairs of integers in [lo, hi]^2 (hi - lo < 2^32), in random order.
std::vector<std::pair<int64_t, int64_t>> DistinctIntegerPairs(size_t count, int64_t lo, int64_t hi,
                                                              std::mt19937_64& rng) {
  std::uniform_int_distribution<int64_t> pick(lo, hi);
  std::unordered_set<uint64_t> seen;
  std::vector<std::pair<int64_t, int64_t>> pairs;
  pairs.reserve(count);
  while (pairs.size() < count) {
    const int64_t a = pick(rng);
    const int64_t b = pick(rng);
    const uint64_t key = (static_cast<uint64_t>(a - lo) << 32) | static_cast<uint64_t>(b - lo);
    if (seen.insert(key).second) pairs.emplace_back(a, b);
  }
  return pairs;
}

// Integer line parameters are drawn from [-range, range]: wide enough that drawing n distinct ones
// stays fast, small enough that every coordinate stays an exact double.
int64_t ParameterRange(size_t n) { return std::max<int64_t>(int64_t{1} << 20, 2 * static_cast<int64_t>(n)); }

}  // namespace

std::vector<Point2> Uniform(size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Point2> points(n);
  for (Point2& p : points) {
    p.x = unit(rng);
    p.y = unit(rng);
  }
  return points;
}

std::vector<Point2> Gaussian(size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Point2> points(n);
  for (Point2& p : points) {
    p.x = normal(rng);
    p.y = normal(rng);
  }
  return points;
}

std::vector<Point2> Clustered(size_t n, uint64_t seed) {
  constexpr int kClusters = 100;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Point2> centres(kClusters);
  for (Point2& c : centres) {
    c.x = unit(rng);
    c.y = unit(rng);
  }
  std::uniform_int_distribution<int> pick_cluster(0, kClusters - 1);
  std::normal_distribution<double> spread(0.0, 1e-3);
  std::vector<Point2> points(n);
  for (Point2& p : points) {
    const Point2& c = centres[pick_cluster(rng)];
    p.x = c.x + spread(rng);
    p.y = c.y + spread(rng);
  }
  return points;
}

std::vector<Point2> Grid(size_t n, uint64_t seed) {
  const size_t side = static_cast<size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  std::vector<Point2> points(n);
  for (size_t i = 0; i < n; ++i) {
    const size_t column = i % side, row = i / side;  // integer division: the cell's row
    points[i] = {static_cast<double>(column), static_cast<double>(row)};
  }
  std::mt19937_64 rng(seed);
  std::shuffle(points.begin(), points.end(), rng);
  return points;
}

std::vector<Point2> Circle(size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> quadrant_angle(0.0, kPi / 2);
  std::vector<Point2> points;
  points.reserve(n);
  while (points.size() + 4 <= n) {
    const double t = quadrant_angle(rng);
    const double c = std::cos(t);
    const double s = std::sin(t);
    points.push_back({c, s});
    points.push_back({-c, s});
    points.push_back({-c, -s});
    points.push_back({c, -s});
  }
  std::uniform_real_distribution<double> any_angle(0.0, 2 * kPi);
  while (points.size() < n) {
    const double t = any_angle(rng);
    points.push_back({std::cos(t), std::sin(t)});
  }
  std::shuffle(points.begin(), points.end(), rng);
  return points;
}

std::vector<Point2> ThinCircle(size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> angle(0.0, 2 * kPi);
  std::uniform_real_distribution<double> radius(1.0, 1.0 + 1e-6);
  std::vector<Point2> points(n);
  for (Point2& p : points) {
    const double t = angle(rng);
    const double r = radius(rng);
    p.x = r * std::cos(t);
    p.y = r * std::sin(t);
  }
  return points;
}

std::vector<Point2> TwoLines(size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  // Integer parameters keep every coordinate exact, so each line is exactly collinear.
  const size_t on_first = n / 2;
  const int64_t range = ParameterRange(n);
  const std::vector<int64_t> t = DistinctIntegers(on_first, -range, range, rng);
  const std::vector<int64_t> s = DistinctIntegers(n - on_first, -range, range, rng);
  std::vector<Point2> points;
  points.reserve(n);
  for (int64_t v : t) points.push_back({3.0 * v, 2.0 * v + 5.0});
  for (int64_t v : s) points.push_back({1.0 * v, 7.0 - 4.0 * v});
  std::shuffle(points.begin(), points.end(), rng);
  return points;
}

std::vector<Point2> ParallelLines(size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  const size_t on_first = n / 2;
  const int64_t range = ParameterRange(n);
  const std::vector<int64_t> a = DistinctIntegers(on_first, -range, range, rng);
  const std::vector<int64_t> b = DistinctIntegers(n - on_first, -range, range, rng);
  std::vector<Point2> points;
  points.reserve(n);
  for (int64_t x : a) points.push_back({1.0 * x, 2.0 * x});
  for (int64_t x : b) points.push_back({1.0 * x, 2.0 * x + 3.0});
  std::shuffle(points.begin(), points.end(), rng);
  return points;
}

std::vector<Point2> WithDuplicates(size_t n, uint64_t seed) {
  const size_t repeats = n / 10;
  std::vector<Point2> points = Uniform(n - repeats, seed);
  std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
  if (!points.empty()) {
    std::uniform_int_distribution<size_t> pick(0, points.size() - 1);
    for (size_t i = 0; i < repeats; ++i) points.push_back(points[pick(rng)]);
  }
  std::shuffle(points.begin(), points.end(), rng);
  return points;
}

std::vector<Point2> HugeOffset(size_t n, uint64_t seed, double offset) {
  std::vector<Point2> points = Uniform(n, seed);
  for (Point2& p : points) {
    p.x = offset + 1000.0 * p.x;
    p.y = offset + 1000.0 * p.y;
  }
  return points;
}

std::vector<Point2> Tiny(size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  // Integers from 1 keep the two halves apart: the normal half has coordinates >= 2^-1000, the
  // subnormal half < 2^26 * 2^-1074 = 2^-1048, and scaling by a power of two is exact.
  constexpr int64_t kMaxInteger = (int64_t{1} << 26) - 1;
  const size_t normal = n - n / 2;
  std::vector<Point2> points;
  points.reserve(n);
  for (const auto& [a, b] : DistinctIntegerPairs(normal, 1, kMaxInteger, rng)) {
    points.push_back({std::ldexp(static_cast<double>(a), -1000), std::ldexp(static_cast<double>(b), -1000)});
  }
  for (const auto& [a, b] : DistinctIntegerPairs(n - normal, 1, kMaxInteger, rng)) {
    points.push_back({std::ldexp(static_cast<double>(a), -1074), std::ldexp(static_cast<double>(b), -1074)});
  }
  std::shuffle(points.begin(), points.end(), rng);
  return points;
}

std::vector<Point2> UlpLattice(size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> nudge(-2, 2);
  auto moved = [&](double v) {
    const int ulps = nudge(rng);
    for (int i = 0; i < std::abs(ulps); ++i) v = std::nextafter(v, ulps > 0 ? INFINITY : -INFINITY);
    return v;
  };
  const auto width = static_cast<size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  std::vector<Point2> points;
  points.reserve(n);
  const size_t columns = std::max<size_t>(width, 1);
  for (size_t i = 0; i < n; ++i) {
    const size_t column = i % columns, row = i / columns;  // integer division: the point's row
    const double x = 1000.0 + 0.1 * static_cast<double>(column);
    const double y = 2000.0 + 0.1 * static_cast<double>(row);
    points.push_back({moved(x), moved(y)});
  }
  std::shuffle(points.begin(), points.end(), rng);
  return points;
}

std::vector<Point2> LidarCentimetres(size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int64_t> centimetres(0, 20000);  // a 200 m tile
  std::vector<Point2> points(n);
  for (Point2& p : points) {
    p.x = static_cast<double>(centimetres(rng)) * 0.01 + 500000.0;
    p.y = static_cast<double>(centimetres(rng)) * 0.01 + 4000000.0;
  }
  return points;
}

std::vector<NamedGenerator> AllDistributions() {
  return {
      {"uniform", Uniform, true},
      {"gaussian", Gaussian, true},
      {"clustered", Clustered, true},
      {"grid", Grid, false},
      {"circle", Circle, false},
      {"thin_circle", ThinCircle, true},
      {"two_lines", TwoLines, false},
      {"parallel_lines", ParallelLines, false},
      {"with_duplicates", WithDuplicates, true},
      {"huge_offset_1e9", [](size_t n, uint64_t seed) { return HugeOffset(n, seed, 1e9); }, true},
      {"huge_offset_1e15", [](size_t n, uint64_t seed) { return HugeOffset(n, seed, 1e15); }, false},
      {"tiny", Tiny, false},
      {"ulp_lattice", UlpLattice, false},
      {"lidar_cm", LidarCentimetres, false},
  };
}

const NamedGenerator* FindDistribution(const std::string& name) {
  static const std::vector<NamedGenerator>* const kAll = new std::vector<NamedGenerator>(AllDistributions());
  for (const NamedGenerator& generator : *kAll) {
    if (generator.name == name) return &generator;
  }
  return nullptr;
}

std::vector<NamedPoints> SmallDegenerateSets() {
  std::vector<NamedPoints> sets;
  std::vector<Point2> grid;
  for (int i = 0; i < 60; ++i) {
    for (int j = 0; j < 45; ++j) grid.push_back({static_cast<double>(i), static_cast<double>(j)});
  }
  std::vector<Point2> holed;
  for (size_t i = 0; i < grid.size(); ++i) {
    if (i % 3 != 1) holed.push_back(grid[i]);
  }
  sets.push_back({"60 x 45 grid", std::move(grid)});
  sets.push_back({"grid with every third point removed", std::move(holed)});
  std::vector<Point2> line;
  for (int i = 0; i < 3000; ++i) line.push_back({0.5 * i, 0.25 * i});
  sets.push_back({"collinear, evenly spaced", std::move(line)});
  std::vector<Point2> spread_line;
  for (int i = 0; i < 2000; ++i) spread_line.push_back({1.0 * i * i, 0.0});
  sets.push_back({"collinear, gaps growing along the line", std::move(spread_line)});
  std::vector<Point2> repeated = Uniform(1500, 9);
  const size_t distinct = repeated.size();
  for (int copy = 0; copy < 2; ++copy) repeated.insert(repeated.end(), repeated.begin(), repeated.begin() + distinct);
  sets.push_back({"every point three times", std::move(repeated)});
  sets.push_back({"no points", {}});
  sets.push_back({"one point", {{1, 2}}});
  sets.push_back({"one point twice", {{1, 2}, {1, 2}}});
  sets.push_back({"two points", {{0, 0}, {1, 0}}});
  sets.push_back({"a triangle", {{0, 0}, {1, 0}, {0, 1}}});
  sets.push_back({"a square (co-circular)", {{0, 0}, {1, 0}, {1, 1}, {0, 1}}});
  return sets;
}

}  // namespace galpha::gen
