// The BuildBatch RPC (issue "Speak GIS and molecules", item 3: one hull per feature): many point
// sets in one client stream, each as a Build stream would carry it (a header, then its chunks),
// read through one decoder a set; then one job on the build scheduler builds the sets that are
// not cached: the small unweighted ones packed into one build (BuildAlphaFamilies; or one a host
// core, ServiceOptions::batch_packing), the others one after the other on its slot; the answer
// goes back in pages of kBatchSetsPerPage. A bad stream fails the whole call, naming the set; a
// set whose build fails answers its own status and the others go on (a packed build that fails
// for any reason but the batch's time limit or the caller's cancellation builds its sets again one
// by one, so that each answers its own limits and errors).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "galpha/v1/alpha_shapes.grpc.pb.h"
#include "server/build_scheduler.hpp"
#include "server/build_stream.hpp"
#include "server/rpc_record.hpp"
#include "server/upload_reactor.hpp"

namespace galpha::server {

class AlphaService;

/// Most sets one BuildBatch stream may carry (INVALID_ARGUMENT past it): bounds the per-set state
/// a stream can make the server hold, whatever its points.
inline constexpr size_t kMaxBatchSets = 100'000;
/// Sets a BuildBatchResponse page answers.
inline constexpr size_t kBatchSetsPerPage = 1000;
/// Sets of at most this many points are small: unweighted ones are packed into one build when the
/// service packs (ServiceOptions::batch_packing), the others are built on the host's cores, one
/// set a core at a time, whatever the service's backend; larger ones on the build's slot.
inline constexpr size_t kHostBatchSetPoints = 20000;
/// Build time a batch is given a set, beyond the limit of one build of all its points: each set
/// costs the engine a fixed start whatever its size.
inline constexpr std::chrono::milliseconds kBatchBuildTimePerSet{100};

/// A BuildBatch stream's message as the Build stream's message it is (the same parts).
galpha::v1::BuildRequest AsBuildRequest(galpha::v1::BuildBatchRequest message);

/// `status` with its message prefixed by the set it concerns ("set 3 ('parcel-17'): ..."), its
/// code and payloads (a refusal's tag) kept.
absl::Status NameBatchSet(const absl::Status& status, size_t set, const std::string& name);

class BuildBatchReactor final
    : public UploadReactor<grpc::ServerBidiReactor<galpha::v1::BuildBatchRequest, galpha::v1::BuildBatchResponse>,
                           galpha::v1::BuildBatchRequest> {
 public:
  /// `tenant` is the caller's, or the authentication's error (the call then fails at once).
  BuildBatchReactor(AlphaService* service, grpc::CallbackServerContext* context, absl::StatusOr<std::string> tenant);

  void OnWriteDone(bool ok) override;

 private:
  // One set of the stream: its decoder (which holds its points' reservation until the set is
  // built), the decoded set once its stream part ended, and its answer.
  struct Set {
    std::string name;  // its header's (what errors name it by)
    std::unique_ptr<BuildStreamDecoder> decoder;
    DecodedBuild* build = nullptr;
    galpha::v1::BatchedBuild answer;
    bool answered = false;
  };

  // UploadReactor. A header starts the next set (ending the one before), a chunk goes to the
  // current set; errors name the set.
  absl::Status AddMessage(galpha::v1::BuildBatchRequest message) override;
  void DropUpload() override { sets_.clear(); }  // the points and their reservations
  void EndOfStream() override;
  void Respond(const absl::Status& status) override;

  // Ends the current set's part of the stream: its decoder's Finish.
  absl::Status EndSet();
  void Run(const BuildSlot& slot, bool draining);
  // Builds set `index` on `slot` (before `deadline` when `limited`; `batch_points`: the points of
  // the sets the batch builds, for the limit's message) and caches its family.
  // `on_host`: on the CPU backend, in host memory, whatever the service's backend.
  void BuildSet(size_t index, const BuildSlot& slot, bool limited, Clock::time_point deadline, uint64_t batch_points,
                bool on_host);
  // Answers set `index` from the cache when an earlier set of this batch with the same points, or
  // another call, built it since the stream ended.
  bool AnswerIfCachedSince(size_t index);
  // Whether set `index` goes into the batch's packed build (small, unweighted, and the service packs).
  bool Packed(size_t index) const;
  // Builds the sets `indices` together on `slot` (BuildAlphaFamilies) and caches their families;
  // returns the sets to build one by one instead (all of them when the packed build failed for a
  // reason of its own), having answered the others.
  std::vector<size_t> BuildPacked(const std::vector<size_t>& indices, const BuildSlot& slot, bool limited,
                                  Clock::time_point deadline, uint64_t batch_points);
  // The batch's time limit as a set's error, `when` it stopped the set ("before this set was
  // built", "during this set's build"); `batch_points`: the points the batch builds.
  absl::Status PastTimeLimit(absl::string_view when, uint64_t batch_points) const;
  // Caches set `index`'s new family and answers it (or the cache's refusal).
  void CacheAndAnswer(size_t index, std::shared_ptr<const CachedFamily> family);
  // `family` as set `index`'s answer.
  void Answer(size_t index, const CachedFamily& family, bool was_cached);
  // Set `index`'s answer as a failure (counted as a refusal when it is one and `count_refusal`).
  void AnswerError(size_t index, const absl::Status& status, bool count_refusal = true);
  // The repeats' answers: their first set's, as a cache hit under their own name.
  void AnswerRepeats();
  // Writes the next page of answers, or finishes the call after the last.
  void WriteNextPage();

  AlphaService* const service_;
  RpcRecord record_;
  std::string tenant_;
  std::vector<Set> sets_;
  uint64_t points_ = 0;  // of the sets whose part of the stream ended
  std::vector<size_t> to_build_;
  std::vector<std::pair<size_t, size_t>> repeats_;  // (set, the earlier set of the same points)
  galpha::v1::BuildBatchResponse page_;
  size_t next_page_set_ = 0;
};

}  // namespace galpha::server
