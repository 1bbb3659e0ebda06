#include "core/io/las_reader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "core/base/scaled_coordinate.hpp"
#include "core/base/status_macros.hpp"

namespace galpha {
namespace {

// The public header block's fields (LAS 1.4 R15, table 3), as byte offsets; all little-endian.
constexpr size_t kVersionMajorAt = 24, kVersionMinorAt = 25, kHeaderSizeAt = 94, kPointDataAt = 96, kVlrCountAt = 100,
                 kPointFormatAt = 104, kRecordLengthAt = 105, kLegacyCountAt = 107, kXScaleAt = 131, kYScaleAt = 139,
                 kXOffsetAt = 155, kYOffsetAt = 163, kEvlrStartAt = 235, kEvlrCountAt = 243, kPointCountAt = 247;
// The header's size by minor version: 1.0-1.2, 1.3 (+ the waveform start), 1.4 (+ EVLRs and
// 64-bit counts). Larger headers are allowed (the specification's user-defined bytes).
constexpr uint64_t kHeaderBytes12 = 227, kHeaderBytes13 = 235, kHeaderBytes14 = 375;
// (Extended) variable length record headers: reserved, user ID (16), record ID, length, description (32).
constexpr uint64_t kVlrHeaderBytes = 54, kEvlrHeaderBytes = 60;
constexpr size_t kUserIdAt = 2, kUserIdBytes = 16, kRecordIdAt = 18, kRecordLengthAfterHeaderAt = 20;
// The OGC coordinate system WKT record (table 21); LASzip's record marks compressed data.
constexpr absl::string_view kProjectionUser = "LASF_Projection", kLasZipUser = "laszip encoded";
constexpr uint16_t kWktRecordId = 2112, kLasZipRecordId = 22204;
// The GeoTIFF GeoKeyDirectoryTag record (table 18) and the keys read from it (GeoTIFF 1.0, 2.7):
// the model type (1 projected, 2 geographic) and the EPSG codes of the projected and geographic
// CRS; 32767 is "user-defined", which names no code.
constexpr uint16_t kGeoKeysRecordId = 34735;
constexpr uint16_t kModelTypeKey = 1024, kGeographicTypeKey = 2048, kProjectedTypeKey = 3072;
constexpr uint16_t kModelProjected = 1, kModelGeographic = 2, kUserDefinedCode = 32767;
// Bytes of point data record formats 0 to 10 (tables 7-17); X and Y are the first two int32 of all.
constexpr uint16_t kFormatBytes[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
constexpr int kLastFormat = 10, kFirstFormatOf14 = 6;
// LASzip sets bit 7 (and some writers bit 6) of the point format byte of a compressed file.
constexpr unsigned kCompressedFormatBits = 0xC0;
// A WKT record longer than this is no coordinate system (EPSG's longest WKT is a few KiB).
constexpr uint64_t kMaxWktBytes = uint64_t{1} << 20;
// Point records read per chunk: about this many bytes.
constexpr size_t kChunkBytes = size_t{1} << 20;

uint16_t U16(const unsigned char* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
uint32_t U32(const unsigned char* p) { return U16(p) | (static_cast<uint32_t>(U16(p + 2)) << 16); }
uint64_t U64(const unsigned char* p) { return U32(p) | (static_cast<uint64_t>(U32(p + 4)) << 32); }
int32_t I32(const unsigned char* p) {
  const uint32_t bits = U32(p);
  int32_t value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}
double F64(const unsigned char* p) {
  const uint64_t bits = U64(p);
  double value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

// A fixed-size, NUL-padded text field, up to its first NUL.
absl::string_view PaddedText(const unsigned char* p, size_t bytes) {
  const auto* text = reinterpret_cast<const char*>(p);
  return absl::string_view(text, std::find(text, text + bytes, '\0') - text);
}

/// The open file, read at offsets; every message names it.
class LasFile {
 public:
  explicit LasFile(const std::string& path) : path_(path), named_(absl::StrCat("points file '", path, "'")) {}
  LasFile(const LasFile&) = delete;
  LasFile& operator=(const LasFile&) = delete;
  ~LasFile() {
    if (fd_ >= 0) close(fd_);
  }

  absl::Status Open() {
    fd_ = open(path_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) {
      if (errno == ENOENT) return absl::NotFoundError(absl::StrCat(named_, " does not exist"));
      return absl::ErrnoToStatus(errno, absl::StrCat("cannot open ", named_));
    }
    struct stat info {};
    if (fstat(fd_, &info) != 0) return absl::ErrnoToStatus(errno, absl::StrCat("cannot inspect ", named_));
    if (!S_ISREG(info.st_mode)) return Invalid("is not a regular file");
    size_ = static_cast<uint64_t>(info.st_size);
    return absl::OkStatus();
  }

  uint64_t size() const { return size_; }

  /// Reads [offset, offset + bytes), which the caller has checked lies in the file.
  absl::Status ReadAt(uint64_t offset, size_t bytes, unsigned char* out) const {
    while (bytes > 0) {
      const ssize_t got = pread(fd_, out, bytes, static_cast<off_t>(offset));
      if (got < 0 && errno == EINTR) continue;
      if (got < 0) return absl::ErrnoToStatus(errno, absl::StrCat("cannot read ", named_));
      if (got == 0) return absl::DataLossError(absl::StrCat(named_, " ended at byte ", offset, " while being read"));
      out += got;
      offset += static_cast<uint64_t>(got);
      bytes -= static_cast<size_t>(got);
    }
    return absl::OkStatus();
  }

  template <typename... Parts>
  absl::Status Invalid(const Parts&... parts) const {
    return absl::InvalidArgumentError(absl::StrCat(named_, ": ", parts...));
  }
  template <typename... Parts>
  absl::Status Truncated(const Parts&... parts) const {
    return absl::DataLossError(absl::StrCat(named_, " is truncated: ", parts...));
  }
  const std::string& named() const { return named_; }

 private:
  const std::string& path_;
  const std::string named_;
  int fd_ = -1;
  uint64_t size_ = 0;
};

/// What the public header says, checked.
struct LasHeader {
  int minor = 0;
  uint64_t header_bytes = 0;
  uint64_t point_data_at = 0;
  uint32_t vlr_count = 0;
  int format = 0;
  uint64_t record_bytes = 0;
  uint64_t count = 0;
  double x_scale = 0, y_scale = 0, x_offset = 0, y_offset = 0;
  uint64_t evlr_start = 0;
  uint32_t evlr_count = 0;
};

absl::Status CheckScale(const LasFile& file, const char* axis, double scale, double offset) {
  if (!std::isfinite(scale) || scale == 0.0) {
    return file.Invalid("the ", axis, " scale factor is ", scale, ": it must be finite and nonzero");
  }
  if (!std::isfinite(offset)) return file.Invalid("the ", axis, " offset is ", offset, ": it must be finite");
  return absl::OkStatus();
}

absl::StatusOr<LasHeader> ReadHeader(const LasFile& file) {
  unsigned char bytes[kHeaderBytes14] = {};
  const size_t have = static_cast<size_t>(std::min<uint64_t>(file.size(), sizeof bytes));
  GALPHA_RETURN_IF_ERROR(file.ReadAt(0, have, bytes));
  if (have < 4 || std::memcmp(bytes, "LASF", 4) != 0) {
    if (have >= 4) return file.Invalid("not a LAS file (it does not start with the signature 'LASF')");
    return file.Truncated(file.size(), " bytes, fewer than the ", kHeaderBytes12, "-byte LAS header");
  }
  if (have < kHeaderBytes12) {
    return file.Truncated(file.size(), " bytes, fewer than the ", kHeaderBytes12, "-byte LAS header");
  }
  LasHeader h;
  const int major = bytes[kVersionMajorAt];
  h.minor = bytes[kVersionMinorAt];
  if (major != 1 || h.minor > 4) return file.Invalid("LAS version ", major, ".", h.minor, ": 1.0 to 1.4 are read");
  const uint64_t needed = h.minor <= 2 ? kHeaderBytes12 : h.minor == 3 ? kHeaderBytes13 : kHeaderBytes14;
  h.header_bytes = U16(bytes + kHeaderSizeAt);
  if (h.header_bytes < needed) {
    return file.Invalid("the header size is ", h.header_bytes, " bytes, fewer than LAS 1.", h.minor, "'s ", needed);
  }
  if (file.size() < h.header_bytes) {
    return file.Truncated(file.size(), " bytes, fewer than its ", h.header_bytes, "-byte header");
  }

  const unsigned format_byte = bytes[kPointFormatAt];
  if ((format_byte & kCompressedFormatBits) != 0) {
    return file.Invalid("compressed (LAZ: point data record format byte ", format_byte,
                        " has bit 7 or 6 set); decompress it to .las first (laszip, pdal translate)");
  }
  h.format = static_cast<int>(format_byte);
  if (h.format > kLastFormat) {
    return file.Invalid("point data record format ", h.format, " is not defined (LAS 1.4 has formats 0 to 10)");
  }
  if (h.format >= kFirstFormatOf14 && h.minor < 4) {
    return file.Invalid("point data record format ", h.format, " needs LAS 1.4; the file is LAS 1.", h.minor);
  }
  h.record_bytes = U16(bytes + kRecordLengthAt);
  if (h.record_bytes < kFormatBytes[h.format]) {
    return file.Invalid("the point data record length is ", h.record_bytes, " bytes, fewer than the ",
                        kFormatBytes[h.format], " that point data record format ", h.format, " needs");
  }

  const uint32_t legacy_count = U32(bytes + kLegacyCountAt);
  h.count = legacy_count;
  if (h.minor == 4) {
    const uint64_t count = U64(bytes + kPointCountAt);
    if (count != 0 && legacy_count != 0 && count != legacy_count) {
      return file.Invalid("the legacy point count (", legacy_count, ") and the 64-bit point count (", count,
                          ") disagree");
    }
    if (count != 0) h.count = count;
    h.evlr_start = U64(bytes + kEvlrStartAt);
    h.evlr_count = U32(bytes + kEvlrCountAt);
  }

  h.x_scale = F64(bytes + kXScaleAt);
  h.y_scale = F64(bytes + kYScaleAt);
  h.x_offset = F64(bytes + kXOffsetAt);
  h.y_offset = F64(bytes + kYOffsetAt);
  GALPHA_RETURN_IF_ERROR(CheckScale(file, "x", h.x_scale, h.x_offset));
  GALPHA_RETURN_IF_ERROR(CheckScale(file, "y", h.y_scale, h.y_offset));

  h.point_data_at = U32(bytes + kPointDataAt);
  h.vlr_count = U32(bytes + kVlrCountAt);
  if (h.point_data_at < h.header_bytes) {
    return file.Invalid("the point data starts at byte ", h.point_data_at, ", inside the ", h.header_bytes,
                        "-byte header");
  }
  if (file.size() < h.point_data_at) {
    return file.Truncated(file.size(), " bytes, but its point data starts at byte ", h.point_data_at);
  }
  return h;
}

/// One (extended) variable length record: what the reader looks for in it.
struct RecordSeen {
  bool wkt = false;
  bool laszip = false;
  bool geokeys = false;
};

RecordSeen Classify(const unsigned char* header) {
  const absl::string_view user = PaddedText(header + kUserIdAt, kUserIdBytes);
  const uint16_t id = U16(header + kRecordIdAt);
  return {user == kProjectionUser && id == kWktRecordId, user == kLasZipUser && id == kLasZipRecordId,
          user == kProjectionUser && id == kGeoKeysRecordId};
}

// The CRS a GeoKeyDirectoryTag body names by EPSG code ("EPSG:26910"): the projected CRS, or the
// geographic one when the model is geographic (or not given, with no projected code). nullopt when the
// directory is malformed (its version, or entries past its end) or names no code (user-defined
// CRSs are described by further keys that are not interpreted: such files need --crs).
std::optional<std::string> EpsgFromGeoKeys(const std::vector<unsigned char>& body) {
  const size_t shorts = body.size() / 2;
  const auto at = [&](size_t i) { return U16(body.data() + 2 * i); };
  // Header: KeyDirectoryVersion (1), KeyRevision, MinorRevision, NumberOfKeys; then 4 shorts a key.
  if (shorts < 4 || at(0) != 1 || 4 + 4 * size_t{at(3)} > shorts) return std::nullopt;
  uint16_t model = 0, geographic = 0, projected = 0;
  for (size_t k = 0; k < at(3); ++k) {
    const size_t entry = 4 + 4 * k;
    // TIFFTagLocation 0: the value is the entry's own last short (one SHORT).
    if (at(entry + 1) != 0 || at(entry + 2) != 1) continue;
    const uint16_t value = at(entry + 3);
    if (at(entry) == kModelTypeKey) model = value;
    if (at(entry) == kGeographicTypeKey) geographic = value;
    if (at(entry) == kProjectedTypeKey) projected = value;
  }
  const auto code = [](uint16_t c) { return c != 0 && c != kUserDefinedCode; };
  // A projected model whose projection is user-defined must not fall back to its geographic base:
  // its coordinates are not degrees.
  if (model == kModelGeographic)
    return code(geographic) ? std::optional(absl::StrCat("EPSG:", geographic)) : std::nullopt;
  if (code(projected)) return absl::StrCat("EPSG:", projected);
  if (model == kModelProjected || !code(geographic)) return std::nullopt;
  return absl::StrCat("EPSG:", geographic);
}

// The WKT of a record body: up to its first NUL (writers terminate and pad it); nullopt when empty.
absl::StatusOr<std::optional<std::string>> ReadWkt(const LasFile& file, uint64_t at, uint64_t bytes) {
  if (bytes > kMaxWktBytes) {
    return file.Invalid("its coordinate system WKT record (at byte ", at, ") has ", bytes, " bytes, more than ",
                        kMaxWktBytes, ", the most a WKT is read with");
  }
  std::vector<unsigned char> body(bytes);
  GALPHA_RETURN_IF_ERROR(file.ReadAt(at, body.size(), body.data()));
  const absl::string_view wkt = PaddedText(body.data(), body.size());
  if (wkt.empty()) return std::nullopt;
  return std::string(wkt);
}

// Walks the VLRs between the header and the point data and, in LAS 1.4, the EVLRs: the CRS (the
// first WKT record's, else the EPSG code of the first GeoTIFF key directory among the VLRs), and
// a refusal for LASzip's record (a compressed file whose format byte was cleared).
absl::StatusOr<std::optional<std::string>> ReadCrs(const LasFile& file, const LasHeader& h) {
  std::optional<std::string> crs;
  std::optional<std::vector<unsigned char>> geokeys;
  uint64_t at = h.header_bytes;
  for (uint32_t i = 0; i < h.vlr_count; ++i) {
    unsigned char header[kVlrHeaderBytes];
    if (h.point_data_at - at < kVlrHeaderBytes) {
      return file.Invalid("variable length record ", i, " of ", h.vlr_count, " (at byte ", at,
                          ") runs past the start of the point data at byte ", h.point_data_at);
    }
    GALPHA_RETURN_IF_ERROR(file.ReadAt(at, sizeof header, header));
    const uint64_t body_bytes = U16(header + kRecordLengthAfterHeaderAt);
    if (h.point_data_at - at - kVlrHeaderBytes < body_bytes) {
      return file.Invalid("variable length record ", i, " of ", h.vlr_count, " (at byte ", at, ", ",
                          kVlrHeaderBytes + body_bytes, " bytes) runs past the start of the point data at byte ",
                          h.point_data_at);
    }
    const RecordSeen seen = Classify(header);
    if (seen.laszip) return file.Invalid("compressed (LAZ: it has a LASzip record); decompress it to .las first");
    if (seen.wkt && !crs) {
      GALPHA_ASSIGN_OR_RETURN(crs, ReadWkt(file, at + kVlrHeaderBytes, body_bytes));
    }
    if (seen.geokeys && !geokeys) {
      geokeys.emplace(body_bytes);
      GALPHA_RETURN_IF_ERROR(file.ReadAt(at + kVlrHeaderBytes, geokeys->size(), geokeys->data()));
    }
    at += kVlrHeaderBytes + body_bytes;
  }
  at = h.evlr_start;
  for (uint32_t i = 0; i < h.evlr_count && !crs; ++i) {
    unsigned char header[kEvlrHeaderBytes];
    if (at > file.size() || file.size() - at < kEvlrHeaderBytes) {
      return file.Truncated("extended variable length record ", i, " of ", h.evlr_count, " (at byte ", at,
                            ") runs past its end at byte ", file.size());
    }
    GALPHA_RETURN_IF_ERROR(file.ReadAt(at, sizeof header, header));
    const uint64_t body_bytes = U64(header + kRecordLengthAfterHeaderAt);
    if (file.size() - at - kEvlrHeaderBytes < body_bytes) {
      return file.Truncated("extended variable length record ", i, " of ", h.evlr_count, " (at byte ", at, ", ",
                            body_bytes, " bytes after its header) runs past its end at byte ", file.size());
    }
    if (Classify(header).wkt) {
      GALPHA_ASSIGN_OR_RETURN(crs, ReadWkt(file, at + kEvlrHeaderBytes, body_bytes));
    }
    at += kEvlrHeaderBytes + body_bytes;
  }
  // The WKT wins where a file has both (LAS 1.4 requires it for formats 6-10; the keys may be
  // left over from an older writer).
  if (!crs && geokeys) crs = EpsgFromGeoKeys(*geokeys);
  return crs;
}

}  // namespace

absl::StatusOr<GeoreferencedPoints> ReadLasPoints(const std::string& path, uint64_t max_points) {
  LasFile file(path);
  GALPHA_RETURN_IF_ERROR(file.Open());
  GALPHA_ASSIGN_OR_RETURN(const LasHeader h, ReadHeader(file));
  // Counts, not count * record length, so that a corrupt count cannot overflow.
  const uint64_t room = (file.size() - h.point_data_at) / h.record_bytes;
  if (h.count > room) {
    return file.Truncated("its header says ", h.count, " points of ", h.record_bytes, " bytes from byte ",
                          h.point_data_at, ", but it has ", file.size(), " bytes, room for ", room);
  }
  if (h.count > max_points) {
    return absl::ResourceExhaustedError(
        absl::StrCat(file.named(), " has ", h.count, " points: more than ", max_points, ", the limit"));
  }
  GeoreferencedPoints out;
  GALPHA_ASSIGN_OR_RETURN(out.crs, ReadCrs(file, h));

  out.points.resize(h.count);
  const uint64_t chunk_records = std::max<uint64_t>(1, kChunkBytes / h.record_bytes);
  std::vector<unsigned char> chunk(std::min(chunk_records, std::max<uint64_t>(h.count, 1)) * h.record_bytes);
  for (uint64_t first = 0; first < h.count; first += chunk_records) {
    const uint64_t records = std::min(chunk_records, h.count - first);
    GALPHA_RETURN_IF_ERROR(file.ReadAt(h.point_data_at + first * h.record_bytes,
                                       static_cast<size_t>(records * h.record_bytes), chunk.data()));
    for (uint64_t r = 0; r < records; ++r) {
      const unsigned char* record = chunk.data() + r * h.record_bytes;
      out.points[first + r] = {ScaledCoordinate(h.x_offset, h.x_scale, I32(record)),
                               ScaledCoordinate(h.y_offset, h.y_scale, I32(record + 4))};
    }
  }
  return out;
}

}  // namespace galpha
