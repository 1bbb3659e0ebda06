#include "core/io/point_io.hpp"

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <system_error>
#include <type_traits>

#include "absl/strings/str_cat.h"

namespace galpha {
namespace {

// The file stores (x, y) pairs back to back, so a host with this layout can read and write the
// point array in one call; only the byte order may need fixing.
static_assert(sizeof(Point2) == 2 * sizeof(double) && std::is_standard_layout_v<Point2>,
              "Point2 must be two packed doubles");
static_assert(sizeof(double) == sizeof(uint64_t) && std::numeric_limits<double>::is_iec559,
              "the format stores IEEE-754 binary64");

constexpr uint64_t kHeaderBytes = sizeof(uint64_t);
constexpr uint64_t kBytesPerPoint = sizeof(Point2);

constexpr bool HostIsLittleEndian() { return __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__; }

uint64_t ByteSwap64(uint64_t v) { return __builtin_bswap64(v); }

// Converts between host and file (little-endian) byte order; an involution.
uint64_t HostFileOrder(uint64_t v) { return HostIsLittleEndian() ? v : ByteSwap64(v); }

void SwapPointBytes(std::vector<Point2>* points) {
  for (Point2& p : *points) {
    for (double* coordinate : {&p.x, &p.y}) {
      uint64_t bits;
      std::memcpy(&bits, coordinate, sizeof bits);
      bits = ByteSwap64(bits);
      std::memcpy(coordinate, &bits, sizeof bits);
    }
  }
}

struct FileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

absl::Status OpenError(const std::string& path, const char* purpose, int error_number) {
  return absl::ErrnoToStatus(error_number, absl::StrCat("cannot open points file '", path, "' for ", purpose));
}

}  // namespace

absl::StatusOr<std::vector<Point2>> ReadPointsBin(const std::string& path) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (status.type() == std::filesystem::file_type::not_found) {
    return absl::NotFoundError(absl::StrCat("points file '", path, "' does not exist"));
  }
  if (error) {
    return absl::ErrnoToStatus(error.value(), absl::StrCat("cannot inspect points file '", path, "'"));
  }
  if (status.type() != std::filesystem::file_type::regular) {
    return absl::InvalidArgumentError(absl::StrCat("points file '", path, "' is not a regular file"));
  }
  const uint64_t file_bytes = std::filesystem::file_size(path, error);
  if (error) {
    return absl::ErrnoToStatus(error.value(), absl::StrCat("cannot size points file '", path, "'"));
  }
  if (file_bytes < kHeaderBytes) {
    return absl::InvalidArgumentError(absl::StrCat("points file '", path, "' has ", file_bytes,
                                                   " bytes, fewer than its 8-byte header (uint64 point count)"));
  }

  FilePtr file(std::fopen(path.c_str(), "rb"));
  if (file == nullptr) return OpenError(path, "reading", errno);

  uint64_t header;
  if (std::fread(&header, sizeof header, 1, file.get()) != 1) {
    return absl::DataLossError(absl::StrCat("cannot read the header of points file '", path, "'"));
  }
  const uint64_t count = HostFileOrder(header);
  const uint64_t body_bytes = file_bytes - kHeaderBytes;
  // Compare counts rather than count * 16 so that a corrupt header cannot overflow.
  if (count != body_bytes / kBytesPerPoint || body_bytes % kBytesPerPoint != 0) {
    const bool truncated = count > body_bytes / kBytesPerPoint;
    return absl::DataLossError(absl::StrCat(
        "points file '", path, "': header says ", count, " points but the file has ", file_bytes, " bytes, room for ",
        body_bytes / kBytesPerPoint, " points",
        truncated ? " (truncated)" : absl::StrCat(" and ", body_bytes - count * kBytesPerPoint, " trailing bytes")));
  }

  std::vector<Point2> points(count);
  if (count > 0 && std::fread(points.data(), kBytesPerPoint, count, file.get()) != count) {
    return absl::DataLossError(absl::StrCat("short read in points file '", path, "': expected ", count, " points"));
  }
  if (!HostIsLittleEndian()) SwapPointBytes(&points);
  return points;
}

absl::Status WritePointsBin(const std::string& path, absl::Span<const Point2> points) {
  FilePtr file(std::fopen(path.c_str(), "wb"));
  if (file == nullptr) return OpenError(path, "writing", errno);

  const uint64_t header = HostFileOrder(points.size());
  bool written = std::fwrite(&header, sizeof header, 1, file.get()) == 1;
  if (written && !points.empty()) {
    if (HostIsLittleEndian()) {
      written = std::fwrite(points.data(), kBytesPerPoint, points.size(), file.get()) == points.size();
    } else {
      std::vector<Point2> swapped(points.begin(), points.end());
      SwapPointBytes(&swapped);
      written = std::fwrite(swapped.data(), kBytesPerPoint, swapped.size(), file.get()) == swapped.size();
    }
  }
  // fclose flushes: its failure is a lost write too.
  const bool closed = std::fclose(file.release()) == 0;
  if (!written || !closed) {
    return absl::DataLossError(absl::StrCat("cannot write ", points.size(), " points to points file '", path, "'"));
  }
  return absl::OkStatus();
}

}  // namespace galpha
