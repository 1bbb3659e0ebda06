#include "server/alpha_service.hpp"

#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/types/span.h"
#include "core/io/point_set_handle.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "server/build_batch_reactor.hpp"
#include "server/build_reactor.hpp"
#include "server/cached_family.hpp"
#include "server/encoded_answer.hpp"
#include "server/grpc_status.hpp"
#include "server/persistence_answers.hpp"
#include "server/query_answers.hpp"
#include "server/rpc_record.hpp"
#include "server/warm_up.hpp"

namespace galpha::server {

namespace v1 = galpha::v1;

namespace {

/// A server-streamed answer written chunk by chunk as the client takes them (a slow reader slows
/// the writer). Two messages: while one is written, the source fills the next, so that its work
/// (classes gathered, chunks encoded) overlaps the transport instead of following each write.
/// Whichever of the two finishes last, the write (OnWriteDone) or the fill, starts the next cycle;
/// at most one write is in flight, and nothing is buffered beyond the one message filled ahead.
template <typename Message>
class ChunkWriter final : public grpc::ServerWriteReactor<Message> {
 public:
  ChunkWriter(RpcRecord record, std::unique_ptr<ChunkSource<Message>> source)
      : record_(record), source_(std::move(source)) {
    if (!source_->Next(&messages_[0])) {
      Done(ToGrpcStatus(source_->status()));
      return;
    }
    // gRPC holds a reactor's first write until the handler returns: the second message is filled
    // after the first is written (by OnWriteDone), so that the first (a Classify summary) is not
    // held back by the fill (an encoded answer's first chunks).
    next_ = 1;
    fill_pending_ = true;
    arrivals_.store(1, std::memory_order_relaxed);
    this->StartWrite(&messages_[0]);
  }
  /// An answer that is only an error.
  ChunkWriter(RpcRecord record, const absl::Status& error) : record_(record) { Done(ToGrpcStatus(error)); }

  void OnWriteDone(bool ok) override {
    if (!ok) write_failed_ = true;                                       // published by the fetch_add below
    if (arrivals_.fetch_add(1, std::memory_order_acq_rel) == 0) return;  // the fill goes on
    WriteCycles();
  }
  void OnDone() override { delete this; }

 private:
  // Runs with no write in flight and messages_[next_] filled (if has_next_; fill_pending_: not yet
  // filled): starts its write and fills the other message meanwhile, as long as the write finishes
  // first.
  void WriteCycles() {
    for (;;) {
      if (write_failed_) {
        Done(grpc::Status(grpc::StatusCode::CANCELLED, "the client stopped reading"));
        return;
      }
      if (fill_pending_) {
        fill_pending_ = false;
        has_next_ = source_->Next(&messages_[next_]);
      }
      if (!has_next_) {
        Done(ToGrpcStatus(source_->status()));
        return;
      }
      Message* writing = &messages_[next_];
      next_ ^= 1;
      arrivals_.store(0, std::memory_order_relaxed);
      this->StartWrite(writing);
      has_next_ = source_->Next(&messages_[next_]);
      if (arrivals_.fetch_add(1, std::memory_order_acq_rel) == 0) return;  // OnWriteDone goes on
    }
  }
  void Done(const grpc::Status& status) {
    record_.Done(status);
    source_.reset();  // drop the family reference before the RPC's end
    this->Finish(status);
  }

  RpcRecord record_;
  std::unique_ptr<ChunkSource<Message>> source_;
  std::array<Message, 2> messages_;
  size_t next_ = 0;            // the message to write next
  bool has_next_ = false;      // whether it holds one
  bool fill_pending_ = false;  // whether it is still to be filled (only before the second write)
  bool write_failed_ = false;
  // The write's end and the fill's: the second to arrive starts the next cycle.
  std::atomic<int> arrivals_{0};
};

/// Finishes a unary RPC with `status`, recorded first.
grpc::ServerUnaryReactor* FinishUnary(grpc::CallbackServerContext* context, const RpcRecord& record,
                                      const absl::Status& status) {
  const grpc::Status result = ToGrpcStatus(status);
  record.Done(result);
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  reactor->Finish(result);
  return reactor;
}

// Runs a unary RPC whose `answer` fills the response itself and returns an absl::Status; the
// reactor finishes with it.
template <typename Answer>
grpc::ServerUnaryReactor* AnswerUnary(grpc::CallbackServerContext* context, ServerMetrics* metrics, const char* method,
                                      Answer answer) {
  RpcRecord record(metrics, method);
  return FinishUnary(context, record, answer());
}

/// The reply of a unary query (AlphaService::AnswerQuery): the answer becomes the response, or its
/// error the RPC's status.
template <typename Response>
class UnaryReply {
 public:
  UnaryReply(grpc::CallbackServerContext* context, Response* response) : context_(context), response_(response) {}
  grpc::ServerUnaryReactor* operator()(const RpcRecord& record, absl::StatusOr<Response> answer) const {
    if (!answer.ok()) return FinishUnary(context_, record, answer.status());
    *response_ = *std::move(answer);
    return FinishUnary(context_, record, absl::OkStatus());
  }

 private:
  grpc::CallbackServerContext* context_;
  Response* response_;
};

/// The reply of a streamed query (AlphaService::AnswerQuery): a ChunkWriter over the answer's
/// chunks, or one that only finishes with its error.
template <typename Message>
struct StreamedReply {
  grpc::ServerWriteReactor<Message>* operator()(const RpcRecord& record,
                                                absl::StatusOr<std::unique_ptr<ChunkSource<Message>>> source) const {
    if (!source.ok()) return new ChunkWriter<Message>(record, source.status());
    return new ChunkWriter<Message>(record, *std::move(source));
  }
};

/// A unary answer of query_answers.hpp reads the family (in either form) only while it answers;
/// the streamed ones take the cached family itself, to keep it while their chunks are written.
template <typename Answer>
auto FromFamilyReader(Answer answer) {
  return [answer](const std::shared_ptr<const CachedFamily>& cached, const auto& request) {
    return answer(cached->reader(), request);
  };
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

// ---- The service ------------------------------------------------------------------------------------

AlphaService::AlphaService(const ServiceOptions& options, ServerMetrics* metrics)
    : options_(options),
      metrics_(metrics),
      in_flight_(options.max_in_flight_bytes, options.max_tenant_in_flight_bytes),
      codec_pool_(std::thread::hardware_concurrency()),
      upload_watchdog_(options.upload_idle_timeout) {}

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
  size_t memory = options.build_memory_bytes;
  if (memory == 0) {
    memory = DefaultMemoryBudget(backend);
    if (backend == Backend::kCuda && options.device_cache_bytes > 0) {
      // The GPU's memory is shared: resident families' tables take the device cache's part.
      if (memory != 0 && options.device_cache_bytes >= memory) {
        return absl::InvalidArgumentError(absl::StrCat("device_cache_bytes ", options.device_cache_bytes,
                                                       " leaves no GPU memory for builds (90% of the GPU is ", memory,
                                                       " bytes): lower it, or set build_memory_bytes"));
      }
      if (memory != 0) memory -= options.device_cache_bytes;
    }
  }
  service->resident_families_ = backend == Backend::kCuda && options.device_cache_bytes > 0;
  service->cache_ =
      std::make_unique<FamilyCache>(FamilyCache::Budgets{options.cache_bytes, options.compact_cache_bytes,
                                                         backend == Backend::kCuda ? options.device_cache_bytes : 0},
                                    metrics);
  service->scheduler_ = std::make_unique<BuildScheduler>(std::move(slot_streams), options.max_queued_builds,
                                                         options.max_tenant_queued_builds, memory, metrics);
  service->promoter_ = std::make_unique<FamilyPromoter>(
      service->cache_.get(), service->scheduler_.get(), backend, service->resident_families_, kBuildBytesPerPoint,
      [metrics](const BuildReport& report, double seconds) { metrics->RecordBuild(report, seconds); });
  metrics->SetBackend(service->backend_name_);
  service->SampleDeviceMemory();
  return service;
}

absl::StatusOr<double> AlphaService::WarmUp() {
  // 16K points, unweighted and weighted: 120-170 ms on an H200, most of it the one-time costs it
  // is there to pay (they do not grow with the size), 170-230 ms on two cores (bench/README.md).
  constexpr int kWarmUpSide = 128;
  // Shared with the job, which may still be returning on its worker thread when this returns.
  auto input = std::make_shared<const WarmUpInput>(WarmUpLattice(kWarmUpSide));
  auto finished = std::make_shared<std::promise<absl::Status>>();
  std::future<absl::Status> done = finished->get_future();
  const size_t points = input->points.size();
  const size_t need = UploadedBuildBytes(points, input->weights.size());  // the weighted build's
  const bool resident = resident_families_ && cache_->FitsDeviceTier(points);
  const Backend backend = backend_;
  const auto start = std::chrono::steady_clock::now();
  absl::Status submitted =
      scheduler_->Submit("", need, [input, finished, resident, backend](const BuildSlot& slot, bool draining) {
        if (draining) {
          finished->set_value(absl::UnavailableError("the server stopped before its warm-up build ran"));
          return;
        }
        absl::Status status;
        for (const bool weighted : {false, true}) {
          BuildOptions options;
          options.backend = backend;
          options.cuda_stream = slot.cuda_stream;
          const absl::Span<const double> weights =
              weighted ? absl::Span<const double>(input->weights) : absl::Span<const double>();
          absl::StatusOr<std::shared_ptr<const CachedFamily>> family =
              BuildCachedFamily(input->points, weights, weighted, options, resident, nullptr);
          if (!family.ok()) {
            status = absl::Status(family.status().code(),
                                  absl::StrCat(weighted ? "weighted" : "unweighted", " build of ", input->points.size(),
                                               " points: ", family.status().message()));
            break;
          }
        }
        finished->set_value(status);
      });
  if (!submitted.ok()) return submitted;
  absl::Status status = done.get();
  if (!status.ok()) return status;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void AlphaService::StartDraining() {
  draining_ = true;
  scheduler_->Stop();
}

void AlphaService::SampleDeviceMemory() {
  if (backend_ != Backend::kCuda) return;
  if (auto memory = QueryDeviceMemory(); memory.ok()) {
    metrics_->SetDeviceMemoryInUse(static_cast<double>(memory->used_bytes()));
  }
}

void AlphaService::ReleaseIdleDeviceMemory() {
  if (backend_ != Backend::kCuda || options_.device_idle_release.count() <= 0 || scheduler_ == nullptr) return;
  // Under the scheduler, so that no build starts (and captures a graph on a slot's stream) while
  // the device is waited for. Once a second while idle: after the first pass it only finds what
  // releases freed since.
  absl::Status released;
  scheduler_->RunIfIdleFor(options_.device_idle_release, [&] { released = ReleaseUnusedDeviceMemory(); });
  if (!released.ok() && !told_release_failure_.exchange(true)) {
    // Not fatal (the memory stays in the pool, as it would without this), but said once.
    std::fprintf(stderr, "galpha_server: %s\n", std::string(released.message()).c_str());
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

absl::Status AlphaService::CheckHandle(const std::string& handle) {
  if (IsWellFormedHandle(handle)) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat("handle '", handle.substr(0, 80), "' is not a handle (expected sha256- and 64 hex digits)"));
}

absl::StatusOr<std::shared_ptr<const CachedFamily>> AlphaService::Lookup(grpc::CallbackServerContext* context,
                                                                         const std::string& handle) {
  auto tenant = Authenticate(context);
  if (!tenant.ok()) return tenant.status();
  if (absl::Status s = CheckHandle(handle); !s.ok()) return s;
  FamilyCache::Found found = cache_->Lookup(*tenant, handle);
  if (found.resident != nullptr) return std::move(found.resident);
  if (found.compact != nullptr) return promoter_->Promote(*tenant, handle, std::move(found.compact));
  return absl::NotFoundError(
      absl::StrCat("no family under handle ", handle, " (never built here, released or evicted): build it again"));
}

grpc::ServerReadReactor<v1::BuildRequest>* AlphaService::Build(grpc::CallbackServerContext* context,
                                                               v1::BuildResponse* response) {
  return new BuildReactor(this, context, response, Authenticate(context));
}

grpc::ServerBidiReactor<v1::BuildBatchRequest, v1::BuildBatchResponse>* AlphaService::BuildBatch(
    grpc::CallbackServerContext* context) {
  return new BuildBatchReactor(this, context, Authenticate(context));
}

template <typename Request, typename Answer, typename Reply>
auto AlphaService::AnswerQuery(grpc::CallbackServerContext* context, const char* method, const Request& request,
                               Answer answer, Reply reply) {
  RpcRecord record(metrics_, method);
  auto family = Lookup(context, request.handle());
  if (!family.ok()) return reply(record, family.status());
  // Answered before the reply, so that a unary answer's family reference ends before the RPC.
  auto answered = answer(*std::move(family), request);
  return reply(record, std::move(answered));
}

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
  return AnswerQuery(context, "Spectrum", *request, FromFamilyReader(AnswerSpectrum), UnaryReply(context, response));
}

grpc::ServerUnaryReactor* AlphaService::Components(grpc::CallbackServerContext* context,
                                                   const v1::ComponentsRequest* request,
                                                   v1::ComponentsResponse* response) {
  return AnswerQuery(context, "Components", *request, FromFamilyReader(AnswerComponents),
                     UnaryReply(context, response));
}

grpc::ServerUnaryReactor* AlphaService::OptimalAlpha(grpc::CallbackServerContext* context,
                                                     const v1::OptimalAlphaRequest* request,
                                                     v1::OptimalAlphaResponse* response) {
  return AnswerQuery(context, "OptimalAlpha", *request, FromFamilyReader(AnswerOptimalAlpha),
                     UnaryReply(context, response));
}

grpc::ServerUnaryReactor* AlphaService::Betti(grpc::CallbackServerContext* context, const v1::BettiRequest* request,
                                              v1::BettiResponse* response) {
  return AnswerQuery(context, "Betti", *request, FromFamilyReader(AnswerBetti), UnaryReply(context, response));
}

grpc::ServerUnaryReactor* AlphaService::Release(grpc::CallbackServerContext* context, const v1::ReleaseRequest* request,
                                                v1::ReleaseResponse* response) {
  return AnswerUnary(context, metrics_, "Release", [&]() -> absl::Status {
    auto tenant = Authenticate(context);
    if (!tenant.ok()) return tenant.status();
    // A malformed handle is the caller's mistake (a typo, an empty field), which an OK answer
    // with released=false would hide; a well-formed unknown one is not (Release is idempotent).
    if (absl::Status s = CheckHandle(request->handle()); !s.ok()) return s;
    // The family's deleter returns its memory to the system when the last query using it ends.
    response->set_released(cache_->Erase(*tenant, request->handle()));
    return absl::OkStatus();
  });
}

grpc::ServerWriteReactor<v1::ClassifyResponse>* AlphaService::Classify(grpc::CallbackServerContext* context,
                                                                       const v1::ClassifyRequest* request) {
  const auto answer = [this](std::shared_ptr<const CachedFamily> cached, const v1::ClassifyRequest& classify)
      -> absl::StatusOr<std::unique_ptr<ChunkSource<v1::ClassifyResponse>>> {
    auto raw = MakeClassifySource(std::move(cached), classify);
    if (!raw.ok()) return raw.status();
    return EncodeSimplexChunks(*std::move(raw), classify.simplex_encoding(), &codec_pool_);
  };
  return AnswerQuery(context, "Classify", *request, answer, StreamedReply<v1::ClassifyResponse>());
}

grpc::ServerWriteReactor<v1::MasterListResponse>* AlphaService::MasterList(grpc::CallbackServerContext* context,
                                                                           const v1::MasterListRequest* request) {
  return AnswerQuery(context, "MasterList", *request, MakeMasterListSource, StreamedReply<v1::MasterListResponse>());
}

grpc::ServerWriteReactor<v1::ShapeResponse>* AlphaService::Shape(grpc::CallbackServerContext* context,
                                                                 const v1::ShapeRequest* request) {
  return AnswerQuery(context, "Shape", *request, MakeShapeSource, StreamedReply<v1::ShapeResponse>());
}

grpc::ServerWriteReactor<v1::PersistenceResponse>* AlphaService::Persistence(grpc::CallbackServerContext* context,
                                                                             const v1::PersistenceRequest* request) {
  return AnswerQuery(context, "Persistence", *request, MakePersistenceSource, StreamedReply<v1::PersistenceResponse>());
}

}  // namespace galpha::server
