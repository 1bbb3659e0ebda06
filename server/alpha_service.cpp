#include "server/alpha_service.hpp"

#include <malloc.h>
#include <unistd.h>

#include <chrono>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/point_set_handle.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "server/query_answers.hpp"

namespace galpha::server {

namespace v1 = galpha::v1;

namespace {

using Clock = std::chrono::steady_clock;

grpc::Status ToGrpc(const absl::Status& status) {
  if (status.ok()) return grpc::Status::OK;
  // absl's canonical codes are gRPC's, number for number.
  return grpc::Status(static_cast<grpc::StatusCode>(status.code()), std::string(status.message()));
}

/// Times one RPC and records its method and status code when it finishes.
class RpcRecord {
 public:
  RpcRecord(ServerMetrics* metrics, const char* method) : metrics_(metrics), method_(method), start_(Clock::now()) {}
  void Done(const grpc::Status& status) const {
    const std::string code = absl::StatusCodeToString(static_cast<absl::StatusCode>(status.error_code()));
    metrics_->RecordRpc(method_, code, std::chrono::duration<double>(Clock::now() - start_).count());
  }

 private:
  ServerMetrics* metrics_;
  const char* method_;
  Clock::time_point start_;
};

/// A server-streamed answer written chunk by chunk as the client takes them (a slow reader slows
/// the writer; nothing is buffered beyond one message).
template <typename Message>
class ChunkWriter final : public grpc::ServerWriteReactor<Message> {
 public:
  ChunkWriter(RpcRecord record, std::unique_ptr<ChunkSource<Message>> source)
      : record_(record), source_(std::move(source)) {
    WriteNext();
  }
  /// An answer that is only an error.
  ChunkWriter(RpcRecord record, const absl::Status& error) : record_(record) { Done(ToGrpc(error)); }

  void OnWriteDone(bool ok) override {
    if (!ok) {
      Done(grpc::Status(grpc::StatusCode::CANCELLED, "the client stopped reading"));
      return;
    }
    WriteNext();
  }
  void OnDone() override { delete this; }

 private:
  void WriteNext() {
    if (source_->Next(&message_)) {
      this->StartWrite(&message_);
    } else {
      Done(grpc::Status::OK);
    }
  }
  void Done(const grpc::Status& status) {
    record_.Done(status);
    source_.reset();  // drop the family reference before the RPC's end
    this->Finish(status);
  }

  RpcRecord record_;
  std::unique_ptr<ChunkSource<Message>> source_;
  Message message_;
};

/// Gives freed heap memory back to the system: a build frees hundreds of bytes per point at once,
/// and without this glibc keeps it, so the process would sit at its peak forever.
void ReturnFreedMemory() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

size_t DefaultMemoryBudget(Backend backend) {
  if (backend == Backend::kCuda) {
    if (auto memory = QueryDeviceMemory(); memory.ok()) return memory->total_bytes / 10 * 9;
  }
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page_size = sysconf(_SC_PAGESIZE);
  if (pages > 0 && page_size > 0) return static_cast<size_t>(pages) * static_cast<size_t>(page_size) / 2;
  return 0;
}

}  // namespace

// ---- Build ------------------------------------------------------------------------------------------

/// One Build call: reads the stream through a decoder, then hands the build to the scheduler, whose
/// worker finishes the call. Deletes itself when gRPC is done with the call.
class BuildReactor final : public grpc::ServerReadReactor<v1::BuildRequest> {
 public:
  BuildReactor(AlphaService* service, grpc::CallbackServerContext* context, v1::BuildResponse* response,
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

  void OnReadDone(bool ok) override {
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

  void OnCancel() override { cancelled_ = true; }
  void OnDone() override { delete this; }

 private:
  void EndOfStream() {
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

  void Run(const BuildSlot& slot, bool draining) {
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

  void Succeed(const CachedFamily& family, bool was_cached) {
    response_->set_handle(build_->handle);
    response_->set_cached(was_cached);
    FillBuildSummary(family, response_->mutable_summary());
    Respond(absl::OkStatus());
  }

  // The last thing any path does: after Finish, gRPC may delete this at any moment.
  void Respond(const absl::Status& status) {
    const grpc::Status result = ToGrpc(status);
    record_.Done(result);
    Finish(result);
  }

  AlphaService* const service_;
  grpc::CallbackServerContext* const context_;
  v1::BuildResponse* const response_;
  RpcRecord record_;
  std::string tenant_;
  v1::BuildRequest request_;
  BuildStreamDecoder decoder_;
  DecodedBuild* build_ = nullptr;
  std::atomic<bool> cancelled_{false};
};

// ---- The service ------------------------------------------------------------------------------------

AlphaService::AlphaService(const ServiceOptions& options, ServerMetrics* metrics)
    : options_(options), metrics_(metrics), in_flight_(options.max_in_flight_bytes) {}

AlphaService::~AlphaService() = default;

absl::StatusOr<std::unique_ptr<AlphaService>> AlphaService::Create(const ServiceOptions& options,
                                                                   ServerMetrics* metrics) {
  std::unique_ptr<AlphaService> service(new AlphaService(options, metrics));
  Backend backend = options.backend;
  if (backend == Backend::kAuto) backend = CudaBackendAvailable() ? Backend::kCuda : Backend::kCpu;
  if (backend == Backend::kCuda && !CudaBackendAvailable()) {
    return absl::UnavailableError("the CUDA backend was asked for, but this build or machine has no GPU");
  }
  service->backend_ = backend;
  service->backend_name_ = BackendName(backend);
  const int slots = options.build_slots > 0 ? options.build_slots : (backend == Backend::kCuda ? 4 : 1);
  std::vector<void*> slot_streams(static_cast<size_t>(slots), nullptr);
  if (backend == Backend::kCuda) {
    auto streams = CudaStreamPool::Create(slots);
    if (!streams.ok()) return streams.status();
    service->streams_ = *std::move(streams);
    for (int i = 0; i < slots; ++i) slot_streams[static_cast<size_t>(i)] = service->streams_->stream(i);
  }
  const size_t memory = options.build_memory_bytes > 0 ? options.build_memory_bytes : DefaultMemoryBudget(backend);
  service->cache_ = std::make_unique<FamilyCache>(options.cache_bytes, metrics);
  service->scheduler_ = std::make_unique<BuildScheduler>(std::move(slot_streams), options.max_queued_builds, memory,
                                                         metrics);
  metrics->SetBackend(service->backend_name_);
  service->SampleDeviceMemory();
  return service;
}

void AlphaService::StartDraining() {
  draining_ = true;
  scheduler_->Stop();
}

void AlphaService::SampleDeviceMemory() {
  if (backend_ != Backend::kCuda) return;
  if (auto memory = QueryDeviceMemory(); memory.ok()) {
    metrics_->SetDeviceMemoryInUse(static_cast<double>(memory->total_bytes - memory->free_bytes));
  }
}

absl::StatusOr<std::string> AlphaService::Authenticate(grpc::CallbackServerContext* context) const {
  if (!options_.tokens.enabled()) return std::string();
  const auto& metadata = context->client_metadata();
  const auto it = metadata.find("authorization");
  if (it == metadata.end()) return options_.tokens.TenantOf(nullptr);
  const std::string value(it->second.data(), it->second.size());
  return options_.tokens.TenantOf(&value);
}

absl::StatusOr<std::shared_ptr<const CachedFamily>> AlphaService::Lookup(grpc::CallbackServerContext* context,
                                                                         const std::string& handle) {
  auto tenant = Authenticate(context);
  if (!tenant.ok()) return tenant.status();
  if (!IsWellFormedHandle(handle)) {
    return absl::InvalidArgumentError(
        absl::StrCat("'", handle.substr(0, 80), "' is not a handle (expected sha256- and 64 hex digits)"));
  }
  auto family = cache_->Find(*tenant, handle);
  if (family == nullptr) {
    return absl::NotFoundError(absl::StrCat("no family under handle ", handle,
                                            " (never built here, released or evicted): build it again"));
  }
  return family;
}

grpc::ServerReadReactor<v1::BuildRequest>* AlphaService::Build(grpc::CallbackServerContext* context,
                                                               v1::BuildResponse* response) {
  return new BuildReactor(this, context, response, Authenticate(context));
}

namespace {
// Runs a unary query: `answer` returns an absl::Status; the reactor finishes with it.
template <typename Answer>
grpc::ServerUnaryReactor* AnswerUnary(grpc::CallbackServerContext* context, ServerMetrics* metrics,
                                      const char* method, Answer answer) {
  RpcRecord record(metrics, method);
  const grpc::Status status = ToGrpc(answer());
  record.Done(status);
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  reactor->Finish(status);
  return reactor;
}
}  // namespace

grpc::ServerUnaryReactor* AlphaService::Describe(grpc::CallbackServerContext* context,
                                                 const v1::DescribeRequest* request, v1::DescribeResponse* response) {
  return AnswerUnary(context, metrics_, "Describe", [&]() -> absl::Status {
    auto family = Lookup(context, request->handle());
    if (!family.ok()) return family.status();
    response->set_handle(request->handle());
    FillBuildSummary(**family, response->mutable_summary());
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* AlphaService::Spectrum(grpc::CallbackServerContext* context,
                                                 const v1::SpectrumRequest* request, v1::SpectrumResponse* response) {
  return AnswerUnary(context, metrics_, "Spectrum", [&]() -> absl::Status {
    auto family = Lookup(context, request->handle());
    if (!family.ok()) return family.status();
    auto answer = AnswerSpectrum((*family)->family(), *request);
    if (!answer.ok()) return answer.status();
    *response = *std::move(answer);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* AlphaService::Components(grpc::CallbackServerContext* context,
                                                   const v1::ComponentsRequest* request,
                                                   v1::ComponentsResponse* response) {
  return AnswerUnary(context, metrics_, "Components", [&]() -> absl::Status {
    auto family = Lookup(context, request->handle());
    if (!family.ok()) return family.status();
    auto answer = AnswerComponents((*family)->family(), *request);
    if (!answer.ok()) return answer.status();
    *response = *std::move(answer);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* AlphaService::OptimalAlpha(grpc::CallbackServerContext* context,
                                                     const v1::OptimalAlphaRequest* request,
                                                     v1::OptimalAlphaResponse* response) {
  return AnswerUnary(context, metrics_, "OptimalAlpha", [&]() -> absl::Status {
    auto family = Lookup(context, request->handle());
    if (!family.ok()) return family.status();
    auto answer = AnswerOptimalAlpha((*family)->family(), *request);
    if (!answer.ok()) return answer.status();
    *response = *std::move(answer);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* AlphaService::Release(grpc::CallbackServerContext* context,
                                                const v1::ReleaseRequest* request, v1::ReleaseResponse* response) {
  return AnswerUnary(context, metrics_, "Release", [&]() -> absl::Status {
    auto tenant = Authenticate(context);
    if (!tenant.ok()) return tenant.status();
    // The family's deleter returns its memory to the system when the last query using it ends.
    response->set_released(cache_->Erase(*tenant, request->handle()));
    return absl::OkStatus();
  });
}

grpc::ServerWriteReactor<v1::ClassifyResponse>* AlphaService::Classify(grpc::CallbackServerContext* context,
                                                                       const v1::ClassifyRequest* request) {
  RpcRecord record(metrics_, "Classify");
  auto family = Lookup(context, request->handle());
  if (!family.ok()) return new ChunkWriter<v1::ClassifyResponse>(record, family.status());
  auto source = MakeClassifySource(*std::move(family), *request);
  if (!source.ok()) return new ChunkWriter<v1::ClassifyResponse>(record, source.status());
  return new ChunkWriter<v1::ClassifyResponse>(record, *std::move(source));
}

grpc::ServerWriteReactor<v1::MasterListResponse>* AlphaService::MasterList(grpc::CallbackServerContext* context,
                                                                           const v1::MasterListRequest* request) {
  RpcRecord record(metrics_, "MasterList");
  auto family = Lookup(context, request->handle());
  if (!family.ok()) return new ChunkWriter<v1::MasterListResponse>(record, family.status());
  auto source = MakeMasterListSource(*std::move(family), *request);
  if (!source.ok()) return new ChunkWriter<v1::MasterListResponse>(record, source.status());
  return new ChunkWriter<v1::MasterListResponse>(record, *std::move(source));
}

grpc::ServerWriteReactor<v1::ShapeResponse>* AlphaService::Shape(grpc::CallbackServerContext* context,
                                                                 const v1::ShapeRequest* request) {
  RpcRecord record(metrics_, "Shape");
  auto family = Lookup(context, request->handle());
  if (!family.ok()) return new ChunkWriter<v1::ShapeResponse>(record, family.status());
  auto source = MakeShapeSource(*std::move(family), *request);
  if (!source.ok()) return new ChunkWriter<v1::ShapeResponse>(record, source.status());
  return new ChunkWriter<v1::ShapeResponse>(record, *std::move(source));
}

}  // namespace galpha::server
