#include "server/compact_family.hpp"

namespace galpha::server {

CompactFamily::CompactFamily(const CachedFamily& cached)
    : points_(cached.reader().points().begin(), cached.reader().points().end()),
      weights_(cached.reader().weights().begin(), cached.reader().weights().end()),
      frame_(cached.Frame()) {
  bytes_ = sizeof(*this) + points_.capacity() * sizeof(Point2) + weights_.capacity() * sizeof(double);
  // The frame may also be held by a resident copy that a query still streams from; it is
  // charged here all the same, since it stays for as long as this entry does.
  if (frame_ != nullptr) bytes_ += sizeof(*frame_) + frame_->input.capacity() * sizeof(Point2);
}

}  // namespace galpha::server
