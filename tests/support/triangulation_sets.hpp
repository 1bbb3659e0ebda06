// A triangulation's triangles and edges as sorted sets, for comparing two triangulations of one
// point set whatever order their arrays are in (header only; delaunay_test, regular_test).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "gpu/triangulation/delaunay.hpp"

namespace galpha::testing {

/// Triangles rotated to start at their smallest index (keeping the counter-clockwise order),
/// sorted: equal for two triangulations exactly when they have the same triangles.
inline std::vector<std::array<uint32_t, 3>> CanonicalTriangles(const Triangulation& t) {
  std::vector<std::array<uint32_t, 3>> out;
  out.reserve(t.triangles.size());
  for (std::array<uint32_t, 3> v : t.triangles) {
    std::rotate(v.begin(), std::min_element(v.begin(), v.end()), v.end());
    out.push_back(v);
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// The edges, sorted.
inline std::vector<std::array<uint32_t, 2>> SortedEdges(const Triangulation& t) {
  std::vector<std::array<uint32_t, 2>> edges = t.edges;
  std::sort(edges.begin(), edges.end());
  return edges;
}

}  // namespace galpha::testing
