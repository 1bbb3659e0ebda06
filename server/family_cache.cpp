#include "server/family_cache.hpp"

#include <utility>

#include "absl/strings/str_cat.h"

namespace galpha::server {

const char* CacheTierName(CacheTier tier) { return tier == CacheTier::kResident ? "resident" : "compact"; }

FamilyCache::FamilyCache(Budgets budgets, CacheObserver* observer) : budgets_(budgets), observer_(observer) {
  std::lock_guard<std::mutex> lock(mutex_);
  ReportSizeLocked();
}

std::string FamilyCache::Key(const std::string& tenant, const std::string& handle) {
  // Handles never contain NUL, so the key is unambiguous.
  return absl::StrCat(tenant, std::string(1, '\0'), handle);
}

FamilyCache::Found FamilyCache::Lookup(const std::string& tenant, const std::string& handle) {
  const std::string key = Key(tenant, handle);
  std::lock_guard<std::mutex> lock(mutex_);
  if (const auto it = resident_index_.find(key); it != resident_index_.end()) {
    ++stats_.resident.hits;
    if (observer_ != nullptr) observer_->OnHit(CacheTier::kResident);
    resident_.splice(resident_.begin(), resident_, it->second);
    return {it->second->family, nullptr};
  }
  if (const auto it = compact_index_.find(key); it != compact_index_.end()) {
    ++stats_.compact.hits;
    if (observer_ != nullptr) observer_->OnHit(CacheTier::kCompact);
    compact_.splice(compact_.begin(), compact_, it->second);
    return {nullptr, it->second->family};
  }
  ++stats_.misses;
  if (observer_ != nullptr) observer_->OnMiss();
  return {};
}

std::shared_ptr<const CachedFamily> FamilyCache::ResidentOrNull(const std::string& tenant,
                                                                const std::string& handle) const {
  const std::string key = Key(tenant, handle);
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = resident_index_.find(key);
  return it == resident_index_.end() ? nullptr : it->second->family;
}

absl::StatusOr<std::shared_ptr<const CachedFamily>> FamilyCache::Insert(const std::string& tenant,
                                                                        const std::string& handle,
                                                                        std::shared_ptr<const CachedFamily> family) {
  const size_t bytes = family->bytes();
  if (bytes > budgets_.resident) {
    return absl::ResourceExhaustedError(absl::StrCat("the family needs ", bytes,
                                                     " bytes of cache; the cache budget is ", budgets_.resident,
                                                     " bytes (raise --cache_bytes)"));
  }
  const size_t device_bytes = family->device_bytes();
  if (device_bytes > budgets_.device) {
    return absl::ResourceExhaustedError(absl::StrCat("the family's tables need ", device_bytes,
                                                     " bytes of GPU memory; the device cache budget is ",
                                                     budgets_.device, " bytes (raise --device_cache_bytes)"));
  }
  std::string key = Key(tenant, handle);
  std::lock_guard<std::mutex> lock(mutex_);
  if (const auto it = resident_index_.find(key); it != resident_index_.end()) {
    // Two builds of the same points raced: keep the first, so every caller sees one object.
    resident_.splice(resident_.begin(), resident_, it->second);
    return it->second->family;
  }
  if (DropCompactLocked(key)) {
    ++stats_.promotions;
    if (observer_ != nullptr) observer_->OnPromotion();
  }
  while (!resident_.empty() && (stats_.resident.bytes + bytes > budgets_.resident ||
                                stats_.resident.device_bytes + device_bytes > budgets_.device)) {
    DemoteOldestLocked();
  }
  resident_.push_front(ResidentEntry{key, family});
  resident_index_.emplace(std::move(key), resident_.begin());
  stats_.resident.bytes += bytes;
  stats_.resident.device_bytes += device_bytes;
  ReportSizeLocked();
  return family;
}

void FamilyCache::DemoteOldestLocked() {
  ResidentEntry victim = std::move(resident_.back());
  resident_index_.erase(victim.key);
  resident_.pop_back();
  stats_.resident.bytes -= victim.family->bytes();
  stats_.resident.device_bytes -= victim.family->device_bytes();
  // The copy of the points is made under the lock: a memory copy of 16 bytes a point (160 ms at
  // 100M points), short next to the build that needed the room.
  auto compact = budgets_.compact > 0 ? std::make_shared<const CompactFamily>(*victim.family) : nullptr;
  if (compact == nullptr || compact->bytes() > budgets_.compact) {
    ++stats_.resident.evictions;
    if (observer_ != nullptr) observer_->OnEviction(CacheTier::kResident);
    return;
  }
  while (!compact_.empty() && stats_.compact.bytes + compact->bytes() > budgets_.compact) {
    CompactEntry& oldest = compact_.back();
    stats_.compact.bytes -= oldest.family->bytes();
    compact_index_.erase(oldest.key);
    compact_.pop_back();
    ++stats_.compact.evictions;
    if (observer_ != nullptr) observer_->OnEviction(CacheTier::kCompact);
  }
  stats_.compact.bytes += compact->bytes();
  compact_.push_front(CompactEntry{victim.key, std::move(compact)});
  compact_index_.emplace(std::move(victim.key), compact_.begin());
  ++stats_.demotions;
  if (observer_ != nullptr) observer_->OnDemotion();
}

bool FamilyCache::DropCompactLocked(const std::string& key) {
  const auto it = compact_index_.find(key);
  if (it == compact_index_.end()) return false;
  stats_.compact.bytes -= it->second->family->bytes();
  compact_.erase(it->second);
  compact_index_.erase(it);
  return true;
}

bool FamilyCache::Erase(const std::string& tenant, const std::string& handle) {
  const std::string key = Key(tenant, handle);
  std::lock_guard<std::mutex> lock(mutex_);
  bool erased = DropCompactLocked(key);
  if (const auto it = resident_index_.find(key); it != resident_index_.end()) {
    stats_.resident.bytes -= it->second->family->bytes();
    stats_.resident.device_bytes -= it->second->family->device_bytes();
    resident_.erase(it->second);
    resident_index_.erase(it);
    erased = true;
  }
  ReportSizeLocked();
  return erased;
}

void FamilyCache::ReportSizeLocked() {
  stats_.resident.entries = resident_.size();
  stats_.compact.entries = compact_.size();
  if (observer_ == nullptr) return;
  observer_->OnSize(CacheTier::kResident, stats_.resident.bytes, stats_.resident.entries);
  observer_->OnSize(CacheTier::kCompact, stats_.compact.bytes, stats_.compact.entries);
  observer_->OnDeviceSize(stats_.resident.device_bytes);
}

FamilyCache::Stats FamilyCache::GetStats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace galpha::server
