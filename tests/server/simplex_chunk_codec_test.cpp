// The compact Classify answers (proto/codec/simplex_chunk_codec.hpp, EncodedSimplexChunk in
// proto/galpha/v1/alpha_shapes.proto): chunks of every kind decode to exactly the raw chunk they
// encoded, in both encodings, on sorted simplex lists of every shape (random, dense, extreme
// indices, counts that are not multiples of four) and on the real answers of a family; bytes written
// by hand from the proto's text decode as it says; the encoder refuses what the format cannot state
// and the decoder refuses every malformed chunk, naming it, without writing past the count's bound.
#include "proto/codec/simplex_chunk_codec.hpp"

#include <zstd.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "server/query_answers.hpp"
#include "tests/server/query_answers_fixture.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::wire {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using ::testing::HasSubstr;

constexpr std::array<v1::SimplexEncoding, 2> kEncodings = {v1::SIMPLEX_ENCODING_DELTA, v1::SIMPLEX_ENCODING_DELTA_ZSTD};

v1::SimplexKind KindOfArity(int arity) {
  return arity == 1 ? v1::SIMPLEX_KIND_VERTEX : arity == 2 ? v1::SIMPLEX_KIND_EDGE : v1::SIMPLEX_KIND_TRIANGLE;
}

// `count` distinct sorted simplices of `arity` vertices drawn below `limit`, in lexicographic
// order, with random classes.
v1::SimplexChunk RandomChunk(int arity, size_t count, uint64_t limit, uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_int_distribution<uint64_t> index(0, limit - 1);
  std::set<std::vector<uint32_t>> simplices;
  while (simplices.size() < count) {
    std::set<uint32_t> vertices;
    while (vertices.size() < static_cast<size_t>(arity)) vertices.insert(static_cast<uint32_t>(index(random)));
    simplices.insert(std::vector<uint32_t>(vertices.begin(), vertices.end()));
  }
  v1::SimplexChunk chunk;
  chunk.set_kind(KindOfArity(arity));
  for (const auto& simplex : simplices) {
    for (uint32_t v : simplex) chunk.add_vertex_indices(v);
    chunk.mutable_classes()->push_back(static_cast<char>(1 + random() % 4));
  }
  return chunk;
}

v1::SimplexChunk RoundTrip(const v1::SimplexChunk& chunk, v1::SimplexEncoding encoding, size_t* bytes = nullptr) {
  SimplexChunkEncoder encoder;
  v1::EncodedSimplexChunk encoded;
  EXPECT_THAT(encoder.Encode(chunk, encoding, &encoded), IsOk());
  EXPECT_EQ(encoded.simplex_count(), static_cast<uint32_t>(chunk.classes().size()));
  if (bytes != nullptr) *bytes = encoded.ByteSizeLong();
  SimplexChunkDecoder decoder;
  v1::SimplexChunk decoded;
  EXPECT_THAT(decoder.Decode(encoded, 0, &decoded), IsOk());
  return decoded;
}

void ExpectSameChunk(const v1::SimplexChunk& got, const v1::SimplexChunk& want) {
  EXPECT_EQ(got.kind(), want.kind());
  ASSERT_EQ(got.vertex_indices().size(), want.vertex_indices().size());
  EXPECT_TRUE(std::equal(got.vertex_indices().begin(), got.vertex_indices().end(), want.vertex_indices().begin()));
  EXPECT_EQ(got.classes(), want.classes());
}

TEST(SimplexChunkCodec, SortedSimplicesOfEveryShapeRoundTrip) {
  for (v1::SimplexEncoding encoding : kEncodings) {
    for (int arity = 1; arity <= 3; ++arity) {
      // Sparse and dense index ranges, counts around multiples of four, indices near 2^32 - 1.
      for (const auto& [count, limit] : std::vector<std::pair<size_t, uint64_t>>{{1, 10},
                                                                                 {2, 10},
                                                                                 {3, 1000},
                                                                                 {4, 1000},
                                                                                 {5, 1000},
                                                                                 {1000, 2000},
                                                                                 {4097, uint64_t{1} << 32},
                                                                                 {20000, 30000},
                                                                                 {777, 4000000000}}) {
        SCOPED_TRACE(::testing::Message() << "encoding " << encoding << " arity " << arity << " count " << count);
        if (arity == 1 && count > limit) continue;
        const v1::SimplexChunk chunk = RandomChunk(arity, count, limit, count * 7 + arity);
        ExpectSameChunk(RoundTrip(chunk, encoding), chunk);
      }
    }
    // The largest indices: the last simplex of each kind ends at 2^32 - 1.
    v1::SimplexChunk top;
    top.set_kind(v1::SIMPLEX_KIND_TRIANGLE);
    for (uint32_t v : {0u, 1u, UINT32_MAX, 1u, UINT32_MAX - 1, UINT32_MAX}) top.add_vertex_indices(v);
    top.set_classes(std::string("\x04\x01", 2));
    ExpectSameChunk(RoundTrip(top, encoding), top);
  }
}

TEST(SimplexChunkCodec, RealAnswersRoundTripAndShrink) {
  // Every chunk of a multi-message Classify answer at several ranks, both modes.
  const auto family = server::testing::LargeFamily();
  const int64_t k = family->reader().max_level();
  size_t raw_bytes = 0;
  std::array<size_t, 2> encoded_bytes{};
  for (int64_t rank : {int64_t{0}, k / 3, k / 2, k}) {
    for (v1::ClassifyMode mode : {v1::CLASSIFY_MODE_GENERAL, v1::CLASSIFY_MODE_REGULARIZED}) {
      for (bool non_exterior_only : {false, true}) {
        v1::ClassifyRequest request;
        *request.mutable_threshold() = server::testing::Rank(rank);
        request.set_mode(mode);
        request.set_non_exterior_only(non_exterior_only);
        auto source = server::MakeClassifySource(family, request);
        ASSERT_THAT(source.status(), IsOk());
        for (const v1::ClassifyResponse& message : server::testing::Drain(**source)) {
          if (!message.has_chunk()) continue;
          raw_bytes += message.ByteSizeLong();
          for (size_t e = 0; e < kEncodings.size(); ++e) {
            size_t bytes = 0;
            ExpectSameChunk(RoundTrip(message.chunk(), kEncodings[e], &bytes), message.chunk());
            encoded_bytes[e] += bytes;
          }
        }
      }
    }
  }
  std::printf("raw %zu bytes, DELTA %zu (%.2fx), DELTA_ZSTD %zu (%.2fx)\n", raw_bytes, encoded_bytes[0],
              static_cast<double>(encoded_bytes[0]) / static_cast<double>(raw_bytes), encoded_bytes[1],
              static_cast<double>(encoded_bytes[1]) / static_cast<double>(raw_bytes));
  // Shuffled input order: at most 3 varint bytes an index against raw's 4, and 2 bits a class
  // against 8.
  EXPECT_LT(static_cast<double>(encoded_bytes[0]), 0.8 * static_cast<double>(raw_bytes));
  EXPECT_LE(encoded_bytes[1], encoded_bytes[0]);
}

// Edges (3, 7), (3, 9), (4, 5) with classes EXTERIOR, SINGULAR, INTERIOR, written from the
// proto's text: classes 0, 1, 3 in bits 0-1, 2-3, 4-5 of one byte; then 3 (the first index
// itself), 7 - 3 - 1 = 3; 3 - 3 = 0 (same first vertex), 9 - 7 - 1 = 1 (the last position); 4 - 3 = 1,
// 5 - 4 - 1 = 0 (the prefix differs). A vertex 300 after vertex 1: a two-byte varint 298 - 0.
TEST(SimplexChunkCodec, DecodesTheLayoutTheProtoDocuments) {
  v1::EncodedSimplexChunk edges;
  edges.set_kind(v1::SIMPLEX_KIND_EDGE);
  edges.set_simplex_count(3);
  edges.set_encoding(v1::SIMPLEX_ENCODING_DELTA);
  edges.set_data(std::string("\x34\x03\x03\x00\x01\x01\x00", 7));
  SimplexChunkDecoder decoder;
  v1::SimplexChunk decoded;
  ASSERT_THAT(decoder.Decode(edges, 0, &decoded), IsOk());
  EXPECT_EQ(decoded.kind(), v1::SIMPLEX_KIND_EDGE);
  EXPECT_EQ(std::vector<uint32_t>(decoded.vertex_indices().begin(), decoded.vertex_indices().end()),
            (std::vector<uint32_t>{3, 7, 3, 9, 4, 5}));
  EXPECT_EQ(decoded.classes(), std::string("\x01\x02\x04", 3));

  v1::EncodedSimplexChunk vertices;
  vertices.set_kind(v1::SIMPLEX_KIND_VERTEX);
  vertices.set_simplex_count(2);
  vertices.set_encoding(v1::SIMPLEX_ENCODING_DELTA);
  // Classes REGULAR (2) then SINGULAR (1): 0b0110; vertex 1; 300 - 1 - 1 = 298 = 0b10_0101010.
  vertices.set_data(std::string("\x06\x01\xAA\x02", 4));
  ASSERT_THAT(decoder.Decode(vertices, 0, &decoded), IsOk());
  EXPECT_EQ(std::vector<uint32_t>(decoded.vertex_indices().begin(), decoded.vertex_indices().end()),
            (std::vector<uint32_t>{1, 300}));
  EXPECT_EQ(decoded.classes(), std::string("\x03\x02", 2));

  // The encoder writes exactly these bytes.
  SimplexChunkEncoder encoder;
  v1::EncodedSimplexChunk encoded;
  const std::vector<uint32_t> indices = {3, 7, 3, 9, 4, 5};
  ASSERT_THAT(encoder.Encode(v1::SIMPLEX_KIND_EDGE, indices, std::string("\x01\x02\x04", 3), v1::SIMPLEX_ENCODING_DELTA,
                             &encoded),
              IsOk());
  EXPECT_EQ(encoded.data(), edges.data());
  // DELTA_ZSTD is one zstd frame of the same bytes.
  ASSERT_THAT(encoder.Encode(v1::SIMPLEX_KIND_EDGE, indices, std::string("\x01\x02\x04", 3),
                             v1::SIMPLEX_ENCODING_DELTA_ZSTD, &encoded),
              IsOk());
  std::string plain(64, '\0');
  const size_t size = ZSTD_decompress(plain.data(), plain.size(), encoded.data().data(), encoded.data().size());
  ASSERT_FALSE(ZSTD_isError(size));
  plain.resize(size);
  EXPECT_EQ(plain, edges.data());
}

TEST(SimplexChunkCodec, TheEncoderRefusesWhatTheFormatCannotState) {
  SimplexChunkEncoder encoder;
  v1::EncodedSimplexChunk out;
  const auto encode = [&](v1::SimplexKind kind, std::vector<uint32_t> indices, std::string classes,
                          v1::SimplexEncoding encoding = v1::SIMPLEX_ENCODING_DELTA) {
    return encoder.Encode(kind, indices, classes, encoding, &out);
  };
  const auto bad = StatusIs(absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(encode(v1::SIMPLEX_KIND_EDGE, {1, 2}, "\x01", v1::SIMPLEX_ENCODING_RAW), bad);
  EXPECT_THAT(encode(v1::SIMPLEX_KIND_UNSPECIFIED, {1}, "\x01"), bad);
  EXPECT_THAT(encode(v1::SIMPLEX_KIND_EDGE, {1, 2, 3}, "\x01"), bad);         // counts disagree
  EXPECT_THAT(encode(v1::SIMPLEX_KIND_EDGE, {}, ""), bad);                    // empty
  EXPECT_THAT(encode(v1::SIMPLEX_KIND_EDGE, {2, 1}, "\x01"), bad);            // not ascending within
  EXPECT_THAT(encode(v1::SIMPLEX_KIND_EDGE, {1, 1}, "\x01"), bad);            // a repeated vertex
  EXPECT_THAT(encode(v1::SIMPLEX_KIND_EDGE, {1, 5, 1, 4}, "\x01\x01"), bad);  // out of order
  EXPECT_THAT(encode(v1::SIMPLEX_KIND_EDGE, {1, 5, 1, 5}, "\x01\x01"), bad);  // a repeated simplex
  EXPECT_THAT(encode(v1::SIMPLEX_KIND_VERTEX, {4, 3}, "\x01\x01"), bad);      // vertices out of order
  EXPECT_THAT(encode(v1::SIMPLEX_KIND_TRIANGLE, {1, 2, 3, 1, 2, 3}, std::string("\x01\x01", 2)), bad);
  EXPECT_THAT(encode(v1::SIMPLEX_KIND_EDGE, {1, 2}, std::string(1, '\0')), bad);  // class 0
  EXPECT_THAT(encode(v1::SIMPLEX_KIND_EDGE, {1, 2}, "\x05"), bad);                // class 5
  EXPECT_THAT(encode(v1::SIMPLEX_KIND_EDGE, {1, 2, 1, 3, 2, 3}, "\x01\x02\x03"), IsOk());
}

TEST(SimplexChunkCodec, MalformedChunksAreRefusedNamingTheChunk) {
  const auto chunk = [](v1::SimplexKind kind, uint32_t count, const std::string& data,
                        v1::SimplexEncoding encoding = v1::SIMPLEX_ENCODING_DELTA) {
    v1::EncodedSimplexChunk out;
    out.set_kind(kind);
    out.set_simplex_count(count);
    out.set_encoding(encoding);
    out.set_data(data);
    return out;
  };
  const auto zstd = [](const std::string& plain) {
    std::string out(ZSTD_compressBound(plain.size()), '\0');
    out.resize(ZSTD_compress(out.data(), out.size(), plain.data(), plain.size(), 1));
    return out;
  };
  struct Case {
    const char* what;
    v1::EncodedSimplexChunk chunk;
    const char* message;
  };
  const std::string one_vertex("\x00\x05", 2);
  const std::vector<Case> cases = {
      {"unknown kind", chunk(v1::SIMPLEX_KIND_UNSPECIFIED, 1, one_vertex), "not a simplex kind"},
      {"RAW is not an encoded chunk", chunk(v1::SIMPLEX_KIND_VERTEX, 1, one_vertex, v1::SIMPLEX_ENCODING_RAW),
       "not DELTA"},
      {"undefined encoding", chunk(v1::SIMPLEX_KIND_VERTEX, 1, one_vertex, static_cast<v1::SimplexEncoding>(9)),
       "not DELTA"},
      {"count 0", chunk(v1::SIMPLEX_KIND_VERTEX, 0, ""), "states 0 simplices"},
      {"count over the limit", chunk(v1::SIMPLEX_KIND_VERTEX, kMaxSimplicesPerEncodedChunk + 1, one_vertex),
       "a chunk holds 1 to"},
      {"no class bytes", chunk(v1::SIMPLEX_KIND_VERTEX, 1, ""), "before its 1 bytes of classes"},
      {"padding bits set", chunk(v1::SIMPLEX_KIND_VERTEX, 1, std::string("\x04\x05", 2)), "unused bits"},
      {"truncated varints", chunk(v1::SIMPLEX_KIND_EDGE, 1, std::string("\x00\x05", 2)), "truncated"},
      {"varint cut inside", chunk(v1::SIMPLEX_KIND_VERTEX, 1, std::string("\x00\x85", 2)), "truncated"},
      {"overlong varint", chunk(v1::SIMPLEX_KIND_EDGE, 1, std::string("\x00\x80\x80\x80\x80\x80\x00", 7)),
       "longer than 5 bytes"},
      {"index over 2^32 - 1 in one varint",
       chunk(v1::SIMPLEX_KIND_VERTEX, 1, std::string("\x00\x80\x80\x80\x80\x10", 6)), "over 2^32 - 1"},
      {"index over 2^32 - 1 by a difference",
       chunk(v1::SIMPLEX_KIND_EDGE, 1, std::string("\x00\xFF\xFF\xFF\xFF\x0F\x00", 7)), "over 2^32 - 1"},
      {"bytes left over", chunk(v1::SIMPLEX_KIND_VERTEX, 1, std::string("\x00\x05\x00", 3)), "bytes after"},
      {"more bytes than the count allows", chunk(v1::SIMPLEX_KIND_VERTEX, 1, std::string(7, '\0')), "more than"},
      {"not a zstd frame", chunk(v1::SIMPLEX_KIND_VERTEX, 1, one_vertex, v1::SIMPLEX_ENCODING_DELTA_ZSTD),
       "not a zstd frame"},
      {"bytes after the frame",
       chunk(v1::SIMPLEX_KIND_VERTEX, 1, zstd(one_vertex) + "x", v1::SIMPLEX_ENCODING_DELTA_ZSTD),
       "after its zstd frame"},
      // A zip bomb: a frame of 10 MB of zeros for one vertex, refused at its bound of 6 bytes.
      {"a frame larger than the count allows",
       chunk(v1::SIMPLEX_KIND_VERTEX, 1, zstd(std::string(10000000, '\0')), v1::SIMPLEX_ENCODING_DELTA_ZSTD),
       "decompresses to more than"},
      {"a corrupt frame's sections are checked too",
       chunk(v1::SIMPLEX_KIND_EDGE, 1, zstd(std::string("\x00\x05", 2)), v1::SIMPLEX_ENCODING_DELTA_ZSTD), "truncated"},
  };
  SimplexChunkDecoder decoder;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    v1::SimplexChunk out;
    const absl::Status status = decoder.Decode(c.chunk, 17, &out);
    EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_THAT(std::string(status.message()), HasSubstr("encoded simplex chunk 17: "));
    EXPECT_THAT(std::string(status.message()), HasSubstr(c.message));
  }
  // And after all that, the decoder still decodes.
  v1::SimplexChunk out;
  EXPECT_THAT(decoder.Decode(chunk(v1::SIMPLEX_KIND_VERTEX, 1, one_vertex), 0, &out), IsOk());
  EXPECT_EQ(out.vertex_indices(0), 5u);
}

}  // namespace
}  // namespace galpha::wire
