// The client side of compact Classify answers (ClassifyRequest.simplex_encoding DELTA or
// DELTA_ZSTD): the answer's encoded chunks are decoded on a few threads while later messages still
// arrive, and handed over in arrival order as the SimplexChunks they encode. Decoded one after
// another on the caller's thread, they were the call's bottleneck (about 5 ns a simplex: 26 ms of
// a 1M-point answer, more than the raw answer's whole transfer over loopback). Free of gRPC, so
// the unit tests drive it directly.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"
#include "galpha/v1/alpha_shapes.pb.h"

namespace galpha::client {

/// One producer (Push, End: the thread that reads the stream) and one consumer (Next).
class ClassifyAnswerDecoder {
 public:
  /// `threads` decoding threads (at least one); at most `max_waiting` messages (at least one) are
  /// pushed and not yet taken by Next.
  ClassifyAnswerDecoder(size_t threads, size_t max_waiting);
  /// Stops, then joins the decoding threads.
  ~ClassifyAnswerDecoder();
  ClassifyAnswerDecoder(const ClassifyAnswerDecoder&) = delete;
  ClassifyAnswerDecoder& operator=(const ClassifyAnswerDecoder&) = delete;

  /// Queues the answer's next message; waits while `max_waiting` messages wait. False, and the
  /// message dropped, once Stop was called.
  bool Push(galpha::v1::ClassifyResponse message);
  /// No more messages will come.
  void End();
  /// The next message in arrival order, an encoded chunk replaced by its SimplexChunk (valid until
  /// the next call); nullptr after the last one (once End was called) or after Stop. An encoded
  /// chunk that does not decode: its InvalidArgument, naming it (its place among the answer's
  /// chunks, from 0); the caller stops there.
  absl::StatusOr<const galpha::v1::ClassifyResponse*> Next();
  /// Drops every waiting message; Push returns false from now on, Next nullptr.
  void Stop();

 private:
  struct Item {
    galpha::v1::ClassifyResponse message;
    galpha::v1::ClassifyResponse decoded;  // encoded chunks only
    absl::Status status;
    uint64_t chunk_index = 0;
    bool encoded = false;
    bool done = false;
  };

  void Work();

  const size_t max_waiting_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::shared_ptr<Item>> waiting_;    // pushed, not yet taken by Next, in order
  std::deque<std::shared_ptr<Item>> undecoded_;  // encoded, not yet taken by a decoding thread
  std::shared_ptr<Item> current_;                // the last message Next returned
  uint64_t chunks_ = 0;
  bool ended_ = false;
  bool stopped_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace galpha::client
