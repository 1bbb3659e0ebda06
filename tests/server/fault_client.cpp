// A misbehaving client for the fault tests, as its own process so that it can vanish the way real
// clients do (the process dies; the kernel closes its socket):
//   fault_client vanish ADDRESS POINTS       announce POINTS, upload half of them, then _exit(0)
//   fault_client slow-classify ADDRESS HANDLE MS
//                                             read a Classify stream of every simplex, MS per message
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "client/galpha_client.hpp"
#include "tests/support/point_generators.hpp"

namespace v1 = galpha::v1;

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: fault_client vanish ADDRESS POINTS | slow-classify ADDRESS HANDLE MS\n");
    return 2;
  }
  const std::string mode = argv[1];
  galpha::client::ClientOptions options;
  options.target = argv[2];
  auto client = galpha::client::AlphaClient::Connect(options);
  if (!client.ok()) return 1;

  if (mode == "vanish") {
    const size_t n = std::strtoull(argv[3], nullptr, 10);
    const auto points = galpha::gen::Uniform(n, static_cast<uint64_t>(getpid()));
    grpc::ClientContext context;
    v1::BuildResponse response;
    auto writer = (*client)->stub().Build(&context, &response);
    v1::BuildRequest message;
    message.mutable_header()->set_expected_points(n);
    writer->Write(message);
    for (size_t begin = 0; begin < n / 2; begin += galpha::client::kPointsPerChunk) {
      const size_t count = std::min(galpha::client::kPointsPerChunk, n / 2 - begin);
      message.mutable_points()->mutable_coordinates()->Assign(&points[begin].x, &points[begin].x + 2 * count);
      if (!writer->Write(message)) break;
    }
    std::fprintf(stdout, "vanishing\n");
    std::fflush(stdout);
    _exit(0);  // no WritesDone, no Finish: the connection just drops
  }
  if (mode == "slow-classify" && argc == 5) {
    v1::ClassifyRequest request;
    request.set_handle(argv[3]);
    request.mutable_threshold()->set_rank(1);
    const int delay_ms = std::atoi(argv[4]);
    size_t messages = 0;
    const absl::Status status = (*client)->Classify(request, [&](const v1::ClassifyResponse&) {
      if (++messages == 1) {
        std::fprintf(stdout, "reading\n");
        std::fflush(stdout);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
      return absl::OkStatus();
    });
    std::fprintf(stdout, "done %zu %s\n", messages, status.ok() ? "ok" : std::string(status.message()).c_str());
    return status.ok() ? 0 : 1;
  }
  std::fprintf(stderr, "fault_client: unknown mode '%s'\n", mode.c_str());
  return 2;
}
