// LAS files written byte by byte from the layout of the ASPRS LAS Specification 1.4 R15 (public
// header block, table 3; VLR and EVLR headers, tables 4 and 5; point records, tables 7-17), for
// the tests of the LAS reader (not with the reader's own code: the offsets are spelled out again).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace galpha::testing {

/// One (extended) variable length record.
struct LasRecord {
  std::string user_id;  // at most 16 bytes, NUL-padded
  uint16_t record_id = 0;
  std::string body;
};

/// What to write; every field of the header can be set wrong on purpose.
struct LasSpec {
  int major = 1;
  int minor = 2;
  int format = 0;
  int format_byte = -1;            // the byte written for the format; -1: `format`
  int record_length = -1;          // -1: the format's size
  int header_size = -1;            // -1: the version's size (227, 235, 375)
  int64_t point_data_offset = -1;  // -1: right after the header and the VLRs
  int64_t legacy_count = -1;       // -1: the points' count (0 for formats 6-10)
  int64_t count64 = -1;            // LAS 1.4: -1: the points' count
  double scale[3] = {0.01, 0.01, 0.01};
  double offset[3] = {0.0, 0.0, 0.0};
  std::vector<std::pair<int32_t, int32_t>> xy;  // X and Y of each record; Z = 7, the rest zero
  std::vector<LasRecord> vlrs;
  std::vector<LasRecord> evlrs;  // LAS 1.4: after the point records
  int64_t evlr_start = -1;       // -1: after the point records
  size_t drop_tail = 0;          // bytes cut off the end (a truncated file)
};

/// The bytes each point data record format needs (tables 7-17).
inline int LasFormatBytes(int format) {
  static const int bytes[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  return format >= 0 && format <= 10 ? bytes[format] : 20;
}

/// The OGC WKT coordinate system record (LASF_Projection 2112), NUL-terminated as writers do.
inline LasRecord LasWktRecord(const std::string& wkt) { return {"LASF_Projection", 2112, wkt + std::string(3, '\0')}; }

/// A GeoTIFF GeoKeyDirectoryTag record (LASF_Projection 34735): the header shorts (version 1,
/// revision 1.0, the key count) then each key's four shorts {KeyID, TIFFTagLocation, Count,
/// Value_Offset}, little-endian.
inline LasRecord LasGeoKeysRecord(const std::vector<std::array<uint16_t, 4>>& keys, uint16_t version = 1) {
  std::vector<uint16_t> shorts = {version, 1, 0, static_cast<uint16_t>(keys.size())};
  for (const auto& key : keys) shorts.insert(shorts.end(), key.begin(), key.end());
  std::string body(2 * shorts.size(), '\0');
  for (size_t i = 0; i < shorts.size(); ++i) {
    body[2 * i] = static_cast<char>(shorts[i] & 0xff);
    body[2 * i + 1] = static_cast<char>(shorts[i] >> 8);
  }
  return {"LASF_Projection", 34735, body};
}

inline std::string LasFileBytes(const LasSpec& spec) {
  const auto put = [](std::string* out, size_t at, const void* value, size_t bytes) {
    if (out->size() < at + bytes) out->resize(at + bytes, '\0');
    std::memcpy(&(*out)[at], value, bytes);  // little-endian hosts only, as the engine
  };
  const auto put16 = [&](std::string* out, size_t at, uint64_t v) {
    const uint16_t w = static_cast<uint16_t>(v);
    put(out, at, &w, 2);
  };
  const auto put32 = [&](std::string* out, size_t at, uint64_t v) {
    const uint32_t w = static_cast<uint32_t>(v);
    put(out, at, &w, 4);
  };
  const auto put64 = [&](std::string* out, size_t at, uint64_t v) { put(out, at, &v, 8); };
  const auto put_double = [&](std::string* out, size_t at, double v) { put(out, at, &v, 8); };

  const int header_size = spec.header_size >= 0 ? spec.header_size
                          : spec.minor <= 2     ? 227
                          : spec.minor == 3     ? 235
                                                : 375;
  const int record_length = spec.record_length >= 0 ? spec.record_length : LasFormatBytes(spec.format);
  std::string bytes(static_cast<size_t>(header_size), '\0');
  bytes.replace(0, 4, "LASF");
  bytes[24] = static_cast<char>(spec.major);
  bytes[25] = static_cast<char>(spec.minor);
  bytes.replace(26, 7, "galpha ");
  put16(&bytes, 94, static_cast<uint64_t>(header_size));
  put32(&bytes, 100, spec.vlrs.size());
  bytes[104] = static_cast<char>(spec.format_byte >= 0 ? spec.format_byte : spec.format);
  put16(&bytes, 105, static_cast<uint64_t>(record_length));
  const uint64_t n = spec.xy.size();
  put32(&bytes, 107, spec.legacy_count >= 0 ? static_cast<uint64_t>(spec.legacy_count) : spec.format >= 6 ? 0 : n);
  for (int axis = 0; axis < 3; ++axis) {
    put_double(&bytes, 131 + 8 * axis, spec.scale[axis]);
    put_double(&bytes, 155 + 8 * axis, spec.offset[axis]);
  }
  std::string vlrs;
  for (const LasRecord& r : spec.vlrs) {
    std::string header(54, '\0');
    header.replace(2, r.user_id.size(), r.user_id);
    put16(&header, 18, r.record_id);
    put16(&header, 20, r.body.size());
    vlrs += header + r.body;
  }
  const uint64_t point_data = spec.point_data_offset >= 0 ? static_cast<uint64_t>(spec.point_data_offset)
                                                          : static_cast<uint64_t>(header_size) + vlrs.size();
  put32(&bytes, 96, point_data);
  bytes.resize(static_cast<size_t>(header_size));
  bytes += vlrs;
  bytes.resize(std::max<size_t>(bytes.size(), point_data), '\0');  // never cuts the header or the VLRs
  for (const auto& [x, y] : spec.xy) {
    std::string record(static_cast<size_t>(record_length), '\0');
    const int32_t xyz[3] = {x, y, 7};
    put(&record, 0, xyz, std::min<size_t>(12, record.size()));
    record.resize(static_cast<size_t>(record_length));
    bytes += record;
  }
  if (spec.minor >= 4) {
    put64(&bytes, 235, spec.evlr_start >= 0 ? static_cast<uint64_t>(spec.evlr_start) : bytes.size());
    put32(&bytes, 243, spec.evlrs.size());
    put64(&bytes, 247, spec.count64 >= 0 ? static_cast<uint64_t>(spec.count64) : n);
    for (const LasRecord& r : spec.evlrs) {
      std::string header(60, '\0');
      header.replace(2, r.user_id.size(), r.user_id);
      put16(&header, 18, r.record_id);
      put64(&header, 20, r.body.size());
      bytes += header + r.body;
    }
  }
  bytes.resize(bytes.size() - std::min(spec.drop_tail, bytes.size()));
  return bytes;
}

}  // namespace galpha::testing
