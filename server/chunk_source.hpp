// A server-streamed answer as a generator of messages, free of gRPC: the query answers produce
// them (query_answers.hpp), encoded_answer.hpp transforms them, the service's writer sends them.
#pragma once

#include "absl/status/status.h"

namespace galpha::server {

/// Next fills the next message, false when the answer is complete or has failed; status() then
/// says which.
template <typename Message>
class ChunkSource {
 public:
  virtual ~ChunkSource() = default;
  virtual bool Next(Message* message) = 0;
  /// OK while the answer goes on and once it is complete; the error that ended it otherwise.
  virtual absl::Status status() const { return absl::OkStatus(); }
};

}  // namespace galpha::server
