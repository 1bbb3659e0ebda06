#include "core/family/canonical_order.hpp"

#include <parallel/algorithm>

#include <algorithm>
#include <array>
#include <utility>

namespace galpha {

CanonicalOrders ComputeCanonicalOrders(const AlphaFamily& family) {
  CanonicalOrders orders;
  // 64-bit keys (smaller << 32 | larger) sort as the pairs do: one pass of std::sort over plain
  // integers instead of a comparator over indirections.
  const auto& edges = family.edges();
  std::vector<std::pair<uint64_t, uint32_t>> edge_keys(edges.size());
  for (uint32_t e = 0; e < edges.size(); ++e) {
    const uint32_t a = std::min(edges[e][0], edges[e][1]), b = std::max(edges[e][0], edges[e][1]);
    edge_keys[e] = {(uint64_t{a} << 32) | b, e};
  }
  // Keys are unique, so the parallel sort's order is the one order (libstdc++'s parallel mode,
  // on the OpenMP threads the family library already uses).
  __gnu_parallel::sort(edge_keys.begin(), edge_keys.end());
  orders.edge_order.resize(edges.size());
  orders.edge_vertices.resize(2 * edges.size());
  for (size_t i = 0; i < edge_keys.size(); ++i) {
    orders.edge_order[i] = edge_keys[i].second;
    orders.edge_vertices[2 * i] = static_cast<uint32_t>(edge_keys[i].first >> 32);
    orders.edge_vertices[2 * i + 1] = static_cast<uint32_t>(edge_keys[i].first);
  }

  const auto& triangles = family.triangles();
  std::vector<std::pair<std::array<uint32_t, 3>, uint32_t>> triangle_keys(triangles.size());
  for (uint32_t t = 0; t < triangles.size(); ++t) {
    std::array<uint32_t, 3> key = triangles[t];
    std::sort(key.begin(), key.end());
    triangle_keys[t] = {key, t};
  }
  __gnu_parallel::sort(triangle_keys.begin(), triangle_keys.end());
  orders.triangle_order.resize(triangles.size());
  orders.triangle_vertices.resize(3 * triangles.size());
  for (size_t i = 0; i < triangle_keys.size(); ++i) {
    orders.triangle_order[i] = triangle_keys[i].second;
    for (size_t k = 0; k < 3; ++k) orders.triangle_vertices[3 * i + k] = triangle_keys[i].first[k];
  }
  return orders;
}

}  // namespace galpha
