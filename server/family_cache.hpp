// The family cache: families by (tenant, handle) in two tiers, each under its own byte budget with
// least-recently-used order. The resident tier holds whole families, ready to answer; the compact
// tier holds what a rebuild needs (server/compact_family.hpp). A family pushed out of the resident
// tier is demoted to the compact tier, and one pushed out of the compact tier (or too large for
// it) is evicted. A lookup that finds a compact entry hands it to the caller, who rebuilds the
// family and promotes it (server/family_promoter.hpp). Thread-safe. A family in use by a query
// stays alive after its demotion or eviction (shared ownership) until that query ends.
#pragma once

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "absl/status/statusor.h"
#include "server/cached_family.hpp"
#include "server/compact_family.hpp"

namespace galpha::server {

enum class CacheTier { kResident = 0, kCompact = 1 };
/// "resident", "compact": the metrics' tier label.
const char* CacheTierName(CacheTier tier);

/// What the cache reports to the metrics (called with the cache's lock held: keep it cheap).
class CacheObserver {
 public:
  virtual ~CacheObserver() = default;
  /// A lookup found its family in `tier`.
  virtual void OnHit(CacheTier tier) = 0;
  /// A lookup found nothing.
  virtual void OnMiss() = 0;
  /// A family left the cache from `tier` to stay within the budgets.
  virtual void OnEviction(CacheTier tier) = 0;
  virtual void OnDemotion() = 0;
  virtual void OnPromotion() = 0;
  virtual void OnSize(CacheTier tier, size_t bytes, size_t entries) = 0;
  /// Device bytes the resident tier's families hold (resident on the GPU they were built on).
  virtual void OnDeviceSize(size_t bytes) = 0;
};

class FamilyCache {
 public:
  struct Budgets {
    /// Bytes of whole families (CachedFamily::bytes()).
    size_t resident = 0;
    /// Bytes of compact entries (CompactFamily::bytes()); 0: no compact tier, a family pushed out
    /// of the resident tier is evicted.
    size_t compact = 0;
    /// Device bytes of the resident tier's families whose tables stayed on the GPU
    /// (CachedFamily::device_bytes()): a family is demoted when either budget of the tier is passed.
    size_t device = 0;
  };
  struct TierStats {
    size_t bytes = 0;
    size_t device_bytes = 0;  // the resident tier's families' tables on the GPU
    size_t entries = 0;
    uint64_t hits = 0;
    uint64_t evictions = 0;
  };
  struct Stats {
    TierStats resident, compact;
    uint64_t misses = 0;
    /// Families moved from the resident tier to the compact one, and back (by a rebuild).
    uint64_t demotions = 0;
    uint64_t promotions = 0;
  };
  /// What a lookup found: the whole family, or its compact entry, or neither.
  struct Found {
    std::shared_ptr<const CachedFamily> resident;
    std::shared_ptr<const CompactFamily> compact;
  };

  /// `observer` may be null; it must outlive the cache.
  FamilyCache(Budgets budgets, CacheObserver* observer);

  /// Looks (tenant, handle) up in both tiers; a hit makes the entry the most recently used of its
  /// tier.
  Found Lookup(const std::string& tenant, const std::string& handle);
  /// Lookup's resident family, or null (a compact hit still counts as one).
  std::shared_ptr<const CachedFamily> Find(const std::string& tenant, const std::string& handle) {
    return Lookup(tenant, handle).resident;
  }
  /// The resident family of (tenant, handle), or null; neither a lookup nor a use (no statistics,
  /// no change of order).
  std::shared_ptr<const CachedFamily> ResidentOrNull(const std::string& tenant, const std::string& handle) const;
  /// Caches `family` in the resident tier (or keeps the one already there, which is returned),
  /// demoting the least recently used families until it fits. A compact entry of the same key is
  /// dropped: the family is back (a promotion). ResourceExhausted when the family is larger than
  /// the resident budget (host bytes or device bytes).
  absl::StatusOr<std::shared_ptr<const CachedFamily>> Insert(const std::string& tenant, const std::string& handle,
                                                             std::shared_ptr<const CachedFamily> family);
  /// Whether a family was dropped (from either tier).
  bool Erase(const std::string& tenant, const std::string& handle);

  Stats GetStats() const;
  size_t byte_budget() const { return budgets_.resident; }
  size_t compact_byte_budget() const { return budgets_.compact; }
  size_t device_byte_budget() const { return budgets_.device; }
  /// Whether a family of `points` points kept on the GPU fits the device budget at all (its
  /// tables measured at most 352 B a point on every generator at 1M on an H100, bench/README.md
  /// "Resident families"; 400 with headroom): a larger one is built into host memory instead.
  bool FitsDeviceTier(size_t points) const { return points * kResidentDeviceBytesPerPoint <= budgets_.device; }
  static constexpr size_t kResidentDeviceBytesPerPoint = 400;

 private:
  struct ResidentEntry {
    std::string key;
    std::shared_ptr<const CachedFamily> family;
  };
  struct CompactEntry {
    std::string key;
    std::shared_ptr<const CompactFamily> family;
  };
  static std::string Key(const std::string& tenant, const std::string& handle);
  /// Moves the least recently used resident family to the compact tier, or evicts it (the lock
  /// held).
  void DemoteOldestLocked();
  /// Drops `key`'s compact entry, if any; returns whether there was one (the lock held).
  bool DropCompactLocked(const std::string& key);
  void ReportSizeLocked();

  const Budgets budgets_;
  CacheObserver* const observer_;
  mutable std::mutex mutex_;
  std::list<ResidentEntry> resident_;  // front: most recently used
  std::unordered_map<std::string, std::list<ResidentEntry>::iterator> resident_index_;
  std::list<CompactEntry> compact_;  // front: most recently used
  std::unordered_map<std::string, std::list<CompactEntry>::iterator> compact_index_;
  Stats stats_;
};

}  // namespace galpha::server
