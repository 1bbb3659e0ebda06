// libFuzzer target: arbitrary bytes as a Build stream (length-prefixed serialized BuildRequest
// messages) through the server's decoder. Besides "no crash, no sanitizer report", it checks the
// decoder's promises: an accepted stream's points are finite, as many as its chunks carried, and its
// handle is the handle of those points.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "core/io/point_set_handle.hpp"
#include "server/build_stream.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  galpha::server::InFlightBytes in_flight(1 << 20);
  {
    galpha::server::BuildStreamLimits limits;
    limits.max_points = 4096;
    galpha::server::BuildStreamDecoder decoder(limits, &in_flight);
    size_t position = 0;
    uint64_t carried = 0;
    bool failed = false;
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
      if (message.has_points()) carried += static_cast<uint64_t>(message.points().coordinates_size()) / 2;
      failed = !decoder.Add(message).ok();
    }
    if (!failed) {
      auto decoded = decoder.Finish();
      if (decoded.ok()) {
        const auto& points = (*decoded)->points;
        if (points.size() != carried) std::abort();
        for (const auto& p : points) {
          if (!std::isfinite(p.x) || !std::isfinite(p.y)) std::abort();
        }
        if ((*decoded)->handle != galpha::PointSetHandle(points)) std::abort();
      }
    }
  }
  // Every reservation is given back when the decoder goes away.
  if (in_flight.held() != 0) std::abort();
  return 0;
}
