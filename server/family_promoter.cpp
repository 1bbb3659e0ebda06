#include "server/family_promoter.hpp"

#include <chrono>
#include <utility>

#include "absl/strings/str_cat.h"
#include "gpu/alpha/alpha_engine.hpp"
#include "server/heap_trim.hpp"

namespace galpha::server {

struct FamilyPromoter::Rebuild {
  std::string key;
  std::string tenant;
  std::string handle;
  std::shared_ptr<const CompactFamily> compact;
  std::promise<Result> promise;
};

FamilyPromoter::FamilyPromoter(FamilyCache* cache, BuildScheduler* scheduler, Backend backend, bool resident,
                               size_t bytes_per_point, BuildRecorder record_build)
    : cache_(cache),
      scheduler_(scheduler),
      backend_(backend),
      resident_(resident),
      bytes_per_point_(bytes_per_point),
      record_build_(std::move(record_build)) {}

FamilyPromoter::~FamilyPromoter() = default;

size_t FamilyPromoter::in_flight() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return in_flight_.size();
}

absl::StatusOr<std::shared_ptr<const CachedFamily>> FamilyPromoter::Promote(
    const std::string& tenant, const std::string& handle, std::shared_ptr<const CompactFamily> compact) {
  if (compact == nullptr) return absl::InvalidArgumentError(absl::StrCat("handle ", handle, ": nothing to rebuild"));
  auto rebuild = std::make_shared<Rebuild>();
  rebuild->key = absl::StrCat(tenant, std::string(1, '\0'), handle);
  std::shared_future<Result> result;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (const auto it = in_flight_.find(rebuild->key); it != in_flight_.end()) {
      result = it->second;
    } else if (auto resident = cache_->ResidentOrNull(tenant, handle)) {
      // Promoted by another caller between this caller's lookup and now.
      return resident;
    } else {
      rebuild->tenant = tenant;
      rebuild->handle = handle;
      rebuild->compact = std::move(compact);
      result = rebuild->promise.get_future().share();
      in_flight_.emplace(rebuild->key, result);
    }
  }
  if (rebuild->compact == nullptr) return result.get();  // another caller's rebuild

  // The rebuild's memory is admitted like an upload's build of the same points.
  const size_t need = rebuild->compact->points().size() * (bytes_per_point_ + sizeof(Point2)) +
                      rebuild->compact->weights().size() * kBuildBytesPerWeight;
  absl::Status submitted = scheduler_->Submit(tenant, need, [this, rebuild](const BuildSlot& slot, bool draining) {
    Run(rebuild, slot.cuda_stream, draining);
  });
  if (!submitted.ok()) {
    Finish(rebuild, absl::Status(submitted.code(),
                                 absl::StrCat("handle ", handle,
                                              " is in the compact tier of the cache and must be rebuilt, but the "
                                              "build scheduler refused the rebuild: ",
                                              submitted.message())));
  }
  return result.get();
}

void FamilyPromoter::Run(const std::shared_ptr<Rebuild>& rebuild, void* cuda_stream, bool draining) {
  const std::string& handle = rebuild->handle;
  if (draining) {
    Finish(rebuild, absl::UnavailableError(absl::StrCat("handle ", handle,
                                                        " is in the compact tier of the cache and the server is "
                                                        "shutting down: the rebuild did not start")));
    return;
  }
  const CompactFamily& compact = *rebuild->compact;
  BuildOptions options;
  options.backend = backend_;
  options.cuda_stream = cuda_stream;
  // No time or comparison limit: these points were built within them once, and the engine is
  // deterministic.
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<std::shared_ptr<const CachedFamily>> family =
      BuildCachedFamily(compact.points(), compact.weights(), !compact.weights().empty(), options,
                        resident_ && cache_->FitsDeviceTier(compact.points().size()), compact.frame());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!family.ok()) {
    ReturnFreedHeapMemory();
    Finish(rebuild,
           absl::Status(family.status().code(),
                        absl::StrCat("handle ", handle, " is in the compact tier of the cache; rebuilding its ",
                                     compact.points().size(), " points failed: ", family.status().message())));
    return;
  }
  if (record_build_) record_build_((*family)->reader().report(), seconds);
  Result inserted = cache_->Insert(rebuild->tenant, handle, *std::move(family));
  ReturnFreedHeapMemory();  // the engine's working memory
  if (!inserted.ok()) {
    inserted = absl::Status(inserted.status().code(), absl::StrCat("handle ", handle,
                                                                   " is in the compact tier of the cache and was "
                                                                   "rebuilt, but ",
                                                                   inserted.status().message()));
  }
  Finish(rebuild, std::move(inserted));
}

void FamilyPromoter::Finish(const std::shared_ptr<Rebuild>& rebuild, Result result) {
  {
    // Off the list first: a caller that comes after the result is set looks the cache up again
    // instead of reading a finished rebuild.
    std::lock_guard<std::mutex> lock(mutex_);
    in_flight_.erase(rebuild->key);
  }
  rebuild->promise.set_value(std::move(result));
}

}  // namespace galpha::server
