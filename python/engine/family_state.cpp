#include "python/engine/family_state.hpp"

#include <algorithm>
#include <array>
#include <utility>

#include "core/io/point_set_handle.hpp"

namespace galpha::python {

FamilyState::FamilyState(AlphaFamily family, std::string name) : family_(std::move(family)), name_(std::move(name)) {
  const size_t e = family_.edges().size(), t = family_.triangles().size();
  bytes_ = sizeof(*this) + family_.HostBytes() + (3 * e + 4 * t + size_t{family_.num_unique()}) * sizeof(uint32_t);
}

const std::string& FamilyState::Handle() const {
  std::call_once(handle_once_, [this] { handle_ = PointSetHandle(family_.points()); });
  return handle_;
}

const std::vector<uint32_t>& FamilyState::DistinctVertices() const {
  std::call_once(orders_once_, [this] { ComputeOrders(); });
  return distinct_vertices_;
}

const std::vector<uint32_t>& FamilyState::EdgeOrder() const {
  std::call_once(orders_once_, [this] { ComputeOrders(); });
  return edge_order_;
}

const std::vector<uint32_t>& FamilyState::TriangleOrder() const {
  std::call_once(orders_once_, [this] { ComputeOrders(); });
  return triangle_order_;
}

const std::vector<uint32_t>& FamilyState::EdgeVerticesInOrder() const {
  std::call_once(orders_once_, [this] { ComputeOrders(); });
  return edge_vertices_;
}

const std::vector<uint32_t>& FamilyState::TriangleVerticesInOrder() const {
  std::call_once(orders_once_, [this] { ComputeOrders(); });
  return triangle_vertices_;
}

void FamilyState::ComputeOrders() const {
  // A duplicate's representative is its first occurrence: the distinct points are those that
  // represent themselves, already ascending.
  const auto& representative = family_.representative();
  distinct_vertices_.reserve(family_.num_unique());
  for (uint32_t v = 0; v < representative.size(); ++v) {
    if (representative[v] == v) distinct_vertices_.push_back(v);
  }

  // 64-bit keys (smaller << 32 | larger) sort as the pairs do, in one pass over plain integers.
  const auto& edges = family_.edges();
  std::vector<std::pair<uint64_t, uint32_t>> edge_keys(edges.size());
  for (uint32_t e = 0; e < edges.size(); ++e) {
    const uint32_t a = std::min(edges[e][0], edges[e][1]), b = std::max(edges[e][0], edges[e][1]);
    edge_keys[e] = {(uint64_t{a} << 32) | b, e};
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
  std::vector<std::pair<std::array<uint32_t, 3>, uint32_t>> triangle_keys(triangles.size());
  for (uint32_t t = 0; t < triangles.size(); ++t) {
    std::array<uint32_t, 3> key = triangles[t];
    std::sort(key.begin(), key.end());
    triangle_keys[t] = {key, t};
  }
  std::sort(triangle_keys.begin(), triangle_keys.end());
  triangle_order_.resize(triangles.size());
  triangle_vertices_.resize(3 * triangles.size());
  for (size_t i = 0; i < triangle_keys.size(); ++i) {
    triangle_order_[i] = triangle_keys[i].second;
    for (size_t k = 0; k < 3; ++k) triangle_vertices_[3 * i + k] = triangle_keys[i].first[k];
  }
}

}  // namespace galpha::python
