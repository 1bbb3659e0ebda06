#include "server/build_reactor.hpp"

#include <malloc.h>

#include <chrono>
#include <memory>
#include <utility>

#include "gpu/alpha/alpha_engine.hpp"
#include "server/alpha_service.hpp"
#include "server/grpc_status.hpp"
#include "server/query_answers.hpp"

namespace galpha::server {

namespace v1 = galpha::v1;

namespace {

using Clock = std::chrono::steady_clock;

/// Gives freed heap memory back to the system: a build frees hundreds of bytes per point at once,
/// and without this glibc keeps it, so the process would sit at its peak forever.
void ReturnFreedMemory() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

}  // namespace

BuildReactor::BuildReactor(AlphaService* service, grpc::CallbackServerContext* context, v1::BuildResponse* response,
                           absl::StatusOr<std::string> tenant)
    : service_(service),
      context_(context),
      response_(response),
      record_(service->metrics_, "Build"),
      decoder_(BuildStreamLimits{service->options_.max_points_per_build}, &service->in_flight_) {
  if (!tenant.ok()) {
    Respond(tenant.status());
    return;
  }
  tenant_ = *std::move(tenant);
  if (service_->draining_) {
    Respond(absl::UnavailableError("the server is draining and accepts no new builds"));
    return;
  }
  StartRead(&request_);
}

void BuildReactor::OnReadDone(bool ok) {
  if (!ok) {
    EndOfStream();
    return;
  }
  if (absl::Status status = decoder_.Add(request_); !status.ok()) {
    if (absl::IsResourceExhausted(status)) service_->metrics_->RecordRejectedBuild("limits");
    Respond(status);
    return;
  }
  StartRead(&request_);
}

void BuildReactor::EndOfStream() {
  if (context_->IsCancelled() || cancelled_) {
    Respond(absl::CancelledError("the client cancelled the build during the upload"));
    return;
  }
  auto decoded = decoder_.Finish();
  if (!decoded.ok()) {
    Respond(decoded.status());
    return;
  }
  build_ = *decoded;
  if (auto cached = service_->cache_->Find(tenant_, build_->handle)) {
    Succeed(*cached, /*was_cached=*/true);
    return;
  }
  const size_t need = build_->points.size() * (kBuildBytesPerPoint + sizeof(Point2));
  absl::Status submitted =
      service_->scheduler_->Submit(need, [this](const BuildSlot& slot, bool draining) { Run(slot, draining); });
  if (!submitted.ok()) {
    service_->metrics_->RecordRejectedBuild(absl::IsUnavailable(submitted) ? "draining" : "queue_or_memory");
    Respond(submitted);
  }
}

void BuildReactor::Run(const BuildSlot& slot, bool draining) {
  if (draining) {
    Respond(absl::UnavailableError("the server is shutting down; the build had not started"));
    return;
  }
  if (cancelled_) {
    Respond(absl::CancelledError("the client went away while the build was queued"));
    return;
  }
  BuildOptions options;
  options.backend = service_->backend_;
  options.cuda_stream = slot.cuda_stream;
  options.cancelled = [this] { return cancelled_.load(); };
  const auto start = Clock::now();
  absl::StatusOr<AlphaFamily> family = BuildAlphaFamily(build_->points, options);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  decoder_.ReleasePoints();
  if (!family.ok()) {
    ReturnFreedMemory();
    Respond(family.status());
    return;
  }
  service_->metrics_->RecordBuild(family->report(), seconds);
  // The last owner of a family (the cache, or a query still streaming from it after a release
  // or an eviction) frees hundreds of megabytes: give them back to the system right then.
  std::shared_ptr<const CachedFamily> cached(new CachedFamily(*std::move(family), build_->header.name()),
                                             [](const CachedFamily* f) {
                                               delete f;
                                               ReturnFreedMemory();
                                             });
  auto inserted = service_->cache_->Insert(tenant_, build_->handle, std::move(cached));
  ReturnFreedMemory();  // the engine's working memory and the points
  if (!inserted.ok()) {
    Respond(inserted.status());
    return;
  }
  Succeed(**inserted, /*was_cached=*/false);
}

void BuildReactor::Succeed(const CachedFamily& family, bool was_cached) {
  response_->set_handle(build_->handle);
  response_->set_cached(was_cached);
  FillBuildSummary(family, response_->mutable_summary());
  Respond(absl::OkStatus());
}

void BuildReactor::Respond(const absl::Status& status) {
  const grpc::Status result = ToGrpcStatus(status);
  record_.Done(result);
  Finish(result);
}

}  // namespace galpha::server
