#include "server/cached_family.hpp"

#include <algorithm>
#include <array>
#include <utility>

namespace galpha::server {

CachedFamily::CachedFamily(AlphaFamily family) : family_(std::move(family)) {
  bytes_ = sizeof(*this) + family_.HostBytes() + family_.edges().size() * 3 * sizeof(uint32_t) +
           family_.triangles().size() * 4 * sizeof(uint32_t);
}

const std::vector<uint32_t>& CachedFamily::EdgeOrder() const {
  std::call_once(orders_once_, [this] { ComputeOrders(); });
  return edge_order_;
}

const std::vector<uint32_t>& CachedFamily::TriangleOrder() const {
  std::call_once(orders_once_, [this] { ComputeOrders(); });
  return triangle_order_;
}

const std::vector<uint32_t>& CachedFamily::EdgeVerticesInOrder() const {
  std::call_once(orders_once_, [this] { ComputeOrders(); });
  return edge_vertices_;
}

const std::vector<uint32_t>& CachedFamily::TriangleVerticesInOrder() const {
  std::call_once(orders_once_, [this] { ComputeOrders(); });
  return triangle_vertices_;
}

void CachedFamily::ComputeOrders() const {
  // Sort 64-bit keys with the id in the low bits where they fit: one pass of std::sort over plain
  // integers instead of a comparator over indirections.
  const auto& edges = family_.edges();
  std::vector<std::pair<uint64_t, uint32_t>> edge_keys(edges.size());
  for (uint32_t e = 0; e < edges.size(); ++e) {
    edge_keys[e] = {(uint64_t{std::min(edges[e][0], edges[e][1])} << 32) | std::max(edges[e][0], edges[e][1]), e};
  }
  std::sort(edge_keys.begin(), edge_keys.end());
  edge_order_.resize(edges.size());
  edge_vertices_.resize(2 * edges.size());
  for (size_t i = 0; i < edge_keys.size(); ++i) {
    edge_order_[i] = edge_keys[i].second;
    edge_vertices_[2 * i] = static_cast<uint32_t>(edge_keys[i].first >> 32);
    edge_vertices_[2 * i + 1] = static_cast<uint32_t>(edge_keys[i].first);
  }

  const auto& triangles = family_.triangles();
  std::vector<std::pair<std::array<uint32_t, 3>, uint32_t>> tri_keys(triangles.size());
  for (uint32_t t = 0; t < triangles.size(); ++t) {
    std::array<uint32_t, 3> key = triangles[t];
    std::sort(key.begin(), key.end());
    tri_keys[t] = {key, t};
  }
  std::sort(tri_keys.begin(), tri_keys.end());
  triangle_order_.resize(triangles.size());
  triangle_vertices_.resize(3 * triangles.size());
  for (size_t i = 0; i < tri_keys.size(); ++i) {
    triangle_order_[i] = tri_keys[i].second;
    for (size_t k = 0; k < 3; ++k) triangle_vertices_[3 * i + k] = tri_keys[i].first[k];
  }
}

}  // namespace galpha::server
