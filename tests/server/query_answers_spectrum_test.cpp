// Spectrum pages against the in-process AlphaFamily's spectrum: pages of every size concatenate to
// the spectrum, a page from "at least alpha_sq", bad requests refused.
#include "server/query_answers.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "gtest/gtest.h"
#include "tests/server/query_answers_fixture.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using testing::Families;
using testing::NamedFamily;

// ---- Spectrum -------------------------------------------------------------------------------------

TEST(QueryAnswersTest, SpectrumPagesConcatenateToTheSpectrum) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = *f.oracle;
    const int64_t k = family.max_level();
    for (const uint32_t page_size : {1u, 7u, 1000u, 0u, kMaxSpectrumPage}) {
      SCOPED_TRACE(page_size);
      std::vector<double> all;
      v1::SpectrumRequest request;
      request.set_page_size(page_size);
      request.set_first_rank(1);
      for (int pages = 0;; ++pages) {
        ASSERT_LT(pages, 100000) << "next_rank never reaches 0";
        const absl::StatusOr<v1::SpectrumResponse> page = AnswerSpectrum(f.cached->reader(), request);
        ASSERT_THAT(page, IsOk());
        EXPECT_EQ(page->first_rank(), request.first_rank());
        EXPECT_EQ(page->spectrum_size(), k);
        const int64_t size = page->alpha_sq_size();
        EXPECT_LE(size, page_size == 0 ? int64_t{kDefaultSpectrumPage} : int64_t{page_size});
        all.insert(all.end(), page->alpha_sq().begin(), page->alpha_sq().end());
        if (page->next_rank() == 0) {
          EXPECT_EQ(request.first_rank() + size - 1, k) << "the last page reaches rank K";
          break;
        }
        EXPECT_EQ(page->next_rank(), request.first_rank() + size);
        EXPECT_GT(size, 0);
        request.set_first_rank(page->next_rank());
      }
      EXPECT_EQ(all, family.spectrum());
    }
    // Without a start: from rank 1, 65536 values per page.
    const absl::StatusOr<v1::SpectrumResponse> whole = AnswerSpectrum(f.cached->reader(), v1::SpectrumRequest());
    ASSERT_THAT(whole, IsOk());
    EXPECT_EQ(whole->first_rank(), 1);
    EXPECT_EQ(std::vector<double>(whole->alpha_sq().begin(), whole->alpha_sq().end()), family.spectrum());
    EXPECT_EQ(whole->next_rank(), 0);
    // K + 1: an empty page at the end.
    v1::SpectrumRequest past;
    past.set_first_rank(k + 1);
    const absl::StatusOr<v1::SpectrumResponse> empty = AnswerSpectrum(f.cached->reader(), past);
    ASSERT_THAT(empty, IsOk());
    EXPECT_EQ(empty->alpha_sq_size(), 0);
    EXPECT_EQ(empty->next_rank(), 0);
    EXPECT_EQ(empty->first_rank(), k + 1);
  }
}

TEST(QueryAnswersTest, SpectrumFromAtLeastAlphaSq) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = *f.oracle;
    const int64_t k = family.max_level();
    const auto& s = family.spectrum();
    std::vector<double> values = {-1.0, 0.0, 1e-300, std::numeric_limits<double>::infinity(), 1e300};
    for (int64_t rank = 1; rank <= k; rank += std::max<int64_t>(1, k / 7)) {
      const double v = s[static_cast<size_t>(rank - 1)];
      values.push_back(v);
      values.push_back(std::nextafter(v, 0.0));
      values.push_back(std::nextafter(v, std::numeric_limits<double>::infinity()));
    }
    for (const double x : values) {
      SCOPED_TRACE(x);
      v1::SpectrumRequest request;
      request.set_at_least_alpha_sq(x);
      request.set_page_size(5);
      const absl::StatusOr<v1::SpectrumResponse> page = AnswerSpectrum(f.cached->reader(), request);
      ASSERT_THAT(page, IsOk());
      const int64_t first = family.RankLowerBound(x);
      EXPECT_EQ(page->first_rank(), first);
      const int64_t end = std::min<int64_t>(k, first + 4);
      ASSERT_EQ(page->alpha_sq_size(), std::max<int64_t>(0, end - first + 1));
      for (int i = 0; i < page->alpha_sq_size(); ++i) {
        EXPECT_EQ(page->alpha_sq(i), s[static_cast<size_t>(first - 1 + i)]);
      }
      EXPECT_EQ(page->next_rank(), end < k ? end + 1 : 0);
    }
  }
}

TEST(QueryAnswersTest, SpectrumRefusesBadRequests) {
  for (const NamedFamily& f : Families()) {
    SCOPED_TRACE(f.name);
    ASSERT_NE(f.cached, nullptr);
    const AlphaFamily& family = *f.oracle;
    const int64_t k = family.max_level();
    for (const int64_t first : {int64_t{0}, int64_t{-1}, k + 2}) {
      v1::SpectrumRequest request;
      request.set_first_rank(first);
      EXPECT_THAT(AnswerSpectrum(f.cached->reader(), request).status(), StatusIs(absl::StatusCode::kInvalidArgument))
          << first;
    }
    v1::SpectrumRequest too_large;
    too_large.set_page_size(kMaxSpectrumPage + 1);
    const auto refused = AnswerSpectrum(f.cached->reader(), too_large);
    EXPECT_THAT(refused.status(), StatusIs(absl::StatusCode::kInvalidArgument));
    v1::SpectrumRequest nan;
    nan.set_at_least_alpha_sq(std::nan(""));
    EXPECT_THAT(AnswerSpectrum(f.cached->reader(), nan).status(), StatusIs(absl::StatusCode::kInvalidArgument));
  }
}

}  // namespace
}  // namespace galpha::server
