// The Persistence RPC's answer: a family's persistence diagram (core/family/persistence.hpp),
// filtered by dimension and minimum persistence, as a stream of chunks of one dimension each, with
// every simplex named by its vertices. Free of gRPC, like query_answers.hpp.
#pragma once

#include <cstdint>
#include <memory>

#include "absl/status/statusor.h"
#include "galpha/v1/alpha_shapes.pb.h"
#include "server/cached_family.hpp"
#include "server/query_answers.hpp"

namespace galpha::server {

/// Pairs per Persistence message (at most 5 vertices, 2 ranks and 2 values each: ~2.6 MB).
inline constexpr uint32_t kPersistencePairsPerChunk = 1u << 16;

/// The diagram is computed when the call starts (O(n log n) from the family's canonical orders).
/// InvalidArgument for a dimension other than 0 or 1, or a negative or NaN min_persistence.
absl::StatusOr<std::unique_ptr<ChunkSource<galpha::v1::PersistenceResponse>>> MakePersistenceSource(
    std::shared_ptr<const CachedFamily> cached, const galpha::v1::PersistenceRequest& request);

}  // namespace galpha::server
