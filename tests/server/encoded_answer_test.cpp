// Compact Classify answers on the codec pool (server/encoded_answer.hpp): for every family and
// request shape, the encoded answer is the raw answer message for message (the summary as it is,
// each chunk its encoding, decoded by the client's decoder to the same chunk), whatever order the
// pool's threads finish in; RAW is the raw answer itself; an encoder refusal ends the answer with an
// internal error that names the chunk, not with a truncated answer that looks complete.
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
using galpha::testing::StatusIs;
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

TEST(EncodedAnswerTest, EveryEncodedAnswerDecodesToTheRawAnswer) {
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

TEST(EncodedAnswerTest, RawIsTheRawAnswerItself) {
  ChunkCodecPool pool(1);
  v1::ClassifyRequest request;
  *request.mutable_threshold() = Rank(1);
  for (v1::SimplexEncoding encoding : {v1::SIMPLEX_ENCODING_UNSPECIFIED, v1::SIMPLEX_ENCODING_RAW}) {
    auto raw = RawSource(LargeFamily(), request);
    const ChunkSource<v1::ClassifyResponse>* address = raw.get();
    EXPECT_EQ(EncodeSimplexChunks(std::move(raw), encoding, &pool).get(), address);
  }
}

// A summary, two good chunks, one the format cannot state (out of order), one more.
class ChunksWithADefect final : public ChunkSource<v1::ClassifyResponse> {
 public:
  bool Next(v1::ClassifyResponse* message) override {
    message->Clear();
    if (sent_ == 5) return false;
    const int n = sent_++;
    if (n == 0) {
      message->mutable_summary()->set_level(3);
      return true;
    }
    v1::SimplexChunk* chunk = message->mutable_chunk();
    chunk->set_kind(v1::SIMPLEX_KIND_EDGE);
    chunk->add_vertex_indices(n == 3 ? 9 : 1);
    chunk->add_vertex_indices(n == 3 ? 2 : 2);
    chunk->set_classes("\x01");
    return true;
  }

 private:
  int sent_ = 0;
};

TEST(EncodedAnswerTest, AnEncoderRefusalEndsTheAnswerWithAnInternalError) {
  ChunkCodecPool pool(2);
  auto source = EncodeSimplexChunks(std::make_unique<ChunksWithADefect>(), v1::SIMPLEX_ENCODING_DELTA_ZSTD, &pool);
  v1::ClassifyResponse message;
  ASSERT_TRUE(source->Next(&message));
  EXPECT_TRUE(message.has_summary());
  ASSERT_TRUE(source->Next(&message));
  EXPECT_TRUE(message.has_encoded_chunk());
  ASSERT_TRUE(source->Next(&message));
  EXPECT_TRUE(message.has_encoded_chunk());
  EXPECT_FALSE(source->Next(&message));
  EXPECT_THAT(source->status(), StatusIs(absl::StatusCode::kInternal));
  EXPECT_NE(source->status().message().find("encoding simplex chunk 2: "), std::string::npos)
      << source->status().message();
  EXPECT_FALSE(source->Next(&message)) << "a failed answer stays failed";
}

}  // namespace
}  // namespace galpha::server
