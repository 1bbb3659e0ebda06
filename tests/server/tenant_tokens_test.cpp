// Bearer-token authentication: the token file's syntax (comments, blank lines, tabs, CRLF), errors
// naming origin:line, a missing file, and TenantOf with authentication off and on.
#include "server/tenant_tokens.hpp"

#include <cstdio>
#include <fstream>
#include <string>

#include "gtest/gtest.h"
#include "tests/support/status_matchers.hpp"

namespace galpha::server {
namespace {

using galpha::testing::IsOk;
using galpha::testing::StatusIs;
using ::testing::Not;

// The tenant of `authorization`, or the status's code name when refused.
std::string TenantOrCode(const TenantTokens& tokens, const std::string& authorization) {
  const absl::StatusOr<std::string> tenant = tokens.TenantOf(&authorization);
  return tenant.ok() ? *tenant : absl::StatusCodeToString(tenant.status().code());
}

TEST(TenantTokensTest, ParsesPairsCommentsBlankLinesAndTabs) {
  const std::string text =
      "# tokens of the staging cluster\n"
      "tok-alice alice\n"
      "\n"
      "   \n"
      "  # an indented comment\n"
      "\ttok-bob\tbob\t\n"
      "tok-carol  \t  carol\r\n"  // CRLF and mixed separators
      "tok-alice-2 alice";        // no final newline; a tenant may hold several tokens
  const absl::StatusOr<TenantTokens> tokens = TenantTokens::Parse(text, "tokens.txt");
  ASSERT_THAT(tokens, IsOk());
  EXPECT_TRUE(tokens->enabled());
  EXPECT_EQ(TenantOrCode(*tokens, "Bearer tok-alice"), "alice");
  EXPECT_EQ(TenantOrCode(*tokens, "Bearer tok-bob"), "bob");
  EXPECT_EQ(TenantOrCode(*tokens, "Bearer tok-carol"), "carol");
  EXPECT_EQ(TenantOrCode(*tokens, "Bearer tok-alice-2"), "alice");
  // A comment line's words are not tokens.
  EXPECT_EQ(TenantOrCode(*tokens, "Bearer #"), "UNAUTHENTICATED");
  EXPECT_EQ(TenantOrCode(*tokens, "Bearer tokens"), "UNAUTHENTICATED");
}

TEST(TenantTokensTest, MalformedLineNamesOriginAndLine) {
  struct Case {
    std::string text;
    std::string where;
  };
  const Case cases[] = {
      {"tok-a alice\n# fine\njust-a-token\n", "tokens.txt:3:"},
      {"tok-a alice three words\n", "tokens.txt:1:"},
      {"\n\n\ntok-a alice\ntok-b bob extra\n", "tokens.txt:5:"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    const absl::StatusOr<TenantTokens> tokens = TenantTokens::Parse(c.text, "tokens.txt");
    ASSERT_THAT(tokens, Not(IsOk()));
    EXPECT_THAT(tokens.status(), StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_NE(tokens.status().message().find(c.where), absl::string_view::npos) << tokens.status();
  }
}

TEST(TenantTokensTest, RepeatedTokenNamesOriginAndLine) {
  const absl::StatusOr<TenantTokens> tokens =
      TenantTokens::Parse("tok-a alice\ntok-b bob\n# comment\ntok-a mallory\n", "/etc/galpha/tokens");
  ASSERT_THAT(tokens, Not(IsOk()));
  EXPECT_THAT(tokens.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(tokens.status().message().find("/etc/galpha/tokens:4:"), absl::string_view::npos) << tokens.status();
  EXPECT_NE(tokens.status().message().find("twice"), absl::string_view::npos) << tokens.status();
}

TEST(TenantTokensTest, ReadFileOfAMissingFileIsNotFound) {
  const std::string path = ::testing::TempDir() + "galpha_tenant_tokens_test_no_such_file";
  std::remove(path.c_str());
  const absl::StatusOr<TenantTokens> tokens = TenantTokens::ReadFile(path);
  EXPECT_THAT(tokens.status(), StatusIs(absl::StatusCode::kNotFound));
  EXPECT_NE(tokens.status().message().find(path), absl::string_view::npos) << tokens.status();
}

// std::ifstream opens a directory on Linux and the read then fails silently: a directory must not
// parse as an empty table, which would turn authentication off (fail-open) for a server started
// with --token_file pointing at a mis-mounted secret volume.
TEST(TenantTokensTest, ReadFileOfADirectoryIsAnError) {
  const absl::StatusOr<TenantTokens> tokens = TenantTokens::ReadFile(::testing::TempDir());
  EXPECT_THAT(tokens, Not(IsOk())) << "a directory was read as a token table with authentication "
                                   << (tokens.ok() && tokens->enabled() ? "on" : "off");
}

TEST(TenantTokensTest, ReadFileOfAFileWithoutTokensIsAnError) {
  const std::string path = ::testing::TempDir() + "galpha_tenant_tokens_test_empty.txt";
  std::ofstream(path) << "# every token revoked\n\n";
  const absl::StatusOr<TenantTokens> tokens = TenantTokens::ReadFile(path);
  EXPECT_THAT(tokens.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(tokens.status().message().find("lists no tokens"), absl::string_view::npos) << tokens.status();
  std::remove(path.c_str());
}

TEST(TenantTokensTest, ReadFileParsesTheFileAndNamesItInErrors) {
  const std::string path = ::testing::TempDir() + "galpha_tenant_tokens_test_tokens.txt";
  {
    std::ofstream out(path);
    out << "# test tokens\ntok-alice alice\n\ntok-bob\tbob\n";
  }
  const absl::StatusOr<TenantTokens> tokens = TenantTokens::ReadFile(path);
  ASSERT_THAT(tokens, IsOk());
  EXPECT_EQ(TenantOrCode(*tokens, "Bearer tok-alice"), "alice");
  EXPECT_EQ(TenantOrCode(*tokens, "Bearer tok-bob"), "bob");

  {
    std::ofstream out(path);
    out << "tok-alice alice\ntok-alice bob\n";
  }
  const absl::StatusOr<TenantTokens> repeated = TenantTokens::ReadFile(path);
  EXPECT_THAT(repeated.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(repeated.status().message().find(path + ":2:"), absl::string_view::npos) << repeated.status();
  std::remove(path.c_str());
}

TEST(TenantTokensTest, DisabledAnswersTheEmptyTenantForAnything) {
  const TenantTokens tokens;
  EXPECT_FALSE(tokens.enabled());
  const absl::StatusOr<std::string> none = tokens.TenantOf(nullptr);
  ASSERT_THAT(none, IsOk());
  EXPECT_EQ(*none, "");
  for (const std::string value : {"", "Bearer tok", "Basic dXNlcjpwYXNz", "garbage"}) {
    SCOPED_TRACE(value);
    EXPECT_EQ(TenantOrCode(tokens, value), "");
  }
}

TEST(TenantTokensTest, EnabledRequiresAKnownBearerToken) {
  const absl::StatusOr<TenantTokens> tokens = TenantTokens::Parse("tok alice\nother bob\n", "inline");
  ASSERT_THAT(tokens, IsOk());
  ASSERT_TRUE(tokens->enabled());

  const absl::StatusOr<std::string> missing = tokens->TenantOf(nullptr);
  EXPECT_THAT(missing.status(), StatusIs(absl::StatusCode::kUnauthenticated));

  EXPECT_EQ(TenantOrCode(*tokens, "Bearer tok"), "alice");
  EXPECT_EQ(TenantOrCode(*tokens, "Bearer other"), "bob");
  EXPECT_EQ(TenantOrCode(*tokens, "Bearer tok "), "alice") << "trailing whitespace is not part of the token";
  EXPECT_EQ(TenantOrCode(*tokens, "bearer tok"), "alice") << "the scheme is case-insensitive (RFC 7235)";
  EXPECT_EQ(TenantOrCode(*tokens, "BEARER other"), "bob");

  for (const std::string value : {"Basic x", "Basic tok", "tok", "Bearertok", "Bearer", "Bearer ", "Bearer unknown",
                                  "Bearer tokx", "Bearer alice", "", "Bearer tok other"}) {
    SCOPED_TRACE(value);
    const absl::StatusOr<std::string> tenant = tokens->TenantOf(&value);
    EXPECT_THAT(tenant.status(), StatusIs(absl::StatusCode::kUnauthenticated))
        << (tenant.ok() ? *tenant : tenant.status().ToString());
  }
}

}  // namespace
}  // namespace galpha::server
