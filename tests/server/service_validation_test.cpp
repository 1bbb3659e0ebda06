// The real server refuses what it used to answer with a silent default (issue 15, item 4): enum
// values it does not know, an empty or malformed handle to Release, an over-long name; a name is
// the caller's own label, never another caller's; Spectrum pages are capped.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/io/point_set_handle.hpp"
#include "server/build_stream.hpp"
#include "server/query_answers.hpp"
#include "tests/server/service_test_calls.hpp"
#include "tests/server/service_test_support.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

namespace v1 = galpha::v1;
using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using testing::ClientOf;
using ::testing::HasSubstr;
using testing::RawBuild;
using testing::StartServer;
using testing::TestServerOptions;

absl::Status Drain(client::AlphaClient& client, const v1::ClassifyRequest& request) {
  return client.Classify(request, [](const v1::ClassifyResponse&) { return absl::OkStatus(); });
}

TEST(ServiceValidationTest, UnknownEnumValuesAreRefusedNotDefaulted) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  auto built = client->Build(gen::Uniform(300, 51));
  ASSERT_THAT(built, IsOk());

  v1::ClassifyRequest classify;
  classify.set_handle(built->handle);
  classify.mutable_threshold()->set_rank(1);
  classify.set_summary_only(true);
  ASSERT_THAT(Drain(*client, classify), IsOk());
  classify.set_mode(static_cast<v1::ClassifyMode>(7));
  EXPECT_THAT(Drain(*client, classify), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("mode 7")));
  classify.set_mode(v1::CLASSIFY_MODE_REGULARIZED);
  classify.set_vertex_rule(static_cast<v1::VertexRule>(9));
  EXPECT_THAT(Drain(*client, classify), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("vertex_rule 9")));

  v1::ShapeRequest shape;
  shape.set_handle(built->handle);
  shape.mutable_threshold()->set_rank(1);
  shape.set_format(v1::SHAPE_FORMAT_WKT);
  shape.set_mode(static_cast<v1::ClassifyMode>(5));
  EXPECT_THAT(client->Shape(shape, [](const v1::ShapeResponse&) { return absl::OkStatus(); }),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("mode 5")));
}

TEST(ServiceValidationTest, ReleaseRefusesWhatIsNoHandle) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  EXPECT_THAT(client->Release("").status(), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("not a handle")));
  EXPECT_THAT(client->Release("sha256-abc").status(), StatusIs(absl::StatusCode::kInvalidArgument));
  // A well-formed handle the server does not hold is no error: Release is idempotent.
  auto unknown = client->Release(PointSetHandle(gen::Uniform(10, 52)));
  ASSERT_THAT(unknown, IsOk());
  EXPECT_FALSE(unknown->released());
}

v1::BuildRequest NamedHeader(const std::string& name) {
  v1::BuildRequest message;
  message.mutable_header()->set_name(name);
  return message;
}

TEST(ServiceValidationTest, NamesHaveALimitAndBelongToTheirCaller) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  const std::vector<Point2> points = gen::Uniform(200, 53);

  const absl::Status too_long = RawBuild(*client, {NamedHeader(std::string(kMaxBuildNameBytes + 1, 'x'))});
  EXPECT_THAT(too_long, StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("name is 257 bytes long")));
  EXPECT_THAT(too_long.message(), HasSubstr("at most 256 bytes"));

  client::BuildCallOptions call;
  call.skip_upload_if_cached = false;
  call.name = std::string(kMaxBuildNameBytes, 'a');
  auto first = client->Build(points, call);
  ASSERT_THAT(first, IsOk());
  EXPECT_FALSE(first->cached);
  EXPECT_EQ(first->summary.name(), call.name);
  // Another caller uploads the same points: a cache hit, answered with its own name.
  auto other = ClientOf(*server);
  call.name = "someone else";
  auto second = other->Build(points, call);
  ASSERT_THAT(second, IsOk());
  EXPECT_TRUE(second->cached);
  EXPECT_EQ(second->summary.name(), "someone else");
  call.name = "";
  auto unnamed = other->Build(points, call);
  ASSERT_THAT(unnamed, IsOk());
  EXPECT_EQ(unnamed->summary.name(), "");
  auto described = other->Describe(first->handle);
  ASSERT_THAT(described, IsOk());
  EXPECT_EQ(described->summary().name(), "") << "Describe has no caller's name to answer with";
  // The client library finds the family with Describe and skips the upload: the answer still
  // carries this caller's name, as the Build answer would.
  client::BuildCallOptions found;
  found.name = "found without an upload";
  auto skipped = other->Build(points, found);
  ASSERT_THAT(skipped, IsOk());
  EXPECT_TRUE(skipped->cached);
  EXPECT_FALSE(skipped->uploaded);
  EXPECT_EQ(skipped->summary.name(), "found without an upload");
}

TEST(ServiceValidationTest, SpectrumPagesAreCapped) {
  auto server = StartServer(TestServerOptions());
  ASSERT_NE(server, nullptr);
  auto client = ClientOf(*server);
  // About 3 values per point: more than one default page.
  auto built = client->Build(gen::Uniform(30000, 54));
  ASSERT_THAT(built, IsOk());
  const uint64_t k = built->summary.spectrum_size();
  ASSERT_GT(k, kDefaultSpectrumPage);

  v1::SpectrumRequest request;
  request.set_handle(built->handle);
  request.set_page_size(0);
  auto page = client->Spectrum(request);
  ASSERT_THAT(page, IsOk());
  EXPECT_EQ(static_cast<uint64_t>(page->alpha_sq_size()), kDefaultSpectrumPage) << "0 is the default page, not all";
  EXPECT_EQ(page->next_rank(), int64_t{kDefaultSpectrumPage} + 1);

  request.set_page_size(kMaxSpectrumPage);
  page = client->Spectrum(request);
  ASSERT_THAT(page, IsOk());
  EXPECT_EQ(static_cast<uint64_t>(page->alpha_sq_size()), std::min<uint64_t>(k, kMaxSpectrumPage));

  request.set_page_size(kMaxSpectrumPage + 1);
  EXPECT_THAT(client->Spectrum(request).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("largest page, 262144 values")));
}

}  // namespace
}  // namespace galpha::server
