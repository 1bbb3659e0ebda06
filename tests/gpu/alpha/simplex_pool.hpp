// Pools of simplices over small point sets, in SimplexPoints' layout, and their exact order by
// GMP rationals: the inputs of the tests that run the spectrum's exact repairs on the host.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <vector>

#include "core/base/point.hpp"
#include "core/exact/radius_rational.hpp"
#include "gpu/alpha/alpha_functors.cuh"

namespace galpha::detail::testing_pool {

// A pool of simplices over one point array, in SimplexPoints' layout (triangles, then edges).
struct SimplexPool {
  std::vector<Point2> points;
  std::vector<TriIdx> tris;
  std::vector<EdgeIdx> edges;
  SimplexPoints view() const {
    return SimplexPoints{points.data(), tris.data(), edges.data(), static_cast<uint32_t>(tris.size())};
  }
  uint32_t size() const { return static_cast<uint32_t>(tris.size() + edges.size()); }
};

// Every triangle and edge among `count` random points, which `point` draws.
template <class Draw>
SimplexPool PoolOf(int count, Draw point) {
  SimplexPool pool;
  for (int i = 0; i < count; ++i) pool.points.push_back(point());
  const auto n = static_cast<uint32_t>(count);
  for (uint32_t a = 0; a < n; ++a) {
    for (uint32_t b = a + 1; b < n; ++b) {
      pool.edges.push_back({{a, b}});
      for (uint32_t c = b + 1; c < n; ++c) {
        const Point2& pa = pool.points[a];
        const Point2& pb = pool.points[b];
        const Point2& pc = pool.points[c];
        // Collinear triples have no finite radius; the spectrum never holds them.
        if ((pb.x - pa.x) * (pc.y - pa.y) != (pb.y - pa.y) * (pc.x - pa.x)) pool.tris.push_back({{a, b, c}});
      }
    }
  }
  return pool;
}

// A pool over 14 points of a lattice with step 1/8, each coordinate nudged by up to two ulps: near
// ties 2^-146 to 2^-224 apart and exact ties that are not congruent.
inline SimplexPool UlpLatticePool(uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> step(0, 5);
  std::uniform_int_distribution<int> ulps(-2, 2);
  auto nudge = [&](double v) {
    const int n = ulps(rng);
    for (int i = 0; i < std::abs(n); ++i) v = std::nextafter(v, n > 0 ? 1e300 : -1e300);
    return v;
  };
  return PoolOf(14, [&] { return Point2{nudge(1000.0 + 0.125 * step(rng)), nudge(2000.0 + 0.125 * step(rng))}; });
}

// Sign of rho^2(a) - rho^2(b), by GMP rationals.
inline int Compare(const SimplexPool& pool, uint32_t a, uint32_t b) {
  Point2 pa[3], pb[3];
  const SimplexPoints simplex = pool.view();
  const int na = simplex(a, pa);
  const int nb = simplex(b, pb);
  return CompareRadiusSqRational(pa, na, pb, nb);
}

// The pool's simplices in exact order of value (equal values in id order).
inline std::vector<uint32_t> ByExactValue(const SimplexPool& pool) {
  std::vector<uint32_t> by_value(pool.size());
  for (uint32_t i = 0; i < pool.size(); ++i) by_value[i] = i;
  std::stable_sort(by_value.begin(), by_value.end(), [&](uint32_t a, uint32_t b) { return Compare(pool, a, b) < 0; });
  return by_value;
}

}  // namespace galpha::detail::testing_pool
