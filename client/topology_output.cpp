#include "client/topology_output.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "absl/strings/str_cat.h"
#include "client/text_output.hpp"
#include "core/io/json_text.hpp"

namespace galpha::alphactl {
namespace {

std::string JoinVertices(const std::vector<uint32_t>& vertices) {
  if (vertices.empty()) return "-";
  std::string out;
  for (size_t i = 0; i < vertices.size(); ++i) absl::StrAppend(&out, i == 0 ? "" : "-", vertices[i]);
  return out;
}

std::string RankText(int64_t rank) { return rank < 0 ? "-" : absl::StrCat(rank); }

void WriteLines(const std::vector<PersistenceRow>& rows, bool csv, ChunkedWriter& out) {
  const char separator = csv ? ',' : ' ';
  if (csv) out.Append("dimension,birth_alpha_sq,death_alpha_sq,birth_rank,death_rank,creator,killer\n");
  for (const PersistenceRow& row : rows) {
    if (!csv) out.Append('H');
    out.AppendUint(row.dimension);
    out.Append(separator);
    out.AppendDouble(row.birth);
    out.Append(separator);
    out.AppendDouble(row.death);  // "inf" when essential
    for (const std::string& field :
         {RankText(row.birth_rank), RankText(row.death_rank), JoinVertices(row.creator), JoinVertices(row.killer)}) {
      out.Append(separator);
      out.Append(field);
    }
    out.Append('\n');
  }
}

void WriteJsonLines(const std::vector<PersistenceRow>& rows, ChunkedWriter& out) {
  for (const PersistenceRow& row : rows) {
    const bool essential = row.death_rank < 0;
    // null for an essential class's death and killer.
    const nlohmann::ordered_json none;
    nlohmann::ordered_json json = {{"dimension", row.dimension},
                                   {"birth_alpha_sq", row.birth},
                                   {"death_alpha_sq", essential ? none : nlohmann::ordered_json(row.death)},
                                   {"birth_rank", row.birth_rank},
                                   {"death_rank", essential ? none : nlohmann::ordered_json(row.death_rank)},
                                   {"creator", row.creator},
                                   {"killer", essential ? none : nlohmann::ordered_json(row.killer)}};
    out.Append(JsonLine(json));
  }
}

// The plot: a square of kSide pixels inside kMargin, birth on x, death on y, both in alpha_sq from 0
// to the largest finite value; essential classes on a line kInfinityGap above the square's top.
void WriteSvg(const std::vector<PersistenceRow>& rows, ChunkedWriter& out) {
  constexpr double kSide = 400, kMargin = 56, kInfinityGap = 24, kTop = kMargin + kInfinityGap;
  double top = 0;
  for (const PersistenceRow& row : rows) {
    top = std::max(top, row.birth);
    if (std::isfinite(row.death)) top = std::max(top, row.death);
  }
  if (top <= 0) top = 1;
  const auto x = [&](double v) { return kMargin + kSide * v / top; };
  const auto y = [&](double v) { return kTop + kSide - kSide * v / top; };
  const double width = 2 * kMargin + kSide, height = kTop + kSide + kMargin;
  std::string svg =
      absl::StrCat(R"(<svg xmlns="http://www.w3.org/2000/svg" width=")", width, R"(" height=")", height,
                   R"(" viewBox="0 0 )", width, " ", height, R"(" font-family="sans-serif" font-size="12">)", "\n");
  absl::StrAppend(&svg, R"(<rect x="0" y="0" width=")", width, R"(" height=")", height, R"(" fill="white"/>)", "\n");
  // Axes, the diagonal and the infinity line.
  absl::StrAppend(&svg, R"(<path d="M)", x(0), " ", y(0), " H", x(top), " M", x(0), " ", y(0), " V", y(top),
                  R"(" stroke="black" fill="none"/>)", "\n");
  absl::StrAppend(&svg, R"(<path d="M)", x(0), " ", y(0), " L", x(top), " ", y(top),
                  R"(" stroke="#999" stroke-dasharray="4 3" fill="none"/>)", "\n");
  absl::StrAppend(&svg, R"(<path d="M)", x(0), " ", kMargin, " H", x(top),
                  R"(" stroke="#999" stroke-dasharray="2 3" fill="none"/>)", "\n");
  absl::StrAppend(&svg, R"(<text x=")", kMargin - 6, R"(" y=")", kMargin + 4, R"(" text-anchor="end">inf</text>)",
                  "\n");
  for (int tick = 0; tick <= 4; ++tick) {
    const double v = top * tick / 4;
    // Tick labels are a reading aid: three significant digits (the points carry the exact values
    // in the other formats).
    char label[32];
    std::snprintf(label, sizeof label, "%.3g", v);
    absl::StrAppend(&svg, R"(<text x=")", x(v), R"(" y=")", y(0) + 16, R"(" text-anchor="middle">)", label,
                    "</text>\n");
    absl::StrAppend(&svg, R"(<text x=")", x(0) - 6, R"(" y=")", y(v) + 4, R"(" text-anchor="end">)", label,
                    "</text>\n");
  }
  absl::StrAppend(&svg, R"(<text x=")", x(top / 2), R"(" y=")", y(0) + 34,
                  R"(" text-anchor="middle">birth (alpha_sq)</text>)", "\n");
  absl::StrAppend(&svg, R"(<text x="14" y=")", y(top / 2), R"(" text-anchor="middle" transform="rotate(-90 14 )",
                  y(top / 2), R"lit()">death (alpha_sq)</text>)lit", "\n");
  // Legend.
  absl::StrAppend(&svg, R"(<circle cx=")", x(0) + 12, R"(" cy="20" r="4" fill="#1f77b4"/><text x=")", x(0) + 20,
                  R"(" y="24">H0 (components)</text>)", "\n");
  absl::StrAppend(&svg, R"(<circle cx=")", x(0) + 152, R"(" cy="20" r="4" fill="#d62728"/><text x=")", x(0) + 160,
                  R"(" y="24">H1 (holes)</text>)", "\n");
  out.Append(svg);
  for (const PersistenceRow& row : rows) {
    const double cy = std::isfinite(row.death) ? y(row.death) : kMargin;
    std::string point = absl::StrCat(R"(<circle cx=")", x(row.birth), R"(" cy=")", cy, R"(" r="2.5" fill=")",
                                     row.dimension == 0 ? "#1f77b4" : "#d62728", R"(" fill-opacity="0.6"/>)", "\n");
    out.Append(point);
  }
  out.Append("</svg>\n");
}

/// The hole's ring counter-clockwise and closed (AssembleShape writes holes clockwise).
std::vector<uint32_t> OuterRingOf(const std::vector<uint32_t>& hole) {
  std::vector<uint32_t> ring(hole.rbegin(), hole.rend());
  if (!ring.empty()) ring.push_back(ring.front());
  return ring;
}

}  // namespace

absl::StatusOr<HolesFormat> ParseHolesFormat(absl::string_view name) {
  if (name == "text") return HolesFormat::kText;
  if (name == "geojson") return HolesFormat::kGeoJson;
  return absl::InvalidArgumentError(absl::StrCat("holes: unknown --format '", name, "' (text or geojson)"));
}

bool WriteHoles(const std::vector<ShapeHole>& holes, absl::Span<const Point2> points, HolesFormat format,
                std::FILE* out) {
  ChunkedWriter writer(out);
  if (format == HolesFormat::kText) {
    for (const ShapeHole& hole : holes) {
      writer.AppendDouble(hole.area);
      writer.Append(' ');
      writer.AppendUint(hole.polygon);
      writer.Append(" POLYGON ((");
      const std::vector<uint32_t> ring = OuterRingOf(hole.ring);
      for (size_t i = 0; i < ring.size(); ++i) {
        if (i > 0) writer.Append(", ");
        writer.AppendDouble(points[ring[i]].x);
        writer.Append(' ');
        writer.AppendDouble(points[ring[i]].y);
      }
      writer.Append("))\n");
    }
    return writer.Finish();
  }
  nlohmann::ordered_json features = nlohmann::ordered_json::array();
  for (const ShapeHole& hole : holes) {
    nlohmann::ordered_json ring = nlohmann::ordered_json::array();
    for (uint32_t v : OuterRingOf(hole.ring)) ring.push_back({points[v].x, points[v].y});
    features.push_back({{"type", "Feature"},
                        {"properties", {{"area", hole.area}, {"polygon", hole.polygon}}},
                        {"geometry", {{"type", "Polygon"}, {"coordinates", {ring}}}}});
  }
  std::string text = JsonText({{"type", "FeatureCollection"}, {"features", features}});
  text += '\n';
  writer.Append(text);
  return writer.Finish();
}

absl::StatusOr<PersistenceFormat> ParsePersistenceFormat(absl::string_view name) {
  if (name == "text") return PersistenceFormat::kText;
  if (name == "csv") return PersistenceFormat::kCsv;
  if (name == "json") return PersistenceFormat::kJson;
  if (name == "svg") return PersistenceFormat::kSvg;
  return absl::InvalidArgumentError(
      absl::StrCat("persistence: unknown --format '", name, "' (text, csv, json or svg)"));
}

bool WritePersistence(const std::vector<PersistenceRow>& rows, PersistenceFormat format, std::FILE* out) {
  ChunkedWriter writer(out);
  switch (format) {
    case PersistenceFormat::kText:
    case PersistenceFormat::kCsv:
      WriteLines(rows, format == PersistenceFormat::kCsv, writer);
      break;
    case PersistenceFormat::kJson:
      WriteJsonLines(rows, writer);
      break;
    case PersistenceFormat::kSvg:
      WriteSvg(rows, writer);
      break;
  }
  return writer.Finish();
}

}  // namespace galpha::alphactl
