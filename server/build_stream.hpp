// Decoding of a Build stream (a header, then point chunks) into a point set, with every limit of
// the service checked as the messages arrive: a bad stream is refused at the first bad message,
// before the rest is uploaded. Free of gRPC (only the protobuf messages), so the fuzz target and
// the unit tests drive it directly.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/base/host_vector.hpp"
#include "core/base/point.hpp"
#include "core/io/point_set_handle.hpp"
#include "galpha/v1/alpha_shapes.pb.h"

namespace galpha::server {

/// Bytes of points held by uploads and builds across the whole server, against a limit.
class InFlightBytes {
 public:
  explicit InFlightBytes(size_t limit) : limit_(limit) {}
  /// Whether `bytes` more fit; if so they are held until Release.
  bool TryReserve(size_t bytes);
  void Release(size_t bytes) { held_.fetch_sub(bytes); }
  size_t held() const { return held_.load(); }
  size_t limit() const { return limit_; }

 private:
  const size_t limit_;
  std::atomic<size_t> held_{0};
};

struct BuildStreamLimits {
  uint64_t max_points = 100'000'000;
};

/// A decoded stream: the header and the points, and the handle of the points.
struct DecodedBuild {
  galpha::v1::BuildHeader header;
  HostVector<Point2> points;  // not zeroed as it grows: every byte is then copied in
  std::string handle;
};

class BuildStreamDecoder {
 public:
  /// `in_flight` may be null (no server-wide limit); it must outlive the decoder.
  BuildStreamDecoder(const BuildStreamLimits& limits, InFlightBytes* in_flight);
  /// Releases the bytes this stream holds in `in_flight` (also after Finish: the builder keeps
  /// the decoder alive while it uses the points).
  ~BuildStreamDecoder();
  BuildStreamDecoder(const BuildStreamDecoder&) = delete;
  BuildStreamDecoder& operator=(const BuildStreamDecoder&) = delete;

  /// One message. InvalidArgument: a chunk before the header, a second header, an odd number of
  /// coordinates, NaN or infinity (naming the point's index in the whole stream), more points
  /// than the header announced. ResourceExhausted: more points than the limit, or more bytes in
  /// flight on the server than its limit.
  absl::Status Add(const galpha::v1::BuildRequest& message);

  /// The end of the stream. InvalidArgument: no header (an empty stream), or fewer points than
  /// the header announced. The decoder keeps its reservation until destroyed.
  absl::StatusOr<DecodedBuild*> Finish();

  uint64_t points_received() const { return decoded_.points.size(); }

  /// Frees the points and gives back the bytes reserved for them (the builder calls this once the
  /// engine has copied them).
  void ReleasePoints();

 private:
  absl::Status Reserve(size_t bytes);

  const BuildStreamLimits limits_;
  InFlightBytes* const in_flight_;
  size_t reserved_ = 0;
  bool has_header_ = false;
  bool finished_ = false;
  DecodedBuild decoded_;
};

}  // namespace galpha::server
