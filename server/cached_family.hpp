// A family as the service holds it: the immutable AlphaFamily (whose report is the build summary a
// Describe returns) and the index orders Classify streams in (computed on first use, once). No
// name: a BuildHeader.name is the label of one Build call, echoed in that call's answer only
// (proto: BuildHeader), so the family that any caller of the tenant may reach keeps none.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/family/alpha_family.hpp"

namespace galpha::server {

class CachedFamily {
 public:
  explicit CachedFamily(AlphaFamily family);

  const AlphaFamily& family() const { return family_; }
  /// Bytes charged to the cache: the family, plus the index orders and ordered vertices once
  /// computed (charged up front so that the charge never changes while cached).
  size_t bytes() const { return bytes_; }

  /// Edge ids sorted by their (smaller, larger) vertex pair; triangle ids by sorted vertex triple.
  const std::vector<uint32_t>& EdgeOrder() const;
  const std::vector<uint32_t>& TriangleOrder() const;
  /// The vertices of the edges (pairs) and triangles (ascending triples) in those orders, flat: so
  /// that Classify copies index runs instead of gathering them one simplex at a time.
  const std::vector<uint32_t>& EdgeVerticesInOrder() const;
  const std::vector<uint32_t>& TriangleVerticesInOrder() const;

 private:
  void ComputeOrders() const;

  AlphaFamily family_;
  size_t bytes_ = 0;
  mutable std::once_flag orders_once_;
  mutable std::vector<uint32_t> edge_order_, triangle_order_;
  mutable std::vector<uint32_t> edge_vertices_, triangle_vertices_;
};

}  // namespace galpha::server
