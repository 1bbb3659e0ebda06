// The real server's TLS and tenant-scoped bearer tokens, and the routing header the client sends
// (against a recording stand-in server).
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "core/io/point_set_handle.hpp"
#include "tests/server/service_test_support.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using ::testing::Not;
using testing::StartServer;
using testing::TestServerOptions;

/// A self-signed certificate for "localhost" made with the openssl command.
bool MakeCertificate(const std::string& dir) {
  const std::string command =
      "openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=localhost "
      "-addext subjectAltName=DNS:localhost -keyout " +
      dir + "/key.pem -out " + dir + "/cert.pem >/dev/null 2>&1";
  return std::system(command.c_str()) == 0;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(ServiceTest, TlsAndTenantScopedTokens) {
  const std::string dir = std::filesystem::temp_directory_path() / ("galpha_tls_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(MakeCertificate(dir)) << "openssl could not make a test certificate";
  ServerOptions options = TestServerOptions();
  options.tls_cert_file = dir + "/cert.pem";
  options.tls_key_file = dir + "/key.pem";
  auto tokens = TenantTokens::Parse("token-a tenant-a\ntoken-b tenant-b\n", "test");
  ASSERT_THAT(tokens, IsOk());
  options.service.tokens = *tokens;
  auto server = StartServer(options);
  ASSERT_NE(server, nullptr);

  auto connect = [&](const std::string& token, bool tls) {
    client::ClientOptions client_options;
    client_options.target = "localhost:" + std::to_string(server->port());
    client_options.bearer_token = token;
    if (tls) client_options.tls_root_certs_pem = ReadFile(dir + "/cert.pem");
    client_options.deadline = std::chrono::seconds(30);
    return *client::AlphaClient::Connect(client_options);
  };
  const std::vector<Point2> points = gen::Uniform(800, 51);
  auto a = connect("token-a", true);
  auto built = a->Build(points);
  ASSERT_THAT(built, IsOk());
  EXPECT_THAT(a->Describe(built->handle), IsOk());

  // Plaintext against a TLS port fails; no token or an unknown one is UNAUTHENTICATED.
  EXPECT_THAT(connect("token-a", false)->Describe(built->handle), Not(IsOk()));
  EXPECT_THAT(connect("", true)->Describe(built->handle).status(), StatusIs(absl::StatusCode::kUnauthenticated));
  EXPECT_THAT(connect("token-x", true)->Describe(built->handle).status(), StatusIs(absl::StatusCode::kUnauthenticated));
  client::BuildCallOptions upload;
  upload.skip_upload_if_cached = false;
  EXPECT_THAT(connect("", true)->Build(points, upload).status(), StatusIs(absl::StatusCode::kUnauthenticated));

  // Another tenant cannot see tenant A's family, even with its handle; its own build is its own.
  auto b = connect("token-b", true);
  EXPECT_THAT(b->Describe(built->handle).status(), StatusIs(absl::StatusCode::kNotFound));
  auto b_built = b->Build(points, upload);
  ASSERT_THAT(b_built, IsOk());
  EXPECT_FALSE(b_built->cached);
  EXPECT_EQ(b_built->handle, built->handle);
  auto released = b->Release(built->handle);
  ASSERT_THAT(released, IsOk());
  EXPECT_THAT(a->Describe(built->handle), IsOk());  // B's release dropped only B's entry
  std::filesystem::remove_all(dir);
}

/// Records the routing header of every call it gets, and answers NOT_FOUND / UNAVAILABLE.
class HeaderRecorder final : public v1::AlphaShapes::CallbackService {
 public:
  std::vector<std::string> headers() {
    std::lock_guard<std::mutex> lock(mutex_);
    return headers_;
  }
  grpc::ServerUnaryReactor* Describe(grpc::CallbackServerContext* context, const v1::DescribeRequest*,
                                     v1::DescribeResponse*) override {
    Record(context);
    auto* reactor = context->DefaultReactor();
    reactor->Finish(grpc::Status(grpc::StatusCode::NOT_FOUND, "recorder"));
    return reactor;
  }
  grpc::ServerReadReactor<v1::BuildRequest>* Build(grpc::CallbackServerContext* context, v1::BuildResponse*) override {
    Record(context);
    class Refuse final : public grpc::ServerReadReactor<v1::BuildRequest> {
     public:
      Refuse() { Finish(grpc::Status(grpc::StatusCode::UNAVAILABLE, "recorder")); }
      void OnDone() override { delete this; }
    };
    return new Refuse();
  }

 private:
  void Record(grpc::CallbackServerContext* context) {
    const auto it = context->client_metadata().find(client::kHandleHeader);
    std::lock_guard<std::mutex> lock(mutex_);
    headers_.push_back(it == context->client_metadata().end() ? "(none)"
                                                              : std::string(it->second.data(), it->second.size()));
  }
  std::mutex mutex_;
  std::vector<std::string> headers_;
};

TEST(ServiceTest, TheClientSendsTheHandleForRouting) {
  HeaderRecorder recorder;
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
  builder.RegisterService(&recorder);
  auto server = builder.BuildAndStart();
  ASSERT_NE(server, nullptr);
  client::ClientOptions options;
  options.target = "127.0.0.1:" + std::to_string(port);
  auto client = *client::AlphaClient::Connect(options);
  const std::vector<Point2> points = gen::Uniform(1000, 61);
  // Describe (is it cached?) then the upload: both carry the handle computed before uploading.
  EXPECT_THAT(client->Build(points).status(), StatusIs(absl::StatusCode::kUnavailable));
  EXPECT_EQ(recorder.headers(), std::vector<std::string>(2, PointSetHandle(points)));
  server->Shutdown();
}

}  // namespace
}  // namespace galpha::server
