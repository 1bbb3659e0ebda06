// The MasterList stream against the in-process AlphaFamily's master list: every entry of the
// requested ranks, in order, in full messages; bad ranges and empty spectra refused.
#include "server/query_answers.hpp"

#include <algorithm>
#include <cstdint>
#include <memory>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "server/cached_family.hpp"
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
using testing::NamedFamily;

// ---- MasterList -----------------------------------------------------------------------------------

// One master-list entry as the stream names it: rank, kind byte, endpoint byte, sorted indices.
using StreamedEntry = std::tuple<uint64_t, int, int, std::vector<uint32_t>>;

std::vector<StreamedEntry> ExpectedMasterList(const AlphaFamily& family, int64_t first, int64_t last) {
  std::vector<StreamedEntry> out;
  for (int64_t rank = first; rank <= last; ++rank) {
    for (const MasterEntry& entry : family.MasterList(rank)) {
      std::vector<uint32_t> indices;
      switch (entry.kind()) {
        case SimplexKind::kVertex:
          indices.push_back(entry.id());
          break;
        case SimplexKind::kEdge:
          for (const uint32_t v : family.edges()[entry.id()]) indices.push_back(v);
          break;
        case SimplexKind::kTriangle:
          for (const uint32_t v : family.triangles()[entry.id()]) indices.push_back(v);
          break;
      }
      std::sort(indices.begin(), indices.end());
      out.emplace_back(static_cast<uint64_t>(rank), static_cast<int>(entry.kind()) + 1,
                       static_cast<int>(entry.endpoint()) + 1, std::move(indices));
    }
  }
  return out;
}

void CheckMasterList(const std::shared_ptr<const CachedFamily>& cached, const AlphaFamily& oracle, int64_t first,
                     int64_t last_field) {
  SCOPED_TRACE(absl::StrCat("ranks ", first, "..", last_field));
  const int64_t last = last_field == 0 ? first : last_field;
  v1::MasterListRequest request;
  request.set_first_rank(first);
  request.set_last_rank(last_field);
  auto source = MakeMasterListSource(cached, request);
  ASSERT_THAT(source, IsOk());
  std::vector<StreamedEntry> streamed;
  const std::vector<v1::MasterListResponse> messages = Drain(**source);
  for (const v1::MasterListResponse& message : messages) {
    const size_t entries = static_cast<size_t>(message.ranks_size());
    EXPECT_GT(entries, 0u);
    EXPECT_LE(entries, kMasterEntriesPerChunk);
    ASSERT_EQ(message.kinds().size(), entries);
    ASSERT_EQ(message.endpoints().size(), entries);
    int position = 0;
    for (size_t i = 0; i < entries; ++i) {
      const int kind = static_cast<unsigned char>(message.kinds()[i]);
      ASSERT_GE(kind, v1::SIMPLEX_KIND_VERTEX);
      ASSERT_LE(kind, v1::SIMPLEX_KIND_TRIANGLE);
      ASSERT_LE(position + kind, message.vertex_indices_size());
      std::vector<uint32_t> indices(message.vertex_indices().begin() + position,
                                    message.vertex_indices().begin() + position + kind);
      position += kind;
      streamed.emplace_back(message.ranks(static_cast<int>(i)), kind, static_cast<int>(message.endpoints()[i]),
                            std::move(indices));
    }
    EXPECT_EQ(position, message.vertex_indices_size());
  }
  const std::vector<StreamedEntry> expected = ExpectedMasterList(oracle, first, last);
  EXPECT_EQ(messages.size(), (expected.size() + kMasterEntriesPerChunk - 1) / kMasterEntriesPerChunk)
      << "every message but the last is full";
  ASSERT_EQ(streamed.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    if (streamed[i] != expected[i]) {
      ADD_FAILURE() << "entry " << i << " differs: rank " << std::get<0>(streamed[i]) << " vs "
                    << std::get<0>(expected[i]);
      break;
    }
  }
}

TEST(QueryAnswersTest, MasterListReproducesTheFamilysList) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const int64_t k = f.oracle->max_level();
    if (k == 0) continue;
    CheckMasterList(f.cached, *f.oracle, 1, 0);
    CheckMasterList(f.cached, *f.oracle, k, 0);
    CheckMasterList(f.cached, *f.oracle, 1, k);
    CheckMasterList(f.cached, *f.oracle, (k + 1) / 2, std::min(k, (k + 1) / 2 + 5));
    CheckMasterList(f.cached, *f.oracle, k, k);
  }
}

TEST(QueryAnswersTest, MasterListOfALargeFamilySpansSeveralMessages) {
  const std::shared_ptr<const CachedFamily> cached = LargeFamily();
  ASSERT_NE(cached, nullptr);
  ASSERT_GT(cached->host_family()->ranks().master.size(), 2 * size_t{kMasterEntriesPerChunk});
  CheckMasterList(cached, *cached->host_family(), 1, cached->host_family()->max_level());
}

TEST(QueryAnswersTest, MasterListRefusesBadRanges) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const int64_t k = f.oracle->max_level();
    std::vector<std::pair<int64_t, int64_t>> bad = {{0, 0},         {0, 1},     {-1, 0}, {k + 1, 0},
                                                    {k + 1, k + 1}, {1, k + 1}, {2, 1}};
    if (k >= 2) bad.emplace_back(k, k - 1);  // reversed (k - 1 = 0 would mean "first alone")
    for (const auto& [first, last] : bad) {
      SCOPED_TRACE(absl::StrCat(first, "..", last));
      v1::MasterListRequest request;
      request.set_first_rank(first);
      request.set_last_rank(last);
      const auto source = MakeMasterListSource(f.cached, request);
      EXPECT_THAT(source.status(), StatusIs(absl::StatusCode::kInvalidArgument));
    }
  }
}

TEST(QueryAnswersTest, MasterListOfAnEmptySpectrumIsRefused) {
  size_t checked = 0;
  for (const NamedFamily& f : Families()) {
    ASSERT_NE(f.cached, nullptr);
    if (f.oracle->max_level() != 0) continue;
    SCOPED_TRACE(f.name);
    ++checked;
    for (const int64_t first : {int64_t{0}, int64_t{1}, int64_t{2}}) {
      v1::MasterListRequest request;
      request.set_first_rank(first);
      const auto source = MakeMasterListSource(f.cached, request);
      EXPECT_THAT(source.status(), StatusIs(absl::StatusCode::kInvalidArgument));
      EXPECT_NE(source.status().message().find("empty"), absl::string_view::npos) << source.status();
    }
  }
  EXPECT_GE(checked, 2u) << "the empty and one-point families have no spectrum";
}

}  // namespace
}  // namespace galpha::server
