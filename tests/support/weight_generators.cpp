#include "tests/support/weight_generators.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace galpha::gen {
namespace {

/// The typical spacing of the points: the larger side of their box over sqrt(n).
double Spacing(const std::vector<Point2>& points) {
  if (points.empty()) return 1.0;
  double min_x = points[0].x, max_x = min_x, min_y = points[0].y, max_y = min_y;
  for (const Point2& p : points) {
    min_x = std::min(min_x, p.x);
    max_x = std::max(max_x, p.x);
    min_y = std::min(min_y, p.y);
    max_y = std::max(max_y, p.y);
  }
  const double side = std::max(max_x - min_x, max_y - min_y);
  return side > 0.0 ? side / std::sqrt(static_cast<double>(points.size())) : 1.0;
}

}  // namespace

std::vector<std::string> WeightKinds() {
  return {"zero", "equal", "uniform", "signed", "one_huge", "many_hidden", "integers"};
}

std::vector<double> Weights(const std::string& kind, const std::vector<Point2>& points, uint64_t seed) {
  std::mt19937_64 rng(seed);
  const double s = Spacing(points);
  const double s2 = s * s;
  std::vector<double> w(points.size(), 0.0);
  if (kind == "zero") return w;
  if (kind == "equal") {
    std::fill(w.begin(), w.end(), s2);
  } else if (kind == "uniform" || kind == "signed") {
    std::uniform_real_distribution<double> u(kind == "signed" ? -s2 : 0.0, s2);
    for (double& x : w) x = u(rng);
  } else if (kind == "one_huge") {
    if (!points.empty()) {
      const double side = s * std::sqrt(static_cast<double>(points.size()));
      w[std::uniform_int_distribution<size_t>(0, points.size() - 1)(rng)] = side * side / 16.0;
    }
  } else if (kind == "many_hidden") {
    for (size_t i = 0; i < w.size(); i += 2) w[i] = 4.0 * s2;
  } else if (kind == "integers") {
    const double unit = s2 > 0.0 ? std::exp2(std::round(std::log2(s2))) : 0.0;
    std::uniform_int_distribution<int> u(-2, 2);
    for (double& x : w) x = u(rng) * unit;
  } else {
    throw std::invalid_argument("unknown weight kind: " + kind);
  }
  return w;
}

}  // namespace galpha::gen
