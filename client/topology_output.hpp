// alphactl's topology outputs: the rows of a persistence diagram (from the local family or the
// Persistence RPC, the same either way) as text, CSV, JSON Lines or an SVG plot of the diagram, and
// the holes of a shape as WKT lines or GeoJSON.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"
#include "core/geometry/shape_holes.hpp"

namespace galpha::alphactl {

/// One class: its ranks (death_rank -1: essential), their published values (death +infinity when
/// essential) and its creating and killing simplices by sorted vertices (killer empty when
/// essential).
struct PersistenceRow {
  uint32_t dimension = 0;
  int64_t birth_rank = 0, death_rank = -1;
  double birth = 0, death = 0;
  std::vector<uint32_t> creator, killer;
};

enum class PersistenceFormat { kText, kCsv, kJson, kSvg };

/// "text", "csv", "json" or "svg"; InvalidArgument naming the value otherwise.
absl::StatusOr<PersistenceFormat> ParsePersistenceFormat(absl::string_view name);

/// Writes every row to `out`: text (one pair a line: 'H<d> BIRTH DEATH BIRTH_RANK DEATH_RANK
/// CREATOR KILLER', vertices joined by '-', 'inf' and '-' for an essential class), CSV (a header,
/// then the same fields), JSON Lines (one object a pair; null death and killer when essential) or
/// SVG (the diagram: birth against death in alpha_sq, one colour per dimension, the diagonal, and
/// essential classes on a line above the others). False when writing failed.
bool WritePersistence(const std::vector<PersistenceRow>& rows, PersistenceFormat format, std::FILE* out);

enum class HolesFormat { kText, kGeoJson };

/// "text" or "geojson"; InvalidArgument naming the value otherwise.
absl::StatusOr<HolesFormat> ParseHolesFormat(absl::string_view name);

/// Writes `holes` (ListHoles' order: largest first): text, one hole a line, 'AREA POLYGON WKT' (the
/// index of the polygon it belongs to, then the hole as a counter-clockwise WKT POLYGON), or a
/// GeoJSON FeatureCollection of Polygons with properties "area" and "polygon". False when writing
/// failed.
bool WriteHoles(const std::vector<ShapeHole>& holes, absl::Span<const Point2> points, HolesFormat format,
                std::FILE* out);

}  // namespace galpha::alphactl
