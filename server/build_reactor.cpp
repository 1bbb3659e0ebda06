#include "server/build_reactor.hpp"

#include <chrono>
#include <memory>
#include <thread>
#include <utility>

#include "absl/strings/str_cat.h"
#include "gpu/alpha/alpha_engine.hpp"
#include "server/alpha_service.hpp"
#include "server/build_refusal.hpp"
#include "server/build_time_limit.hpp"
#include "server/exact_comparison_limit.hpp"
#include "server/grpc_status.hpp"
#include "server/heap_trim.hpp"
#include "server/query_answers.hpp"

namespace galpha::server {

namespace v1 = galpha::v1;

namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

BuildReactor::BuildReactor(AlphaService* service, grpc::CallbackServerContext* context, v1::BuildResponse* response,
                           absl::StatusOr<std::string> tenant)
    : UploadReactor(&service->upload_watchdog_, context, "the upload", "the build"),
      service_(service),
      response_(response),
      record_(service->metrics_, "Build"),
      decoder_(BuildStreamLimits{service->options_.max_points_per_build}, &service->in_flight_,
               tenant.ok() ? *tenant : std::string(), &service->codec_pool_) {
  if (!tenant.ok()) {
    BeginUpload(tenant.status());
    return;
  }
  tenant_ = *std::move(tenant);
  BeginUpload(service_->draining_
                  ? TagRefusal(absl::UnavailableError("the server is draining and accepts no new builds"),
                               BuildRefusal::kDraining)
                  : absl::OkStatus());
}

void BuildReactor::EndOfStream() {
  if (CallerGone()) {
    Respond(absl::CancelledError("the client cancelled the build during the upload"));
    return;
  }
  auto decoded = decoder_.Finish();
  if (!decoded.ok()) {
    Respond(decoded.status());
    return;
  }
  build_ = *decoded;
  const FamilyCache::Found found = service_->cache_->Lookup(tenant_, build_->handle);
  if (found.resident != nullptr) {
    if (build_->frame != nullptr) found.resident->AttachFrameIfNone(build_->frame);
    Succeed(*found.resident, /*was_cached=*/true);
    return;
  }
  // A compact entry of these points: they are here, so they are built as uploaded (the cache then
  // drops the entry: a promotion); the frame it kept stays attached, as on a resident hit.
  if (found.compact != nullptr && build_->frame == nullptr) build_->frame = found.compact->frame();
  const size_t need = UploadedBuildBytes(build_->points.size(), build_->weights.size());
  absl::Status submitted = service_->scheduler_->Submit(
      tenant_, need, [this](const BuildSlot& slot, bool draining) { Run(slot, draining); });
  if (!submitted.ok()) Respond(submitted);
}

void BuildReactor::Run(const BuildSlot& slot, bool draining) {
  if (draining) {
    Respond(TagRefusal(absl::UnavailableError("the server is shutting down; the build had not started"),
                       BuildRefusal::kDraining));
    return;
  }
  if (CallerGone()) {
    Respond(absl::CancelledError("the client went away while the build was queued"));
    return;
  }
  BuildOptions options;
  options.backend = service_->backend_;
  options.cuda_stream = slot.cuda_stream;
  // The time limit counts from the start on a slot (queueing is the service's doing, not the
  // input's); the engine polls between its phases, so a build stops at the next boundary.
  const bool cuda = service_->backend_name_ == "cuda";
  const unsigned cores = std::thread::hardware_concurrency();
  const size_t points = build_->points.size();
  const auto limit = BuildTimeLimit(points, cuda, cores, service_->options_.build_time);
  const auto start = Clock::now();
  const bool limited = limit.count() > 0;
  const auto deadline = start + std::chrono::duration_cast<Clock::duration>(limit);
  options.cancelled = [this, limited, deadline] { return cancelled_.load() || (limited && Clock::now() > deadline); };
  options.max_exact_comparisons = ExactComparisonLimit(points, service_->options_.exact_comparisons);
  absl::StatusOr<std::shared_ptr<const CachedFamily>> family =
      BuildCachedFamily(build_->points, build_->weights, build_->header.weighted(), options,
                        service_->resident_families_ && service_->cache_->FitsDeviceTier(points), build_->frame);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  decoder_.ReleasePoints();
  if (!family.ok()) {
    ReturnFreedHeapMemory();
    if (absl::IsCancelled(family.status()) && !cancelled_ && limited && Clock::now() > deadline) {
      Respond(TagRefusal(
          absl::DeadlineExceededError(BuildTimeLimitMessage(points, cuda, cores, service_->options_.build_time)),
          BuildRefusal::kBuildTime));
      return;
    }
    if (IsExactComparisonLimit(family.status())) {
      Respond(TagRefusal(
          absl::ResourceExhaustedError(ExactComparisonLimitMessage(points, service_->options_.exact_comparisons)),
          BuildRefusal::kExactComparisons));
      return;
    }
    Respond(family.status());
    return;
  }
  service_->metrics_->RecordBuild((*family)->reader().report(), seconds);
  auto inserted = service_->cache_->Insert(tenant_, build_->handle, *std::move(family));
  ReturnFreedHeapMemory();  // the engine's working memory and the points
  if (!inserted.ok()) {
    Respond(absl::IsResourceExhausted(inserted.status()) ? TagRefusal(inserted.status(), BuildRefusal::kCacheBytes)
                                                         : inserted.status());
    return;
  }
  Succeed(**inserted, /*was_cached=*/false);
}

void BuildReactor::Succeed(const CachedFamily& family, bool was_cached) {
  response_->set_handle(build_->handle);
  response_->set_cached(was_cached);
  FillBuildSummary(family, response_->mutable_summary());
  // The name is the caller's label (proto: BuildHeader.name): a cache hit answers with this
  // caller's name, never the one of the build that computed the family.
  response_->mutable_summary()->set_name(build_->header.name());
  Respond(absl::OkStatus());
}

void BuildReactor::Respond(const absl::Status& status) {
  if (const std::string reason = RefusalLabelOf(status); !reason.empty()) {
    service_->metrics_->RecordRejectedBuild(reason);
  }
  const grpc::Status result = ToGrpcStatus(status);
  record_.Done(result);
  Finish(result);
}

}  // namespace galpha::server
