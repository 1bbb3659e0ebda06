#include "server/tenant_tokens.hpp"

#include <fstream>
#include <sstream>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace galpha::server {

absl::StatusOr<TenantTokens> TenantTokens::ReadFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return absl::NotFoundError(absl::StrCat("cannot read the token file '", path, "'"));
  std::stringstream text;
  text << in.rdbuf();
  return Parse(text.str(), path);
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
  if (!absl::ConsumePrefix(&value, "Bearer ")) {
    return absl::UnauthenticatedError("the authorization header must be 'Bearer TOKEN'");
  }
  const auto it = tenant_of_token_.find(std::string(absl::StripAsciiWhitespace(value)));
  if (it == tenant_of_token_.end()) return absl::UnauthenticatedError("the bearer token is not known to this server");
  return it->second;
}

}  // namespace galpha::server
