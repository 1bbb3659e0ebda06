// Promotion: a query for a family that the cache holds in its compact tier rebuilds the family
// from the compact entry's points and caches it in the resident tier again, transparently to the
// client (which only waits for the rebuild). A rebuild is a build like any other: it takes a slot
// of the build scheduler (a CUDA stream on a GPU) and is admitted by its memory need, so promotions
// and uploads share the device fairly. Concurrent queries for one family share one rebuild.
#pragma once

#include <cstddef>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "absl/status/statusor.h"
#include "core/family/alpha_family.hpp"
#include "gpu/triangulation/delaunay.hpp"
#include "server/build_scheduler.hpp"
#include "server/family_cache.hpp"

namespace galpha::server {

class FamilyPromoter {
 public:
  /// Called after every successful rebuild with its report and wall time (the build metrics).
  using BuildRecorder = std::function<void(const BuildReport& report, double seconds)>;

  /// Rebuilds on `backend` through `scheduler` (as resident families when `resident` and the
  /// family fits the cache's device budget: BuildCachedFamily), charging `bytes_per_point` a point to its memory
  /// admission, and caches the result in `cache`. All three must outlive the promoter's jobs (destroy the scheduler
  /// first: its queued jobs then end without building).
  FamilyPromoter(FamilyCache* cache, BuildScheduler* scheduler, Backend backend, bool resident, size_t bytes_per_point,
                 BuildRecorder record_build);
  ~FamilyPromoter();
  FamilyPromoter(const FamilyPromoter&) = delete;
  FamilyPromoter& operator=(const FamilyPromoter&) = delete;

  /// The family of (tenant, handle), rebuilt from `compact` and cached (or the resident one, when
  /// another caller promoted it meanwhile). Blocks until then. Errors name the handle and why:
  /// the scheduler's refusals (ResourceExhausted: queue full; Unavailable: draining), the
  /// engine's (ResourceExhausted when it ran out of memory), the cache's (a family larger than the
  /// resident budget), and InvalidArgument for a null `compact`.
  absl::StatusOr<std::shared_ptr<const CachedFamily>> Promote(const std::string& tenant, const std::string& handle,
                                                              std::shared_ptr<const CompactFamily> compact);

  /// Rebuilds that have started and not yet ended (for tests).
  size_t in_flight() const;

 private:
  using Result = absl::StatusOr<std::shared_ptr<const CachedFamily>>;
  struct Rebuild;
  /// Runs on a build slot: builds, caches, and hands the result to every waiter.
  void Run(const std::shared_ptr<Rebuild>& rebuild, void* cuda_stream, bool draining);
  void Finish(const std::shared_ptr<Rebuild>& rebuild, Result result);

  FamilyCache* const cache_;
  BuildScheduler* const scheduler_;
  const Backend backend_;
  const bool resident_;
  const size_t bytes_per_point_;
  const BuildRecorder record_build_;
  mutable std::mutex mutex_;
  // By cache key (tenant NUL handle): the rebuild that every concurrent caller waits for.
  std::unordered_map<std::string, std::shared_future<Result>> in_flight_;
};

}  // namespace galpha::server
