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
  PersistenceSource(std::shared_ptr<const CachedFamily> cached, std::shared_ptr<const AlphaFamily> family,
                    PersistenceDiagram diagram, std::array<bool, 2> dimensions, double min_persistence)
      : cached_(std::move(cached)),
        family_(std::move(family)),
        diagram_(std::move(diagram)),
        dimensions_(dimensions),
        min_persistence_(min_persistence) {}

  bool Next(v1::PersistenceResponse* message) override {
    message->Clear();
    const AlphaFamily& family = *family_;
    for (; dimension_ < 2; ++dimension_, position_ = diagram_.dimension_begin[dimension_]) {
      if (!dimensions_[dimension_]) continue;
      const size_t end = diagram_.dimension_begin[dimension_ + 1];
      position_ = std::max(position_, diagram_.dimension_begin[dimension_]);
      uint32_t count = 0;
      for (; position_ < end && count < kPersistencePairsPerChunk; ++position_) {
        const PersistencePair& p = diagram_.pairs[position_];
        if (!PersistsAtLeast(family, p, min_persistence_)) continue;
        Append(family, p, RankValue(family, p.birth_rank), RankValue(family, p.death_rank), message);
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
  static void Append(const AlphaFamily& family, const PersistencePair& p, double birth, double death,
                     v1::PersistenceResponse* message) {
    message->add_birth_rank(p.birth_rank);
    message->add_death_rank(p.essential() ? -1 : static_cast<int64_t>(p.death_rank));
    message->add_birth_alpha_sq(birth);
    message->add_death_alpha_sq(death);
    const PairVertices vertices = VerticesOf(family, p);
    for (uint32_t i = 0; i <= p.dimension; ++i) message->add_creator_vertices(vertices.creator[i]);
    for (uint32_t i = 0; i <= p.dimension + 1; ++i) message->add_killer_vertices(vertices.killer[i]);
  }

  std::shared_ptr<const CachedFamily> cached_;  // kept while the stream runs, as every source's
  std::shared_ptr<const AlphaFamily> family_;   // the cached one, or a resident one's download
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
  // The diagram is computed from the family in host memory (a resident family's is downloaded for
  // this call), on the GPU when the family was built there (gpu/alpha/persistence_engine.hpp).
  absl::StatusOr<std::shared_ptr<const AlphaFamily>> family = cached->reader().HostFamily();
  if (!family.ok()) return family.status();
  absl::StatusOr<PersistenceDiagram> diagram =
      PersistenceDiagramOf(**family, cached->EdgeOrder(), cached->TriangleOrder());
  if (!diagram.ok()) return diagram.status();
  return std::make_unique<PersistenceSource>(std::move(cached), *std::move(family), *std::move(diagram), dimensions,
                                             min_persistence);
}

}  // namespace galpha::server
