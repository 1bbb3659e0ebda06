#include "core/io/point_io.hpp"

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <string>
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
constexpr uint64_t kBytesPerWeightedPoint = 3 * sizeof(double);

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
  if ((count & kWeightedBinFlag) != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("points file '", path, "' is weighted (x, y, weight triples): read it as weighted points"));
  }
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

absl::StatusOr<GeoreferencedPoints> ReadWeightedPointsBin(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::ErrnoToStatus(errno, absl::StrCat("cannot open points file '", path, "'"));
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return absl::DataLossError(absl::StrCat("cannot read points file '", path, "'"));
  if (bytes.size() < kHeaderBytes) {
    return absl::InvalidArgumentError(absl::StrCat("points file '", path, "' has ", bytes.size(),
                                                   " bytes, fewer than its 8-byte header (uint64 point count)"));
  }
  uint64_t header;
  std::memcpy(&header, bytes.data(), sizeof header);
  header = HostFileOrder(header);
  if ((header & kWeightedBinFlag) == 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "points file '", path, "' holds (x, y) pairs without weights (its header lacks the weighted flag, bit 63)"));
  }
  const uint64_t count = header & ~kWeightedBinFlag;
  const uint64_t body_bytes = bytes.size() - kHeaderBytes;
  if (count != body_bytes / kBytesPerWeightedPoint || body_bytes % kBytesPerWeightedPoint != 0) {
    return absl::DataLossError(
        absl::StrCat("points file '", path, "': header says ", count, " weighted points but the file has room for ",
                     body_bytes / kBytesPerWeightedPoint, " (", bytes.size(), " bytes; 24 a point)"));
  }
  GeoreferencedPoints out;
  out.points.resize(count);
  out.weights.resize(count);
  for (uint64_t i = 0; i < count; ++i) {
    uint64_t bits[3];
    std::memcpy(bits, bytes.data() + kHeaderBytes + kBytesPerWeightedPoint * i, sizeof bits);
    double v[3];
    for (int k = 0; k < 3; ++k) {
      const uint64_t host = HostFileOrder(bits[k]);
      std::memcpy(&v[k], &host, sizeof host);
    }
    out.points[i] = {v[0], v[1]};
    out.weights[i] = v[2];
  }
  return out;
}

absl::Status WriteWeightedPointsBin(const std::string& path, absl::Span<const Point2> points,
                                    absl::Span<const double> weights) {
  if (weights.size() != points.size()) {
    return absl::InvalidArgumentError(absl::StrCat(weights.size(), " weights for ", points.size(), " points"));
  }
  std::string bytes(kHeaderBytes + kBytesPerWeightedPoint * points.size(), '\0');
  const uint64_t header = HostFileOrder(points.size() | kWeightedBinFlag);
  std::memcpy(bytes.data(), &header, sizeof header);
  for (size_t i = 0; i < points.size(); ++i) {
    const double v[3] = {points[i].x, points[i].y, weights[i]};
    for (int k = 0; k < 3; ++k) {
      uint64_t bits;
      std::memcpy(&bits, &v[k], sizeof bits);
      bits = HostFileOrder(bits);
      std::memcpy(bytes.data() + kHeaderBytes + kBytesPerWeightedPoint * i + 8 * k, &bits, sizeof bits);
    }
  }
  FilePtr file(std::fopen(path.c_str(), "wb"));
  if (file == nullptr) return OpenError(path, "writing", errno);
  const bool written = std::fwrite(bytes.data(), 1, bytes.size(), file.get()) == bytes.size();
  const bool closed = std::fclose(file.release()) == 0;
  if (!written || !closed) {
    return absl::DataLossError(
        absl::StrCat("cannot write ", points.size(), " weighted points to points file '", path, "'"));
  }
  return absl::OkStatus();
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
