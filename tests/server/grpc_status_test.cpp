// The service's status conversion: every absl code becomes the gRPC code of the same name (the
// codes clients are documented to see), with the message unchanged; OK stays OK, with no message.
#include "server/grpc_status.hpp"

#include <string>
#include <utility>
#include <vector>

#include "gtest/gtest.h"

namespace galpha::server {
namespace {

TEST(GrpcStatusTest, OkIsOkWithoutMessage) {
  const grpc::Status status = ToGrpcStatus(absl::OkStatus());
  EXPECT_TRUE(status.ok());
  EXPECT_EQ(status.error_code(), grpc::StatusCode::OK);
  EXPECT_EQ(status.error_message(), "");
}

TEST(GrpcStatusTest, EveryCodeMapsToTheSameNamedGrpcCodeAndKeepsItsMessage) {
  // Listed by name, not derived from the numbers, so that the test does not assume what it checks.
  const std::vector<std::pair<absl::StatusCode, grpc::StatusCode>> codes = {
      {absl::StatusCode::kCancelled, grpc::StatusCode::CANCELLED},
      {absl::StatusCode::kUnknown, grpc::StatusCode::UNKNOWN},
      {absl::StatusCode::kInvalidArgument, grpc::StatusCode::INVALID_ARGUMENT},
      {absl::StatusCode::kDeadlineExceeded, grpc::StatusCode::DEADLINE_EXCEEDED},
      {absl::StatusCode::kNotFound, grpc::StatusCode::NOT_FOUND},
      {absl::StatusCode::kAlreadyExists, grpc::StatusCode::ALREADY_EXISTS},
      {absl::StatusCode::kPermissionDenied, grpc::StatusCode::PERMISSION_DENIED},
      {absl::StatusCode::kResourceExhausted, grpc::StatusCode::RESOURCE_EXHAUSTED},
      {absl::StatusCode::kFailedPrecondition, grpc::StatusCode::FAILED_PRECONDITION},
      {absl::StatusCode::kAborted, grpc::StatusCode::ABORTED},
      {absl::StatusCode::kOutOfRange, grpc::StatusCode::OUT_OF_RANGE},
      {absl::StatusCode::kUnimplemented, grpc::StatusCode::UNIMPLEMENTED},
      {absl::StatusCode::kInternal, grpc::StatusCode::INTERNAL},
      {absl::StatusCode::kUnavailable, grpc::StatusCode::UNAVAILABLE},
      {absl::StatusCode::kDataLoss, grpc::StatusCode::DATA_LOSS},
      {absl::StatusCode::kUnauthenticated, grpc::StatusCode::UNAUTHENTICATED},
  };
  // Every code absl has but OK (16 of them: its enum stops at kUnauthenticated).
  EXPECT_EQ(codes.size(), static_cast<size_t>(absl::StatusCode::kUnauthenticated));
  for (const auto& [from, to] : codes) {
    const std::string message = "no family under handle sha256-00ff: build it again (\xc3\xa9t\xc3\xa9, 100%)";
    const grpc::Status status = ToGrpcStatus(absl::Status(from, message));
    EXPECT_EQ(status.error_code(), to) << absl::StatusCodeToString(from);
    EXPECT_EQ(status.error_message(), message) << absl::StatusCodeToString(from);
    EXPECT_EQ(status.error_details(), "") << absl::StatusCodeToString(from);
  }
}

TEST(GrpcStatusTest, AnErrorWithoutMessageStaysWithout) {
  const grpc::Status status = ToGrpcStatus(absl::InternalError(""));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INTERNAL);
  EXPECT_EQ(status.error_message(), "");
}

}  // namespace
}  // namespace galpha::server
