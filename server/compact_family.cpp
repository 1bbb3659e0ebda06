#include "server/compact_family.hpp"

namespace galpha::server {

CompactFamily::CompactFamily(const CachedFamily& cached)
    : points_(cached.family().points().begin(), cached.family().points().end()),
      weights_(cached.family().weights().begin(), cached.family().weights().end()),
      frame_(cached.Frame()) {
  bytes_ = sizeof(*this) + points_.capacity() * sizeof(Point2) + weights_.capacity() * sizeof(double);
  // The frame may also be held by a resident copy that a query still streams from; it is
  // charged here all the same, since it stays for as long as this entry does.
  if (frame_ != nullptr) bytes_ += sizeof(*frame_) + frame_->input.capacity() * sizeof(Point2);
}

}  // namespace galpha::server
