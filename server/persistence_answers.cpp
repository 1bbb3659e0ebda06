#include "server/persistence_answers.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/family/persistence.hpp"
#include "gpu/alpha/persistence_engine.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;

class PersistenceSource final : public ChunkSource<v1::PersistenceResponse> {
 public:
  /// `resident_spectrum`: a resident family's spectrum values, read for this call (a family in
  /// host memory is read where it is, and passes none).
  PersistenceSource(std::shared_ptr<const CachedFamily> cached, std::vector<double> resident_spectrum,
                    PersistenceDiagram diagram, std::array<bool, 2> dimensions, double min_persistence)
      : cached_(std::move(cached)),
        resident_spectrum_(std::move(resident_spectrum)),
        spectrum_(cached_->host_family() != nullptr ? absl::MakeConstSpan(cached_->host_family()->spectrum())
                                                    : absl::MakeConstSpan(resident_spectrum_)),
        diagram_(std::move(diagram)),
        dimensions_(dimensions),
        min_persistence_(min_persistence) {}

  bool Next(v1::PersistenceResponse* message) override {
    message->Clear();
    for (; dimension_ < 2; ++dimension_, position_ = diagram_.dimension_begin[dimension_]) {
      if (!dimensions_[dimension_]) continue;
      const size_t end = diagram_.dimension_begin[dimension_ + 1];
      position_ = std::max(position_, diagram_.dimension_begin[dimension_]);
      uint32_t count = 0;
      for (; position_ < end && count < kPersistencePairsPerChunk; ++position_) {
        const PersistencePair& p = diagram_.pairs[position_];
        if (!PersistsAtLeast(spectrum_, p, min_persistence_)) continue;
        Append(p, message);
        ++count;
      }
      if (count > 0) {
        message->set_dimension(dimension_);
        return true;
      }
    }
    return false;
  }

 private:
  void Append(const PersistencePair& p, v1::PersistenceResponse* message) const {
    message->add_birth_rank(p.birth_rank);
    message->add_death_rank(p.essential() ? -1 : static_cast<int64_t>(p.death_rank));
    message->add_birth_alpha_sq(RankValue(spectrum_, p.birth_rank));
    message->add_death_alpha_sq(RankValue(spectrum_, p.death_rank));
    const FamilyReader& family = cached_->reader();
    const PairVertices vertices =
        VerticesOf(absl::MakeConstSpan(family.edges()), absl::MakeConstSpan(family.triangles()), p);
    for (uint32_t i = 0; i <= p.dimension; ++i) message->add_creator_vertices(vertices.creator[i]);
    for (uint32_t i = 0; i <= p.dimension + 1; ++i) message->add_killer_vertices(vertices.killer[i]);
  }

  std::shared_ptr<const CachedFamily> cached_;  // kept while the stream runs, as every source's
  std::vector<double> resident_spectrum_;
  absl::Span<const double> spectrum_;
  PersistenceDiagram diagram_;
  std::array<bool, 2> dimensions_;
  double min_persistence_;
  uint32_t dimension_ = 0;
  size_t position_ = 0;
};

}  // namespace

absl::StatusOr<std::unique_ptr<ChunkSource<v1::PersistenceResponse>>> MakePersistenceSource(
    std::shared_ptr<const CachedFamily> cached, const v1::PersistenceRequest& request) {
  std::array<bool, 2> dimensions = {request.dimensions().empty(), request.dimensions().empty()};
  for (uint32_t d : request.dimensions()) {
    if (d > 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("dimension ", d, " has no classes: a planar alpha complex has H0 (0) and H1 (1) only"));
    }
    dimensions[d] = true;
  }
  const double min_persistence = request.min_persistence();
  if (std::isnan(min_persistence) || min_persistence < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("min_persistence ", min_persistence, " is not a length: give 0 or more"));
  }
  // The diagram is computed where the family lives (a resident family's on its device, only the
  // mesh uploaded; a host family's on the GPU when it was built there:
  // gpu/alpha/persistence_engine.hpp), and the values are read from its spectrum (a resident
  // family's downloaded once, 8 bytes a value).
  const FamilyReader& reader = cached->reader();
  absl::StatusOr<PersistenceDiagram> diagram = reader.Persistence(cached->EdgeOrder(), cached->TriangleOrder());
  if (!diagram.ok()) return diagram.status();
  std::vector<double> resident_spectrum;
  if (cached->host_family() == nullptr) {
    absl::StatusOr<std::vector<double>> values = reader.Spectrum(0, reader.max_level());
    if (!values.ok()) return values.status();
    resident_spectrum = *std::move(values);
  }
  return std::make_unique<PersistenceSource>(std::move(cached), std::move(resident_spectrum), *std::move(diagram),
                                             dimensions, min_persistence);
}

}  // namespace galpha::server
