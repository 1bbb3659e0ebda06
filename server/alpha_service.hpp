// galpha.v1.AlphaShapes on gRPC's callback API: Build streams points into the build scheduler and
// caches the family; the queries answer from the cache (server/query_answers.hpp). Every RPC is
// authenticated (when tokens are configured), scoped to its tenant, timed and counted.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "core/base/point.hpp"
#include "galpha/v1/alpha_shapes.grpc.pb.h"
#include "gpu/system/device_streams.hpp"
#include "gpu/triangulation/delaunay.hpp"
#include "server/build_scheduler.hpp"
#include "server/build_stream.hpp"
#include "server/build_time_limit.hpp"
#include "server/chunk_codec_pool.hpp"
#include "server/exact_comparison_limit.hpp"
#include "server/family_cache.hpp"
#include "server/family_promoter.hpp"
#include "server/metrics.hpp"
#include "server/tenant_tokens.hpp"
#include "server/upload_watchdog.hpp"

namespace galpha::server {

/// Estimated peak working memory of one build, per point, with headroom over the engine's measured
/// peaks (bench/README.md): 520 B/pt of device memory on an H100 (uniform, gaussian and clustered
/// points) and 584 B/pt of host memory on the CPU backend. Admission charges this plus the point
/// itself (16 bytes): 656 B/pt.
inline constexpr size_t kBuildBytesPerPoint = 640;

/// What admission charges a build of `points` uploaded points with `weights` weights (0 or one a
/// point): the estimate above plus the points themselves, and kBuildBytesPerWeight a weight.
inline size_t UploadedBuildBytes(size_t points, size_t weights) {
  return points * (kBuildBytesPerPoint + sizeof(Point2)) + weights * kBuildBytesPerWeight;
}

/// How BuildBatch builds its small unweighted sets (server/build_batch_reactor.hpp).
enum class BatchPacking {
  kAuto,  ///< packed on the CUDA backend (a set alone costs the GPU a fixed start), else one a core
  kOn,    ///< packed together in one build of the service's backend (BuildAlphaFamilies)
  kOff,   ///< one set a host core, each its own build
};

struct ServiceOptions {
  /// kAuto: the GPU when this build and machine have one, else the CPU.
  Backend backend = Backend::kAuto;
  /// Builds running at once (CUDA streams); 0: 4 on a GPU, 1 on the CPU (which uses every core).
  int build_slots = 0;
  /// Builds waiting for a slot before RESOURCE_EXHAUSTED.
  size_t max_queued_builds = 16;
  /// Builds of one tenant waiting for a slot before RESOURCE_EXHAUSTED (half the queue: one
  /// tenant cannot fill it). Without tokens every caller is the one anonymous tenant.
  size_t max_tenant_queued_builds = 8;
  /// Working memory admitted to running builds; 0: 90% of the GPU's memory, or half the host's.
  size_t build_memory_bytes = 0;
  uint64_t max_points_per_build = 100'000'000;
  /// Bytes of points held by uploads and builds at once; 0: no limit.
  size_t max_in_flight_bytes = size_t{8} << 30;
  /// Bytes of points one tenant's uploads and builds hold at once (half the server's: one tenant
  /// cannot take the whole budget); 0: no limit per tenant.
  size_t max_tenant_in_flight_bytes = size_t{4} << 30;
  /// A Build stream with no message for this long is ended (DEADLINE_EXCEEDED) and its points
  /// dropped; zero: never.
  std::chrono::milliseconds upload_idle_timeout{30000};
  /// How long one build may run (server/build_time_limit.hpp); past it the build stops at its
  /// next phase boundary and answers DEADLINE_EXCEEDED.
  BuildTimeLimitOptions build_time;
  /// How many exact radius comparisons one build may make (server/exact_comparison_limit.hpp);
  /// past it the build stops and answers RESOURCE_EXHAUSTED.
  ExactComparisonLimitOptions exact_comparisons;
  /// Byte budget of the family cache's resident tier (whole families, ready to answer).
  size_t cache_bytes = size_t{8} << 30;
  /// Byte budget of its compact tier (the points of families pushed out of the resident tier,
  /// rebuilt when a query asks for them; server/family_cache.hpp); 0: no compact tier.
  size_t compact_cache_bytes = size_t{4} << 30;
  /// GPU memory for families whose rank tables stay on the GPU after their build (resident
  /// families: no download, queries answered there; server/README.md "Cache"), taken from the
  /// builds' default memory budget; 0: CUDA families are copied to host memory. Unused on the CPU
  /// backend, whose families are held in host memory.
  size_t device_cache_bytes = 0;
  /// After this long with no build running or queued, the device memory that CUDA's pool keeps
  /// for reuse (freed by builds, and by families that left the device) goes back to the device,
  /// checked once a second; the first build after it maps its memory again. 0: kept for good.
  std::chrono::milliseconds device_idle_release{2000};
  TenantTokens tokens;
  /// BuildBatch's small unweighted sets: packed into one build, or one set a host core.
  BatchPacking batch_packing = BatchPacking::kAuto;
};

class AlphaService final : public galpha::v1::AlphaShapes::CallbackService {
 public:
  /// Unavailable when the CUDA backend is asked for and there is none.
  static absl::StatusOr<std::unique_ptr<AlphaService>> Create(const ServiceOptions& options, ServerMetrics* metrics);
  ~AlphaService() override;

  /// The backend builds run on ("cuda" or "cpu").
  const std::string& backend_name() const { return backend_name_; }
  size_t build_slots() const { return scheduler_->slots(); }
  FamilyCache& cache() { return *cache_; }
  /// Bytes of points held by uploads and builds right now, in all and by one tenant.
  size_t in_flight_bytes() const { return in_flight_.held(); }
  size_t in_flight_bytes_of(const std::string& tenant) const { return in_flight_.held_by(tenant); }

  /// Builds the warm-up lattice (server/warm_up.hpp), unweighted and weighted, on a build slot as
  /// a caller's build runs (the same backend, stream and family form; nothing is cached), and
  /// returns the seconds both took. The server calls it before it listens (ServerOptions::warm_up).
  /// The engine's error if a build fails.
  absl::StatusOr<double> WarmUp();

  /// Refuses new builds (UNAVAILABLE); queued builds that have not started fail UNAVAILABLE,
  /// running ones finish. Queries go on until the server shuts down.
  void StartDraining();
  /// Samples device memory into the metrics (the server calls this periodically on a GPU).
  void SampleDeviceMemory();
  /// Gives the device memory the pool keeps for reuse back to the device when no build has run or
  /// waited for ServiceOptions::device_idle_release (the server calls this periodically on a GPU).
  void ReleaseIdleDeviceMemory();

  grpc::ServerReadReactor<galpha::v1::BuildRequest>* Build(grpc::CallbackServerContext* context,
                                                           galpha::v1::BuildResponse* response) override;
  grpc::ServerBidiReactor<galpha::v1::BuildBatchRequest, galpha::v1::BuildBatchResponse>* BuildBatch(
      grpc::CallbackServerContext* context) override;
  grpc::ServerUnaryReactor* Describe(grpc::CallbackServerContext* context, const galpha::v1::DescribeRequest* request,
                                     galpha::v1::DescribeResponse* response) override;
  grpc::ServerWriteReactor<galpha::v1::ClassifyResponse>* Classify(grpc::CallbackServerContext* context,
                                                                   const galpha::v1::ClassifyRequest* request) override;
  grpc::ServerWriteReactor<galpha::v1::MasterListResponse>* MasterList(
      grpc::CallbackServerContext* context, const galpha::v1::MasterListRequest* request) override;
  grpc::ServerUnaryReactor* Spectrum(grpc::CallbackServerContext* context, const galpha::v1::SpectrumRequest* request,
                                     galpha::v1::SpectrumResponse* response) override;
  grpc::ServerWriteReactor<galpha::v1::ShapeResponse>* Shape(grpc::CallbackServerContext* context,
                                                             const galpha::v1::ShapeRequest* request) override;
  grpc::ServerUnaryReactor* Components(grpc::CallbackServerContext* context,
                                       const galpha::v1::ComponentsRequest* request,
                                       galpha::v1::ComponentsResponse* response) override;
  grpc::ServerUnaryReactor* OptimalAlpha(grpc::CallbackServerContext* context,
                                         const galpha::v1::OptimalAlphaRequest* request,
                                         galpha::v1::OptimalAlphaResponse* response) override;
  grpc::ServerUnaryReactor* Betti(grpc::CallbackServerContext* context, const galpha::v1::BettiRequest* request,
                                  galpha::v1::BettiResponse* response) override;
  grpc::ServerWriteReactor<galpha::v1::PersistenceResponse>* Persistence(
      grpc::CallbackServerContext* context, const galpha::v1::PersistenceRequest* request) override;
  grpc::ServerUnaryReactor* Release(grpc::CallbackServerContext* context, const galpha::v1::ReleaseRequest* request,
                                    galpha::v1::ReleaseResponse* response) override;

 private:
  friend class BuildReactor;
  friend class BuildBatchReactor;
  AlphaService(const ServiceOptions& options, ServerMetrics* metrics);

  /// The caller's tenant, or Unauthenticated.
  absl::StatusOr<std::string> Authenticate(grpc::CallbackServerContext* context) const;
  /// InvalidArgument naming `handle` when it is not one (sha256- and 64 hex digits).
  static absl::Status CheckHandle(const std::string& handle);
  /// The cached family of (tenant, handle), rebuilt first when the cache holds it in its compact
  /// tier (the call then waits for the rebuild), or NotFound / InvalidArgument, or the rebuild's
  /// error (FamilyPromoter::Promote).
  absl::StatusOr<std::shared_ptr<const CachedFamily>> Lookup(grpc::CallbackServerContext* context,
                                                             const std::string& handle);
  /// One query on a built family, the same for the unary and the streamed ones: times the RPC as
  /// `method`, looks the family up by the request's handle, answers from it with `answer` (a
  /// query_answers.hpp function of the family and the request) and finishes the RPC with `reply`
  /// (of the record and the answer, or the lookup's error). Returns the reply's reactor.
  template <typename Request, typename Answer, typename Reply>
  auto AnswerQuery(grpc::CallbackServerContext* context, const char* method, const Request& request, Answer answer,
                   Reply reply);

  ServiceOptions options_;
  ServerMetrics* metrics_;
  Backend backend_ = Backend::kCpu;
  std::string backend_name_;
  /// Whether CUDA builds keep their tables on the GPU (a device cache budget).
  bool resident_families_ = false;
  std::unique_ptr<CudaStreamPool> streams_;
  std::unique_ptr<FamilyCache> cache_;
  std::unique_ptr<FamilyPromoter> promoter_;  // before scheduler_: its jobs call it
  InFlightBytes in_flight_;
  /// Decodes the Build streams' encoded chunks and encodes compact Classify answers, one thread a
  /// core (build_stream.hpp, encoded_answer.hpp).
  ChunkCodecPool codec_pool_;
  UploadWatchdog upload_watchdog_;
  std::atomic<bool> draining_{false};
  std::atomic<bool> told_release_failure_{false};
  // Last: its workers run builds that use everything above, so it stops first.
  std::unique_ptr<BuildScheduler> scheduler_;
};

}  // namespace galpha::server
