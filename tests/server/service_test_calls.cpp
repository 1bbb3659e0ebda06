// The calls of service_test_calls.hpp.
#include "tests/server/service_test_calls.hpp"

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <utility>

#include "gpu/alpha/alpha_engine.hpp"
#include "tests/server/service_test_support.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server::testing {

using galpha::testing::IsOk;

size_t SlowBuildPoints() { return TestBackend() == "cuda" ? 4000000 : 400000; }

AlphaFamily LocalFamily(const std::vector<Point2>& points) {
  BuildOptions options;
  options.backend = Backend::kCpu;
  auto family = BuildAlphaFamily(points, options);
  EXPECT_THAT(family, IsOk());
  return *std::move(family);
}

std::vector<double> SpectrumRemote(client::AlphaClient& client, const std::string& handle, uint32_t page) {
  std::vector<double> values;
  v1::SpectrumRequest request;
  request.set_handle(handle);
  request.set_page_size(page);
  int64_t next = 1;
  while (next != 0) {
    request.set_first_rank(next);
    auto answer = client.Spectrum(request);
    EXPECT_THAT(answer, IsOk());
    if (!answer.ok()) break;
    values.insert(values.end(), answer->alpha_sq().begin(), answer->alpha_sq().end());
    next = answer->next_rank();
  }
  return values;
}

absl::Status RawBuild(client::AlphaClient& client, const std::vector<v1::BuildRequest>& messages,
                      v1::BuildResponse* response) {
  grpc::ClientContext context;
  v1::BuildResponse ignored;
  auto writer = client.stub().Build(&context, response != nullptr ? response : &ignored);
  for (const auto& message : messages) {
    if (!writer->Write(message)) break;
  }
  writer->WritesDone();
  return client::FromGrpc(writer->Finish());
}

v1::BuildRequest Header(uint64_t expected) {
  v1::BuildRequest message;
  message.mutable_header()->set_expected_points(expected);
  return message;
}

v1::BuildRequest Chunk(const std::vector<double>& coordinates) {
  v1::BuildRequest message;
  message.mutable_points()->mutable_coordinates()->Add(coordinates.begin(), coordinates.end());
  return message;
}

}  // namespace galpha::server::testing
