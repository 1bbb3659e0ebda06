// A family as the service holds it: the immutable AlphaFamily, the build summary a Describe returns,
// and the index orders Classify streams in (computed on first use, once).
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/alpha_family.hpp"

namespace galpha::server {

class CachedFamily {
 public:
  CachedFamily(AlphaFamily family, std::string name, uint64_t input_points);

  const AlphaFamily& family() const { return family_; }
  const std::string& name() const { return name_; }
  /// Bytes charged to the cache: the family, plus the index orders once computed (reserved up
  /// front so that the charge never changes while cached).
  size_t bytes() const { return bytes_; }

  /// Edge ids sorted by their (smaller, larger) vertex pair; triangle ids by sorted vertex triple.
  const std::vector<uint32_t>& EdgeOrder() const;
  const std::vector<uint32_t>& TriangleOrder() const;

 private:
  void ComputeOrders() const;

  AlphaFamily family_;
  std::string name_;
  size_t bytes_ = 0;
  mutable std::once_flag orders_once_;
  mutable std::vector<uint32_t> edge_order_, triangle_order_;
};

}  // namespace galpha::server
