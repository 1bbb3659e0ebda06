// The compact tier's form of a cached family: the points it was built from (with their weights,
// for a weighted family) and where they came from, and nothing else. The engine is deterministic
// (the CUDA and CPU backends give the same family bit for bit), so a rebuild from these points is
// the family that was demoted, and holding 16 bytes a point (24 weighted, 32 with a geographic
// input frame) instead of the ~400 a whole family takes is what lets a server keep many times
// more families reachable than it keeps built.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "core/base/point.hpp"
#include "server/cached_family.hpp"

namespace galpha::server {

class CompactFamily {
 public:
  /// Copies `cached`'s points (and weights) and keeps its input frame (shared: it is immutable).
  explicit CompactFamily(const CachedFamily& cached);

  /// The points the family was built from, in input order (duplicates included).
  const std::vector<Point2>& points() const { return points_; }
  /// A weighted family's weights, one per point; empty for an unweighted family.
  const std::vector<double>& weights() const { return weights_; }
  /// The input frame attached to the family when it was demoted (null when none).
  const std::shared_ptr<const CachedFamily::InputFrame>& frame() const { return frame_; }
  /// Bytes charged to the compact tier: the points, the weights, the frame's input points and this
  /// object.
  size_t bytes() const { return bytes_; }

 private:
  std::vector<Point2> points_;
  std::vector<double> weights_;
  std::shared_ptr<const CachedFamily::InputFrame> frame_;
  size_t bytes_ = 0;
};

}  // namespace galpha::server
