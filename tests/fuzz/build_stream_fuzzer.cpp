// libFuzzer target: arbitrary bytes as a Build stream (length-prefixed serialized BuildRequest
// messages, raw PointChunks and EncodedPointChunks) through the server's decoder. Besides "no
// crash, no sanitizer report", it checks the decoder's promises: an accepted stream's points are
// finite, as many as its chunks carried (an encoded chunk: its point_count), its handle is the
// handle of those points (with their weights, in a weighted stream: BuildHeader.weighted), and no
// refused chunk holds bytes in flight. Every accepted raw chunk's points (and weights) also go
// through the encoder in every form it can take and must decode bit for bit. The same messages go
// through a second decoder that decompresses on a pool of threads (as the server's does): it must
// end the same way, accepting the same points and handle or refusing with the same status,
// whichever message or the end of the stream it refuses at.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <vector>

#include "core/io/point_set_handle.hpp"
#include "proto/codec/point_chunk_codec.hpp"
#include "server/build_stream.hpp"
#include "server/chunk_codec_pool.hpp"

namespace {

namespace v1 = galpha::v1;

uint64_t Bits(double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}

// Encodes `points` (and `weights`, when not empty) as `encoding` says (when it can), decodes, and
// aborts unless they come back bit for bit.
void CheckRoundTrip(const std::vector<galpha::Point2>& points, const std::vector<double>& weights,
                    const galpha::wire::ChunkEncoding& encoding) {
  galpha::wire::PointChunkEncoder encoder(1);
  v1::EncodedPointChunk chunk;
  if (!encoder.Encode(points, weights, encoding, &chunk).ok()) return;
  galpha::wire::PointChunkDecoder decoder;
  std::vector<galpha::Point2> decoded(points.size());
  std::vector<double> decoded_weights(points.size());
  const bool decoded_ok = weights.empty()
                              ? decoder.Decode(chunk, {}, decoded.data()).ok()
                              : decoder.DecodeWeighted(chunk, {}, decoded.data(), decoded_weights.data()).ok();
  if (!decoded_ok) std::abort();  // the raw chunk was finite
  for (size_t i = 0; i < points.size(); ++i) {
    if (Bits(decoded[i].x) != Bits(points[i].x) || Bits(decoded[i].y) != Bits(points[i].y)) std::abort();
    if (!weights.empty() && Bits(decoded_weights[i]) != Bits(weights[i])) std::abort();
  }
}

void CheckEveryEncoding(const v1::PointChunk& raw, bool weighted) {
  const size_t axes = weighted ? 3 : 2;
  std::vector<galpha::Point2> points(static_cast<size_t>(raw.coordinates_size()) / axes);
  if (points.empty()) return;
  std::vector<double> weights(weighted ? points.size() : 0);
  for (size_t i = 0; i < points.size(); ++i) {
    points[i] = {raw.coordinates(static_cast<int>(axes * i)), raw.coordinates(static_cast<int>(axes * i + 1))};
    if (weighted) weights[i] = raw.coordinates(static_cast<int>(axes * i + 2));
  }
  galpha::wire::ChunkEncoding encoding;
  const std::optional<galpha::wire::ScaledAxes> scaled = galpha::wire::FindScaledIntegers(points, weights);
  for (v1::PointTransform transform : {v1::POINT_TRANSFORM_NONE, v1::POINT_TRANSFORM_BYTE_SHUFFLE,
                                       v1::POINT_TRANSFORM_DELTA_SHUFFLE, v1::POINT_TRANSFORM_DELTA2_SHUFFLE}) {
    for (v1::PointCompression compression : {v1::POINT_COMPRESSION_NONE, v1::POINT_COMPRESSION_ZSTD}) {
      encoding.value_type = v1::POINT_VALUE_TYPE_FLOAT64;
      encoding.transform = transform;
      encoding.compression = compression;
      CheckRoundTrip(points, weights, encoding);
      if (!scaled) continue;
      encoding.value_type = scaled->value_type;
      encoding.x_scale = scaled->x;
      encoding.y_scale = scaled->y;
      encoding.w_scale = scaled->w;
      CheckRoundTrip(points, weights, encoding);  // found scales must reproduce every value: Encode may not fail
      v1::EncodedPointChunk chunk;
      galpha::wire::PointChunkEncoder encoder(1);
      if (!encoder.Encode(points, weights, encoding, &chunk).ok()) std::abort();
      encoding.x_scale.Clear();
      encoding.y_scale.Clear();
      encoding.w_scale.Clear();
    }
  }
}

// Aborts unless the decoder on a pool ended as the one without: both accepted the same points,
// weights and handle, or both refused with the same status.
void CheckSameEnd(const absl::StatusOr<galpha::server::DecodedBuild*>& direct,
                  const absl::StatusOr<galpha::server::DecodedBuild*>& pooled) {
  if (direct.ok() != pooled.ok()) std::abort();
  if (!direct.ok()) {
    if (direct.status() != pooled.status()) std::abort();
    return;
  }
  const galpha::server::DecodedBuild& a = **direct;
  const galpha::server::DecodedBuild& b = **pooled;
  if (a.handle != b.handle || a.points.size() != b.points.size() || a.weights.size() != b.weights.size()) std::abort();
  for (size_t i = 0; i < a.points.size(); ++i) {
    if (Bits(a.points[i].x) != Bits(b.points[i].x) || Bits(a.points[i].y) != Bits(b.points[i].y)) std::abort();
  }
  for (size_t i = 0; i < a.weights.size(); ++i) {
    if (Bits(a.weights[i]) != Bits(b.weights[i])) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static galpha::server::ChunkCodecPool pool(2);
  galpha::server::InFlightBytes in_flight(1 << 20);
  galpha::server::InFlightBytes pooled_in_flight(1 << 20);
  {
    galpha::server::BuildStreamLimits limits;
    limits.max_points = 4096;
    galpha::server::BuildStreamDecoder decoder(limits, &in_flight);
    galpha::server::BuildStreamDecoder pooled(limits, &pooled_in_flight, "", &pool);
    absl::Status pooled_refusal;
    size_t position = 0;
    uint64_t carried = 0;
    bool failed = false;
    bool weighted = false;  // the accepted header's
    // Each message: a 2-byte little-endian length, then that many bytes of a serialized message.
    while (position + 2 <= size && !failed) {
      const size_t length = std::min<size_t>(data[position] | (size_t{data[position + 1]} << 8), size - position - 2);
      position += 2;
      galpha::v1::BuildRequest message;
      if (!message.ParseFromArray(data + position, static_cast<int>(length))) {
        position += length;
        continue;
      }
      position += length;
      if (message.has_points()) {
        carried += static_cast<uint64_t>(message.points().coordinates_size()) / (weighted ? 3 : 2);
      }
      if (message.has_encoded_points()) carried += message.encoded_points().point_count();
      const uint64_t before = decoder.points_received();
      if (pooled_refusal.ok()) pooled_refusal = pooled.Add(message);
      const absl::Status added = decoder.Add(message);
      failed = !added.ok();
      // The pool may refuse later than this message (a chunk still decoding), never earlier.
      if (!pooled_refusal.ok() && added.ok()) std::abort();
      if (failed) CheckSameEnd(added, pooled_refusal.ok() ? pooled.Finish().status() : pooled_refusal);
      // A refused chunk adds no points (and, below, holds no bytes once the decoder is gone).
      if (failed && decoder.points_received() != before) std::abort();
      if (!failed && message.has_header()) weighted = message.header().weighted();
      if (!failed && message.has_points()) CheckEveryEncoding(message.points(), weighted);
    }
    if (!failed) {
      auto decoded = decoder.Finish();
      if (pooled_refusal.ok()) {
        CheckSameEnd(decoded, pooled.Finish());
      } else {
        CheckSameEnd(decoded, pooled_refusal);
      }
      if (decoded.ok()) {
        const auto& points = (*decoded)->points;
        const auto& weights = (*decoded)->weights;
        if (points.size() != carried) std::abort();
        for (const auto& p : points) {
          if (!std::isfinite(p.x) || !std::isfinite(p.y)) std::abort();
        }
        for (const double w : weights) {
          if (!std::isfinite(w)) std::abort();
        }
        // A weighted stream of points: their weights, one each, in the handle; of none: the empty
        // set's handle (BuildHeader.weighted).
        if (weighted && !points.empty()) {
          if (weights.size() != points.size()) std::abort();
          if ((*decoded)->handle != galpha::WeightedPointSetHandle(points, weights)) std::abort();
        } else {
          if (!weights.empty()) std::abort();
          if ((*decoded)->handle != galpha::PointSetHandle(points)) std::abort();
        }
      }
    }
  }
  // Every reservation is given back when the decoder goes away.
  if (in_flight.held() != 0 || pooled_in_flight.held() != 0) std::abort();
  return 0;
}
