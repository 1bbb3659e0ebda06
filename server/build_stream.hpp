// Decoding of a Build stream (a header, then point chunks) into a point set, with every limit of
// the service checked as the messages arrive: a bad stream is refused at the first bad message
// (with a decoding pool, what only decompression finds a message or a few later), before the rest
// is uploaded. Free of gRPC (only the protobuf messages), so the fuzz target and
// the unit tests drive it directly.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/base/host_vector.hpp"
#include "core/base/point.hpp"
#include "core/io/point_set_handle.hpp"
#include "galpha/v1/alpha_shapes.pb.h"
#include "proto/codec/point_chunk_codec.hpp"
#include "server/cached_family.hpp"
#include "server/chunk_codec_pool.hpp"

namespace galpha::server {

/// Bytes of points held by uploads and builds: against a server-wide limit, and against a limit per
/// tenant so that one tenant's uploads cannot take the whole budget from the others. Uploads
/// reserve as their bytes arrive (never what a header announces), so a stream that only announces
/// holds nothing. Thread-safe.
class InFlightBytes {
 public:
  /// `limit`: the server's (--max_in_flight_bytes); `tenant_limit`: each tenant's
  /// (--max_tenant_in_flight_bytes). 0: no such limit.
  explicit InFlightBytes(size_t limit, size_t tenant_limit = 0) : limit_(limit), tenant_limit_(tenant_limit) {}

  /// Holds `bytes` more for `tenant` until Release. ResourceExhausted naming the limit (tagged
  /// kInFlightBytes or kTenantInFlightBytes) when they do not fit now; nothing is held then.
  absl::Status Reserve(const std::string& tenant, size_t bytes);
  /// ResourceExhausted (tagged as Reserve's) when `bytes` exceed a limit even with nothing else
  /// held: such an upload can never fit, so it is refused at its header, before it is sent.
  absl::Status CheckCanEverFit(const std::string& tenant, size_t bytes) const;
  void Release(const std::string& tenant, size_t bytes);

  size_t held() const;
  size_t held_by(const std::string& tenant) const;
  size_t limit() const { return limit_; }
  size_t tenant_limit() const { return tenant_limit_; }

 private:
  const size_t limit_;
  const size_t tenant_limit_;
  mutable std::mutex mutex_;
  size_t held_ = 0;
  std::map<std::string, size_t> held_by_tenant_;  // only tenants holding bytes
};

/// Points of a header's announced count that the decoder allocates for at the first chunk (64 MiB
/// of address space, 96 weighted; more only as points arrive).
inline constexpr uint64_t kTrustedAnnouncedPoints = uint64_t{1} << 22;

/// Longest BuildHeader.name, in bytes: a label, not a payload (it is kept with the family and sent
/// back with every Build and Describe answer).
inline constexpr size_t kMaxBuildNameBytes = 256;

struct BuildStreamLimits {
  uint64_t max_points = 100'000'000;
};

/// A decoded stream: the header and the points, and the handle of the points.
struct DecodedBuild {
  galpha::v1::BuildHeader header;
  HostVector<Point2> points;  // not zeroed as it grows: every byte is then copied in
  /// A weighted stream's weights (header.weighted), one per point; empty otherwise.
  HostVector<double> weights;
  std::string handle;
  /// With a header CRS: the CRS and, for a geographic one, the points as sent (`points` then
  /// holds their local projection, which the handle hashes).
  std::shared_ptr<const CachedFamily::InputFrame> frame;
};

/// Applies `build`'s header CRS (header.crs non-empty): describes it and, for a geographic CRS,
/// replaces the points by their local projection, keeping the points as sent in `frame`.
/// InvalidArgument ("the header's crs: ...") for a CRS PROJ does not read or points it cannot take.
absl::Status FrameByCrs(DecodedBuild* build);

class BuildStreamDecoder {
 public:
  /// `in_flight` may be null (no limit on bytes in flight); it must outlive the decoder. `tenant`
  /// is whose bytes these are ("" without authentication: one anonymous tenant). With a
  /// `codec_pool` (which must outlive the decoder), encoded chunks are decompressed there while
  /// the stream goes on (see Add); without one, in Add.
  BuildStreamDecoder(const BuildStreamLimits& limits, InFlightBytes* in_flight, std::string tenant = "",
                     ChunkCodecPool* codec_pool = nullptr);
  /// Waits for the chunks still decoding, then releases the bytes this stream holds in
  /// `in_flight` (also after Finish: the builder keeps the decoder alive while it uses the points).
  ~BuildStreamDecoder();
  BuildStreamDecoder(const BuildStreamDecoder&) = delete;
  BuildStreamDecoder& operator=(const BuildStreamDecoder&) = delete;

  /// One message. InvalidArgument: a chunk before the header, a second header, a name longer than
  /// kMaxBuildNameBytes, a weighted header with a geographic crs, an odd number of coordinates
  /// (weighted: not a multiple of 3), NaN or infinity in a coordinate or a weight (naming the
  /// point's index in the whole stream), more points than the header announced, a malformed EncodedPointChunk (naming
  /// the chunk: wire::PointChunkDecoder::Decode). ResourceExhausted (tagged with its BuildRefusal):
  /// more points than the limit, more bytes in flight than the server's or the tenant's limit (a
  /// header announcing more than a limit could ever hold is refused at once). Every limit counts
  /// decoded points, 16 bytes each (24 weighted): an encoded chunk's stated count is checked and its decoded bytes
  /// reserved before it is decompressed.
  ///
  /// With a codec pool, an encoded chunk that passes those checks is decompressed on the pool
  /// (the message is kept until then), and what only its decoding finds (a malformed payload, a
  /// NaN) is answered by the next Add or by Finish: the stream is refused a message or a few later,
  /// with the error of the earliest chunk that failed, and its points are not taken back. Without
  /// one, a refused chunk adds nothing and holds nothing.
  absl::Status Add(galpha::v1::BuildRequest message);

  /// The end of the stream, once every chunk has decoded. InvalidArgument: no header (an empty
  /// stream), fewer points than the header announced, or a chunk whose decoding failed. The
  /// decoder keeps its reservation until destroyed.
  absl::StatusOr<DecodedBuild*> Finish();

  /// Points of the chunks accepted so far (with a decoding pool, some may still be decoding).
  uint64_t points_received() const { return decoded_.points.size(); }

  /// Frees the points (after the chunks still decoding into them) and gives back the bytes reserved
  /// for them (the builder calls this once the engine has copied them).
  void ReleasePoints();

 private:
  absl::Status Reserve(size_t bytes);
  // Bytes a decoded point holds: 16, or 24 with its weight.
  size_t PointBytes() const;
  // The point limits for a stream of `after` points: ResourceExhausted or InvalidArgument.
  absl::Status CheckPointCount(uint64_t after) const;
  // Add without the rule that a refusal names a failed earlier chunk first.
  absl::Status AddMessage(galpha::v1::BuildRequest message);
  // `count` more points at the end of decoded_.points, their bytes reserved first. When the
  // vectors must move, the chunks decoding into them finish first.
  absl::Status Grow(uint64_t count);
  // Queues the decoding of `message`'s encoded chunk into the points from `first` on.
  void DecodeOnPool(galpha::v1::BuildRequest message, const wire::ChunkPosition& at, uint64_t first);
  // Blocks until no chunk of this stream is decoding.
  void WaitForDecodes();
  // The error of the earliest chunk whose decoding failed (after the chunks still decoding), or OK.
  absl::Status DecodeFailure();

  const BuildStreamLimits limits_;
  InFlightBytes* const in_flight_;
  const std::string tenant_;
  size_t reserved_ = 0;
  bool has_header_ = false;
  bool finished_ = false;
  uint64_t chunks_ = 0;  // point chunks so far, raw and encoded (errors name encoded ones by index)
  DecodedBuild decoded_;
  wire::PointChunkDecoder chunk_decoder_;

  // Chunks on the pool: how many are still decoding, and the earliest that failed.
  ChunkCodecPool* const codec_pool_;
  std::mutex decodes_mutex_;
  std::condition_variable decodes_idle_;
  size_t decoding_ = 0;
  bool decode_failed_ = false;
  uint64_t failed_chunk_ = 0;
  absl::Status decode_failure_;
};

}  // namespace galpha::server
