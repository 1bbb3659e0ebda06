#include "server/family_cache.hpp"

#include <utility>

#include "absl/strings/str_cat.h"

namespace galpha::server {

FamilyCache::FamilyCache(size_t byte_budget, CacheObserver* observer) : byte_budget_(byte_budget), observer_(observer) {
  if (observer_ != nullptr) observer_->OnSize(0, 0);
}

std::string FamilyCache::Key(const std::string& tenant, const std::string& handle) {
  // Handles never contain NUL, so the key is unambiguous.
  return absl::StrCat(tenant, std::string(1, '\0'), handle);
}

std::shared_ptr<const CachedFamily> FamilyCache::Find(const std::string& tenant, const std::string& handle) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = index_.find(Key(tenant, handle));
  const bool hit = it != index_.end();
  ++(hit ? stats_.hits : stats_.misses);
  if (observer_ != nullptr) observer_->OnLookup(hit);
  if (!hit) return nullptr;
  lru_.splice(lru_.begin(), lru_, it->second);
  return it->second->family;
}

absl::StatusOr<std::shared_ptr<const CachedFamily>> FamilyCache::Insert(const std::string& tenant,
                                                                        const std::string& handle,
                                                                        std::shared_ptr<const CachedFamily> family) {
  const size_t bytes = family->bytes();
  if (bytes > byte_budget_) {
    return absl::ResourceExhaustedError(absl::StrCat("the family needs ", bytes,
                                                     " bytes of cache; the cache budget is ", byte_budget_,
                                                     " bytes (raise --cache_bytes)"));
  }
  std::lock_guard<std::mutex> lock(mutex_);
  std::string key = Key(tenant, handle);
  if (const auto it = index_.find(key); it != index_.end()) {
    // Two builds of the same points raced: keep the first, so every caller sees one object.
    lru_.splice(lru_.begin(), lru_, it->second);
    return it->second->family;
  }
  while (!lru_.empty() && stats_.bytes + bytes > byte_budget_) {
    Entry& victim = lru_.back();
    stats_.bytes -= victim.family->bytes();
    index_.erase(victim.key);
    lru_.pop_back();
    ++stats_.evictions;
    if (observer_ != nullptr) observer_->OnEviction();
  }
  lru_.push_front(Entry{key, family});
  index_.emplace(std::move(key), lru_.begin());
  stats_.bytes += bytes;
  stats_.entries = lru_.size();
  ReportSize();
  return family;
}

bool FamilyCache::Erase(const std::string& tenant, const std::string& handle) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = index_.find(Key(tenant, handle));
  if (it == index_.end()) return false;
  stats_.bytes -= it->second->family->bytes();
  lru_.erase(it->second);
  index_.erase(it);
  ReportSize();
  return true;
}

void FamilyCache::ReportSize() {
  stats_.entries = lru_.size();
  if (observer_ != nullptr) observer_->OnSize(stats_.bytes, stats_.entries);
}

FamilyCache::Stats FamilyCache::GetStats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace galpha::server
