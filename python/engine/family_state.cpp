#include "python/engine/family_state.hpp"

#include <utility>

#include "core/family/canonical_order.hpp"
#include "core/io/point_set_handle.hpp"

namespace galpha::python {

FamilyState::FamilyState(AlphaFamily family, std::string name) : family_(std::move(family)), name_(std::move(name)) {
  const size_t e = family_.edges().size(), t = family_.triangles().size();
  bytes_ = sizeof(*this) + family_.HostBytes() + (3 * e + 4 * t + size_t{family_.num_unique()}) * sizeof(uint32_t);
}

const std::string& FamilyState::Handle() const {
  std::call_once(handle_once_, [this] {
    handle_ = family_.weighted() ? WeightedPointSetHandle(family_.points(), family_.weights())
                                 : PointSetHandle(family_.points());
  });
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

  CanonicalOrders orders = ComputeCanonicalOrders(family_);
  edge_order_ = std::move(orders.edge_order);
  edge_vertices_ = std::move(orders.edge_vertices);
  triangle_order_ = std::move(orders.triangle_order);
  triangle_vertices_ = std::move(orders.triangle_vertices);
}

}  // namespace galpha::python
