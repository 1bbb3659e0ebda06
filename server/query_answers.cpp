#include "server/query_answers.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/family/area_ratio.hpp"
#include "core/family/canonical_order.hpp"
#include "core/family/classification_summary.hpp"
#include "core/geometry/shape_holes.hpp"

namespace galpha::server {

namespace v1 = galpha::v1;

namespace {

v1::ClassCounts ToClassCounts(const std::array<uint64_t, 4>& counts) {
  v1::ClassCounts out;
  out.set_exterior(counts[0]);
  out.set_singular(counts[1]);
  out.set_regular(counts[2]);
  out.set_interior(counts[3]);
  return out;
}

char ClassByte(SimplexClass c) { return static_cast<char>(static_cast<int>(c) + 1); }

class ClassifySource final : public ChunkSource<v1::ClassifyResponse> {
 public:
  /// The chunks numbered part, part + parts, ... of the answer (all of them with parts 1); the
  /// summary first in part 0 only (`counts`, `topology` and `hull_area` are not read in the others).
  ClassifySource(std::shared_ptr<const CachedFamily> cached, std::shared_ptr<const Classification> classes,
                 ClassificationSummary counts, ResolvedLevel level, TopologyAtLevel topology, double hull_area,
                 ClassifyMode mode, bool non_exterior_only, bool summary_only, uint32_t part, uint32_t parts)
      : cached_(std::move(cached)),
        classes_(std::move(classes)),
        counts_(counts),
        level_(level),
        topology_(topology),
        hull_area_(hull_area),
        mode_(mode),
        non_exterior_only_(non_exterior_only),
        part_(part),
        parts_(parts),
        phase_(summary_only ? Phase::kLastSummary
               : part == 0  ? Phase::kSummary
                            : Phase::kVertices) {}

  bool Next(v1::ClassifyResponse* message) override {
    message->Clear();
    const FamilyReader& family = cached_->reader();
    while (true) {
      switch (phase_) {
        case Phase::kSummary:
        case Phase::kLastSummary:
          FillSummary(message->mutable_summary());
          phase_ = phase_ == Phase::kSummary ? Phase::kVertices : Phase::kDone;
          return true;
        case Phase::kVertices:
          if (FillChunk(message, v1::SIMPLEX_KIND_VERTEX, 1, family.points().size(), [&](size_t v, uint32_t* out) {
                if (family.representative()[v] != v)
                  return std::pair<SimplexClass, bool>{SimplexClass::kExterior, false};
                out[0] = static_cast<uint32_t>(v);
                return Emit(classes_->vertices[v]);
              })) {
            if (ChunkIsMine()) return true;
            break;
          }
          phase_ = Phase::kEdges;
          position_ = 0;
          break;
        case Phase::kEdges:
          if (FillOrdered(message, v1::SIMPLEX_KIND_EDGE, 2, cached_->EdgeVerticesInOrder(), cached_->EdgeOrder(),
                          classes_->edges)) {
            if (ChunkIsMine()) return true;
            break;
          }
          phase_ = Phase::kTriangles;
          position_ = 0;
          break;
        case Phase::kTriangles:
          if (FillOrdered(message, v1::SIMPLEX_KIND_TRIANGLE, 3, cached_->TriangleVerticesInOrder(),
                          cached_->TriangleOrder(), classes_->triangles)) {
            if (ChunkIsMine()) return true;
            break;
          }
          phase_ = Phase::kDone;
          break;
        case Phase::kDone:
          return false;
      }
    }
  }

 private:
  enum class Phase { kSummary, kLastSummary, kVertices, kEdges, kTriangles, kDone };

  // Whether the chunk just passed belongs to this part (it was filled, else only skipped), counting it.
  bool ChunkIsMine() { return chunk_++ % parts_ == part_; }
  // Whether the next chunk is another part's: it is then skipped (its simplices passed, not copied).
  bool SkipNext() const { return chunk_ % parts_ != part_; }

  // What a simplex contributes: its class, and whether it is sent.
  std::pair<SimplexClass, bool> Emit(SimplexClass c) const {
    return {c, !(non_exterior_only_ && c == SimplexClass::kExterior)};
  }

  void FillSummary(v1::ClassifySummary* summary) const {
    summary->set_level(level_.level);
    summary->set_alpha_sq(level_.alpha_sq);
    *summary->mutable_vertices() = ToClassCounts(counts_.vertices);
    *summary->mutable_edges() = ToClassCounts(counts_.edges);
    *summary->mutable_triangles() = ToClassCounts(counts_.triangles);
    summary->set_components(topology_.components);
    summary->set_solid_components(topology_.solid_components);
    summary->set_interior_area(counts_.interior_area);
    summary->set_holes(mode_ == ClassifyMode::kGeneral ? topology_.holes : topology_.regularized_holes);
    summary->set_hull_area(hull_area_);
  }

  // Fills one chunk of edges or triangles from position_ on: the ordered vertices are copied in a
  // run and the classes gathered through the order; with non_exterior_only, item by item.
  bool FillOrdered(v1::ClassifyResponse* message, v1::SimplexKind kind, int arity,
                   const std::vector<uint32_t>& vertices, const std::vector<uint32_t>& order,
                   const std::vector<SimplexClass>& classes) {
    const size_t count = order.size();
    if (non_exterior_only_) {
      return FillChunk(message, kind, arity, count, [&](size_t i, uint32_t* out) {
        for (int k = 0; k < arity; ++k) out[k] = vertices[i * static_cast<size_t>(arity) + static_cast<size_t>(k)];
        return Emit(classes[order[i]]);
      });
    }
    if (position_ >= count) return false;
    const size_t n = std::min<size_t>(kSimplicesPerChunk, count - position_);
    if (SkipNext()) {
      position_ += n;
      return true;
    }
    const size_t a = static_cast<size_t>(arity);
    v1::SimplexChunk* chunk = message->mutable_chunk();
    chunk->set_kind(kind);
    chunk->mutable_vertex_indices()->Resize(static_cast<int>(n * a), 0);
    std::memcpy(chunk->mutable_vertex_indices()->mutable_data(), vertices.data() + position_ * a,
                n * a * sizeof(uint32_t));
    std::string* bytes = chunk->mutable_classes();
    bytes->resize(n);
    char* out = bytes->data();
    const uint32_t* ids = order.data() + position_;
    for (size_t j = 0; j < n; ++j) out[j] = ClassByte(classes[ids[j]]);
    position_ += n;
    return true;
  }

  // Fills one chunk of `kind` from items position_..count-1; `item(i, out)` writes `arity`
  // indices and returns (class, sent). Returns whether the chunk holds anything.
  template <typename Item>
  bool FillChunk(v1::ClassifyResponse* message, v1::SimplexKind kind, int arity, size_t count, Item item) {
    if (SkipNext()) {
      // Another part's chunk: its simplices are passed, counting those it sends, into a scratch.
      std::array<uint32_t, 3> scratch{};
      size_t sent = 0;
      for (; position_ < count && sent < kSimplicesPerChunk; ++position_) {
        if (item(position_, scratch.data()).second) ++sent;
      }
      return sent > 0;
    }
    v1::SimplexChunk* chunk = message->mutable_chunk();
    chunk->set_kind(kind);
    auto* indices = chunk->mutable_vertex_indices();
    std::string* classes = chunk->mutable_classes();
    const size_t budget = std::min<size_t>(kSimplicesPerChunk, count - std::min(position_, count));
    indices->Resize(static_cast<int>(budget * static_cast<size_t>(arity)), 0);
    classes->resize(budget);
    uint32_t* out = indices->mutable_data();
    size_t sent = 0;
    for (; position_ < count && sent < kSimplicesPerChunk; ++position_) {
      const auto [cls, emit] = item(position_, out + sent * static_cast<size_t>(arity));
      if (!emit) continue;
      (*classes)[sent] = ClassByte(cls);
      ++sent;
    }
    indices->Truncate(static_cast<int>(sent * static_cast<size_t>(arity)));
    classes->resize(sent);
    if (sent == 0) {
      message->clear_chunk();
      return false;
    }
    return true;
  }

  std::shared_ptr<const CachedFamily> cached_;
  std::shared_ptr<const Classification> classes_;
  ClassificationSummary counts_;
  ResolvedLevel level_;
  TopologyAtLevel topology_;
  double hull_area_;
  ClassifyMode mode_;
  bool non_exterior_only_;
  uint32_t part_, parts_;
  Phase phase_;
  size_t position_ = 0;
  uint64_t chunk_ = 0;  // chunks of the whole answer passed so far (sent by this part or skipped)
};

class MasterListSource final : public ChunkSource<v1::MasterListResponse> {
 public:
  /// `begins`: master_begin[first..last + 1]; `entries`: the entries of ranks first..last.
  MasterListSource(std::shared_ptr<const CachedFamily> cached, int64_t first, std::vector<uint32_t> begins,
                   std::vector<MasterEntry> entries)
      : cached_(std::move(cached)), first_(first), begins_(std::move(begins)), entries_(std::move(entries)) {}

  bool Next(v1::MasterListResponse* message) override {
    message->Clear();
    if (position_ >= entries_.size()) return false;
    const FamilyReader& family = cached_->reader();
    const size_t offset = begins_[0];
    const size_t count = std::min<size_t>(kMasterEntriesPerChunk, entries_.size() - position_);
    message->mutable_ranks()->Reserve(static_cast<int>(count));
    message->mutable_vertex_indices()->Reserve(static_cast<int>(count * 3));
    std::string* kinds = message->mutable_kinds();
    std::string* endpoints = message->mutable_endpoints();
    for (size_t i = 0; i < count; ++i, ++position_) {
      while (offset + position_ >= begins_[rank_index_ + 1]) ++rank_index_;
      const MasterEntry entry = entries_[position_];
      message->add_ranks(static_cast<uint64_t>(first_ + static_cast<int64_t>(rank_index_)));
      kinds->push_back(static_cast<char>(static_cast<int>(entry.kind()) + 1));
      endpoints->push_back(static_cast<char>(static_cast<int>(entry.endpoint()) + 1));
      switch (entry.kind()) {
        case SimplexKind::kVertex:
          message->add_vertex_indices(entry.id());
          break;
        case SimplexKind::kEdge:
          for (uint32_t v : SortedEdge(family.edges()[entry.id()])) message->add_vertex_indices(v);
          break;
        case SimplexKind::kTriangle:
          for (uint32_t v : SortedTriangle(family.triangles()[entry.id()])) message->add_vertex_indices(v);
          break;
      }
    }
    return true;
  }

 private:
  std::shared_ptr<const CachedFamily> cached_;
  int64_t first_;
  std::vector<uint32_t> begins_;
  std::vector<MasterEntry> entries_;
  size_t rank_index_ = 0;
  size_t position_ = 0;
};

class ShapeTextSource final : public ChunkSource<v1::ShapeResponse> {
 public:
  explicit ShapeTextSource(std::string text) : text_(std::move(text)) {}
  bool Next(v1::ShapeResponse* message) override {
    message->Clear();
    if (position_ >= text_.size()) return false;
    const size_t count = std::min(kShapeTextBytesPerChunk, text_.size() - position_);
    message->set_text(text_.substr(position_, count));
    position_ += count;
    return true;
  }

 private:
  std::string text_;
  size_t position_ = 0;
};

class ShapeRingsSource final : public ChunkSource<v1::ShapeResponse> {
 public:
  explicit ShapeRingsSource(ShapeGeometry shape) : shape_(std::move(shape)) {}
  bool Next(v1::ShapeResponse* message) override {
    message->Clear();
    const bool first = !started_;
    started_ = true;
    if (!first && polygon_ >= shape_.polygons.size() && edge_ >= shape_.singular_edges.size() &&
        point_ >= shape_.isolated_points.size()) {
      return false;
    }
    v1::ShapeRings* rings = message->mutable_rings();
    if (first) rings->set_area(shape_.area);
    size_t indices = 0;
    for (; polygon_ < shape_.polygons.size() && indices < kShapeIndicesPerChunk; ++polygon_) {
      const ShapePolygon& polygon = shape_.polygons[polygon_];
      v1::ShapePolygon* out = rings->add_polygons();
      out->mutable_outer()->Add(polygon.outer.begin(), polygon.outer.end());
      indices += polygon.outer.size();
      for (const auto& hole : polygon.holes) {
        out->add_holes()->mutable_vertex_indices()->Add(hole.begin(), hole.end());
        indices += hole.size();
      }
    }
    for (; edge_ < shape_.singular_edges.size() && indices < kShapeIndicesPerChunk; ++edge_, indices += 2) {
      rings->add_singular_edges(shape_.singular_edges[edge_][0]);
      rings->add_singular_edges(shape_.singular_edges[edge_][1]);
    }
    for (; point_ < shape_.isolated_points.size() && indices < kShapeIndicesPerChunk; ++point_, ++indices) {
      rings->add_isolated_points(shape_.isolated_points[point_]);
    }
    return true;
  }

 private:
  ShapeGeometry shape_;
  bool started_ = false;
  size_t polygon_ = 0, edge_ = 0, point_ = 0;
};

}  // namespace

absl::StatusOr<ResolvedLevel> ResolveLevel(const FamilyReader& family, const v1::Threshold& threshold) {
  Threshold t;
  switch (threshold.value_case()) {
    case v1::Threshold::kRank:
      t.kind = Threshold::Kind::kRank;
      t.rank = threshold.rank();
      break;
    case v1::Threshold::kAlphaSq:
      t.kind = Threshold::Kind::kAlphaSq;
      t.value = threshold.alpha_sq();
      break;
    case v1::Threshold::kAlpha:
      t.kind = Threshold::Kind::kAlpha;
      t.value = threshold.alpha();
      break;
    case v1::Threshold::kRatio:
      t.kind = Threshold::Kind::kRatio;
      t.value = threshold.ratio();
      break;
    case v1::Threshold::VALUE_NOT_SET:
      return absl::InvalidArgumentError("the request has no threshold: set alpha_sq, alpha, rank or ratio");
  }
  return family.Resolve(t);
}

absl::StatusOr<ClassifyMode> ToClassifyMode(v1::ClassifyMode mode) {
  switch (mode) {
    case v1::CLASSIFY_MODE_UNSPECIFIED:
    case v1::CLASSIFY_MODE_GENERAL:
      return ClassifyMode::kGeneral;
    case v1::CLASSIFY_MODE_REGULARIZED:
      return ClassifyMode::kRegularized;
    default:
      return absl::InvalidArgumentError(absl::StrCat(
          "mode ", static_cast<int>(mode), " is not a ClassifyMode (GENERAL = 1 or REGULARIZED = 2; 0 means GENERAL)"));
  }
}

absl::StatusOr<VertexRule> ToVertexRule(v1::VertexRule rule) {
  switch (rule) {
    case v1::VERTEX_RULE_UNSPECIFIED:
    case v1::VERTEX_RULE_REPORT:
      return VertexRule::kReport;
    case v1::VERTEX_RULE_CGAL:
      return VertexRule::kCgal;
    default:
      return absl::InvalidArgumentError(absl::StrCat("vertex_rule ", static_cast<int>(rule),
                                                     " is not a VertexRule (REPORT = 1 or CGAL = 2; 0 means REPORT)"));
  }
}

void FillBuildSummary(const CachedFamily& cached, v1::BuildSummary* summary) {
  const FamilyReader& family = cached.reader();
  summary->set_points(family.points().size());
  summary->set_distinct_points(family.num_unique());
  summary->set_duplicates(family.points().size() - family.num_unique());
  summary->set_triangles(family.triangles().size());
  summary->set_edges(family.edges().size());
  summary->set_spectrum_size(static_cast<uint64_t>(family.max_level()));
  const BuildReport& report = family.report();
  summary->set_backend(report.backend);
  for (const StageTime& stage : report.stage_times) {
    v1::StageTime* out = summary->add_stage_times();
    out->set_stage(stage.stage);
    out->set_seconds(stage.seconds);
  }
  summary->mutable_comparisons()->set_filter(report.comparisons.filter);
  summary->mutable_comparisons()->set_device_exact(report.comparisons.bounded_exact);
  summary->mutable_comparisons()->set_cpu_fallback(report.comparisons.cpu_fallback);
  summary->set_peak_memory_bytes(report.peak_memory_bytes);
  summary->set_family_bytes(cached.bytes());
  summary->set_family_device_bytes(cached.device_bytes());
  if (const auto frame = cached.Frame()) summary->set_projection(frame->projection);
  summary->set_weighted(family.weighted());
  if (family.weighted()) {
    // Counted from the flags: HiddenPoints() would build the whole list for its length.
    uint64_t hidden = 0;
    for (const uint8_t flag : family.hidden_flags()) hidden += flag != 0 ? 1 : 0;
    summary->set_hidden_points(hidden);
  }
}

absl::StatusOr<std::unique_ptr<ChunkSource<v1::ClassifyResponse>>> MakeClassifySource(
    std::shared_ptr<const CachedFamily> cached, const v1::ClassifyRequest& request) {
  const FamilyReader& family = cached->reader();
  const absl::StatusOr<ClassifyMode> mode = ToClassifyMode(request.mode());
  if (!mode.ok()) return mode.status();
  const absl::StatusOr<VertexRule> rule = ToVertexRule(request.vertex_rule());
  if (!rule.ok()) return rule.status();
  if (!v1::SimplexEncoding_IsValid(request.simplex_encoding())) {
    return absl::InvalidArgumentError(absl::StrCat("simplex_encoding ", static_cast<int>(request.simplex_encoding()),
                                                   " is not a SimplexEncoding (RAW = 1, DELTA = 2, DELTA_ZSTD = 3; 0 "
                                                   "means RAW)"));
  }
  const uint32_t parts = std::max<uint32_t>(request.part_count(), 1);
  if (parts > kMaxClassifyParts) {
    return absl::InvalidArgumentError(absl::StrCat("part_count ", request.part_count(), " is over ", kMaxClassifyParts,
                                                   ", the most parts an answer is split into"));
  }
  if (request.part_index() >= parts) {
    return absl::InvalidArgumentError(absl::StrCat("part_index ", request.part_index(), " is not below part_count ",
                                                   parts, request.part_count() == 0 ? " (0: the whole answer)" : ""));
  }
  if (parts > 1 && request.summary_only()) {
    return absl::InvalidArgumentError(
        absl::StrCat("a summary_only answer has no chunks to split into ", parts, " parts: ask for part_count 0"));
  }
  auto level = ResolveLevel(family, request.threshold());
  if (!level.ok()) return level.status();
  // Shared with the other parts of a split answer (and any identical Classify at the same time).
  absl::StatusOr<std::shared_ptr<const Classification>> classes =
      cached->SharedClassification(level->level, *mode, *rule);
  if (!classes.ok()) return classes.status();
  ClassificationSummary counts;
  TopologyAtLevel topology;
  double hull_area = 0.0;
  if (request.part_index() == 0) {  // the part that sends the summary
    counts = SummarizeClassification(family.representative(), cached->TriangleAreaTerms(), **classes);
    const absl::StatusOr<std::vector<TopologyAtLevel>> topologies = family.TopologyBetween(level->level, level->level);
    if (!topologies.ok()) return topologies.status();
    topology = topologies->front();
    const absl::StatusOr<double> hull = family.HullAreaApprox();
    if (!hull.ok()) return hull.status();
    hull_area = *hull;
  }
  return std::make_unique<ClassifySource>(std::move(cached), *std::move(classes), counts, *level, topology, hull_area,
                                          *mode, request.non_exterior_only(), request.summary_only(),
                                          request.part_index(), parts);
}

absl::StatusOr<std::unique_ptr<ChunkSource<v1::MasterListResponse>>> MakeMasterListSource(
    std::shared_ptr<const CachedFamily> cached, const v1::MasterListRequest& request) {
  const FamilyReader& family = cached->reader();
  const int64_t k = family.max_level();
  const int64_t first = request.first_rank();
  const int64_t last = request.last_rank() == 0 ? first : request.last_rank();
  if (k == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("rank ", first, " is out of range: the spectrum is empty, the master list has no ranks"));
  }
  if (first < 1 || first > k) {
    return absl::InvalidArgumentError(
        absl::StrCat("first_rank ", first, " is outside 1..", k, " (the spectrum has ", k, " values)"));
  }
  if (last < first || last > k) {
    return absl::InvalidArgumentError(absl::StrCat("last_rank ", last, " is outside ", first, "..", k));
  }
  absl::StatusOr<std::vector<uint32_t>> begins = family.MasterBegins(first, last - first + 2);
  if (!begins.ok()) return begins.status();
  absl::StatusOr<std::vector<MasterEntry>> entries =
      family.MasterEntries(begins->front(), begins->back() - begins->front());
  if (!entries.ok()) return entries.status();
  return std::make_unique<MasterListSource>(std::move(cached), first, *std::move(begins), *std::move(entries));
}

// The shared_ptr is taken by value like every Make*Source's (one signature for the service's
// query helper), though this one only reads through it.
absl::StatusOr<std::unique_ptr<ChunkSource<v1::ShapeResponse>>> MakeShapeSource(
    std::shared_ptr<const CachedFamily> cached,  // NOLINT(performance-unnecessary-value-param)
    const v1::ShapeRequest& request) {
  if (request.format() == v1::SHAPE_FORMAT_UNSPECIFIED) {
    return absl::InvalidArgumentError("the shape request has no format: GEOJSON, WKT, SVG or RINGS");
  }
  const absl::StatusOr<ClassifyMode> mode = ToClassifyMode(request.mode());
  if (!mode.ok()) return mode.status();
  const FamilyReader& family = cached->reader();
  auto level = ResolveLevel(family, request.threshold());
  if (!level.ok()) return level.status();
  const double min_hole_area = request.min_hole_area();
  if (std::isnan(min_hole_area) || min_hole_area < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("min_hole_area ", min_hole_area, " is not an area: give 0 (keep every hole) or more"));
  }
  // A resident family's boundary is found where its tables live.
  absl::StatusOr<ShapeGeometry> shape = family.ShapeAt(level->level, *mode);
  if (!shape.ok()) return shape.status();
  // Areas in the family's units (metres for a projected geographic set).
  if (min_hole_area > 0) FillHolesSmallerThan(&*shape, family.points(), min_hole_area);
  // Text geometry in the points as sent, GeoJSON in WGS84 longitude/latitude (the header's CRS).
  const auto frame = cached->Frame();
  absl::Span<const Point2> points = family.points();
  if (frame != nullptr && !frame->input.empty()) points = frame->input;
  std::vector<Point2> lonlat;
  if (frame != nullptr && request.format() == v1::SHAPE_FORMAT_GEOJSON) {
    absl::StatusOr<std::vector<Point2>> converted = ToWgs84LonLat(frame->crs, points);
    if (!converted.ok()) return converted.status();
    lonlat = *std::move(converted);
    points = lonlat;
  }
  const std::string crs_label = frame == nullptr ? std::string() : CoordinatesLabel(frame->crs);
  switch (request.format()) {
    case v1::SHAPE_FORMAT_GEOJSON:
      return std::make_unique<ShapeTextSource>(ShapeToGeoJson(*shape, points));
    case v1::SHAPE_FORMAT_WKT:
      return std::make_unique<ShapeTextSource>(ShapeToWkt(*shape, points));
    case v1::SHAPE_FORMAT_SVG:
      return std::make_unique<ShapeTextSource>(ShapeToSvg(*shape, points, crs_label));
    case v1::SHAPE_FORMAT_RINGS:
      return std::make_unique<ShapeRingsSource>(*std::move(shape));
    default:
      return absl::InvalidArgumentError(absl::StrCat("unknown shape format ", static_cast<int>(request.format())));
  }
}

absl::StatusOr<v1::SpectrumResponse> AnswerSpectrum(const FamilyReader& family, const v1::SpectrumRequest& request) {
  const int64_t k = family.max_level();
  int64_t first = 1;
  switch (request.start_case()) {
    case v1::SpectrumRequest::kFirstRank:
      first = request.first_rank();
      if (first < 1 || first > k + 1) {
        return absl::InvalidArgumentError(absl::StrCat("first_rank ", first, " is outside 1..", k + 1));
      }
      break;
    case v1::SpectrumRequest::kAtLeastAlphaSq:
      if (std::isnan(request.at_least_alpha_sq())) return absl::InvalidArgumentError("at_least_alpha_sq is NaN");
      if (const absl::StatusOr<int64_t> bound = family.RankLowerBound(request.at_least_alpha_sq()); bound.ok()) {
        first = *bound;
      } else {
        return bound.status();
      }
      break;
    case v1::SpectrumRequest::START_NOT_SET:
      break;
  }
  uint32_t page = request.page_size() == 0 ? kDefaultSpectrumPage : request.page_size();
  if (page > kMaxSpectrumPage) {
    return absl::InvalidArgumentError(absl::StrCat("page_size ", page, " exceeds the largest page, ", kMaxSpectrumPage,
                                                   " values (0 asks for the default, ", kDefaultSpectrumPage,
                                                   "): page through the spectrum with first_rank and next_rank"));
  }
  v1::SpectrumResponse response;
  response.set_first_rank(first);
  response.set_spectrum_size(k);
  const int64_t end = std::min<int64_t>(k, first - 1 + page);  // last rank on the page
  if (end >= first) {
    const absl::StatusOr<std::vector<double>> values = family.Spectrum(first - 1, end - first + 1);
    if (!values.ok()) return values.status();
    response.mutable_alpha_sq()->Add(values->begin(), values->end());
  }
  response.set_next_rank(end < k ? end + 1 : 0);
  return response;
}

namespace {

/// Levels first..last of a request for a threshold or a rank range (Components, Betti).
struct LevelRange {
  int64_t first = 0, last = 0;
};

template <typename Request>
absl::StatusOr<LevelRange> ResolveLevelRange(const FamilyReader& family, const Request& request) {
  if (request.has_threshold()) {
    auto level = ResolveLevel(family, request.threshold());
    if (!level.ok()) return level.status();
    return LevelRange{level->level, level->level};
  }
  if (!request.has_ranks()) return absl::InvalidArgumentError("the request has neither a threshold nor a rank range");
  const int64_t k = family.max_level();
  const int64_t first = request.ranks().first(), last = request.ranks().last();
  if (first < 0 || last > k || last < first) {
    return absl::InvalidArgumentError(
        absl::StrCat("rank range ", first, "..", last, " is not within 0..", k, " (first <= last)"));
  }
  if (last - first + 1 > kMaxComponentLevels) {
    return absl::InvalidArgumentError(absl::StrCat("rank range ", first, "..", last, " holds more than ",
                                                   kMaxComponentLevels, " ranks: ask in pieces"));
  }
  return LevelRange{first, last};
}

}  // namespace

absl::StatusOr<v1::ComponentsResponse> AnswerComponents(const FamilyReader& family,
                                                        const v1::ComponentsRequest& request) {
  const absl::StatusOr<LevelRange> range = ResolveLevelRange(family, request);
  if (!range.ok()) return range.status();
  const absl::StatusOr<std::vector<TopologyAtLevel>> curves = family.TopologyBetween(range->first, range->last);
  if (!curves.ok()) return curves.status();
  v1::ComponentsResponse response;
  response.set_first_level(range->first);
  for (const TopologyAtLevel& at : *curves) {
    response.add_components(at.components);
    response.add_solid_components(at.solid_components);
  }
  return response;
}

absl::StatusOr<v1::BettiResponse> AnswerBetti(const FamilyReader& family, const v1::BettiRequest& request) {
  const absl::StatusOr<LevelRange> range = ResolveLevelRange(family, request);
  if (!range.ok()) return range.status();
  const absl::StatusOr<std::vector<TopologyAtLevel>> curves = family.TopologyBetween(range->first, range->last);
  if (!curves.ok()) return curves.status();
  v1::BettiResponse response;
  response.set_first_level(range->first);
  for (const TopologyAtLevel& at : *curves) {
    response.add_components(at.components);
    response.add_holes(at.holes);
    response.add_regularized_components(at.regularized_components);
    response.add_regularized_holes(at.regularized_holes);
  }
  return response;
}

absl::StatusOr<v1::OptimalAlphaResponse> AnswerOptimalAlpha(const FamilyReader& family,
                                                            const v1::OptimalAlphaRequest& request) {
  if (request.max_components() < 1) return absl::InvalidArgumentError("max_components must be at least 1");
  const std::optional<uint32_t> max_holes =
      request.has_max_holes() ? std::optional<uint32_t>(request.max_holes()) : std::nullopt;
  v1::OptimalAlphaResponse response;
  // Each answer's level, published value and curves.
  auto fill = [&](int64_t level, bool regularized, v1::OptimalLevel* out) -> absl::Status {
    const absl::StatusOr<double> alpha_sq = family.PublishedAlphaSq(level);
    if (!alpha_sq.ok()) return alpha_sq.status();
    const absl::StatusOr<std::vector<TopologyAtLevel>> at = family.TopologyBetween(level, level);
    if (!at.ok()) return at.status();
    out->set_rank(level);
    out->set_alpha_sq(*alpha_sq);
    out->set_components(regularized ? at->front().solid_components : at->front().components);
    out->set_holes(regularized ? at->front().regularized_holes : at->front().holes);
    return absl::OkStatus();
  };
  const absl::StatusOr<std::optional<int64_t>> regularized =
      family.OptimalLevelRegularized(request.max_components(), max_holes);
  if (!regularized.ok()) return regularized.status();
  if (*regularized) {
    if (absl::Status filled = fill(**regularized, true, response.mutable_regularized()); !filled.ok()) return filled;
  }
  const absl::StatusOr<std::optional<int64_t>> general =
      family.OptimalLevelGeneral(request.max_components(), max_holes);
  if (!general.ok()) return general.status();
  if (*general) {
    if (absl::Status filled = fill(**general, false, response.mutable_general()); !filled.ok()) return filled;
  }
  return response;
}

}  // namespace galpha::server
