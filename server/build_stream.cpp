#include "server/build_stream.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/io/coordinate_system.hpp"
#include "server/build_refusal.hpp"

namespace galpha::server {

namespace {

std::string TenantName(const std::string& tenant) {
  return tenant.empty() ? std::string("the anonymous tenant") : absl::StrCat("tenant '", tenant, "'");
}

}  // namespace

absl::Status InFlightBytes::Reserve(const std::string& tenant, size_t bytes) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (limit_ != 0 && held_ + bytes > limit_) {
    return TagRefusal(absl::ResourceExhaustedError(absl::StrCat(
                          "the server holds ", held_, " bytes of points in flight; ", bytes,
                          " more would exceed its limit of ", limit_, " bytes (--max_in_flight_bytes): retry later")),
                      BuildRefusal::kInFlightBytes);
  }
  const auto it = held_by_tenant_.find(tenant);
  const size_t tenant_held = it == held_by_tenant_.end() ? 0 : it->second;
  if (tenant_limit_ != 0 && tenant_held + bytes > tenant_limit_) {
    return TagRefusal(absl::ResourceExhaustedError(absl::StrCat(
                          TenantName(tenant), " holds ", tenant_held, " bytes of points in flight; ", bytes,
                          " more would exceed its limit of ", tenant_limit_,
                          " bytes (--max_tenant_in_flight_bytes): finish or cancel its other uploads, or retry later")),
                      BuildRefusal::kTenantInFlightBytes);
  }
  held_ += bytes;
  if (bytes > 0) held_by_tenant_[tenant] = tenant_held + bytes;
  return absl::OkStatus();
}

absl::Status InFlightBytes::CheckCanEverFit(const std::string& tenant, size_t bytes) const {
  if (limit_ != 0 && bytes > limit_) {
    return TagRefusal(absl::ResourceExhaustedError(absl::StrCat("the header announces ", bytes,
                                                                " bytes of points; the server holds at most ", limit_,
                                                                " bytes of points in flight (--max_in_flight_bytes)")),
                      BuildRefusal::kInFlightBytes);
  }
  if (tenant_limit_ != 0 && bytes > tenant_limit_) {
    return TagRefusal(absl::ResourceExhaustedError(absl::StrCat("the header announces ", bytes, " bytes of points; ",
                                                                TenantName(tenant), " may hold at most ", tenant_limit_,
                                                                " bytes in flight (--max_tenant_in_flight_bytes)")),
                      BuildRefusal::kTenantInFlightBytes);
  }
  return absl::OkStatus();
}

void InFlightBytes::Release(const std::string& tenant, size_t bytes) {
  if (bytes == 0) return;
  std::lock_guard<std::mutex> lock(mutex_);
  held_ -= bytes;
  const auto it = held_by_tenant_.find(tenant);
  if (it == held_by_tenant_.end()) return;
  it->second -= bytes;
  if (it->second == 0) held_by_tenant_.erase(it);  // the map holds active tenants only
}

size_t InFlightBytes::held() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return held_;
}

size_t InFlightBytes::held_by(const std::string& tenant) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = held_by_tenant_.find(tenant);
  return it == held_by_tenant_.end() ? 0 : it->second;
}

BuildStreamDecoder::BuildStreamDecoder(const BuildStreamLimits& limits, InFlightBytes* in_flight, std::string tenant,
                                       ChunkCodecPool* codec_pool)
    : limits_(limits), in_flight_(in_flight), tenant_(std::move(tenant)), codec_pool_(codec_pool) {}

BuildStreamDecoder::~BuildStreamDecoder() {
  WaitForDecodes();  // their tasks write into decoded_ and report here
  if (in_flight_ != nullptr && reserved_ > 0) in_flight_->Release(tenant_, reserved_);
}

void BuildStreamDecoder::WaitForDecodes() {
  std::unique_lock<std::mutex> lock(decodes_mutex_);
  decodes_idle_.wait(lock, [&] { return decoding_ == 0; });
}

absl::Status BuildStreamDecoder::DecodeFailure() {
  std::unique_lock<std::mutex> lock(decodes_mutex_);
  if (!decode_failed_) return absl::OkStatus();
  // An earlier chunk may still be decoding and fail too: the answer is the earliest failure's, so
  // that it does not depend on the order in which the pool's threads finished.
  decodes_idle_.wait(lock, [&] { return decoding_ == 0; });
  return decode_failure_;
}

void BuildStreamDecoder::DecodeOnPool(galpha::v1::BuildRequest message, const wire::ChunkPosition& at, uint64_t first) {
  Point2* points = &decoded_.points[first];
  double* weights = decoded_.header.weighted() ? &decoded_.weights[first] : nullptr;
  // std::function needs a copyable task: the message travels in a shared_ptr.
  auto owned = std::make_shared<galpha::v1::BuildRequest>(std::move(message));
  {
    // Back-pressure: a stream has at most this many chunks waiting or decoding, so its encoded
    // payloads (not counted in the in-flight bytes) stay bounded and one stream cannot fill the
    // pool's queue ahead of the others; past it the reactor waits, and gRPC's flow control slows
    // the client, as when the reactor decoded each chunk itself.
    std::unique_lock<std::mutex> lock(decodes_mutex_);
    decodes_idle_.wait(lock, [&] { return decoding_ < 2 * codec_pool_->threads(); });
    ++decoding_;
  }
  const auto task = [this, owned, at, points, weights](ChunkCodecs& codecs) {
    wire::PointChunkDecoder& decoder = codecs.point_decoder;
    absl::Status decoded;
    try {
      const galpha::v1::EncodedPointChunk& chunk = owned->encoded_points();
      decoded =
          weights != nullptr ? decoder.DecodeWeighted(chunk, at, points, weights) : decoder.Decode(chunk, at, points);
    } catch (const std::bad_alloc&) {
      decoded =
          absl::ResourceExhaustedError(absl::StrCat("encoded point chunk ", at.chunk_index, " (from point ",
                                                    at.first_point, "): the server ran out of memory decoding it"));
    }
    std::lock_guard<std::mutex> lock(decodes_mutex_);
    if (!decoded.ok() && (!decode_failed_ || at.chunk_index < failed_chunk_)) {
      decode_failed_ = true;
      failed_chunk_ = at.chunk_index;
      decode_failure_ = std::move(decoded);
    }
    --decoding_;
    decodes_idle_.notify_all();  // WaitForDecodes waits for none, the back-pressure for fewer
  };
  try {
    codec_pool_->Submit(task);
  } catch (...) {
    std::lock_guard<std::mutex> lock(decodes_mutex_);
    --decoding_;
    decodes_idle_.notify_all();
    throw;
  }
}

void BuildStreamDecoder::ReleasePoints() {
  WaitForDecodes();
  HostVector<Point2>().swap(decoded_.points);
  HostVector<double>().swap(decoded_.weights);
  if (in_flight_ != nullptr && reserved_ > 0) in_flight_->Release(tenant_, reserved_);
  reserved_ = 0;
}

absl::Status BuildStreamDecoder::Reserve(size_t bytes) {
  if (in_flight_ == nullptr || bytes == 0) return absl::OkStatus();
  if (absl::Status s = in_flight_->Reserve(tenant_, bytes); !s.ok()) return s;
  reserved_ += bytes;
  return absl::OkStatus();
}

absl::Status BuildStreamDecoder::CheckPointCount(uint64_t after) const {
  if (after > limits_.max_points) {
    return TagRefusal(absl::ResourceExhaustedError(absl::StrCat("the stream carries more than ", limits_.max_points,
                                                                " points, this server's limit per build "
                                                                "(--max_points_per_build)")),
                      BuildRefusal::kPointsPerBuild);
  }
  const uint64_t expected = decoded_.header.expected_points();
  if (expected > 0 && after > expected) {
    return absl::InvalidArgumentError(
        absl::StrCat("the stream carries more points than the ", expected, " its header announced"));
  }
  return absl::OkStatus();
}

size_t BuildStreamDecoder::PointBytes() const {
  return decoded_.header.weighted() ? sizeof(Point2) + sizeof(double) : sizeof(Point2);
}

absl::Status BuildStreamDecoder::Grow(uint64_t count) {
  if (absl::Status s = Reserve(count * PointBytes()); !s.ok()) return s;
  const size_t after = decoded_.points.size() + count;
  if (after > decoded_.points.capacity() || (decoded_.header.weighted() && after > decoded_.weights.capacity())) {
    WaitForDecodes();  // the pool writes into the vectors that are about to move
    // Capacity grows with the bytes that arrived (doubling, as a vector does, but never past an
    // announced count), not with the announcement: an announced 100M points would otherwise
    // map 1.6 GB per stream before a single point arrives. Once points arrive, an announcement
    // is trusted up to kTrustedAnnouncedPoints: the vectors of a stream of up to that many points
    // then never move (each move waits for the chunks decoding into them and copies what arrived:
    // four moves were ~10 ms of a 1M-point upload), and an inflated announcement costs at most
    // that much address space (64 MiB, 96 weighted). The vectors are not zeroed, so only pages
    // the points fill become resident: what arrived, rounded up to a 2 MiB huge page (HostVector
    // asks for huge pages from 8 MiB on).
    const uint64_t expected = decoded_.header.expected_points();
    size_t capacity = std::max<size_t>(after, 2 * decoded_.points.capacity());
    if (expected > 0) {
      capacity = std::max<size_t>(capacity, std::min<uint64_t>(expected, kTrustedAnnouncedPoints));
      capacity = std::min<size_t>(capacity, expected);
    }
    decoded_.points.reserve(capacity);
    if (decoded_.header.weighted()) decoded_.weights.reserve(capacity);
  }
  decoded_.points.resize(after);
  if (decoded_.header.weighted()) decoded_.weights.resize(after);
  return absl::OkStatus();
}

absl::Status BuildStreamDecoder::Add(galpha::v1::BuildRequest message) {
  absl::Status added = AddMessage(std::move(message));
  if (added.ok() || codec_pool_ == nullptr) return added;
  // A chunk still decoding may fail too, and it came before this message: its error is the answer,
  // as it would be without a pool.
  WaitForDecodes();
  if (absl::Status failed = DecodeFailure(); !failed.ok()) return failed;
  return added;
}

absl::Status BuildStreamDecoder::AddMessage(galpha::v1::BuildRequest message) {
  if (finished_) return absl::FailedPreconditionError("the build stream already ended");
  if (absl::Status failed = DecodeFailure(); !failed.ok()) return failed;
  switch (message.part_case()) {
    case galpha::v1::BuildRequest::kHeader: {
      if (has_header_) return absl::InvalidArgumentError("the build stream has a second header");
      has_header_ = true;
      decoded_.header = message.header();
      if (decoded_.header.name().size() > kMaxBuildNameBytes) {
        return absl::InvalidArgumentError(absl::StrCat("the header's name is ", decoded_.header.name().size(),
                                                       " bytes long; a name is at most ", kMaxBuildNameBytes,
                                                       " bytes"));
      }
      const uint64_t expected = decoded_.header.expected_points();
      if (expected > limits_.max_points) {
        return TagRefusal(absl::ResourceExhaustedError(
                              absl::StrCat("the header announces ", expected, " points; this server builds at most ",
                                           limits_.max_points, " points (--max_points_per_build)")),
                          BuildRefusal::kPointsPerBuild);
      }
      // A CRS PROJ does not read is refused before the upload (Finish applies it to the points).
      if (!decoded_.header.crs().empty()) {
        absl::StatusOr<CrsInfo> crs = DescribeCrs(decoded_.header.crs());
        if (!crs.ok()) return absl::InvalidArgumentError(absl::StrCat("the header's crs: ", crs.status().message()));
        // A weight is a squared length in the units of the coordinates: degrees are none, and the
        // local projection would change distances without changing the weights.
        if (decoded_.header.weighted() && crs->geographic) {
          return absl::InvalidArgumentError(
              absl::StrCat("the header is weighted and its crs (", crs->name,
                           ") is geographic: weights need planar coordinates (project the centres and radii first)"));
        }
      }
      // Nothing is reserved for an announced size (a stream that only announces would hold the
      // budget for nothing): only a size that no limit could ever hold is refused now.
      if (in_flight_ == nullptr) return absl::OkStatus();
      const uint64_t most = std::numeric_limits<uint64_t>::max();
      return in_flight_->CheckCanEverFit(tenant_, expected > most / PointBytes() ? most : expected * PointBytes());
    }
    case galpha::v1::BuildRequest::kPoints: {
      if (!has_header_) return absl::InvalidArgumentError("the build stream must start with a header");
      const auto& coordinates = message.points().coordinates();
      const size_t count = static_cast<size_t>(coordinates.size());
      const uint64_t before = decoded_.points.size();
      const bool weighted = decoded_.header.weighted();
      const size_t axes = weighted ? 3 : 2;  // doubles a point
      ++chunks_;
      if (!weighted && count % 2 != 0) {
        return absl::InvalidArgumentError(absl::StrCat("a point chunk holds an odd number of doubles (", count,
                                                       ") after point ", before, ": send x, y pairs"));
      }
      if (weighted && count % 3 != 0) {
        return absl::InvalidArgumentError(absl::StrCat("a point chunk holds ", count,
                                                       " doubles, not a multiple of 3, after point ", before,
                                                       ": the header is weighted, send x, y, w triples"));
      }
      if (absl::Status s = CheckPointCount(before + count / axes); !s.ok()) return s;
      // One branch-free pass over the chunk (it vectorises); the index only when one is bad.
      const double* values = coordinates.data();
      bool all_finite = true;
      for (size_t i = 0; i < count; ++i) all_finite &= std::isfinite(values[i]);
      if (!all_finite) {
        size_t i = 0;
        while (std::isfinite(values[i])) ++i;
        const size_t axis = i % axes;
        return absl::InvalidArgumentError(absl::StrCat("point ", before + i / axes, " has a ",
                                                       std::isnan(values[i]) ? "NaN" : "infinite",
                                                       axis == 2   ? " weight"
                                                       : axis == 0 ? " x coordinate"
                                                                   : " y coordinate"));
      }
      if (absl::Status s = Grow(count / axes); !s.ok()) return s;
      if (!weighted) {
        if (count > 0) std::memcpy(&decoded_.points[before], coordinates.data(), count * sizeof(double));
        return absl::OkStatus();
      }
      for (size_t i = 0; i < count / 3; ++i) {
        decoded_.points[before + i] = Point2{values[3 * i], values[3 * i + 1]};
        decoded_.weights[before + i] = values[3 * i + 2];
      }
      return absl::OkStatus();
    }
    case galpha::v1::BuildRequest::kEncodedPoints: {
      if (!has_header_) return absl::InvalidArgumentError("the build stream must start with a header");
      const galpha::v1::EncodedPointChunk& chunk = message.encoded_points();
      const uint64_t before = decoded_.points.size();
      const wire::ChunkPosition at{chunks_++, before};
      // Every limit applies to the decoded points, checked before anything is decompressed: the
      // stated count against the limits, its decoded bytes reserved, then the decoder writes at
      // most that many points.
      const bool weighted = decoded_.header.weighted();
      if (absl::Status s = wire::CheckEncodedChunkShape(chunk, at, weighted); !s.ok()) return s;
      const uint64_t count = chunk.point_count();
      if (absl::Status s = CheckPointCount(before + count); !s.ok()) return s;
      if (absl::Status s = Grow(count); !s.ok()) return s;
      if (codec_pool_ != nullptr) {
        DecodeOnPool(std::move(message), at, before);
        return absl::OkStatus();
      }
      absl::Status decoded =
          weighted ? chunk_decoder_.DecodeWeighted(chunk, at, &decoded_.points[before], &decoded_.weights[before])
                   : chunk_decoder_.Decode(chunk, at, &decoded_.points[before]);
      if (!decoded.ok()) {
        // A refused chunk adds nothing and holds nothing.
        decoded_.points.resize(before);
        if (weighted) decoded_.weights.resize(before);
        if (in_flight_ != nullptr) {
          in_flight_->Release(tenant_, count * PointBytes());
          reserved_ -= count * PointBytes();
        }
      }
      return decoded;
    }
    case galpha::v1::BuildRequest::PART_NOT_SET:
      return absl::InvalidArgumentError(
          "a build stream message has neither a header nor points (a newer client's kind of chunk?)");
  }
  return absl::InvalidArgumentError("a build stream message of unknown kind");
}

absl::StatusOr<DecodedBuild*> BuildStreamDecoder::Finish() {
  if (finished_) return absl::FailedPreconditionError("the build stream already ended");
  finished_ = true;
  chunk_decoder_.ReleaseScratch();  // the decoder outlives the stream while the build runs
  WaitForDecodes();
  if (absl::Status failed = DecodeFailure(); !failed.ok()) return failed;
  if (!has_header_) return absl::InvalidArgumentError("the build stream is empty: it needs a header, then points");
  const uint64_t expected = decoded_.header.expected_points();
  if (expected > 0 && decoded_.points.size() != expected) {
    return absl::InvalidArgumentError(
        absl::StrCat("the stream ended after ", decoded_.points.size(), " points; its header announced ", expected));
  }
  if (!decoded_.header.crs().empty()) {
    absl::Status framed = FrameByCrs(&decoded_);
    if (!framed.ok()) return framed;
  }
  // Hashed once the points are all here: in parallel (point_set_handle.hpp), ~1 ms at 1M points
  // on 16 cores.
  // A weighted stream of no points is the empty set, unweighted (as BuildWeightedAlphaFamily
  // builds it): one family and one handle for every empty set.
  decoded_.handle = decoded_.header.weighted() && !decoded_.points.empty()
                        ? WeightedPointSetHandle(decoded_.points, decoded_.weights)
                        : PointSetHandle(decoded_.points);
  return &decoded_;
}

absl::Status FrameByCrs(DecodedBuild* build) {
  absl::StatusOr<CrsInfo> crs = DescribeCrs(build->header.crs());
  if (!crs.ok()) return absl::InvalidArgumentError(absl::StrCat("the header's crs: ", crs.status().message()));
  auto frame = std::make_shared<CachedFamily::InputFrame>();
  frame->crs = *std::move(crs);
  if (frame->crs.geographic) {
    const absl::Span<const Point2> sent(build->points.data(), build->points.size());
    absl::StatusOr<LocalMetres> local = ProjectToLocalMetres(frame->crs, sent);
    if (!local.ok()) return absl::InvalidArgumentError(absl::StrCat("the header's crs: ", local.status().message()));
    frame->input.assign(sent.begin(), sent.end());
    std::copy(local->points.begin(), local->points.end(), build->points.data());
    frame->projection = std::move(local->projection);
  }
  build->frame = std::move(frame);
  return absl::OkStatus();
}

}  // namespace galpha::server
