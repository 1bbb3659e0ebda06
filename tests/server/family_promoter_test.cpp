// Promotion from the compact tier: the rebuild is the family that was demoted (bit for bit), it
// is cached resident again, concurrent callers share one rebuild, and a rebuild the scheduler
// refuses (queue full, draining) fails with a status that names the handle and the reason while
// the compact entry stays. Real families on the CPU backend, a real scheduler.
#include "server/family_promoter.hpp"

#include <algorithm>
#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "gtest/gtest.h"
#include "server/build_scheduler.hpp"
#include "server/family_cache.hpp"
#include "tests/server/cached_family_fixture.hpp"
#include "tests/support/one_shot_gate.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using ::testing::HasSubstr;

using Gate = galpha::testing::OneShotGate;

// A cache whose resident tier holds one of the test's families, with `a` demoted by `b`.
class FamilyPromoterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    a_ = testing::MakeCachedFamily(gen::Clustered(400, 7), "a");
    b_ = testing::MakeCachedFamily(gen::Uniform(300, 8), "b");
    ASSERT_NE(a_, nullptr);
    ASSERT_NE(b_, nullptr);
    cache_ = std::make_unique<FamilyCache>(FamilyCache::Budgets{std::max(a_->bytes(), b_->bytes()), size_t{1} << 30},
                                           nullptr);
    ASSERT_THAT(cache_->Insert("t", "h-a", a_), IsOk());
    ASSERT_THAT(cache_->Insert("t", "h-b", b_), IsOk());
    compact_ = cache_->Lookup("t", "h-a").compact;
    ASSERT_NE(compact_, nullptr) << "a was demoted";
  }

  // A scheduler of one CPU slot; `max_queue` jobs may wait for it.
  static std::unique_ptr<BuildScheduler> OneSlot(size_t max_queue) {
    return std::make_unique<BuildScheduler>(std::vector<void*>{nullptr}, max_queue, max_queue, 0, nullptr);
  }

  // Runs a job on the scheduler's only slot that holds it until `release` opens.
  static void HoldTheSlot(BuildScheduler& scheduler, Gate* release) {
    // Shared: the job may still be inside Open() when this returns.
    auto holding = std::make_shared<Gate>();
    ASSERT_THAT(scheduler.Submit("t", 0,
                                 [holding, release](const BuildSlot&, bool) {
                                   holding->Open();
                                   release->Wait();
                                 }),
                IsOk());
    ASSERT_TRUE(holding->Wait());
  }

  FamilyPromoter MakePromoter(BuildScheduler* scheduler) {
    return FamilyPromoter(cache_.get(), scheduler, Backend::kCpu, /*resident=*/false, 640,
                          [this](const BuildReport&, double) { ++rebuilds_; });
  }

  std::shared_ptr<const CachedFamily> a_, b_;
  std::unique_ptr<FamilyCache> cache_;
  std::shared_ptr<const CompactFamily> compact_;
  std::atomic<int> rebuilds_{0};
};

TEST_F(FamilyPromoterTest, RebuildsTheDemotedFamilyAndCachesIt) {
  auto scheduler = OneSlot(4);
  FamilyPromoter promoter = MakePromoter(scheduler.get());
  const auto promoted = promoter.Promote("t", "h-a", compact_);
  ASSERT_THAT(promoted, IsOk());
  EXPECT_EQ(rebuilds_.load(), 1);
  EXPECT_EQ(promoter.in_flight(), 0u);
  const AlphaFamily &before = *a_->host_family(), &after = *(*promoted)->host_family();
  EXPECT_NE(&before, &after);
  EXPECT_TRUE(std::equal(before.triangles().begin(), before.triangles().end(), after.triangles().begin(),
                         after.triangles().end()));
  EXPECT_TRUE(std::equal(before.edges().begin(), before.edges().end(), after.edges().begin(), after.edges().end()));
  EXPECT_TRUE(
      std::equal(before.spectrum().begin(), before.spectrum().end(), after.spectrum().begin(), after.spectrum().end()));
  EXPECT_TRUE(std::equal(before.ranks().master.begin(), before.ranks().master.end(), after.ranks().master.begin(),
                         after.ranks().master.end(),
                         [](const MasterEntry& x, const MasterEntry& y) { return x.packed() == y.packed(); }));
  EXPECT_EQ((*promoted)->bytes(), a_->bytes());

  EXPECT_EQ(cache_->Find("t", "h-a").get(), promoted->get()) << "resident again";
  const FamilyCache::Stats stats = cache_->GetStats();
  EXPECT_EQ(stats.promotions, 1u);
  EXPECT_EQ(stats.demotions, 2u) << "b made room for it";
  EXPECT_NE(cache_->Lookup("t", "h-b").compact, nullptr);
}

TEST_F(FamilyPromoterTest, ConcurrentCallersShareOneRebuild) {
  auto scheduler = OneSlot(4);
  FamilyPromoter promoter = MakePromoter(scheduler.get());
  // The only slot is held until every caller has asked, so that their calls overlap the rebuild.
  Gate release;
  ASSERT_NO_FATAL_FAILURE(HoldTheSlot(*scheduler, &release));
  constexpr int kCallers = 6;
  std::vector<absl::StatusOr<std::shared_ptr<const CachedFamily>>> results(kCallers, absl::UnknownError("not run"));
  std::atomic<int> asking{0};
  std::vector<std::thread> callers;
  for (int i = 0; i < kCallers; ++i) {
    callers.emplace_back([&, i] {
      ++asking;
      results[static_cast<size_t>(i)] = promoter.Promote("t", "h-a", compact_);
    });
  }
  while (asking.load() < kCallers) std::this_thread::yield();
  release.Open();
  for (std::thread& caller : callers) caller.join();
  // Exactly one rebuild whatever the interleaving: a caller either joins the rebuild in flight or,
  // once it is cached, finds the family resident.
  EXPECT_EQ(rebuilds_.load(), 1);
  for (const auto& result : results) {
    ASSERT_THAT(result, IsOk());
    EXPECT_EQ(result->get(), results[0]->get()) << "every caller gets the one cached object";
  }
  EXPECT_EQ(cache_->GetStats().promotions, 1u);
}

TEST_F(FamilyPromoterTest, AFullQueueRefusesTheRebuildAndKeepsTheEntry) {
  auto scheduler = OneSlot(0);
  FamilyPromoter promoter = MakePromoter(scheduler.get());
  Gate release;
  ASSERT_NO_FATAL_FAILURE(HoldTheSlot(*scheduler, &release));
  const auto refused = promoter.Promote("t", "h-a", compact_);
  release.Open();
  EXPECT_THAT(refused.status(), StatusIs(absl::StatusCode::kResourceExhausted));
  EXPECT_THAT(std::string(refused.status().message()), HasSubstr("handle h-a is in the compact tier"));
  EXPECT_EQ(rebuilds_.load(), 0);
  EXPECT_EQ(promoter.in_flight(), 0u) << "a refused rebuild leaves nothing for later callers to wait on";
  EXPECT_NE(cache_->Lookup("t", "h-a").compact, nullptr) << "the entry stays for the next query";
}

TEST_F(FamilyPromoterTest, AStoppedSchedulerAnswersUnavailable) {
  auto scheduler = OneSlot(4);
  FamilyPromoter promoter = MakePromoter(scheduler.get());
  scheduler->Stop();
  const auto refused = promoter.Promote("t", "h-a", compact_);
  EXPECT_THAT(refused.status(), StatusIs(absl::StatusCode::kUnavailable));
  EXPECT_THAT(std::string(refused.status().message()), HasSubstr("h-a"));
  EXPECT_NE(cache_->Lookup("t", "h-a").compact, nullptr);
}

TEST_F(FamilyPromoterTest, AFamilyResidentAgainIsNotRebuilt) {
  // Another caller promoted it between this caller's lookup and its call.
  ASSERT_THAT(cache_->Insert("t", "h-a", a_), IsOk());
  auto scheduler = OneSlot(4);
  FamilyPromoter promoter = MakePromoter(scheduler.get());
  const auto promoted = promoter.Promote("t", "h-a", compact_);
  ASSERT_THAT(promoted, IsOk());
  EXPECT_EQ(promoted->get(), a_.get());
  EXPECT_EQ(rebuilds_.load(), 0);
}

}  // namespace
}  // namespace galpha::server
