#include "server/cached_family.hpp"

#include <algorithm>
#include <array>
#include <utility>

namespace galpha::server {

CachedFamily::CachedFamily(AlphaFamily family, std::string name, uint64_t /*input_points*/)
    : family_(std::move(family)), name_(std::move(name)) {
  bytes_ = sizeof(*this) + family_.HostBytes() + name_.capacity() +
           (family_.edges().size() + family_.triangles().size()) * sizeof(uint32_t);
}

const std::vector<uint32_t>& CachedFamily::EdgeOrder() const {
  std::call_once(orders_once_, [this] { ComputeOrders(); });
  return edge_order_;
}

const std::vector<uint32_t>& CachedFamily::TriangleOrder() const {
  std::call_once(orders_once_, [this] { ComputeOrders(); });
  return triangle_order_;
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
  for (size_t i = 0; i < edge_keys.size(); ++i) edge_order_[i] = edge_keys[i].second;

  const auto& triangles = family_.triangles();
  std::vector<std::pair<std::array<uint32_t, 3>, uint32_t>> tri_keys(triangles.size());
  for (uint32_t t = 0; t < triangles.size(); ++t) {
    std::array<uint32_t, 3> key = triangles[t];
    std::sort(key.begin(), key.end());
    tri_keys[t] = {key, t};
  }
  std::sort(tri_keys.begin(), tri_keys.end());
  triangle_order_.resize(triangles.size());
  for (size_t i = 0; i < tri_keys.size(); ++i) triangle_order_[i] = tri_keys[i].second;
}

}  // namespace galpha::server
