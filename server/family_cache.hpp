// The family cache: families by (tenant, handle) under a byte budget with least-recently-used
// eviction. Thread-safe. A family in use by a query stays alive after eviction (shared ownership)
// until that query ends; new lookups of an evicted handle miss.
#pragma once

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "absl/status/status.h"
#include "server/cached_family.hpp"

namespace galpha::server {

/// What the cache reports to the metrics (called with the cache's lock held: keep it cheap).
class CacheObserver {
 public:
  virtual ~CacheObserver() = default;
  virtual void OnLookup(bool hit) = 0;
  virtual void OnEviction() = 0;
  virtual void OnSize(size_t bytes, size_t entries) = 0;
};

class FamilyCache {
 public:
  struct Stats {
    size_t bytes = 0;
    size_t entries = 0;
    uint64_t hits = 0;
    uint64_t misses = 0;
    uint64_t evictions = 0;
  };

  /// `observer` may be null; it must outlive the cache.
  FamilyCache(size_t byte_budget, CacheObserver* observer);

  /// The family, or null; a hit makes it the most recently used.
  std::shared_ptr<const CachedFamily> Find(const std::string& tenant, const std::string& handle);
  /// Caches `family` (or keeps the one already there, which is returned), evicting the least
  /// recently used families until it fits. ResourceExhausted when it is larger than the budget.
  absl::StatusOr<std::shared_ptr<const CachedFamily>> Insert(const std::string& tenant, const std::string& handle,
                                                             std::shared_ptr<const CachedFamily> family);
  /// Whether a family was dropped.
  bool Erase(const std::string& tenant, const std::string& handle);

  Stats GetStats() const;
  size_t byte_budget() const { return byte_budget_; }

 private:
  struct Entry {
    std::string key;
    std::shared_ptr<const CachedFamily> family;
  };
  static std::string Key(const std::string& tenant, const std::string& handle);
  void ReportSize();

  const size_t byte_budget_;
  CacheObserver* const observer_;
  mutable std::mutex mutex_;
  std::list<Entry> lru_;  // front: most recently used
  std::unordered_map<std::string, std::list<Entry>::iterator> index_;
  Stats stats_;
};

}  // namespace galpha::server
