// Answers to the service's queries, computed from a cached family: pure functions and chunk
// generators over the protobuf messages, free of gRPC so that tests check them directly and the
// service only moves them over the wire.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "core/family/alpha_family.hpp"
#include "core/family/threshold.hpp"
#include "core/geometry/shape.hpp"
#include "galpha/v1/alpha_shapes.pb.h"
#include "server/cached_family.hpp"
#include "server/chunk_source.hpp"

namespace galpha::server {

/// Simplices per Classify chunk (at most 13 bytes each: well under gRPC's 4 MiB message limit).
inline constexpr uint32_t kSimplicesPerChunk = 1u << 17;
/// The most parts a Classify answer is split into (ClassifyRequest.part_count).
inline constexpr uint32_t kMaxClassifyParts = 64;
/// Master-list entries per MasterList message.
inline constexpr uint32_t kMasterEntriesPerChunk = 1u << 17;
/// Bytes of text per Shape message; indices per ShapeRings message (about).
inline constexpr size_t kShapeTextBytesPerChunk = 1u << 20;
inline constexpr size_t kShapeIndicesPerChunk = 1u << 18;
/// Spectrum page sizes (page_size 0 asks for the default; more than the largest is refused) and the
/// longest Components range. The largest page, 2 MiB of doubles, stays under the 4 MiB that gRPC
/// clients receive by default: a whole spectrum in one message would pass it from ~500K values.
inline constexpr uint32_t kDefaultSpectrumPage = 65536;
inline constexpr uint32_t kMaxSpectrumPage = 262144;
inline constexpr int64_t kMaxComponentLevels = 262144;

/// A threshold resolved against a family (core/family/threshold.hpp).
using ResolvedLevel = ResolvedThreshold;
/// InvalidArgument: no threshold set, NaN, a negative alpha, a rank outside 0..K.
absl::StatusOr<ResolvedLevel> ResolveLevel(const FamilyReader& family, const galpha::v1::Threshold& threshold);

/// The engine's mode and vertex rule of a request's `mode` and `vertex_rule` (UNSPECIFIED: GENERAL,
/// REPORT). InvalidArgument naming the field and the value for a number the enum does not define
/// (proto3 enums are open: a newer client's value, or garbage): the default would answer another
/// question than the one asked.
absl::StatusOr<ClassifyMode> ToClassifyMode(galpha::v1::ClassifyMode mode);
absl::StatusOr<VertexRule> ToVertexRule(galpha::v1::VertexRule rule);

/// Describe's and Build's summary of a cached family, without a name (Build adds its caller's).
void FillBuildSummary(const CachedFamily& cached, galpha::v1::BuildSummary* summary);

/// Classify: the summary, then vertex, edge and triangle chunks in index order, always raw
/// (SimplexChunk; the service encodes them as the request asks: encoded_answer.hpp); of a split
/// answer (part_count > 1), the part's chunks only, after the summary in part 0. The classification
/// is shared with the other parts (CachedFamily::SharedClassification). InvalidArgument for a bad
/// threshold, mode, vertex rule, simplex encoding or part.
absl::StatusOr<std::unique_ptr<ChunkSource<galpha::v1::ClassifyResponse>>> MakeClassifySource(
    std::shared_ptr<const CachedFamily> cached, const galpha::v1::ClassifyRequest& request);

/// MasterList for ranks first..last. InvalidArgument for ranks outside 1..K or last < first.
absl::StatusOr<std::unique_ptr<ChunkSource<galpha::v1::MasterListResponse>>> MakeMasterListSource(
    std::shared_ptr<const CachedFamily> cached, const galpha::v1::MasterListRequest& request);

/// Shape as text chunks or ring chunks. InvalidArgument for an unspecified or unknown format, an
/// unknown mode or a bad threshold.
absl::StatusOr<std::unique_ptr<ChunkSource<galpha::v1::ShapeResponse>>> MakeShapeSource(
    std::shared_ptr<const CachedFamily> cached, const galpha::v1::ShapeRequest& request);

absl::StatusOr<galpha::v1::SpectrumResponse> AnswerSpectrum(const FamilyReader& family,
                                                            const galpha::v1::SpectrumRequest& request);
absl::StatusOr<galpha::v1::ComponentsResponse> AnswerComponents(const FamilyReader& family,
                                                                const galpha::v1::ComponentsRequest& request);
/// Betti curves at a threshold or over a rank range (the same limits as Components).
absl::StatusOr<galpha::v1::BettiResponse> AnswerBetti(const FamilyReader& family,
                                                      const galpha::v1::BettiRequest& request);
absl::StatusOr<galpha::v1::OptimalAlphaResponse> AnswerOptimalAlpha(const FamilyReader& family,
                                                                    const galpha::v1::OptimalAlphaRequest& request);

}  // namespace galpha::server
