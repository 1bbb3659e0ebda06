// The family cache with real families (small point sets built on the CPU backend): hits and misses,
// least-recently-used eviction under a byte budget, the compact tier (demotion with the points,
// promotion by an insert, its own eviction), tenants kept apart, the first of two racing
// inserts kept, the observer agreeing with the statistics, and a family in use outliving its
// eviction. Also the index orders a CachedFamily computes for Classify.
#include "server/family_cache.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gpu/alpha/alpha_engine.hpp"
#include "gtest/gtest.h"
#include "server/cached_family.hpp"
#include "server/compact_family.hpp"
#include "tests/server/cached_family_fixture.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

using galpha::testing::IsOk;
using galpha::testing::StatusIs;

std::shared_ptr<const CachedFamily> MakeFamily(const std::vector<Point2>& points, const std::string& name) {
  return testing::MakeCachedFamily(points, name);
}

// Records every callback, so that tests compare it with GetStats().
class RecordingObserver : public CacheObserver {
 public:
  void OnHit(CacheTier tier) override { ++hits[static_cast<size_t>(tier)]; }
  void OnMiss() override { ++misses; }
  void OnEviction(CacheTier tier) override { ++evictions[static_cast<size_t>(tier)]; }
  void OnDemotion() override { ++demotions; }
  void OnPromotion() override { ++promotions; }
  void OnSize(CacheTier tier, size_t bytes, size_t entries) override {
    last_bytes[static_cast<size_t>(tier)] = bytes;
    last_entries[static_cast<size_t>(tier)] = entries;
    ++size_reports;
  }
  void OnDeviceSize(size_t bytes) override { last_device_bytes = bytes; }

  size_t last_device_bytes = 0;
  std::array<uint64_t, 2> hits{}, evictions{};
  uint64_t misses = 0, demotions = 0, promotions = 0, size_reports = 0;
  std::array<size_t, 2> last_bytes{}, last_entries{};
};

void ExpectObserverAgrees(const RecordingObserver& observer, const FamilyCache& cache) {
  const FamilyCache::Stats stats = cache.GetStats();
  const std::array<const FamilyCache::TierStats*, 2> tiers = {&stats.resident, &stats.compact};
  for (size_t tier = 0; tier < 2; ++tier) {
    SCOPED_TRACE(CacheTierName(static_cast<CacheTier>(tier)));
    EXPECT_EQ(observer.hits[tier], tiers[tier]->hits);
    EXPECT_EQ(observer.evictions[tier], tiers[tier]->evictions);
    EXPECT_EQ(observer.last_bytes[tier], tiers[tier]->bytes);
    EXPECT_EQ(observer.last_entries[tier], tiers[tier]->entries);
  }
  EXPECT_EQ(observer.misses, stats.misses);
  EXPECT_EQ(observer.demotions, stats.demotions);
  EXPECT_EQ(observer.promotions, stats.promotions);
}

/// A cache with only the resident tier (what the tests of its LRU order need).
FamilyCache::Budgets ResidentOnly(size_t bytes) { return {bytes, 0}; }

class FamilyCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    a_ = MakeFamily(gen::Uniform(40, 1), "a");
    b_ = MakeFamily(gen::Uniform(50, 2), "b");
    c_ = MakeFamily(gen::Uniform(60, 3), "c");
    ASSERT_NE(a_, nullptr);
    ASSERT_NE(b_, nullptr);
    ASSERT_NE(c_, nullptr);
    // Any two fit, all three do not.
    two_fit_ = std::max({a_->bytes() + b_->bytes(), b_->bytes() + c_->bytes(), a_->bytes() + c_->bytes()});
    ASSERT_LT(two_fit_, a_->bytes() + b_->bytes() + c_->bytes());
  }

  // Caches a, b and c under h-a, h-b and h-c, in that order.
  void InsertInTurn(FamilyCache& cache) const {
    ASSERT_THAT(cache.Insert("", "h-a", a_), IsOk());
    ASSERT_THAT(cache.Insert("", "h-b", b_), IsOk());
    ASSERT_THAT(cache.Insert("", "h-c", c_), IsOk());
  }

  std::shared_ptr<const CachedFamily> a_, b_, c_;
  size_t two_fit_ = 0;
};

TEST_F(FamilyCacheTest, FindCountsMissesAndHits) {
  RecordingObserver observer;
  FamilyCache cache(ResidentOnly(size_t{1} << 30), &observer);
  EXPECT_EQ(observer.size_reports, 2u) << "the constructor reports the empty tiers";
  EXPECT_EQ(cache.byte_budget(), size_t{1} << 30);

  EXPECT_EQ(cache.Find("", "h-a"), nullptr);
  auto inserted = cache.Insert("", "h-a", a_);
  ASSERT_THAT(inserted, IsOk());
  EXPECT_EQ(inserted->get(), a_.get());
  EXPECT_EQ(cache.Find("", "h-a").get(), a_.get());
  EXPECT_EQ(cache.Find("", "h-a").get(), a_.get());
  EXPECT_EQ(cache.Find("", "h-b"), nullptr);

  const FamilyCache::Stats stats = cache.GetStats();
  EXPECT_EQ(stats.resident.hits, 2u);
  EXPECT_EQ(stats.misses, 2u);
  EXPECT_EQ(stats.resident.entries, 1u);
  EXPECT_EQ(stats.resident.bytes, a_->bytes());
  EXPECT_EQ(stats.resident.evictions, 0u);
  ExpectObserverAgrees(observer, cache);
}

TEST_F(FamilyCacheTest, EvictsTheLeastRecentlyUsed) {
  RecordingObserver observer;
  FamilyCache cache(ResidentOnly(two_fit_), &observer);
  ASSERT_THAT(cache.Insert("", "h-a", a_), IsOk());
  ASSERT_THAT(cache.Insert("", "h-b", b_), IsOk());
  EXPECT_EQ(cache.GetStats().resident.entries, 2u);
  ASSERT_THAT(cache.Insert("", "h-c", c_), IsOk());

  const FamilyCache::Stats stats = cache.GetStats();
  EXPECT_EQ(stats.resident.evictions, 1u);
  EXPECT_EQ(stats.resident.entries, 2u);
  EXPECT_EQ(stats.resident.bytes, b_->bytes() + c_->bytes());
  EXPECT_LE(stats.resident.bytes, cache.byte_budget());
  EXPECT_EQ(cache.Find("", "h-a"), nullptr) << "a was the least recently used";
  EXPECT_EQ(cache.Find("", "h-b").get(), b_.get());
  EXPECT_EQ(cache.Find("", "h-c").get(), c_.get());
  ExpectObserverAgrees(observer, cache);
}

TEST_F(FamilyCacheTest, FindMakesAFamilyTheMostRecentlyUsed) {
  RecordingObserver observer;
  FamilyCache cache(ResidentOnly(two_fit_), &observer);
  ASSERT_THAT(cache.Insert("", "h-a", a_), IsOk());
  ASSERT_THAT(cache.Insert("", "h-b", b_), IsOk());
  ASSERT_EQ(cache.Find("", "h-a").get(), a_.get());  // now b is the least recently used
  ASSERT_THAT(cache.Insert("", "h-c", c_), IsOk());

  EXPECT_EQ(cache.GetStats().resident.evictions, 1u);
  EXPECT_EQ(cache.GetStats().resident.bytes, a_->bytes() + c_->bytes());
  EXPECT_EQ(cache.Find("", "h-b"), nullptr) << "b was the least recently used";
  EXPECT_EQ(cache.Find("", "h-a").get(), a_.get());
  EXPECT_EQ(cache.Find("", "h-c").get(), c_.get());
  ExpectObserverAgrees(observer, cache);
}

TEST_F(FamilyCacheTest, ReinsertMakesAFamilyTheMostRecentlyUsed) {
  FamilyCache cache(ResidentOnly(two_fit_), nullptr);
  ASSERT_THAT(cache.Insert("", "h-a", a_), IsOk());
  ASSERT_THAT(cache.Insert("", "h-b", b_), IsOk());
  ASSERT_THAT(cache.Insert("", "h-a", a_), IsOk());  // an existing key is touched, not added
  EXPECT_EQ(cache.GetStats().resident.entries, 2u);
  ASSERT_THAT(cache.Insert("", "h-c", c_), IsOk());
  EXPECT_EQ(cache.Find("", "h-b"), nullptr);
  EXPECT_NE(cache.Find("", "h-a"), nullptr);
}

TEST_F(FamilyCacheTest, EvictsAsManyAsNeeded) {
  // a and b fit together; c alone fills the budget, so both go.
  const size_t budget = std::max(a_->bytes() + b_->bytes(), c_->bytes());
  ASSERT_LT(budget, a_->bytes() + c_->bytes());
  ASSERT_LT(budget, b_->bytes() + c_->bytes());
  RecordingObserver observer;
  FamilyCache cache(ResidentOnly(budget), &observer);
  ASSERT_THAT(cache.Insert("", "h-a", a_), IsOk());
  ASSERT_THAT(cache.Insert("", "h-b", b_), IsOk());
  ASSERT_THAT(cache.Insert("", "h-c", c_), IsOk());
  EXPECT_EQ(cache.GetStats().resident.evictions, 2u);
  EXPECT_EQ(cache.GetStats().resident.entries, 1u);
  EXPECT_EQ(cache.GetStats().resident.bytes, c_->bytes());
  ExpectObserverAgrees(observer, cache);
}

TEST_F(FamilyCacheTest, FamilyLargerThanTheBudgetIsRefused) {
  RecordingObserver observer;
  FamilyCache cache(ResidentOnly(c_->bytes() - 1), &observer);
  ASSERT_THAT(cache.Insert("", "h-a", a_), IsOk());
  const auto refused = cache.Insert("", "h-c", c_);
  EXPECT_THAT(refused.status(), StatusIs(absl::StatusCode::kResourceExhausted));
  const FamilyCache::Stats stats = cache.GetStats();
  EXPECT_EQ(stats.resident.evictions, 0u) << "a refused family evicts nothing";
  EXPECT_EQ(stats.resident.entries, 1u);
  EXPECT_EQ(stats.resident.bytes, a_->bytes());
  EXPECT_EQ(cache.Find("", "h-c"), nullptr);
  EXPECT_EQ(cache.Find("", "h-a").get(), a_.get());
  ExpectObserverAgrees(observer, cache);

  FamilyCache exact(ResidentOnly(c_->bytes()), nullptr);
  EXPECT_THAT(exact.Insert("", "h-c", c_), IsOk()) << "a family exactly the budget fits";
}

TEST_F(FamilyCacheTest, TenantsAreIsolated) {
  FamilyCache cache(ResidentOnly(size_t{1} << 30), nullptr);
  ASSERT_THAT(cache.Insert("alice", "h", a_), IsOk());
  EXPECT_EQ(cache.Find("bob", "h"), nullptr);
  EXPECT_EQ(cache.Find("", "h"), nullptr);
  EXPECT_EQ(cache.Find("alice", "h").get(), a_.get());

  const auto bobs = cache.Insert("bob", "h", b_);
  ASSERT_THAT(bobs, IsOk());
  EXPECT_EQ(bobs->get(), b_.get()) << "the same handle under another tenant is another entry";
  EXPECT_EQ(cache.GetStats().resident.entries, 2u);
  EXPECT_EQ(cache.GetStats().resident.bytes, a_->bytes() + b_->bytes());
  EXPECT_EQ(cache.Find("alice", "h").get(), a_.get());
  EXPECT_EQ(cache.Find("bob", "h").get(), b_.get());

  EXPECT_TRUE(cache.Erase("bob", "h"));
  EXPECT_EQ(cache.Find("bob", "h"), nullptr);
  EXPECT_EQ(cache.Find("alice", "h").get(), a_.get()) << "erasing one tenant's entry keeps the other's";
}

TEST_F(FamilyCacheTest, TenantAndHandleDoNotRunTogether) {
  // A key built by plain concatenation would confuse ("ab", "c") with ("a", "bc").
  FamilyCache cache(ResidentOnly(size_t{1} << 30), nullptr);
  ASSERT_THAT(cache.Insert("ab", "c", a_), IsOk());
  EXPECT_EQ(cache.Find("a", "bc"), nullptr);
  EXPECT_EQ(cache.Find("abc", ""), nullptr);
}

TEST_F(FamilyCacheTest, InsertOfAnExistingKeyReturnsTheCachedFamily) {
  RecordingObserver observer;
  FamilyCache cache(ResidentOnly(size_t{1} << 30), &observer);
  const auto first = cache.Insert("", "h", a_);
  ASSERT_THAT(first, IsOk());
  // A second build of the same points races with the first: its family is another object.
  const std::shared_ptr<const CachedFamily> again = MakeFamily(gen::Uniform(40, 1), "a again");
  ASSERT_NE(again, nullptr);
  ASSERT_NE(again.get(), a_.get());
  const auto second = cache.Insert("", "h", again);
  ASSERT_THAT(second, IsOk());
  EXPECT_EQ(second->get(), a_.get());
  EXPECT_EQ(cache.Find("", "h").get(), a_.get());
  EXPECT_EQ(cache.GetStats().resident.entries, 1u);
  EXPECT_EQ(cache.GetStats().resident.bytes, a_->bytes());
  ExpectObserverAgrees(observer, cache);
}

TEST_F(FamilyCacheTest, Erase) {
  RecordingObserver observer;
  FamilyCache cache(ResidentOnly(size_t{1} << 30), &observer);
  ASSERT_THAT(cache.Insert("", "h-a", a_), IsOk());
  ASSERT_THAT(cache.Insert("", "h-b", b_), IsOk());
  EXPECT_FALSE(cache.Erase("", "h-c"));
  EXPECT_FALSE(cache.Erase("other", "h-a"));
  EXPECT_TRUE(cache.Erase("", "h-a"));
  EXPECT_FALSE(cache.Erase("", "h-a")) << "Erase is idempotent";
  EXPECT_EQ(cache.Find("", "h-a"), nullptr);
  EXPECT_EQ(cache.Find("", "h-b").get(), b_.get());

  const FamilyCache::Stats stats = cache.GetStats();
  EXPECT_EQ(stats.resident.entries, 1u);
  EXPECT_EQ(stats.resident.bytes, b_->bytes());
  EXPECT_EQ(stats.resident.evictions, 0u) << "an erase is not an eviction";
  ExpectObserverAgrees(observer, cache);

  EXPECT_TRUE(cache.Erase("", "h-b"));
  EXPECT_EQ(cache.GetStats().resident.bytes, 0u);
  EXPECT_EQ(cache.GetStats().resident.entries, 0u);
  ExpectObserverAgrees(observer, cache);
  ASSERT_THAT(cache.Insert("", "h-a", a_), IsOk()) << "an erased key can be cached again";
  EXPECT_EQ(cache.Find("", "h-a").get(), a_.get());
}

TEST_F(FamilyCacheTest, StatsAndObserverAgreeThroughAMixedSequence) {
  RecordingObserver observer;
  FamilyCache cache(ResidentOnly(two_fit_), &observer);
  const std::vector<std::shared_ptr<const CachedFamily>> families = {a_, b_, c_};
  for (int round = 0; round < 5; ++round) {
    for (size_t i = 0; i < families.size(); ++i) {
      const std::string handle = absl::StrCat("h", i);
      if (cache.Find("", handle) == nullptr) {
        ASSERT_THAT(cache.Insert("", handle, families[i]), IsOk());
      }
      ExpectObserverAgrees(observer, cache);
      EXPECT_LE(cache.GetStats().resident.bytes, cache.byte_budget());
    }
    if (round == 2) cache.Erase("", "h1");
    ExpectObserverAgrees(observer, cache);
  }
  const FamilyCache::Stats stats = cache.GetStats();
  EXPECT_EQ(stats.resident.hits + stats.misses, 15u);
  EXPECT_GT(stats.resident.evictions, 0u);
  EXPECT_EQ(stats.resident.entries, 2u);
}

TEST_F(FamilyCacheTest, FamilyHeldByACallerOutlivesItsEviction) {
  FamilyCache cache(ResidentOnly(two_fit_), nullptr);
  ASSERT_THAT(cache.Insert("", "h-a", MakeFamily(gen::Uniform(40, 1), "held")), IsOk());
  std::shared_ptr<const CachedFamily> held = cache.Find("", "h-a");
  ASSERT_NE(held, nullptr);
  const size_t points = held->reader().points().size();
  const size_t triangles = held->reader().triangles().size();
  ASSERT_THAT(cache.Insert("", "h-b", b_), IsOk());
  ASSERT_THAT(cache.Insert("", "h-c", c_), IsOk());
  ASSERT_EQ(cache.Find("", "h-a"), nullptr) << "evicted";
  EXPECT_EQ(held.use_count(), 1) << "the caller's reference is the only one left";
  EXPECT_EQ(held->reader().points().size(), points);
  EXPECT_EQ(held->reader().triangles().size(), triangles);
  EXPECT_EQ(held->EdgeOrder().size(), held->reader().edges().size());
}

TEST_F(FamilyCacheTest, ConcurrentLookupsAndInsertsAreCounted) {
  RecordingObserver observer;  // called under the cache's lock, so plain counters suffice
  FamilyCache cache(ResidentOnly(two_fit_), &observer);
  const std::vector<std::shared_ptr<const CachedFamily>> families = {a_, b_, c_};
  constexpr int kThreads = 4;
  constexpr int kLookups = 300;
  std::vector<std::thread> threads;
  threads.reserve(kThreads);
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < kLookups; ++i) {
        const size_t f = static_cast<size_t>(i + t) % families.size();
        const std::string handle = absl::StrCat("h", f);
        std::shared_ptr<const CachedFamily> found = cache.Find("", handle);
        if (found == nullptr) {
          const auto inserted = cache.Insert("", handle, families[f]);
          if (!inserted.ok()) ADD_FAILURE() << inserted.status();
        } else if (found.get() != families[f].get()) {
          ADD_FAILURE() << "handle " << handle << " found another family";
        }
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  const FamilyCache::Stats stats = cache.GetStats();
  EXPECT_EQ(stats.resident.hits + stats.misses, uint64_t{kThreads * kLookups});
  EXPECT_LE(stats.resident.bytes, cache.byte_budget());
  ExpectObserverAgrees(observer, cache);
}

// ---- The compact tier ------------------------------------------------------------------------------

/// `compact` holds exactly the points `family` was built from.
void ExpectPointsOf(const CachedFamily& family, const CompactFamily& compact) {
  const auto& points = family.reader().points();
  EXPECT_TRUE(std::equal(points.begin(), points.end(), compact.points().begin(), compact.points().end(),
                         [](const Point2& p, const Point2& q) { return p.x == q.x && p.y == q.y; }));
}

/// The compact entry a demotion of `family` makes: its bytes are what the compact tier charges.
size_t CompactBytes(const std::shared_ptr<const CachedFamily>& family) { return CompactFamily(*family).bytes(); }

TEST_F(FamilyCacheTest, PushedOutFamiliesAreDemotedWithTheirPoints) {
  RecordingObserver observer;
  FamilyCache cache({two_fit_, size_t{1} << 30}, &observer);
  EXPECT_EQ(cache.compact_byte_budget(), size_t{1} << 30);
  ASSERT_NO_FATAL_FAILURE(InsertInTurn(cache));

  FamilyCache::Stats stats = cache.GetStats();
  EXPECT_EQ(stats.demotions, 1u);
  EXPECT_EQ(stats.resident.evictions, 0u) << "the compact tier took it";
  EXPECT_EQ(stats.resident.entries, 2u);
  EXPECT_EQ(stats.resident.bytes, b_->bytes() + c_->bytes());
  EXPECT_EQ(stats.compact.entries, 1u);
  EXPECT_EQ(stats.compact.bytes, CompactBytes(a_));
  ExpectObserverAgrees(observer, cache);

  const FamilyCache::Found found = cache.Lookup("", "h-a");
  EXPECT_EQ(found.resident, nullptr);
  ASSERT_NE(found.compact, nullptr);
  ExpectPointsOf(*a_, *found.compact);
  EXPECT_EQ(cache.Find("", "h-a"), nullptr) << "Find answers the resident tier only";
  stats = cache.GetStats();
  EXPECT_EQ(stats.compact.hits, 2u);
  EXPECT_EQ(stats.misses, 0u) << "a compact entry is a hit, not a miss";
  ExpectObserverAgrees(observer, cache);
}

TEST_F(FamilyCacheTest, CompactEntriesHoldSixteenBytesAPoint) {
  // The bound is 64 bytes per input point; the points alone are 16.
  const std::vector<Point2> points = gen::Uniform(20000, 4);
  const std::shared_ptr<const CachedFamily> family = MakeFamily(points, "large");
  ASSERT_NE(family, nullptr);
  const CompactFamily compact(*family);
  EXPECT_LE(compact.bytes(), points.size() * sizeof(Point2) + 256);
  EXPECT_LE(static_cast<double>(compact.bytes()) / static_cast<double>(points.size()), 64.0);
  EXPECT_GT(family->bytes(), 10 * compact.bytes()) << "a whole family is far larger";

  // A geographic frame's points as sent are kept too (and charged).
  auto frame = std::make_shared<CachedFamily::InputFrame>();
  frame->input = points;
  frame->projection = "+proj=aeqd";
  family->AttachFrameIfNone(frame);
  const CompactFamily framed(*family);
  EXPECT_EQ(framed.frame().get(), frame.get());
  EXPECT_LE(static_cast<double>(framed.bytes()) / static_cast<double>(points.size()), 64.0);
  EXPECT_GE(framed.bytes(), compact.bytes() + points.size() * sizeof(Point2));
}

TEST_F(FamilyCacheTest, InsertOfADemotedFamilyPromotesIt) {
  RecordingObserver observer;
  FamilyCache cache({two_fit_, size_t{1} << 30}, &observer);
  ASSERT_NO_FATAL_FAILURE(InsertInTurn(cache));  // a demoted
  const FamilyCache::Found found = cache.Lookup("", "h-a");
  ASSERT_NE(found.compact, nullptr);

  // The rebuild from the compact entry's points is the family that was demoted.
  const std::shared_ptr<const CachedFamily> rebuilt = MakeFamily(found.compact->points(), "a rebuilt");
  ASSERT_NE(rebuilt, nullptr);
  EXPECT_EQ(rebuilt->bytes(), a_->bytes());
  const AlphaFamily &before = *a_->host_family(), &after = *rebuilt->host_family();
  EXPECT_TRUE(std::equal(before.triangles().begin(), before.triangles().end(), after.triangles().begin(),
                         after.triangles().end()));
  EXPECT_TRUE(
      std::equal(before.spectrum().begin(), before.spectrum().end(), after.spectrum().begin(), after.spectrum().end()));
  EXPECT_TRUE(std::equal(before.ranks().tri_rank.begin(), before.ranks().tri_rank.end(), after.ranks().tri_rank.begin(),
                         after.ranks().tri_rank.end()));

  ASSERT_THAT(cache.Insert("", "h-a", rebuilt), IsOk());
  FamilyCache::Stats stats = cache.GetStats();
  EXPECT_EQ(stats.promotions, 1u);
  EXPECT_EQ(stats.demotions, 2u) << "b, now the least recently used, made room";
  EXPECT_EQ(stats.compact.entries, 1u);
  EXPECT_EQ(cache.Find("", "h-a").get(), rebuilt.get());
  const FamilyCache::Found b = cache.Lookup("", "h-b");
  ASSERT_NE(b.compact, nullptr);
  ExpectPointsOf(*b_, *b.compact);
  ExpectObserverAgrees(observer, cache);
}

TEST_F(FamilyCacheTest, CompactTierEvictsItsLeastRecentlyUsed) {
  // One family resident and one compact entry at a time.
  const size_t one_family = std::max({a_->bytes(), b_->bytes(), c_->bytes()});
  const size_t one_compact = std::max({CompactBytes(a_), CompactBytes(b_), CompactBytes(c_)});
  ASSERT_LT(one_family, a_->bytes() + b_->bytes());
  RecordingObserver observer;
  FamilyCache cache({one_family, one_compact + 1}, &observer);
  ASSERT_THAT(cache.Insert("", "h-a", a_), IsOk());
  ASSERT_THAT(cache.Insert("", "h-b", b_), IsOk());  // a demoted
  ASSERT_THAT(cache.Insert("", "h-c", c_), IsOk());  // b demoted, a evicted from the compact tier
  const FamilyCache::Stats stats = cache.GetStats();
  EXPECT_EQ(stats.demotions, 2u);
  EXPECT_EQ(stats.compact.evictions, 1u);
  EXPECT_EQ(stats.resident.evictions, 0u);
  EXPECT_EQ(stats.compact.entries, 1u);
  EXPECT_LE(stats.compact.bytes, cache.compact_byte_budget());
  const FamilyCache::Found a = cache.Lookup("", "h-a");
  EXPECT_EQ(a.resident, nullptr);
  EXPECT_EQ(a.compact, nullptr) << "gone from both tiers";
  EXPECT_NE(cache.Lookup("", "h-b").compact, nullptr);
  EXPECT_NE(cache.Find("", "h-c"), nullptr);
  ExpectObserverAgrees(observer, cache);
}

TEST_F(FamilyCacheTest, FamilyTooLargeForTheCompactTierIsEvicted) {
  RecordingObserver observer;
  FamilyCache cache({two_fit_, CompactBytes(a_) - 1}, &observer);
  ASSERT_NO_FATAL_FAILURE(InsertInTurn(cache));
  const FamilyCache::Stats stats = cache.GetStats();
  EXPECT_EQ(stats.demotions, 0u);
  EXPECT_EQ(stats.resident.evictions, 1u);
  EXPECT_EQ(stats.compact.entries, 0u);
  EXPECT_EQ(stats.compact.bytes, 0u);
  EXPECT_EQ(cache.Lookup("", "h-a").compact, nullptr);
  ExpectObserverAgrees(observer, cache);
}

TEST_F(FamilyCacheTest, EraseDropsACompactEntry) {
  RecordingObserver observer;
  FamilyCache cache({two_fit_, size_t{1} << 30}, &observer);
  ASSERT_NO_FATAL_FAILURE(InsertInTurn(cache));  // a demoted
  EXPECT_FALSE(cache.Erase("other", "h-a"));
  EXPECT_TRUE(cache.Erase("", "h-a"));
  EXPECT_FALSE(cache.Erase("", "h-a"));
  const FamilyCache::Found found = cache.Lookup("", "h-a");
  EXPECT_EQ(found.resident, nullptr);
  EXPECT_EQ(found.compact, nullptr);
  EXPECT_EQ(cache.GetStats().compact.entries, 0u);
  EXPECT_EQ(cache.GetStats().compact.bytes, 0u);
  EXPECT_EQ(cache.GetStats().compact.evictions, 0u) << "an erase is not an eviction";
  ExpectObserverAgrees(observer, cache);
}

TEST_F(FamilyCacheTest, ResidentOrNullIsNotALookup) {
  RecordingObserver observer;
  FamilyCache cache({two_fit_, size_t{1} << 30}, &observer);
  ASSERT_THAT(cache.Insert("", "h-a", a_), IsOk());
  ASSERT_THAT(cache.Insert("", "h-b", b_), IsOk());
  EXPECT_EQ(cache.ResidentOrNull("", "h-a").get(), a_.get());
  EXPECT_EQ(cache.ResidentOrNull("", "h-x"), nullptr);
  ASSERT_THAT(cache.Insert("", "h-c", c_), IsOk());
  EXPECT_EQ(cache.ResidentOrNull("", "h-a"), nullptr) << "a stayed the least recently used, so it was demoted";
  EXPECT_EQ(cache.GetStats().resident.hits + cache.GetStats().compact.hits + cache.GetStats().misses, 0u);
  ExpectObserverAgrees(observer, cache);
}

// ---- CachedFamily's index orders ------------------------------------------------------------------

void ExpectIsPermutation(const std::vector<uint32_t>& order, size_t n) {
  ASSERT_EQ(order.size(), n);
  std::vector<bool> seen(n, false);
  for (const uint32_t id : order) {
    ASSERT_LT(id, n);
    EXPECT_FALSE(seen[id]) << "id " << id << " appears twice";
    seen[id] = true;
  }
}

TEST(CachedFamilyTest, OrdersArePermutationsSortedByVertexIndices) {
  for (const gen::NamedGenerator& generator : gen::AllDistributions()) {
    SCOPED_TRACE(generator.name);
    const std::vector<Point2> points = generator.generate(300, 21);
    const std::shared_ptr<const CachedFamily> cached = MakeFamily(points, generator.name);
    ASSERT_NE(cached, nullptr);
    const AlphaFamily& family = *cached->host_family();
    const size_t bytes = cached->bytes();

    const std::vector<uint32_t>& edge_order = cached->EdgeOrder();
    ExpectIsPermutation(edge_order, family.edges().size());
    std::vector<std::array<uint32_t, 2>> edges;
    for (const uint32_t e : edge_order) {
      const auto& edge = family.edges()[e];
      edges.push_back({std::min(edge[0], edge[1]), std::max(edge[0], edge[1])});
    }
    EXPECT_TRUE(std::is_sorted(edges.begin(), edges.end()));
    EXPECT_TRUE(std::adjacent_find(edges.begin(), edges.end()) == edges.end()) << "an edge appears twice";

    const std::vector<uint32_t>& triangle_order = cached->TriangleOrder();
    ExpectIsPermutation(triangle_order, family.triangles().size());
    std::vector<std::array<uint32_t, 3>> triangles;
    for (const uint32_t t : triangle_order) {
      std::array<uint32_t, 3> triangle = family.triangles()[t];
      std::sort(triangle.begin(), triangle.end());
      triangles.push_back(triangle);
    }
    EXPECT_TRUE(std::is_sorted(triangles.begin(), triangles.end()));
    EXPECT_TRUE(std::adjacent_find(triangles.begin(), triangles.end()) == triangles.end());

    EXPECT_EQ(&cached->EdgeOrder(), &edge_order) << "computed once";
    EXPECT_EQ(cached->bytes(), bytes) << "the charge does not change once the orders exist";
    EXPECT_GE(bytes, family.HostBytes() + (edges.size() + triangles.size()) * sizeof(uint32_t));
  }
}

TEST(CachedFamilyTest, OrdersOfTinyInputs) {
  for (size_t n = 0; n <= 3; ++n) {
    SCOPED_TRACE(n);
    const std::shared_ptr<const CachedFamily> cached = MakeFamily(gen::Uniform(n, 22), "tiny");
    ASSERT_NE(cached, nullptr);
    ExpectIsPermutation(cached->EdgeOrder(), cached->reader().edges().size());
    ExpectIsPermutation(cached->TriangleOrder(), cached->reader().triangles().size());
  }
}

TEST(CachedFamilyTest, OrdersAreSafeToComputeFromManyThreads) {
  const std::shared_ptr<const CachedFamily> cached = MakeFamily(gen::Uniform(2000, 23), "shared");
  ASSERT_NE(cached, nullptr);
  std::vector<const std::vector<uint32_t>*> seen(4, nullptr);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < seen.size(); ++t) {
    threads.emplace_back([&, t] { seen[t] = t % 2 == 0 ? &cached->EdgeOrder() : &cached->TriangleOrder(); });
  }
  for (std::thread& thread : threads) thread.join();
  for (size_t t = 0; t < seen.size(); ++t) {
    EXPECT_EQ(seen[t], t % 2 == 0 ? &cached->EdgeOrder() : &cached->TriangleOrder());
  }
  ExpectIsPermutation(cached->EdgeOrder(), cached->reader().edges().size());
}

}  // namespace
}  // namespace galpha::server
