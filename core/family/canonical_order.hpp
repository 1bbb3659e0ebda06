// The canonical order in which answers list a family's edges and triangles (the service's
// Classify order, alphactl's and the Python package's): edges by their (smaller, larger) vertex
// pair, triangles by their ascending vertex triple, both lexicographically. One computation for
// every front end, so that they cannot drift apart.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "core/family/alpha_family.hpp"

namespace galpha {

struct CanonicalOrders {
  /// Edge ids in canonical order, and their vertex pairs in that order, flat (2 per edge).
  std::vector<uint32_t> edge_order, edge_vertices;
  /// Triangle ids in canonical order, and their ascending vertex triples in that order, flat.
  std::vector<uint32_t> triangle_order, triangle_vertices;
};

/// How answers name a simplex: its vertices ascending.
inline std::array<uint32_t, 2> SortedEdge(const std::array<uint32_t, 2>& e) {
  return {std::min(e[0], e[1]), std::max(e[0], e[1])};
}
inline std::array<uint32_t, 3> SortedTriangle(std::array<uint32_t, 3> t) {
  std::sort(t.begin(), t.end());
  return t;
}

/// Linear passes on every core (a radix sort: core/family/radix_sort.hpp); the orders depend only
/// on the triangulation, so callers compute them once.
CanonicalOrders ComputeCanonicalOrders(const AlphaFamily& family);
/// The same from the mesh alone (a resident family's, whose mesh is on the host).
CanonicalOrders ComputeCanonicalOrders(size_t num_points, const HostVector<std::array<uint32_t, 2>>& edges,
                                       const HostVector<std::array<uint32_t, 3>>& triangles);

}  // namespace galpha
