// libFuzzer target: the point-file parsers (delimited text, .npy, GeoJSON) on arbitrary bytes; the
// first byte picks the parser. Errors are fine; crashes, hangs and sanitizer reports are not.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "core/io/point_formats.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const absl::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  absl::StatusOr<std::vector<galpha::Point2>> points;
  switch (data[0] % 3) {
    case 0:
      points = galpha::ParsePointsText(bytes, "fuzz.csv");
      break;
    case 1:
      points = galpha::ParsePointsNpy(bytes, "fuzz.npy");
      break;
    default:
      points = galpha::ParsePointsGeoJson(bytes, "fuzz.geojson");
      break;
  }
  // A parse that succeeds returns at most one point per 2 input bytes (no format is denser).
  if (points.ok() && points->size() > size) std::abort();
  return 0;
}
