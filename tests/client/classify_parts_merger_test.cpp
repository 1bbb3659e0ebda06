// The merging of a Classify answer read in parts (client/classify_parts_merger.hpp): the parts a
// server deals round-robin come out as the whole answer, message for message, whatever the
// readers' timing and however small their queues; a server that answers every part whole gives
// the whole answer once; a part's failure, a part 0 without its summary and chunks past the
// answer's end are errors; Stop releases readers that wait for room.
#include "client/classify_parts_merger.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/status_matchers.hpp"

namespace galpha::client {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::StatusIs;

// The whole answer: a summary, then `chunks` chunks, each telling its number.
std::vector<v1::ClassifyResponse> WholeAnswer(uint32_t chunks) {
  std::vector<v1::ClassifyResponse> answer(1);
  answer[0].mutable_summary()->set_level(static_cast<int64_t>(chunks));
  for (uint32_t c = 0; c < chunks; ++c) {
    v1::ClassifyResponse message;
    message.mutable_chunk()->set_kind(v1::SIMPLEX_KIND_EDGE);
    message.mutable_chunk()->add_vertex_indices(c);
    message.mutable_chunk()->add_vertex_indices(c + 1);
    message.mutable_chunk()->mutable_classes()->push_back(static_cast<char>(1 + c % 4));
    answer.push_back(message);
  }
  return answer;
}

// What a server that splits answers sends as part `part` of `parts`.
std::vector<v1::ClassifyResponse> PartOf(const std::vector<v1::ClassifyResponse>& whole, size_t part, size_t parts) {
  std::vector<v1::ClassifyResponse> sent;
  if (part == 0) sent.push_back(whole[0]);
  for (size_t c = part; c + 1 < whole.size(); c += parts) sent.push_back(whole[c + 1]);
  return sent;
}

// Readers: one thread a part, pushing its messages with random pauses, then ending with `ends[p]`.
std::vector<std::thread> StartReaders(ClassifyPartsMerger* merger,
                                      const std::vector<std::vector<v1::ClassifyResponse>>& sent,
                                      const std::vector<absl::Status>& ends, uint32_t seed) {
  std::vector<std::thread> readers;
  for (size_t p = 0; p < sent.size(); ++p) {
    readers.emplace_back([merger, &sent, &ends, p, seed] {
      std::mt19937 random(seed * 131 + static_cast<uint32_t>(p));
      for (const v1::ClassifyResponse& message : sent[p]) {
        if (random() % 3 == 0) std::this_thread::sleep_for(std::chrono::microseconds(random() % 200));
        if (!merger->Push(p, message)) break;  // no longer read: the call would be cancelled
      }
      merger->End(p, ends[p]);
    });
  }
  return readers;
}

// Everything Next gives until the end or an error (returned beside it).
std::vector<std::string> Drain(ClassifyPartsMerger& merger, absl::Status* error) {
  std::vector<std::string> out;
  for (;;) {
    absl::StatusOr<const v1::ClassifyResponse*> next = merger.Next();
    if (!next.ok()) {
      *error = next.status();
      return out;
    }
    if (*next == nullptr) return out;
    out.push_back((*next)->SerializeAsString());
  }
}

std::vector<std::string> Serialized(const std::vector<v1::ClassifyResponse>& messages) {
  std::vector<std::string> out;
  for (const auto& message : messages) out.push_back(message.SerializeAsString());
  return out;
}

TEST(ClassifyPartsMergerTest, PartsDealtRoundRobinComeOutAsTheWholeAnswer) {
  uint32_t seed = 1;
  for (const uint32_t chunks : {0u, 1u, 2u, 5u, 17u, 64u}) {
    for (const size_t parts : {2u, 3u, 8u}) {
      for (const size_t queued : {1u, 4u}) {
        const std::vector<v1::ClassifyResponse> whole = WholeAnswer(chunks);
        std::vector<std::vector<v1::ClassifyResponse>> sent;
        for (size_t p = 0; p < parts; ++p) sent.push_back(PartOf(whole, p, parts));
        const std::vector<absl::Status> ends(parts, absl::OkStatus());
        ClassifyPartsMerger merger(parts, queued);
        std::vector<std::thread> readers = StartReaders(&merger, sent, ends, ++seed);
        absl::Status error;
        const std::vector<std::string> merged = Drain(merger, &error);
        for (std::thread& reader : readers) reader.join();
        EXPECT_TRUE(error.ok()) << error;
        EXPECT_EQ(merged, Serialized(whole)) << chunks << " chunks in " << parts << " parts";
        EXPECT_FALSE(merger.whole_from_part_zero());
      }
    }
  }
}

// A server older than part_count answers every call whole: part 0 is the answer, the others are
// dropped (their pushes refused) and their ends ignored.
TEST(ClassifyPartsMergerTest, AServerThatDoesNotSplitGivesTheWholeAnswerOnce) {
  uint32_t seed = 100;
  for (const uint32_t chunks : {0u, 1u, 9u}) {
    const std::vector<v1::ClassifyResponse> whole = WholeAnswer(chunks);
    const size_t parts = 4;
    const std::vector<std::vector<v1::ClassifyResponse>> sent(parts, whole);
    // Once the merger drops them the client cancels the other calls; with no chunk it never does.
    std::vector<absl::Status> ends(parts,
                                   chunks > 0 ? absl::CancelledError("cancelled by the client") : absl::OkStatus());
    ends[0] = absl::OkStatus();
    ClassifyPartsMerger merger(parts, 2);
    std::vector<std::thread> readers = StartReaders(&merger, sent, ends, ++seed);
    absl::Status error;
    const std::vector<std::string> merged = Drain(merger, &error);
    for (std::thread& reader : readers) reader.join();
    EXPECT_TRUE(error.ok()) << error;
    EXPECT_EQ(merged, Serialized(whole)) << chunks << " chunks";
    EXPECT_EQ(merger.whole_from_part_zero(), chunks > 0) << "with no chunk, part 1's turn never comes";
  }
}

TEST(ClassifyPartsMergerTest, APartsFailureEndsTheAnswerAtItsTurn) {
  const std::vector<v1::ClassifyResponse> whole = WholeAnswer(8);
  std::vector<std::vector<v1::ClassifyResponse>> sent = {PartOf(whole, 0, 2), PartOf(whole, 1, 2)};
  sent[1].resize(1);  // part 1 sends chunk 1, then fails
  const std::vector<absl::Status> ends = {absl::OkStatus(), absl::UnavailableError("connection reset")};
  ClassifyPartsMerger merger(2, 8);
  std::vector<std::thread> readers = StartReaders(&merger, sent, ends, 7);
  absl::Status error;
  const std::vector<std::string> merged = Drain(merger, &error);
  merger.Stop();
  for (std::thread& reader : readers) reader.join();
  EXPECT_THAT(error, StatusIs(absl::StatusCode::kUnavailable));
  const std::vector<std::string> before = Serialized(whole);
  EXPECT_EQ(merged, std::vector<std::string>(before.begin(), before.begin() + 4)) << "summary and chunks 0-2";
}

TEST(ClassifyPartsMergerTest, ChunksPastTheAnswersEndAreAnError) {
  const std::vector<v1::ClassifyResponse> whole = WholeAnswer(4);
  // Part 0 stops before chunk 2 (the answer ends there), part 1 still sends chunk 3.
  std::vector<std::vector<v1::ClassifyResponse>> sent = {PartOf(whole, 0, 2), PartOf(whole, 1, 2)};
  sent[0].resize(2);
  const std::vector<absl::Status> ends(2, absl::OkStatus());
  ClassifyPartsMerger merger(2, 8);
  std::vector<std::thread> readers = StartReaders(&merger, sent, ends, 9);
  absl::Status error;
  Drain(merger, &error);
  for (std::thread& reader : readers) reader.join();
  EXPECT_THAT(error, StatusIs(absl::StatusCode::kInternal));
  EXPECT_NE(error.message().find("part 1 of 2"), std::string::npos) << error;

  // More chunks past the end than the part may queue: its reader waits for room, and the merger
  // must not wait for its end.
  const std::vector<v1::ClassifyResponse> longer = WholeAnswer(40);
  std::vector<std::vector<v1::ClassifyResponse>> many = {PartOf(longer, 0, 2), PartOf(longer, 1, 2)};
  many[0].resize(2);  // the answer ends at chunk 2; part 1 goes on to chunk 39
  ClassifyPartsMerger small(2, 1);
  std::vector<std::thread> more = StartReaders(&small, many, ends, 10);
  absl::Status stuck;
  Drain(small, &stuck);
  small.Stop();  // releases the reader waiting for room, as the client does after an error
  for (std::thread& reader : more) reader.join();
  EXPECT_THAT(stuck, StatusIs(absl::StatusCode::kInternal));
}

TEST(ClassifyPartsMergerTest, PartZeroMustStartWithTheSummary) {
  const std::vector<v1::ClassifyResponse> whole = WholeAnswer(3);
  std::vector<std::vector<v1::ClassifyResponse>> sent = {PartOf(whole, 0, 2), PartOf(whole, 1, 2)};
  sent[0].erase(sent[0].begin());
  const std::vector<absl::Status> ends(2, absl::OkStatus());
  ClassifyPartsMerger merger(2, 8);
  std::vector<std::thread> readers = StartReaders(&merger, sent, ends, 11);
  absl::Status error;
  EXPECT_TRUE(Drain(merger, &error).empty());
  merger.Stop();
  for (std::thread& reader : readers) reader.join();
  EXPECT_THAT(error, StatusIs(absl::StatusCode::kInternal));
}

TEST(ClassifyPartsMergerTest, StopReleasesReadersWaitingForRoom) {
  const std::vector<v1::ClassifyResponse> whole = WholeAnswer(200);
  std::vector<std::vector<v1::ClassifyResponse>> sent;
  for (size_t p = 0; p < 3; ++p) sent.push_back(PartOf(whole, p, 3));
  const std::vector<absl::Status> ends(3, absl::OkStatus());
  ClassifyPartsMerger merger(3, 1);
  std::vector<std::thread> readers = StartReaders(&merger, sent, ends, 13);
  absl::StatusOr<const v1::ClassifyResponse*> first = merger.Next();
  ASSERT_TRUE(first.ok() && *first != nullptr && (*first)->has_summary());
  merger.Stop();  // the readers wait for room in their one-message queues: released, pushes refused
  for (std::thread& reader : readers) reader.join();
  absl::StatusOr<const v1::ClassifyResponse*> after = merger.Next();
  ASSERT_TRUE(after.ok());
  EXPECT_EQ(*after, nullptr);
}

}  // namespace
}  // namespace galpha::client
