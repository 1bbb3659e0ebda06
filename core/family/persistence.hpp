// Persistent homology of the alpha filtration (H0 and H1) from a built family: which simplex
// creates each component and hole, which one ends it, and at which exact thresholds.
//
// The filtration orders simplices by birth rank, then dimension (vertex < edge < triangle), then
// their canonical position (core/family/canonical_order.hpp: vertex index, edge vertex pair,
// ascending triangle triple), so the diagram depends only on the points, never on the backend that
// built the family. H0 pairs come from a union-find over the edges in that order (elder rule: of
// two merging components, the one whose oldest vertex comes later dies). In the plane, H1 is dual
// to H0 of the complement (Alexander duality): a union-find over the triangles and the outer face
// in reverse order, joined by the edges that close a loop, pairs each such edge with the triangle
// that fills the hole it made last (the elder rule again, in reverse). Semantics: docs/topology.md.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/family/alpha_family.hpp"
#include "core/family/canonical_order.hpp"
#include "core/family/persistence_pair.hpp"

namespace galpha {

/// Two parallel sorts of (rank, canonical position) keys, then two union-finds (path halving:
/// amortized logarithmic a find, one or two hops in practice);
/// `edge_order` and `triangle_order` are the canonical orders (CanonicalOrders' fields). Internal
/// error only if the family contradicts planar duality.
absl::StatusOr<PersistenceDiagram> ComputePersistence(const AlphaFamily& family, absl::Span<const uint32_t> edge_order,
                                                      absl::Span<const uint32_t> triangle_order);
/// The same, computing the canonical orders first.
absl::StatusOr<PersistenceDiagram> ComputePersistence(const AlphaFamily& family);

/// No vertex: the killer's vertices of an essential class, as answers write them.
constexpr uint32_t kNoVertex = 0xFFFFFFFFu;

/// A pair's simplices as answers name them, by sorted vertices: the creator's dimension + 1 first
/// entries of `creator` (H0: the vertex; H1: the edge), the killer's dimension + 2 first entries
/// of `killer` (H0: the edge; H1: the triangle), kNoVertex when the class is essential.
struct PairVertices {
  std::array<uint32_t, 2> creator{kNoVertex, kNoVertex};
  std::array<uint32_t, 3> killer{kNoVertex, kNoVertex, kNoVertex};
};
PairVertices VerticesOf(const AlphaFamily& family, const PersistencePair& pair);
/// The same from a family's mesh (a resident family's host arrays).
PairVertices VerticesOf(absl::Span<const std::array<uint32_t, 2>> edges,
                        absl::Span<const std::array<uint32_t, 3>> triangles, const PersistencePair& pair);

/// Whether `pair` is listed under a minimum persistence (alpha_sq units, on the published values:
/// RankValue(death) - RankValue(birth) >= min_persistence, compared exactly); essential classes
/// always are.
bool PersistsAtLeast(const AlphaFamily& family, const PersistencePair& pair, double min_persistence);
/// The same from a family's spectrum values (AlphaFamily::spectrum()).
bool PersistsAtLeast(absl::Span<const double> spectrum, const PersistencePair& pair, double min_persistence);

/// The value of a rank as the family reports it: 0 for rank 0, the spectrum's nearest double for
/// 1..K, +infinity for kNeverRank.
double RankValue(const AlphaFamily& family, uint32_t rank);
double RankValue(absl::Span<const double> spectrum, uint32_t rank);

}  // namespace galpha
