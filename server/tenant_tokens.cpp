#include "server/tenant_tokens.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace galpha::server {

absl::StatusOr<TenantTokens> TenantTokens::ReadFile(const std::string& path) {
  // Fail closed: a token file that cannot be read, or names no token, must not start a server
  // without authentication (a directory opens fine as an ifstream and reads as empty).
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    return absl::NotFoundError(absl::StrCat("the token file '", path, "' does not exist"));
  }
  if (!std::filesystem::is_regular_file(path, error)) {
    return absl::InvalidArgumentError(absl::StrCat("the token file '", path, "' is not a regular file"));
  }
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) return absl::PermissionDeniedError(absl::StrCat("cannot read the token file '", path, "'"));
  auto tokens = Parse(text.str(), path);
  if (tokens.ok() && !tokens->enabled()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the token file '", path, "' lists no tokens: authentication would be off"));
  }
  return tokens;
}

absl::StatusOr<TenantTokens> TenantTokens::Parse(const std::string& text, const std::string& origin) {
  TenantTokens tokens;
  int line_number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_number;
    line = absl::StripAsciiWhitespace(line);
    if (line.empty() || line.front() == '#') continue;
    std::vector<absl::string_view> words = absl::StrSplit(line, absl::ByAnyChar(" \t"), absl::SkipEmpty());
    if (words.size() != 2) {
      return absl::InvalidArgumentError(
          absl::StrCat(origin, ":", line_number, ": expected 'TOKEN TENANT', found ", words.size(), " words"));
    }
    if (!tokens.tenant_of_token_.emplace(std::string(words[0]), std::string(words[1])).second) {
      return absl::InvalidArgumentError(absl::StrCat(origin, ":", line_number, ": the token is listed twice"));
    }
  }
  return tokens;
}

absl::StatusOr<std::string> TenantTokens::TenantOf(const std::string* authorization) const {
  if (!enabled()) return std::string();
  if (authorization == nullptr) {
    return absl::UnauthenticatedError("this server requires an 'authorization: Bearer TOKEN' header");
  }
  absl::string_view value = *authorization;
  // The scheme name is case-insensitive (RFC 7235 section 2.1).
  if (value.size() < 7 || !absl::EqualsIgnoreCase(value.substr(0, 7), "bearer ")) {
    return absl::UnauthenticatedError("the authorization header must be 'Bearer TOKEN'");
  }
  value.remove_prefix(7);
  const auto it = tenant_of_token_.find(std::string(absl::StripAsciiWhitespace(value)));
  if (it == tenant_of_token_.end()) return absl::UnauthenticatedError("the bearer token is not known to this server");
  return it->second;
}

}  // namespace galpha::server
