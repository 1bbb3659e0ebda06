#include "server/cached_family.hpp"

#include <malloc.h>

#include <utility>

#include "core/family/canonical_order.hpp"

namespace galpha::server {

CachedFamily::CachedFamily(AlphaFamily family, std::shared_ptr<const InputFrame> frame)
    : family_(std::move(family)), frame_(std::move(frame)) {
  bytes_ = sizeof(*this) + family_.HostBytes() + family_.edges().size() * 3 * sizeof(uint32_t) +
           family_.triangles().size() * 4 * sizeof(uint32_t);
  if (frame_ != nullptr) bytes_ += frame_->input.capacity() * sizeof(Point2);
}

std::shared_ptr<const CachedFamily::InputFrame> CachedFamily::Frame() const {
  absl::MutexLock lock(&frame_mutex_);
  return frame_;
}

void CachedFamily::AttachFrameIfNone(std::shared_ptr<const InputFrame> frame) const {
  absl::MutexLock lock(&frame_mutex_);
  if (frame_ == nullptr) frame_ = std::move(frame);
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
  CanonicalOrders orders = ComputeCanonicalOrders(family_);
  edge_order_ = std::move(orders.edge_order);
  edge_vertices_ = std::move(orders.edge_vertices);
  triangle_order_ = std::move(orders.triangle_order);
  triangle_vertices_ = std::move(orders.triangle_vertices);
}

void ReturnFreedHeapMemory() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

std::shared_ptr<const CachedFamily> ShareCachedFamily(AlphaFamily family,
                                                      std::shared_ptr<const CachedFamily::InputFrame> frame) {
  return std::shared_ptr<const CachedFamily>(new CachedFamily(std::move(family), std::move(frame)),
                                             [](const CachedFamily* f) {
                                               delete f;
                                               ReturnFreedHeapMemory();
                                             });
}

}  // namespace galpha::server
