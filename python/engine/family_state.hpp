// A built family as galpha._engine holds it: the immutable AlphaFamily, the caller's label, and
// the canonical index orders the answers use (the service's Classify order: distinct vertices
// ascending, edges as ascending pairs and triangles as ascending triples, each sorted
// lexicographically). The orders are computed on first use, once, so that a build costs what the
// engine costs; afterwards NumPy arrays view them without copies (numpy_arrays.hpp).
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "core/family/alpha_family.hpp"

namespace galpha::python {

class FamilyState {
 public:
  FamilyState(AlphaFamily family, std::string name);

  const AlphaFamily& family() const { return family_; }
  /// The label given to the build (echoed in the summary, as a BuildResponse echoes its header's).
  const std::string& name() const { return name_; }
  /// Host memory charged for the family: its arrays plus the orders (charged up front, computed or
  /// not, as the service charges its cache, so that the figure never changes).
  size_t bytes() const { return bytes_; }

  /// The content handle of the family's points (core/io/point_set_handle.hpp; of the points and
  /// their weights for a weighted family), computed once.
  const std::string& Handle() const;

  /// Input indices of the distinct points (each first occurrence), ascending.
  const std::vector<uint32_t>& DistinctVertices() const;
  /// Edge ids sorted by their (smaller, larger) vertex pair; triangle ids by sorted vertex triple.
  const std::vector<uint32_t>& EdgeOrder() const;
  const std::vector<uint32_t>& TriangleOrder() const;
  /// The vertices of the edges (pairs) and triangles (ascending triples) in those orders, flat.
  const std::vector<uint32_t>& EdgeVerticesInOrder() const;
  const std::vector<uint32_t>& TriangleVerticesInOrder() const;

 private:
  void ComputeOrders() const;

  AlphaFamily family_;
  std::string name_;
  size_t bytes_ = 0;
  mutable std::once_flag handle_once_;
  mutable std::string handle_;
  mutable std::once_flag orders_once_;
  mutable std::vector<uint32_t> distinct_vertices_;
  mutable std::vector<uint32_t> edge_order_, triangle_order_;
  mutable std::vector<uint32_t> edge_vertices_, triangle_vertices_;
};

}  // namespace galpha::python
