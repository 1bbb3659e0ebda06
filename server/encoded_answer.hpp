// Compact Classify answers (ClassifyRequest.simplex_encoding DELTA or DELTA_ZSTD): the raw answer's
// simplex chunks, encoded on the server's codec pool a few chunks ahead of the writes, so that the
// encoding of one chunk overlaps the writing of the ones before it and runs on every core.
#pragma once

#include <memory>

#include "absl/status/statusor.h"
#include "galpha/v1/alpha_shapes.pb.h"
#include "server/chunk_codec_pool.hpp"
#include "server/chunk_source.hpp"

namespace galpha::server {

/// `raw` with each SimplexChunk replaced by its EncodedSimplexChunk (same order; the summary as it
/// is). RAW and UNSPECIFIED return `raw` itself. `pool` must outlive the answer. At most one chunk
/// a pool thread (and at most 8) is encoded or waiting at once, so an answer holds at most that
/// many chunks beyond those its writer holds (the one being written and the one filled ahead).
std::unique_ptr<ChunkSource<galpha::v1::ClassifyResponse>> EncodeSimplexChunks(
    std::unique_ptr<ChunkSource<galpha::v1::ClassifyResponse>> raw, galpha::v1::SimplexEncoding encoding,
    ChunkCodecPool* pool);

}  // namespace galpha::server
