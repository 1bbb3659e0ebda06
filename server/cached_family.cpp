#include "server/cached_family.hpp"

#include <iterator>
#include <utility>

#include "core/family/canonical_order.hpp"
#include "core/family/classification_summary.hpp"
#include "server/heap_trim.hpp"

namespace galpha::server {

namespace {

/// The index orders and ordered vertices (ComputeOrders) and the area terms, charged up front.
size_t OrderBytes(const FamilyReader& reader) {
  return reader.edges().size() * 3 * sizeof(uint32_t) +
         reader.triangles().size() * (4 * sizeof(uint32_t) + sizeof(double));
}

}  // namespace

CachedFamily::CachedFamily(AlphaFamily family, std::shared_ptr<const InputFrame> frame)
    : host_(std::make_shared<const AlphaFamily>(std::move(family))),
      reader_(std::make_unique<HostFamilyReader>(host_)),
      frame_(std::move(frame)) {
  bytes_ = sizeof(*this) + host_->HostBytes() + OrderBytes(*reader_);
  if (frame_ != nullptr) bytes_ += frame_->input.capacity() * sizeof(Point2);
}

CachedFamily::CachedFamily(ResidentAlphaFamily family, std::shared_ptr<const InputFrame> frame)
    : resident_(std::make_shared<const ResidentAlphaFamily>(std::move(family))),
      reader_(std::make_unique<ResidentFamilyReader>(resident_)),
      frame_(std::move(frame)) {
  bytes_ = sizeof(*this) + resident_->HostBytes() + OrderBytes(*reader_);
  // On the CPU backend the tables' "device" is this process's memory.
  if (resident_->TablesInDeviceMemory()) {
    device_bytes_ = resident_->ResidentBytes();
  } else {
    bytes_ += resident_->ResidentBytes();
  }
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

absl::StatusOr<std::shared_ptr<const Classification>> CachedFamily::SharedClassification(int64_t level,
                                                                                         ClassifyMode mode,
                                                                                         VertexRule rule) const {
  std::shared_ptr<PendingClassification> pending;
  {
    absl::MutexLock lock(&shared_mutex_);
    for (auto it = shared_classifications_.begin(); it != shared_classifications_.end();) {
      it = it->second.expired() ? shared_classifications_.erase(it) : std::next(it);
    }
    std::weak_ptr<PendingClassification>& slot = shared_classifications_[ClassificationKey{level, mode, rule}];
    pending = slot.lock();
    if (pending == nullptr) {
      pending = std::make_shared<PendingClassification>();
      slot = pending;
    }
  }
  std::call_once(pending->once, [&] { pending->classes = reader_->ClassifyAll(level, mode, rule); });
  if (!pending->classes.ok()) return pending->classes.status();
  // Shares the entry's life: the map's weak reference holds while any caller streams from it.
  return std::shared_ptr<const Classification>(pending, &*pending->classes);
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

const std::vector<double>& CachedFamily::TriangleAreaTerms() const {
  // Apart from the orders: a summary-only Classify needs the terms, not the orders.
  std::call_once(area_terms_once_,
                 [this] { triangle_area_terms_ = galpha::TriangleAreaTerms(reader_->points(), reader_->triangles()); });
  return triangle_area_terms_;
}

void CachedFamily::ComputeOrders() const {
  CanonicalOrders orders = ComputeCanonicalOrders(reader_->points().size(), reader_->edges(), reader_->triangles());
  edge_order_ = std::move(orders.edge_order);
  edge_vertices_ = std::move(orders.edge_vertices);
  triangle_order_ = std::move(orders.triangle_order);
  triangle_vertices_ = std::move(orders.triangle_vertices);
}

namespace {

std::shared_ptr<const CachedFamily> Shared(CachedFamily* family) {
  return std::shared_ptr<const CachedFamily>(family, [](const CachedFamily* f) {
    delete f;
    ReturnFreedHeapMemory();
  });
}

}  // namespace

std::shared_ptr<const CachedFamily> ShareCachedFamily(AlphaFamily family,
                                                      std::shared_ptr<const CachedFamily::InputFrame> frame) {
  return Shared(new CachedFamily(std::move(family), std::move(frame)));
}

std::shared_ptr<const CachedFamily> ShareCachedFamily(ResidentAlphaFamily family,
                                                      std::shared_ptr<const CachedFamily::InputFrame> frame) {
  return Shared(new CachedFamily(std::move(family), std::move(frame)));
}

absl::StatusOr<std::shared_ptr<const CachedFamily>> BuildCachedFamily(
    absl::Span<const Point2> points, absl::Span<const double> weights, bool weighted, BuildOptions options,
    bool resident, std::shared_ptr<const CachedFamily::InputFrame> frame) {
  if (resident) {
    options.cuda_stream = nullptr;
    absl::StatusOr<ResidentAlphaFamily> family = weighted ? BuildWeightedResidentAlphaFamily(points, weights, options)
                                                          : BuildResidentAlphaFamily(points, options);
    if (!family.ok()) return family.status();
    return ShareCachedFamily(*std::move(family), std::move(frame));
  }
  absl::StatusOr<AlphaFamily> family =
      weighted ? BuildWeightedAlphaFamily(points, weights, options) : BuildAlphaFamily(points, options);
  if (!family.ok()) return family.status();
  return ShareCachedFamily(*std::move(family), std::move(frame));
}

}  // namespace galpha::server
