// Uncompressed LAS point clouds, versions 1.0 to 1.4 (ASPRS LAS Specification 1.4 R15): x and y of
// every point record, and the CRS of the OGC WKT record or the GeoTIFF keys if the file has one. Compressed LAZ files
// are refused (no LASzip decoder here), as are files whose header does not add up.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

#include "absl/status/statusor.h"
#include "core/io/georeferenced_points.hpp"

namespace galpha {

/// Reads the points of the LAS file at `path`: for each point record, x = x_offset + x_scale * X
/// and y likewise from the record's int32 X and Y, rounded as ScaledCoordinate
/// (core/base/scaled_coordinate.hpp) says; Z and every other attribute are ignored. `crs` is the
/// OGC WKT of the first "LASF_Projection" record 2112, a VLR or (LAS 1.4) an EVLR, without its
/// trailing NULs. Without one, the GeoTIFF key directory (record 34735, a VLR) gives "EPSG:CODE":
/// ProjectedCSTypeGeoKey's code, or GeographicTypeGeoKey's where the model is geographic (or not
/// given, with no projected code). nullopt when neither names a CRS (a user-defined GeoTIFF CRS,
/// whose further keys are not interpreted, or a malformed directory).
/// Records are read in chunks of about 1 MiB, so memory is the points and one chunk. O(N).
///
/// Errors name the file: NotFound when it does not exist, errno-derived codes when it cannot be
/// opened or read, InvalidArgument when it is not a regular file or its header is not LAS 1.0-1.4
/// as the specification lays it out (the signature, the version, a header size too small for the
/// version, a point data offset inside the header or the VLRs, a compressed (LAZ) point format, a
/// point format over 10 or 6-10 before LAS 1.4, a record length smaller than the format's fields,
/// a zero, NaN or infinite scale or a non-finite offset, legacy and 64-bit point counts that
/// disagree), DataLoss when the file is shorter than the header, its VLRs or its point records
/// need (truncated), ResourceExhausted when it holds more than `max_points` points, decided from
/// the header before anything is allocated.
absl::StatusOr<GeoreferencedPoints> ReadLasPoints(const std::string& path,
                                                  uint64_t max_points = std::numeric_limits<uint64_t>::max());

}  // namespace galpha
