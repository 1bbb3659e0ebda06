#include "core/io/point_formats.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <system_error>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/base/status_macros.hpp"
#include "core/io/las_reader.hpp"
#include "core/io/point_io.hpp"
#include "core/io/vector_points.hpp"
#include "nlohmann/json.hpp"

namespace galpha {
namespace {

// Up to the first `wanted` fields of a line into `out`; returns how many it found. A line with a
// comma, semicolon or tab is split on that delimiter and keeps its empty fields ("1,,2" has an
// empty y, not y = 2); otherwise runs of spaces separate the fields.
int FirstFields(absl::string_view line, int wanted, absl::string_view* out) {
  const size_t delimiter_at = line.find_first_of(",;\t");
  std::vector<absl::string_view> fields;
  if (delimiter_at != absl::string_view::npos) {
    fields = absl::StrSplit(line, line[delimiter_at]);
  } else {
    fields = absl::StrSplit(line, ' ', absl::SkipWhitespace());
  }
  const int found = static_cast<int>(std::min<size_t>(fields.size(), static_cast<size_t>(wanted)));
  for (int i = 0; i < found; ++i) out[i] = absl::StripAsciiWhitespace(fields[static_cast<size_t>(i)]);
  return found;
}

bool ParseCoordinate(absl::string_view field, double* value) {
  // SimpleAtod also takes a leading '+', "inf" and "nan": the validation layer rejects the last two
  // with the point's index.
  return absl::SimpleAtod(field, value);
}

// The value of `key` in a .npy header dictionary ("{'descr': '<f8', 'fortran_order': False,
// 'shape': (3, 2), }"), up to the next top-level comma or the closing brace.
bool NpyHeaderValue(absl::string_view header, absl::string_view key, absl::string_view* value) {
  const std::string quoted = absl::StrCat("'", key, "'");
  size_t at = header.find(quoted);
  if (at == absl::string_view::npos) return false;
  at = header.find(':', at + quoted.size());
  if (at == absl::string_view::npos) return false;
  size_t end = at + 1;
  int depth = 0;
  for (; end < header.size(); ++end) {
    const char c = header[end];
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if (depth == 0 && (c == ',' || c == '}')) break;
  }
  *value = absl::StripAsciiWhitespace(header.substr(at + 1, end - at - 1));
  return true;
}

uint64_t LittleEndianUint(absl::string_view bytes, size_t offset, size_t width) {
  uint64_t v = 0;
  for (size_t i = 0; i < width; ++i) v |= uint64_t{static_cast<unsigned char>(bytes[offset + i])} << (8 * i);
  return v;
}

double DoubleAt(absl::string_view bytes, size_t offset, bool little_endian) {
  uint64_t bits = 0;
  for (size_t i = 0; i < 8; ++i) {
    const size_t byte = little_endian ? i : 7 - i;
    bits |= uint64_t{static_cast<unsigned char>(bytes[offset + i])} << (8 * byte);
  }
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

/// A group column of GeoJSON features: its property name, each point's value (output), and the
/// value of the feature being read.
struct GeoJsonGroups {
  std::string property;
  std::vector<std::optional<std::string>>* values = nullptr;
  std::optional<std::string> current;
};

/// A property's value as group text: strings as they are, other values as their JSON; nullopt for
/// null or a missing property.
std::optional<std::string> GroupText(const nlohmann::json& feature, const std::string& property) {
  if (!feature.contains("properties") || !feature["properties"].is_object()) return std::nullopt;
  const nlohmann::json& properties = feature["properties"];
  if (!properties.contains(property) || properties[property].is_null()) return std::nullopt;
  const nlohmann::json& value = properties[property];
  return value.is_string() ? value.get<std::string>() : value.dump();
}

// Appends the points of one GeoJSON object (geometry, feature or collection) at `where`.
absl::Status AppendGeoJsonPoints(const nlohmann::json& object, const std::string& where, const std::string& source,
                                 std::vector<Point2>* points, GeoJsonGroups* groups = nullptr) {
  auto error = [&](const std::string& what) {
    return absl::InvalidArgumentError(absl::StrCat(source, ": ", where.empty() ? "the document" : where, ": ", what));
  };
  auto position = [&](const nlohmann::json& p, const std::string& at) -> absl::Status {
    if (!p.is_array() || p.size() < 2 || p.size() > 3 || !p[0].is_number() || !p[1].is_number()) {
      return absl::InvalidArgumentError(
          absl::StrCat(source, ": ", at, ": a position must be an array of two or three numbers"));
    }
    points->push_back({p[0].get<double>(), p[1].get<double>()});
    if (groups != nullptr) groups->values->push_back(groups->current);
    return absl::OkStatus();
  };
  if (!object.is_object() || !object.contains("type") || !object["type"].is_string()) {
    return error("expected a GeoJSON object with a \"type\"");
  }
  const std::string type = object["type"].get<std::string>();
  const std::string prefix = where.empty() ? "" : absl::StrCat(where, ".");
  if (type == "FeatureCollection" || type == "GeometryCollection") {
    const char* member = type == "FeatureCollection" ? "features" : "geometries";
    if (!object.contains(member) || !object[member].is_array()) {
      return error(absl::StrCat(type, " without a \"", member, "\" array"));
    }
    const nlohmann::json& items = object[member];
    for (size_t i = 0; i < items.size(); ++i) {
      absl::Status status =
          AppendGeoJsonPoints(items[i], absl::StrCat(prefix, member, "[", i, "]"), source, points, groups);
      if (!status.ok()) return status;
    }
    return absl::OkStatus();
  }
  if (type == "Feature") {
    if (!object.contains("geometry")) return error("Feature without a \"geometry\"");
    if (object["geometry"].is_null()) return absl::OkStatus();  // an unlocated feature: no point
    if (groups != nullptr) groups->current = GroupText(object, groups->property);
    absl::Status status =
        AppendGeoJsonPoints(object["geometry"], absl::StrCat(prefix, "geometry"), source, points, groups);
    if (groups != nullptr) groups->current.reset();
    return status;
  }
  if (type == "Point" || type == "MultiPoint") {
    if (!object.contains("coordinates")) return error(absl::StrCat(type, " without \"coordinates\""));
    const nlohmann::json& coordinates = object["coordinates"];
    if (type == "Point") return position(coordinates, absl::StrCat(prefix, "coordinates"));
    if (!coordinates.is_array()) return error("MultiPoint coordinates must be an array of positions");
    for (size_t i = 0; i < coordinates.size(); ++i) {
      absl::Status status = position(coordinates[i], absl::StrCat(prefix, "coordinates[", i, "]"));
      if (!status.ok()) return status;
    }
    return absl::OkStatus();
  }
  return error(absl::StrCat("a ", type, " is not a point geometry (Point or MultiPoint)"));
}

}  // namespace

namespace {

/// The CRS a GeoJSON document states: RFC 7946's WGS84 longitude/latitude, unless a 2008-style
/// "crs" member names another (GDAL still writes one for other CRSs).
absl::StatusOr<std::string> GeoJsonCrs(const nlohmann::json& document, const std::string& source) {
  if (!document.is_object() || !document.contains("crs") || document["crs"].is_null()) return std::string("OGC:CRS84");
  const nlohmann::json& crs = document["crs"];
  const nlohmann::json* properties =
      crs.is_object() && crs.contains("properties") && crs["properties"].is_object() ? &crs["properties"] : nullptr;
  if (properties != nullptr && crs.value("type", "") == "name" && properties->contains("name") &&
      (*properties)["name"].is_string()) {
    return (*properties)["name"].get<std::string>();
  }
  if (properties != nullptr && crs.value("type", "") == "EPSG" && properties->contains("code") &&
      (*properties)["code"].is_number_integer()) {
    return absl::StrCat("EPSG:", (*properties)["code"].get<int64_t>());
  }
  return absl::InvalidArgumentError(
      absl::StrCat(source,
                   ": the crs member is neither {\"type\": \"name\", \"properties\": {\"name\": ...}} nor "
                   "{\"type\": \"EPSG\", \"properties\": {\"code\": ...}}"));
}

}  // namespace

absl::StatusOr<GeoreferencedPoints> ParseGeoreferencedGeoJson(absl::string_view text, const std::string& source,
                                                              const std::string& group_property) {
  nlohmann::json document;
  try {
    document = nlohmann::json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::parse_error& e) {
    return absl::InvalidArgumentError(absl::StrCat(source, ": not valid JSON at byte ", e.byte));
  } catch (const nlohmann::json::exception& e) {
    // A number beyond the range of a double (1e400) is valid JSON that nlohmann refuses with
    // out_of_range; found by the point-format fuzzer.
    return absl::InvalidArgumentError(absl::StrCat(source, ": JSON the parser cannot represent (", e.what(), ")"));
  }
  GeoreferencedPoints out;
  GeoJsonGroups groups{group_property, &out.groups, std::nullopt};
  const absl::Status status =
      AppendGeoJsonPoints(document, "", source, &out.points, group_property.empty() ? nullptr : &groups);
  if (!status.ok()) return status;
  if (!group_property.empty() && !out.points.empty() &&
      std::none_of(out.groups.begin(), out.groups.end(), [](const auto& g) { return g.has_value(); })) {
    return absl::InvalidArgumentError(
        absl::StrCat(source, ": no feature has a property '", group_property, "' (to group the points by)"));
  }
  absl::StatusOr<std::string> crs = GeoJsonCrs(document, source);
  if (!crs.ok()) return crs.status();
  out.crs = *std::move(crs);
  return out;
}

absl::StatusOr<std::vector<Point2>> ParsePointsGeoJson(absl::string_view text, const std::string& source) {
  absl::StatusOr<GeoreferencedPoints> read = ParseGeoreferencedGeoJson(text, source);
  if (!read.ok()) return read.status();
  return std::move(read->points);
}

namespace {

// Rows of (x, y) into points, rows of (x, y, weight) into weighted points.
std::vector<Point2> PointsOfRows(const std::vector<double>& values) {
  std::vector<Point2> points(values.size() / 2);
  for (size_t i = 0; i < points.size(); ++i) points[i] = {values[2 * i], values[2 * i + 1]};
  return points;
}

GeoreferencedPoints WeightedPointsOfRows(const std::vector<double>& values) {
  GeoreferencedPoints out;
  out.points.resize(values.size() / 3);
  out.weights.resize(values.size() / 3);
  for (size_t i = 0; i < out.points.size(); ++i) {
    out.points[i] = {values[3 * i], values[3 * i + 1]};
    out.weights[i] = values[3 * i + 2];
  }
  return out;
}

// Delimited text with `columns` numeric fields a record (x, y[, weight]), into `values` (row by
// row). The header rule and the errors of ParsePointsText, over the first `columns` fields.
absl::Status ParseTextColumns(absl::string_view text, const std::string& source, int columns,
                              std::vector<double>* values) {
  bool first_line = true;
  size_t line_number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_number;
    line = absl::StripAsciiWhitespace(line);  // also drops the '\r' of CRLF files
    if (line.empty() || line[0] == '#') continue;
    absl::string_view fields[3];
    double parsed[3] = {0.0, 0.0, 0.0};
    const int found = FirstFields(line, columns, fields);
    bool numeric = found == columns, some_text = false;
    for (int i = 0; i < found; ++i) {
      const bool number = ParseCoordinate(fields[i], &parsed[i]);
      numeric = numeric && number;
      some_text = some_text || !number;
    }
    // A header names its columns: one of its first fields is not a number.
    const bool header = first_line && some_text;
    first_line = false;
    if (header) continue;
    if (!numeric) {
      return absl::InvalidArgumentError(
          absl::StrCat(source, ":", line_number,
                       columns == 2 ? ": expected x and y as the first two numeric fields, got '"
                                    : ": expected x, y and a weight as the first three numeric fields, got '",
                       line.substr(0, 80), "'"));
    }
    values->insert(values->end(), parsed, parsed + columns);
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::vector<Point2>> ParsePointsText(absl::string_view text, const std::string& source) {
  std::vector<double> values;
  GALPHA_RETURN_IF_ERROR(ParseTextColumns(text, source, 2, &values));
  return PointsOfRows(values);
}

absl::StatusOr<GeoreferencedPoints> ParseWeightedPointsText(absl::string_view text, const std::string& source) {
  std::vector<double> values;
  GALPHA_RETURN_IF_ERROR(ParseTextColumns(text, source, 3, &values));
  return WeightedPointsOfRows(values);
}

namespace {

// A float64 .npy array of shape (N, columns), row by row into `values`.
absl::Status ParseNpyColumns(absl::string_view bytes, const std::string& source, uint64_t columns_wanted,
                             std::vector<double>* values) {
  constexpr absl::string_view kMagic("\x93NUMPY", 6);
  if (bytes.size() < 10 || bytes.substr(0, 6) != kMagic) {
    return absl::InvalidArgumentError(absl::StrCat(source, ": not a .npy file (no \\x93NUMPY magic)"));
  }
  const int major = static_cast<unsigned char>(bytes[6]);
  if (major < 1 || major > 3) {
    return absl::InvalidArgumentError(absl::StrCat(source, ": unsupported .npy format version ", major));
  }
  const size_t length_width = major == 1 ? 2 : 4;
  if (bytes.size() < 8 + length_width) {
    return absl::InvalidArgumentError(absl::StrCat(source, ": truncated .npy header"));
  }
  const uint64_t header_length = LittleEndianUint(bytes, 8, length_width);
  const uint64_t data_offset = 8 + length_width + header_length;
  if (data_offset > bytes.size()) {
    return absl::InvalidArgumentError(absl::StrCat(source, ": truncated .npy header"));
  }
  const absl::string_view header = bytes.substr(8 + length_width, header_length);
  absl::string_view descr, fortran, shape;
  if (!NpyHeaderValue(header, "descr", &descr) || !NpyHeaderValue(header, "fortran_order", &fortran) ||
      !NpyHeaderValue(header, "shape", &shape)) {
    return absl::InvalidArgumentError(absl::StrCat(source, ": malformed .npy header '", header, "'"));
  }
  bool little_endian;
  if (descr == "'<f8'" || descr == "'=f8'") {
    little_endian = true;
  } else if (descr == "'>f8'") {
    little_endian = false;
  } else {
    return absl::InvalidArgumentError(
        absl::StrCat(source, ": the array's dtype is ", descr, "; float64 ('<f8' or '>f8') is needed"));
  }
  if (fortran != "False" && fortran != "True") {
    return absl::InvalidArgumentError(absl::StrCat(source, ": malformed fortran_order ", fortran));
  }
  const bool fortran_order = fortran == "True";
  // shape: "(N, 2)"
  uint64_t n = 0, columns = 0;
  {
    absl::string_view inside = absl::StripAsciiWhitespace(shape);
    if (!absl::ConsumePrefix(&inside, "(") || !absl::ConsumeSuffix(&inside, ")")) {
      return absl::InvalidArgumentError(absl::StrCat(source, ": malformed .npy shape ", shape));
    }
    std::vector<absl::string_view> dims = absl::StrSplit(inside, ',', absl::SkipWhitespace());
    if (dims.size() != 2 || !absl::SimpleAtoi(absl::StripAsciiWhitespace(dims[0]), &n) ||
        !absl::SimpleAtoi(absl::StripAsciiWhitespace(dims[1]), &columns) || columns != columns_wanted) {
      return absl::InvalidArgumentError(absl::StrCat(source, ": the array's shape is ", shape, "; (N, ", columns_wanted,
                                                     ") is needed",
                                                     columns_wanted == 3 ? " (x, y and a weight a row)" : ""));
    }
  }
  const uint64_t data_bytes = bytes.size() - data_offset;
  const uint64_t row_bytes = 8 * columns_wanted;
  if (n > data_bytes / row_bytes || data_bytes != n * row_bytes) {
    return absl::DataLossError(absl::StrCat(source, ": the .npy header announces ", n, " points (", n * row_bytes,
                                            " bytes) but the file holds ", data_bytes, " bytes of data"));
  }
  values->resize(n * columns_wanted);
  for (uint64_t i = 0; i < n; ++i) {
    for (uint64_t c = 0; c < columns_wanted; ++c) {
      const uint64_t at = fortran_order ? c * n + i : columns_wanted * i + c;
      (*values)[columns_wanted * i + c] = DoubleAt(bytes, data_offset + 8 * at, little_endian);
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::vector<Point2>> ParsePointsNpy(absl::string_view bytes, const std::string& source) {
  std::vector<double> values;
  GALPHA_RETURN_IF_ERROR(ParseNpyColumns(bytes, source, 2, &values));
  return PointsOfRows(values);
}

absl::StatusOr<GeoreferencedPoints> ParseWeightedPointsNpy(absl::string_view bytes, const std::string& source) {
  std::vector<double> values;
  GALPHA_RETURN_IF_ERROR(ParseNpyColumns(bytes, source, 3, &values));
  return WeightedPointsOfRows(values);
}

absl::StatusOr<GeoreferencedPoints> ParseWeightedGeoJson(absl::string_view text, const std::string& source,
                                                         const std::string& weight_property) {
  if (weight_property.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(source, ": name the feature property that holds the weights"));
  }
  absl::StatusOr<GeoreferencedPoints> read = ParseGeoreferencedGeoJson(text, source, weight_property);
  if (!read.ok()) {
    // The group reader's word for a property that no feature has.
    if (absl::StrContains(read.status().message(), "(to group the points by)")) {
      return absl::InvalidArgumentError(
          absl::StrCat(source, ": no feature has a property '", weight_property, "' (to take the weights from)"));
    }
    return read.status();
  }
  GeoreferencedPoints out = *std::move(read);
  out.weights.resize(out.points.size());
  for (size_t i = 0; i < out.points.size(); ++i) {
    const std::optional<std::string>& value = out.groups[i];
    if (!value.has_value() || !absl::SimpleAtod(*value, &out.weights[i])) {
      return absl::InvalidArgumentError(absl::StrCat(source, ": point ", i, " (in document order) has ",
                                                     value.has_value() ? absl::StrCat("'", *value, "' as") : "no",
                                                     " property '", weight_property,
                                                     "': every point's feature needs a numeric weight there"));
    }
  }
  out.groups.clear();
  return out;
}

absl::StatusOr<std::vector<Point2>> ReadPointsFile(const std::string& path) {
  absl::StatusOr<GeoreferencedPoints> read = ReadGeoreferencedPointsFile(path);
  if (!read.ok()) return read.status();
  return std::move(read->points);
}

absl::StatusOr<GeoreferencedPoints> ReadGeoreferencedPointsFile(const std::string& path) {
  const std::string extension = absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    return absl::NotFoundError(absl::StrCat("points file '", path, "' does not exist"));
  }
  // A directory opens as a stream on Linux and fails only when read (by exception).
  if (std::filesystem::is_directory(path, error)) {
    return absl::InvalidArgumentError(absl::StrCat("points file '", path, "' is a directory"));
  }
  // Formats without a CRS.
  auto plain = [](absl::StatusOr<std::vector<Point2>> points) -> absl::StatusOr<GeoreferencedPoints> {
    if (!points.ok()) return points.status();
    GeoreferencedPoints out;
    out.points = *std::move(points);
    return out;
  };
  if (extension == ".bin") return plain(ReadPointsBin(path));
  if (extension == ".las") return ReadLasPoints(path);
  if (extension == ".laz") {
    return absl::InvalidArgumentError(
        absl::StrCat("points file '", path, "' is compressed LAS (LAZ), which is not read: decompress it to .las"));
  }
  if (IsVectorPointsExtension(extension)) {
    return absl::InvalidArgumentError(absl::StrCat("points file '", path,
                                                   "' is a GDAL vector source: read it with ReadVectorPoints "
                                                   "(core/io/vector_points.hpp, the galpha_vector_io library)"));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::ErrnoToStatus(errno, absl::StrCat("cannot open points file '", path, "'"));
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return absl::DataLossError(absl::StrCat("cannot read points file '", path, "'"));
  if (extension == ".npy") return plain(ParsePointsNpy(bytes, path));
  if (extension == ".geojson" || extension == ".json") return ParseGeoreferencedGeoJson(bytes, path);
  return plain(ParsePointsText(bytes, path));
}

absl::StatusOr<GeoreferencedPoints> ReadWeightedPointsFile(const std::string& path,
                                                           const std::string& weight_property) {
  const std::string extension = absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  const bool geojson = extension == ".geojson" || extension == ".json";
  if (geojson && weight_property.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("points file '", path, "' is GeoJSON: name the property that holds the weights"));
  }
  if (!geojson && !weight_property.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("a weight property applies to GeoJSON features, not to points file '", path, "'"));
  }
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    return absl::NotFoundError(absl::StrCat("points file '", path, "' does not exist"));
  }
  if (std::filesystem::is_directory(path, error)) {
    return absl::InvalidArgumentError(absl::StrCat("points file '", path, "' is a directory"));
  }
  if (extension == ".bin") return ReadWeightedPointsBin(path);
  if (extension == ".las" || extension == ".laz" || IsVectorPointsExtension(extension)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "points file '", path,
        "' holds no weights galpha reads: weighted points come as delimited text (x, y, weight), .npy (N, 3), "
        "weighted .bin or GeoJSON with a weight property"));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::ErrnoToStatus(errno, absl::StrCat("cannot open points file '", path, "'"));
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return absl::DataLossError(absl::StrCat("cannot read points file '", path, "'"));
  if (extension == ".npy") return ParseWeightedPointsNpy(bytes, path);
  if (geojson) return ParseWeightedGeoJson(bytes, path, weight_property);
  return ParseWeightedPointsText(bytes, path);
}

}  // namespace galpha
