// Compact Classify answers of real families (server/encoded_answer.hpp over MakeClassifySource):
// for every family and request shape, the encoded answer is the raw answer message for message (the
// summary as it is, each chunk its encoding, decoded by the client's decoder to the same chunk).
// The pool's own behaviour is in encoded_answer_test.cpp.
#include "server/encoded_answer.hpp"

#include <memory>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "proto/codec/simplex_chunk_codec.hpp"
#include "tests/server/query_answers_fixture.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using testing::Drain;
using testing::Families;
using testing::LargeFamily;
using testing::Rank;

std::unique_ptr<ChunkSource<v1::ClassifyResponse>> RawSource(std::shared_ptr<const CachedFamily> family,
                                                             const v1::ClassifyRequest& request) {
  auto source = MakeClassifySource(std::move(family), request);
  EXPECT_THAT(source.status(), IsOk());
  return source.ok() ? *std::move(source) : nullptr;
}

TEST(QueryAnswersTest, EveryEncodedClassifyAnswerDecodesToTheRawAnswer) {
  ChunkCodecPool pool(3);
  std::vector<std::shared_ptr<const CachedFamily>> families = {LargeFamily()};
  for (const auto& named : Families()) families.push_back(named.cached);
  for (const auto& family : families) {
    const int64_t k = family->reader().max_level();
    for (int64_t rank : {int64_t{0}, k / 2, k}) {
      for (bool non_exterior_only : {false, true}) {
        for (v1::SimplexEncoding encoding : {v1::SIMPLEX_ENCODING_DELTA, v1::SIMPLEX_ENCODING_DELTA_ZSTD}) {
          SCOPED_TRACE(::testing::Message() << "rank " << rank << " of " << k << ", encoding " << encoding
                                            << (non_exterior_only ? ", non-exterior only" : ""));
          v1::ClassifyRequest request;
          *request.mutable_threshold() = Rank(rank);
          request.set_non_exterior_only(non_exterior_only);
          const std::vector<v1::ClassifyResponse> raw = Drain(*RawSource(family, request));
          auto encoded_source = EncodeSimplexChunks(RawSource(family, request), encoding, &pool);
          const std::vector<v1::ClassifyResponse> encoded = Drain(*encoded_source);
          EXPECT_THAT(encoded_source->status(), IsOk());
          ASSERT_EQ(encoded.size(), raw.size());
          wire::SimplexChunkDecoder decoder;
          for (size_t i = 0; i < raw.size(); ++i) {
            if (raw[i].has_summary()) {
              EXPECT_EQ(encoded[i].SerializeAsString(), raw[i].SerializeAsString()) << "message " << i;
              continue;
            }
            ASSERT_TRUE(encoded[i].has_encoded_chunk()) << "message " << i;
            EXPECT_EQ(encoded[i].encoded_chunk().encoding(), encoding);
            v1::ClassifyResponse decoded;
            ASSERT_THAT(decoder.Decode(encoded[i].encoded_chunk(), i, decoded.mutable_chunk()), IsOk());
            EXPECT_EQ(decoded.SerializeAsString(), raw[i].SerializeAsString()) << "message " << i;
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace galpha::server
