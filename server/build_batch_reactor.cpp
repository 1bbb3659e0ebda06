#include "server/build_batch_reactor.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <thread>
#include <utility>

#include "absl/strings/cord.h"
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

v1::BuildRequest AsBuildRequest(v1::BuildBatchRequest message) {
  v1::BuildRequest out;
  switch (message.part_case()) {
    case v1::BuildBatchRequest::kHeader:
      *out.mutable_header() = std::move(*message.mutable_header());
      break;
    case v1::BuildBatchRequest::kPoints:
      *out.mutable_points() = std::move(*message.mutable_points());
      break;
    case v1::BuildBatchRequest::kEncodedPoints:
      *out.mutable_encoded_points() = std::move(*message.mutable_encoded_points());
      break;
    case v1::BuildBatchRequest::PART_NOT_SET:
      break;  // the decoder refuses a message of no kind
  }
  return out;
}

absl::Status NameBatchSet(const absl::Status& status, size_t set, const std::string& name) {
  absl::Status named(status.code(), absl::StrCat("set ", set, " ('", name, "'): ", status.message()));
  status.ForEachPayload([&](absl::string_view url, const absl::Cord& payload) { named.SetPayload(url, payload); });
  return named;
}

BuildBatchReactor::BuildBatchReactor(AlphaService* service, grpc::CallbackServerContext* context,
                                     absl::StatusOr<std::string> tenant)
    : UploadReactor(&service->upload_watchdog_, context, "the batch upload", "the batch"),
      service_(service),
      record_(service->metrics_, "BuildBatch") {
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

absl::Status BuildBatchReactor::EndSet() {
  Set& set = sets_.back();
  auto decoded = set.decoder->Finish();
  if (!decoded.ok()) return decoded.status();
  set.build = *decoded;
  points_ += set.build->points.size();
  return absl::OkStatus();
}

absl::Status BuildBatchReactor::AddMessage(v1::BuildBatchRequest batch_message) {
  v1::BuildRequest message = AsBuildRequest(std::move(batch_message));
  if (message.has_header()) {
    if (!sets_.empty()) {
      if (absl::Status ended = EndSet(); !ended.ok()) return NameBatchSet(ended, sets_.size() - 1, sets_.back().name);
    }
    if (sets_.size() == kMaxBatchSets) {
      return absl::InvalidArgumentError(
          absl::StrCat("a BuildBatch stream carries at most ", kMaxBatchSets, " sets; send the rest in another"));
    }
    Set& set = sets_.emplace_back();
    set.decoder = std::make_unique<BuildStreamDecoder>(BuildStreamLimits{service_->options_.max_points_per_build},
                                                       &service_->in_flight_, tenant_, &service_->codec_pool_);
    set.name = message.header().name().substr(0, kMaxBuildNameBytes);  // the decoder refuses a longer one
    if (absl::Status added = set.decoder->Add(std::move(message)); !added.ok()) {
      return NameBatchSet(added, sets_.size() - 1, set.name);
    }
    return absl::OkStatus();
  }
  if (sets_.empty()) {
    return absl::InvalidArgumentError("a BuildBatch stream starts with a set's header; this one began with points");
  }
  Set& set = sets_.back();
  absl::Status added = set.decoder->Add(std::move(message));
  // The batch is one build job: its points together are held to the limit of one build.
  const uint64_t points = points_ + set.decoder->points_received();
  if (added.ok() && points > service_->options_.max_points_per_build) {
    added = TagRefusal(absl::ResourceExhaustedError(absl::StrCat(
                           "the batch's sets hold ", points, " points together, over the server's limit of ",
                           service_->options_.max_points_per_build, " points a build (--max_points_per_build)")),
                       BuildRefusal::kPointsPerBuild);
  }
  if (!added.ok()) return NameBatchSet(added, sets_.size() - 1, set.name);
  return absl::OkStatus();
}

void BuildBatchReactor::EndOfStream() {
  if (CallerGone()) {
    Respond(absl::CancelledError("the client cancelled the batch during the upload"));
    return;
  }
  if (sets_.empty()) {
    Respond(absl::InvalidArgumentError("the BuildBatch stream carried no set: it needs a header, then points, a set"));
    return;
  }
  if (absl::Status ended = EndSet(); !ended.ok()) {
    Respond(NameBatchSet(ended, sets_.size() - 1, sets_.back().name));
    return;
  }
  // Cached sets answer now; the others are built by one job: the packed sets in one build, then
  // the large ones one after the other on its slot, while the other small sets are built on host
  // cores at once. Its working memory is the larger of the packed build's and the largest set's,
  // plus the small sets' built on host cores at once, plus every set's points (already reserved
  // as in flight, and held until their set is built) and the packed sets' points once more (the
  // packed build's input, all of them together).
  size_t largest = 0;        // the largest set's working memory, of those built one by one
  size_t largest_small = 0;  // the same of the sets built on host cores, several at once
  size_t small = 0;
  size_t packed_points = 0;
  size_t held = 0;                         // every set's points and weights, held until the set is built
  std::map<std::string, size_t> first_of;  // handle -> the first set to build with it
  for (size_t i = 0; i < sets_.size(); ++i) {
    Set& set = sets_[i];
    // A set repeated in the batch is built once (the sets are built side by side, so the cache
    // would not yet hold it for the repeat) and answered as a cache hit after it.
    if (auto first = first_of.find(set.build->handle); first != first_of.end()) {
      repeats_.emplace_back(i, first->second);
      continue;
    }
    const FamilyCache::Found found = service_->cache_->Lookup(tenant_, set.build->handle);
    if (found.resident != nullptr) {
      if (set.build->frame != nullptr) found.resident->AttachFrameIfNone(set.build->frame);
      Answer(i, *found.resident, /*was_cached=*/true);
      set.decoder.reset();
      continue;
    }
    if (found.compact != nullptr && set.build->frame == nullptr) set.build->frame = found.compact->frame();
    held += set.build->points.size() * sizeof(Point2) + set.build->weights.size() * sizeof(double);
    first_of.emplace(set.build->handle, i);
    to_build_.push_back(i);
    if (Packed(i)) {
      packed_points += set.build->points.size();
      continue;
    }
    const size_t working =
        set.build->points.size() * kBuildBytesPerPoint + set.build->weights.size() * kBuildBytesPerWeight;
    largest = std::max(largest, working);
    if (set.build->points.size() <= kHostBatchSetPoints) {
      largest_small = std::max(largest_small, working);
      ++small;
    }
  }
  const size_t host_threads = std::min<size_t>(std::max(std::thread::hardware_concurrency(), 1u), small);
  const size_t need = std::max(largest, packed_points * kBuildBytesPerPoint) + host_threads * largest_small + held +
                      packed_points * sizeof(Point2);
  if (to_build_.empty()) {
    AnswerRepeats();
    WriteNextPage();
    return;
  }
  absl::Status submitted = service_->scheduler_->Submit(
      tenant_, need, [this](const BuildSlot& slot, bool draining) { Run(slot, draining); });
  if (!submitted.ok()) Respond(submitted);
}

void BuildBatchReactor::Run(const BuildSlot& slot, bool draining) {
  if (draining) {
    Respond(TagRefusal(absl::UnavailableError("the server is shutting down; the batch had not started"),
                       BuildRefusal::kDraining));
    return;
  }
  if (CallerGone()) {
    Respond(absl::CancelledError("the client went away while the batch was queued"));
    return;
  }
  uint64_t points = 0;
  for (size_t i : to_build_) points += sets_[i].build->points.size();
  const bool cuda = service_->backend_name_ == "cuda";
  const unsigned cores = std::thread::hardware_concurrency();
  const auto one_build = BuildTimeLimit(points, cuda, cores, service_->options_.build_time);
  const bool limited = one_build.count() > 0;
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(one_build) +
                        kBatchBuildTimePerSet * static_cast<int64_t>(to_build_.size());
  const absl::Status late = PastTimeLimit("before this set was built", points);
  std::atomic<bool> any_late{false};
  // Builds `indices` in order, from `next` on (shared by the threads that take them), until the
  // deadline: past it, the sets left are answered `late` without being started.
  const auto build_all = [&](const std::vector<size_t>& indices, std::atomic<size_t>* next, bool on_host) {
    for (size_t k = (*next)++; k < indices.size() && !CallerGone(); k = (*next)++) {
      if (limited && Clock::now() > deadline) {
        any_late = true;
        AnswerError(indices[k], late, /*count_refusal=*/false);
        sets_[indices[k]].decoder.reset();
        continue;
      }
      BuildSet(indices[k], slot, limited, deadline, points, on_host);
    }
  };
  // Small unweighted sets are packed into one build on this slot (BuildAlphaFamilies: each
  // family the same bit for bit as its own build's, packed_families_test) when the service packs:
  // a set alone costs the GPU mostly its fixed start (about 6 ms a 1,000-point set on an H200,
  // bench/README.md). The other small sets are built on the host's cores, one set a core (each
  // build on one thread): a family is the same bit for bit on either backend
  // (alpha_backend_identity_test), and a host core builds a small set in a few milliseconds.
  // Larger sets are built on this slot after the packed build, one after another, on the
  // service's backend, while the host cores work.
  std::vector<size_t> packed, small, large;
  for (size_t i : to_build_) {
    if (Packed(i)) {
      packed.push_back(i);
    } else {
      (sets_[i].build->points.size() <= kHostBatchSetPoints ? small : large).push_back(i);
    }
  }
  std::atomic<size_t> next_small{0}, next_large{0};
  std::vector<std::thread> workers;
  const size_t threads = std::min<size_t>(std::max(cores, 1u), small.size());
  workers.reserve(threads);
  for (size_t t = 0; t < threads; ++t) {
    workers.emplace_back([&] {
      omp_set_num_threads(1);  // this thread's parallel regions: one thread (a set a core)
      build_all(small, &next_small, /*on_host=*/true);
    });
  }
  if (!packed.empty() && !CallerGone()) {
    // A failed packed build's sets are built one by one on this slot, before the large ones.
    const std::vector<size_t> alone = BuildPacked(packed, slot, limited, deadline, points);
    std::atomic<size_t> next_alone{0};
    build_all(alone, &next_alone, /*on_host=*/false);
  }
  build_all(large, &next_large, /*on_host=*/false);
  for (std::thread& worker : workers) worker.join();
  if (any_late) service_->metrics_->RecordRejectedBuild(RefusalLabelOf(late));
  AnswerRepeats();
  ReturnFreedHeapMemory();  // the engine's working memory and the points
  if (CallerGone()) {
    Respond(absl::CancelledError("the client went away during the batch; the sets built so far stay cached"));
    return;
  }
  WriteNextPage();
}

void BuildBatchReactor::BuildSet(size_t index, const BuildSlot& slot, bool limited, Clock::time_point deadline,
                                 uint64_t batch_points, bool on_host) {
  Set& set = sets_[index];
  const DecodedBuild& build = *set.build;
  if (AnswerIfCachedSince(index)) return;
  const size_t points = build.points.size();
  BuildOptions options;
  options.backend = on_host ? Backend::kCpu : service_->backend_;
  options.cuda_stream = on_host ? nullptr : slot.cuda_stream;
  options.cancelled = [this, limited, deadline] { return cancelled_.load() || (limited && Clock::now() > deadline); };
  options.max_exact_comparisons = ExactComparisonLimit(points, service_->options_.exact_comparisons);
  const auto start = Clock::now();
  absl::StatusOr<std::shared_ptr<const CachedFamily>> family = BuildCachedFamily(
      build.points, build.weights, build.header.weighted(), options,
      !on_host && service_->resident_families_ && service_->cache_->FitsDeviceTier(points), build.frame);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (!family.ok()) {
    if (absl::IsCancelled(family.status()) && !cancelled_ && limited && Clock::now() > deadline) {
      AnswerError(index, PastTimeLimit("during this set's build", batch_points));
    } else if (IsExactComparisonLimit(family.status())) {
      AnswerError(index, TagRefusal(absl::ResourceExhaustedError(
                                        ExactComparisonLimitMessage(points, service_->options_.exact_comparisons)),
                                    BuildRefusal::kExactComparisons));
    } else {
      AnswerError(index, family.status());
    }
    set.decoder.reset();  // its points and their reservation
    return;
  }
  service_->metrics_->RecordBuild((*family)->reader().report(), seconds);
  CacheAndAnswer(index, *std::move(family));
}

bool BuildBatchReactor::AnswerIfCachedSince(size_t index) {
  Set& set = sets_[index];
  const DecodedBuild& build = *set.build;
  const FamilyCache::Found found = service_->cache_->Lookup(tenant_, build.handle);
  if (found.resident == nullptr) return false;
  if (build.frame != nullptr) found.resident->AttachFrameIfNone(build.frame);
  Answer(index, *found.resident, /*was_cached=*/true);
  set.decoder.reset();
  return true;
}

bool BuildBatchReactor::Packed(size_t index) const {
  const BatchPacking packing = service_->options_.batch_packing;
  const bool packs =
      packing == BatchPacking::kOn || (packing == BatchPacking::kAuto && service_->backend_name_ == "cuda");
  const DecodedBuild& build = *sets_[index].build;
  return packs && !build.header.weighted() && build.points.size() <= kHostBatchSetPoints;
}

std::vector<size_t> BuildBatchReactor::BuildPacked(const std::vector<size_t>& indices, const BuildSlot& slot,
                                                   bool limited, Clock::time_point deadline, uint64_t batch_points) {
  std::vector<size_t> to_pack;
  for (size_t i : indices) {
    if (!AnswerIfCachedSince(i)) to_pack.push_back(i);
  }
  if (to_pack.empty()) return {};
  std::vector<Point2> points;
  std::vector<uint32_t> set_begin{0};
  BuildOptions options;
  options.backend = service_->backend_;
  options.cuda_stream = slot.cuda_stream;
  options.cancelled = [this, limited, deadline] { return cancelled_.load() || (limited && Clock::now() > deadline); };
  // The sets' limits of exact comparisons, together (none when one of them has none).
  bool unlimited = false;
  try {
    set_begin.reserve(to_pack.size() + 1);
    for (size_t i : to_pack) {
      const HostVector<Point2>& set = sets_[i].build->points;
      points.insert(points.end(), set.begin(), set.end());
      set_begin.push_back(static_cast<uint32_t>(points.size()));
      const uint64_t limit = ExactComparisonLimit(set.size(), service_->options_.exact_comparisons);
      unlimited |= limit == 0;
      options.max_exact_comparisons += limit;
    }
  } catch (const std::bad_alloc&) {
    return to_pack;  // no memory for the packed input: one by one, each with its own
  }
  if (unlimited) options.max_exact_comparisons = 0;
  const auto start = Clock::now();
  absl::StatusOr<AlphaFamilies> built = BuildAlphaFamilies(points, set_begin, options);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  points = {};
  if (!built.ok()) {
    if (!absl::IsCancelled(built.status())) return to_pack;  // each set then answers its own limits and errors
    if (!cancelled_ && limited && Clock::now() > deadline) {
      for (size_t i : to_pack) {
        AnswerError(i, PastTimeLimit("during this set's build", batch_points));
        sets_[i].decoder.reset();
      }
    }
    return {};  // the caller went away: Run answers for the batch
  }
  // One build: its stage times and comparisons counted once.
  service_->metrics_->RecordBuild(built->report, seconds);
  for (size_t k = 0; k < to_pack.size(); ++k) {
    CacheAndAnswer(to_pack[k], ShareCachedFamily(std::move(built->families[k]), sets_[to_pack[k]].build->frame));
  }
  return {};
}

absl::Status BuildBatchReactor::PastTimeLimit(absl::string_view when, uint64_t batch_points) const {
  const bool cuda = service_->backend_name_ == "cuda";
  const unsigned cores = std::thread::hardware_concurrency();
  return TagRefusal(
      absl::DeadlineExceededError(absl::StrCat(
          "the batch ran past its time limit ", when, " (a batch may take the limit of one build of all its ",
          batch_points, " points plus ", kBatchBuildTimePerSet.count(),
          " ms a set: ", BuildTimeLimitMessage(batch_points, cuda, cores, service_->options_.build_time), ")")),
      BuildRefusal::kBuildTime);
}

void BuildBatchReactor::CacheAndAnswer(size_t index, std::shared_ptr<const CachedFamily> family) {
  Set& set = sets_[index];
  auto inserted = service_->cache_->Insert(tenant_, set.build->handle, std::move(family));
  if (!inserted.ok()) {
    AnswerError(index, absl::IsResourceExhausted(inserted.status())
                           ? TagRefusal(inserted.status(), BuildRefusal::kCacheBytes)
                           : inserted.status());
  } else {
    Answer(index, **inserted, /*was_cached=*/false);
  }
  set.decoder.reset();  // its points and their reservation
}

void BuildBatchReactor::Answer(size_t index, const CachedFamily& family, bool was_cached) {
  Set& set = sets_[index];
  v1::BuildResponse* result = set.answer.mutable_result();
  result->set_handle(set.build->handle);
  result->set_cached(was_cached);
  FillBuildSummary(family, result->mutable_summary());
  result->mutable_summary()->set_name(set.build->header.name());
  set.answered = true;
}

void BuildBatchReactor::AnswerRepeats() {
  for (const auto& [index, first] : repeats_) {
    Set& set = sets_[index];
    set.answer = sets_[first].answer;
    if (set.answer.code() == 0) {
      set.answer.mutable_result()->set_cached(true);
      set.answer.mutable_result()->mutable_summary()->set_name(set.build->header.name());
    }
    set.answered = true;
    set.decoder.reset();
  }
}

void BuildBatchReactor::AnswerError(size_t index, const absl::Status& status, bool count_refusal) {
  if (const std::string reason = RefusalLabelOf(status); count_refusal && !reason.empty()) {
    service_->metrics_->RecordRejectedBuild(reason);
  }
  Set& set = sets_[index];
  set.answer.Clear();
  set.answer.set_code(static_cast<int32_t>(status.code()));
  set.answer.set_message(std::string(status.message()));
  set.answered = true;
}

void BuildBatchReactor::WriteNextPage() {
  if (next_page_set_ >= sets_.size()) {
    Respond(absl::OkStatus());
    return;
  }
  page_.Clear();
  page_.set_first_set(next_page_set_);
  page_.set_set_count(sets_.size());
  const size_t end = std::min(sets_.size(), next_page_set_ + kBatchSetsPerPage);
  for (size_t i = next_page_set_; i < end; ++i) {
    Set& set = sets_[i];
    if (!set.answered) {
      // Only a cancelled batch leaves sets unanswered, and it does not write.
      set.answer.set_code(static_cast<int32_t>(absl::StatusCode::kCancelled));
      set.answer.set_message("the batch ended before this set was built");
    }
    *page_.add_sets() = std::move(set.answer);
  }
  next_page_set_ = end;
  StartWrite(&page_);
}

void BuildBatchReactor::OnWriteDone(bool ok) {
  if (!ok) {
    Respond(absl::CancelledError("the client went away while the batch's answer was written"));
    return;
  }
  WriteNextPage();
}

void BuildBatchReactor::Respond(const absl::Status& status) {
  if (const std::string reason = RefusalLabelOf(status); !reason.empty()) {
    service_->metrics_->RecordRejectedBuild(reason);
  }
  const grpc::Status result = ToGrpcStatus(status);
  record_.Done(result);
  Finish(result);
}

}  // namespace galpha::server
