// The parts of one Classify answer read over several calls at once (ClassifyRequest.part_index and
// part_count; docs/design.md, "Classify in parts"), merged back into the order one call sends: the
// summary (part 0's first message), then chunk c from part c % P. One gRPC stream carries an
// answer at about 1 GB/s on loopback whatever the machine; P streams on P connections carry it
// about P times as fast (bench/README.md). Free of gRPC, so the unit tests drive it directly.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <vector>

#include "absl/status/statusor.h"
#include "galpha/v1/alpha_shapes.pb.h"

namespace galpha::client {

/// One producer a part (Push, End: the thread that reads that part's call) and one consumer
/// (Next, the caller's thread).
class ClassifyPartsMerger {
 public:
  /// `parts` (at least 2) calls; each queues at most `queued_per_part` messages (at least one) that
  /// Next has not taken, and its reader waits beyond.
  ClassifyPartsMerger(size_t parts, size_t queued_per_part);

  /// Part `part`'s next message, its chunks decoded (SimplexChunk). False, and the message dropped,
  /// once the merger no longer reads that part (Stop; a server that did not split): the reader then
  /// reads on to its call's end.
  bool Push(size_t part, galpha::v1::ClassifyResponse message);
  /// Part `part`'s call ended with `status` (its gRPC status, or the error that made its reader
  /// stop, such as a chunk that does not decode).
  void End(size_t part, const absl::Status& status);

  /// The next message in the order of the whole answer (valid until the next call); nullptr once
  /// the answer is complete: a part ended at its turn and every part has ended with nothing left.
  /// Errors: a part's failure, as it ended; part 0 without its summary first; a part with chunks
  /// past the answer's end (Internal).
  ///
  /// A server older than part_count ignores it and answers each call whole: a part other than 0
  /// then starts with a summary. From then on the merger reads part 0 alone, which is the whole
  /// answer; the caller cancels the other calls (whole_from_part_zero()), whose ends are ignored.
  absl::StatusOr<const galpha::v1::ClassifyResponse*> Next();
  /// Whether the server answered each part whole (see Next).
  bool whole_from_part_zero() const;
  /// Drops every queued message; Push returns false from now on.
  void Stop();

 private:
  struct Part {
    std::deque<galpha::v1::ClassifyResponse> queue;
    bool ended = false;
    bool dropped = false;  // no longer read: pushes are refused
    bool first = true;     // nothing taken from it yet
    absl::Status status;
  };

  // Waits until part `p` has a message or has ended; true with the message moved into current_.
  bool Take(std::unique_lock<std::mutex>& lock, size_t p);
  // After the answer's last chunk: waits for every part's end, and checks that none has more.
  absl::Status FinishAll(std::unique_lock<std::mutex>& lock);

  const size_t queued_per_part_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<Part> parts_;
  galpha::v1::ClassifyResponse current_;
  bool summary_taken_ = false;
  bool whole_from_part_zero_ = false;
  bool complete_ = false;
  uint64_t next_chunk_ = 0;  // the answer's next chunk, from 0
};

}  // namespace galpha::client
