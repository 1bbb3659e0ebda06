// Compact Classify answers on the codec pool (server/encoded_answer.hpp), over synthetic raw
// answers (gRPC-free, and so also in the ThreadSanitizer build): the encoded answer is the raw one
// message for message, each chunk decoding to the raw chunk, whatever order the pool's threads
// finish in; RAW is the raw answer itself; an encoder refusal ends the answer with an internal
// error naming the chunk, not with a truncated answer that looks complete; an answer dropped while
// its chunks are still encoding leaves the pool working.
#include "server/encoded_answer.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "proto/codec/simplex_chunk_codec.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using galpha::testing::StatusIs;

// A summary, then `chunks` chunks of sorted edges or triangles of random sizes (1 to 3,000).
std::vector<v1::ClassifyResponse> RandomAnswer(int chunks, uint64_t seed) {
  std::mt19937_64 random(seed);
  std::vector<v1::ClassifyResponse> messages(1);
  messages[0].mutable_summary()->set_level(static_cast<int64_t>(seed));
  for (int c = 0; c < chunks; ++c) {
    v1::ClassifyResponse message;
    v1::SimplexChunk* chunk = message.mutable_chunk();
    const bool triangles = c % 2 == 1;
    chunk->set_kind(triangles ? v1::SIMPLEX_KIND_TRIANGLE : v1::SIMPLEX_KIND_EDGE);
    const int n = 1 + static_cast<int>(random() % 3000);
    uint32_t first = static_cast<uint32_t>(random() % 1000);
    for (int i = 0; i < n; ++i) {
      first += static_cast<uint32_t>(random() % 3 == 0);  // runs of equal first vertices
      chunk->add_vertex_indices(first);
      chunk->add_vertex_indices(first + 1 + static_cast<uint32_t>(i));
      if (triangles)
        chunk->add_vertex_indices(first + 2 + static_cast<uint32_t>(i) + static_cast<uint32_t>(random() % 7));
      chunk->mutable_classes()->push_back(static_cast<char>(1 + random() % 4));
    }
    messages.push_back(std::move(message));
  }
  return messages;
}

// Hands out `messages` one by one; then its `status` (OK: the answer is complete).
class ListSource final : public ChunkSource<v1::ClassifyResponse> {
 public:
  explicit ListSource(std::vector<v1::ClassifyResponse> messages, absl::Status status = absl::OkStatus())
      : messages_(std::move(messages)), status_(std::move(status)) {}
  bool Next(v1::ClassifyResponse* message) override {
    if (next_ == messages_.size()) return false;
    *message = messages_[next_++];
    return true;
  }
  absl::Status status() const override { return next_ == messages_.size() ? status_ : absl::OkStatus(); }
  /// How many messages were taken so far.
  size_t taken() const { return next_; }

 private:
  std::vector<v1::ClassifyResponse> messages_;
  size_t next_ = 0;
  absl::Status status_;
};

TEST(EncodedAnswerTest, EncodedAnswersDecodeToTheRawAnswerInOrder) {
  ChunkCodecPool pool(4);
  for (uint64_t seed = 1; seed <= 12; ++seed) {
    for (v1::SimplexEncoding encoding : {v1::SIMPLEX_ENCODING_DELTA, v1::SIMPLEX_ENCODING_DELTA_ZSTD}) {
      SCOPED_TRACE(::testing::Message() << "seed " << seed << ", encoding " << encoding);
      const std::vector<v1::ClassifyResponse> raw = RandomAnswer(static_cast<int>(seed * 3), seed);
      auto encoded = EncodeSimplexChunks(std::make_unique<ListSource>(raw), encoding, &pool);
      wire::SimplexChunkDecoder decoder;
      v1::ClassifyResponse message;
      size_t i = 0;
      while (encoded->Next(&message)) {
        ASSERT_LT(i, raw.size());
        if (i == 0) {
          EXPECT_EQ(message.SerializeAsString(), raw[0].SerializeAsString());
        } else {
          ASSERT_TRUE(message.has_encoded_chunk()) << "message " << i;
          EXPECT_EQ(message.encoded_chunk().encoding(), encoding);
          v1::ClassifyResponse decoded;
          ASSERT_THAT(decoder.Decode(message.encoded_chunk(), i - 1, decoded.mutable_chunk()), IsOk());
          EXPECT_EQ(decoded.SerializeAsString(), raw[i].SerializeAsString()) << "message " << i;
        }
        ++i;
      }
      EXPECT_EQ(i, raw.size());
      EXPECT_THAT(encoded->status(), IsOk());
    }
  }
}

// The summary is handed over before any chunk is taken from the raw answer (the copies of the
// next chunks would hold it back); a part of a split answer, chunks only, encodes in order too.
TEST(EncodedAnswerTest, TheSummaryGoesOutBeforeTheChunksAreTaken) {
  ChunkCodecPool pool(4);
  const std::vector<v1::ClassifyResponse> raw = RandomAnswer(20, 77);
  auto list = std::make_unique<ListSource>(raw);
  const ListSource* source = list.get();
  auto encoded = EncodeSimplexChunks(std::move(list), v1::SIMPLEX_ENCODING_DELTA, &pool);
  v1::ClassifyResponse message;
  ASSERT_TRUE(encoded->Next(&message));
  EXPECT_TRUE(message.has_summary());
  EXPECT_EQ(source->taken(), 1u) << "chunks were taken before the summary was handed over";
  ASSERT_TRUE(encoded->Next(&message));
  EXPECT_TRUE(message.has_encoded_chunk());
  EXPECT_GT(source->taken(), 2u) << "with a chunk at the front, the window fills behind it";

  const std::vector<v1::ClassifyResponse> part(raw.begin() + 1, raw.end());  // no summary
  auto chunks_only = EncodeSimplexChunks(std::make_unique<ListSource>(part), v1::SIMPLEX_ENCODING_DELTA_ZSTD, &pool);
  wire::SimplexChunkDecoder decoder;
  size_t i = 0;
  while (chunks_only->Next(&message)) {
    ASSERT_LT(i, part.size());
    ASSERT_TRUE(message.has_encoded_chunk()) << "message " << i;
    v1::ClassifyResponse decoded;
    ASSERT_THAT(decoder.Decode(message.encoded_chunk(), i, decoded.mutable_chunk()), IsOk());
    EXPECT_EQ(decoded.SerializeAsString(), part[i].SerializeAsString()) << "message " << i;
    ++i;
  }
  EXPECT_EQ(i, part.size());
  EXPECT_THAT(chunks_only->status(), IsOk());
}

TEST(EncodedAnswerTest, RawIsTheRawAnswerItself) {
  ChunkCodecPool pool(1);
  for (v1::SimplexEncoding encoding : {v1::SIMPLEX_ENCODING_UNSPECIFIED, v1::SIMPLEX_ENCODING_RAW}) {
    auto raw = std::make_unique<ListSource>(RandomAnswer(2, 1));
    const ChunkSource<v1::ClassifyResponse>* address = raw.get();
    EXPECT_EQ(EncodeSimplexChunks(std::move(raw), encoding, &pool).get(), address);
  }
}

TEST(EncodedAnswerTest, AnEncoderRefusalEndsTheAnswerWithAnInternalError) {
  ChunkCodecPool pool(2);
  std::vector<v1::ClassifyResponse> raw = RandomAnswer(4, 7);
  // Chunk 2 (message 3) out of order: its first edge reversed.
  auto* indices = raw[3].mutable_chunk()->mutable_vertex_indices();
  std::swap((*indices)[0], (*indices)[1]);
  auto source = EncodeSimplexChunks(std::make_unique<ListSource>(raw), v1::SIMPLEX_ENCODING_DELTA_ZSTD, &pool);
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

TEST(EncodedAnswerTest, TheRawAnswersErrorEndsTheEncodedAnswer) {
  ChunkCodecPool pool(2);
  auto source = EncodeSimplexChunks(std::make_unique<ListSource>(RandomAnswer(3, 2), absl::DataLossError("lost")),
                                    v1::SIMPLEX_ENCODING_DELTA, &pool);
  v1::ClassifyResponse message;
  int messages = 0;
  while (source->Next(&message)) ++messages;
  EXPECT_EQ(messages, 4);
  EXPECT_THAT(source->status(), StatusIs(absl::StatusCode::kDataLoss));
}

TEST(EncodedAnswerTest, AnAnswerDroppedMidwayLeavesThePoolWorking) {
  ChunkCodecPool pool(3);
  for (int round = 0; round < 20; ++round) {
    auto source = EncodeSimplexChunks(std::make_unique<ListSource>(RandomAnswer(30, 100 + round)),
                                      v1::SIMPLEX_ENCODING_DELTA_ZSTD, &pool);
    v1::ClassifyResponse message;
    ASSERT_TRUE(source->Next(&message));  // the summary; chunks are encoding behind it
    ASSERT_TRUE(source->Next(&message));
  }
  // Every dropped answer's tasks still ran or run; a new answer is served in full.
  auto source =
      EncodeSimplexChunks(std::make_unique<ListSource>(RandomAnswer(5, 3)), v1::SIMPLEX_ENCODING_DELTA, &pool);
  v1::ClassifyResponse message;
  int messages = 0;
  while (source->Next(&message)) ++messages;
  EXPECT_EQ(messages, 6);
  EXPECT_THAT(source->status(), IsOk());
}

}  // namespace
}  // namespace galpha::server
