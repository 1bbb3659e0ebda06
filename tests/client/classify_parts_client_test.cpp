// The C++ client reading a Classify answer in parts against a scripted server (a fake
// AlphaShapes service that answers Classify only): what a real server never sends, such as a
// corrupt encoded chunk in one part, reaches the caller as a status that names where it was.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "client/galpha_client.hpp"
#include "galpha/v1/alpha_shapes.grpc.pb.h"
#include "tests/support/status_matchers.hpp"

namespace galpha {
namespace {

using ::testing::HasSubstr;
using testing::StatusIs;

/// Answers a split Classify: part 0 its summary and chunk 0 (one vertex, raw), every other part
/// one encoded chunk whose kind is no simplex kind (a decoder refuses it).
class CorruptPartService final : public v1::AlphaShapes::Service {
 public:
  grpc::Status Classify(grpc::ServerContext*, const v1::ClassifyRequest* request,
                        grpc::ServerWriter<v1::ClassifyResponse>* writer) override {
    v1::ClassifyResponse message;
    if (request->part_index() == 0) {
      message.mutable_summary();
      writer->Write(message);
      message.Clear();
      v1::SimplexChunk* chunk = message.mutable_chunk();
      chunk->set_kind(v1::SIMPLEX_KIND_VERTEX);
      chunk->add_vertex_indices(0);
      chunk->set_classes(std::string(1, '\x01'));
    } else {
      v1::EncodedSimplexChunk* chunk = message.mutable_encoded_chunk();
      chunk->set_kind(v1::SIMPLEX_KIND_UNSPECIFIED);
      chunk->set_simplex_count(1);
      chunk->set_encoding(v1::SIMPLEX_ENCODING_DELTA);
    }
    writer->Write(message);
    return grpc::Status::OK;
  }
};

TEST(ClassifyPartsClientTest, ACorruptChunkNamesItsPartAndItsPlaceThere) {
  CorruptPartService service;
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
  builder.RegisterService(&service);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  ASSERT_NE(server, nullptr);
  ASSERT_GT(port, 0);
  client::ClientOptions options;
  options.target = "127.0.0.1:" + std::to_string(port);
  options.classify_parts = 3;
  auto connected = client::AlphaClient::Connect(options);
  ASSERT_TRUE(connected.ok()) << connected.status();
  v1::ClassifyRequest request;
  request.set_simplex_encoding(v1::SIMPLEX_ENCODING_DELTA);
  const absl::Status status =
      (*connected)->Classify(request, [](const v1::ClassifyResponse&) { return absl::OkStatus(); });
  // Part 1's first chunk is the answer's chunk 1 (part 2's the answer's chunk 2): the status
  // names the part and the chunk's place in it, whichever of the two failed first.
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument,
                               HasSubstr(" of 3 of the Classify answer, its encoded simplex chunk 0: ")));
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("is not a simplex kind")));
  server->Shutdown();
}

}  // namespace
}  // namespace galpha
