// The client's decoding of compact Classify answers on several threads
// (client/classify_answer_decoder.hpp): every message comes out in the order it went in, encoded
// chunks as the SimplexChunk they encode (checked against the chunks that were encoded), whatever
// order the threads finish in and however small the window; a chunk that does not decode ends the
// answer with its error, naming it, after every message before it; Stop releases a producer that
// waits for room.
#include "client/classify_answer_decoder.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "proto/codec/simplex_chunk_codec.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::client {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using galpha::testing::StatusIs;

// Chunk i: 1 + 977 * i edges (i, i + 1 + j), classes cycling, so that every chunk differs in size.
v1::SimplexChunk RawChunk(uint32_t i) {
  v1::SimplexChunk chunk;
  chunk.set_kind(v1::SIMPLEX_KIND_EDGE);
  for (uint32_t j = 0; j < 1 + 977 * i; ++j) {
    chunk.add_vertex_indices(i);
    chunk.add_vertex_indices(i + 1 + j);
    chunk.mutable_classes()->push_back(static_cast<char>(1 + (i + j) % 4));
  }
  return chunk;
}

// A summary, then `chunks` chunks: encoded, but every fifth one raw.
std::vector<v1::ClassifyResponse> Answer(uint32_t chunks) {
  std::vector<v1::ClassifyResponse> messages(1);
  messages[0].mutable_summary()->set_level(42);
  wire::SimplexChunkEncoder encoder;
  for (uint32_t i = 0; i < chunks; ++i) {
    v1::ClassifyResponse message;
    if (i % 5 == 4) {
      *message.mutable_chunk() = RawChunk(i);
    } else {
      EXPECT_THAT(encoder.Encode(RawChunk(i), i % 2 == 0 ? v1::SIMPLEX_ENCODING_DELTA : v1::SIMPLEX_ENCODING_DELTA_ZSTD,
                                 message.mutable_encoded_chunk()),
                  IsOk());
    }
    messages.push_back(std::move(message));
  }
  return messages;
}

TEST(ClassifyAnswerDecoderTest, MessagesComeOutInOrderDecoded) {
  for (const auto& [threads, window] : std::vector<std::pair<size_t, size_t>>{{1, 1}, {3, 2}, {4, 10}, {8, 100}}) {
    SCOPED_TRACE(::testing::Message() << threads << " threads, window " << window);
    ClassifyAnswerDecoder decoder(threads, window);
    const std::vector<v1::ClassifyResponse> sent = Answer(40);
    std::thread producer([&] {
      for (const v1::ClassifyResponse& message : sent) EXPECT_TRUE(decoder.Push(message));
      decoder.End();
    });
    size_t received = 0;
    for (;;) {
      absl::StatusOr<const v1::ClassifyResponse*> next = decoder.Next();
      ASSERT_THAT(next.status(), IsOk());
      if (*next == nullptr) break;
      ASSERT_LT(received, sent.size());
      if (received == 0) {
        EXPECT_EQ((*next)->SerializeAsString(), sent[0].SerializeAsString());
      } else {
        ASSERT_TRUE((*next)->has_chunk()) << "message " << received;
        EXPECT_EQ((*next)->chunk().SerializeAsString(),
                  RawChunk(static_cast<uint32_t>(received - 1)).SerializeAsString())
            << "message " << received;
      }
      ++received;
    }
    producer.join();
    EXPECT_EQ(received, sent.size());
    EXPECT_EQ(decoder.Next().value(), nullptr) << "an ended answer stays ended";
  }
}

TEST(ClassifyAnswerDecoderTest, AChunkThatDoesNotDecodeEndsTheAnswerAfterTheOnesBeforeIt) {
  ClassifyAnswerDecoder decoder(4, 6);
  std::vector<v1::ClassifyResponse> sent = Answer(12);
  // Chunk 6 (message 7) loses its last byte: a truncated varint.
  std::string* data = sent[7].mutable_encoded_chunk()->mutable_data();
  ASSERT_EQ(sent[7].encoded_chunk().encoding(), v1::SIMPLEX_ENCODING_DELTA);
  data->pop_back();
  std::thread producer([&] {
    for (const v1::ClassifyResponse& message : sent) {
      if (!decoder.Push(message)) break;
    }
    decoder.End();
  });
  for (size_t i = 0; i < 7; ++i) {
    absl::StatusOr<const v1::ClassifyResponse*> next = decoder.Next();
    ASSERT_THAT(next.status(), IsOk()) << "message " << i;
    ASSERT_NE(*next, nullptr);
  }
  absl::StatusOr<const v1::ClassifyResponse*> failed = decoder.Next();
  EXPECT_THAT(failed.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(failed.status().message().find("encoded simplex chunk 6: "), std::string::npos) << failed.status();
  decoder.Stop();
  producer.join();
  EXPECT_EQ(decoder.Next().value(), nullptr);
}

TEST(ClassifyAnswerDecoderTest, StopReleasesAProducerWaitingForRoom) {
  ClassifyAnswerDecoder decoder(2, 1);
  const std::vector<v1::ClassifyResponse> sent = Answer(5);
  std::atomic<int> pushed{0};
  std::atomic<bool> refused{false};
  std::thread producer([&] {
    for (const v1::ClassifyResponse& message : sent) {
      if (!decoder.Push(message)) {
        refused = true;
        return;
      }
      ++pushed;
    }
  });
  // Nobody takes anything: the producer waits after the first message until Stop.
  while (pushed.load() < 1) std::this_thread::yield();
  decoder.Stop();
  producer.join();
  EXPECT_TRUE(refused.load());
  EXPECT_EQ(pushed.load(), 1);
}

}  // namespace
}  // namespace galpha::client
