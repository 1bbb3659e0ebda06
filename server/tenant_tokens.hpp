// Bearer-token authentication: a table from token to tenant, read from a file the operator
// mounts (one "TOKEN TENANT" pair per line, '#' comments). Families are cached per tenant, so one
// tenant can never read another's family, even with its handle.
#pragma once

#include <map>
#include <string>

#include "absl/status/statusor.h"

namespace galpha::server {

class TenantTokens {
 public:
  /// No tokens: authentication is off, every caller is the tenant "".
  TenantTokens() = default;
  /// InvalidArgument naming the line for a malformed line or a repeated token, or for a file that
  /// is not a regular file or lists no token (fail closed); NotFound for a missing file.
  static absl::StatusOr<TenantTokens> ReadFile(const std::string& path);
  /// From "TOKEN TENANT" lines (the file's content).
  static absl::StatusOr<TenantTokens> Parse(const std::string& text, const std::string& origin);

  bool enabled() const { return !tenant_of_token_.empty(); }
  /// The tenant of an "authorization" header value ("Bearer TOKEN", the scheme in any case);
  /// Unauthenticated otherwise.
  /// With authentication off: "" for any value.
  absl::StatusOr<std::string> TenantOf(const std::string* authorization) const;

 private:
  std::map<std::string, std::string> tenant_of_token_;
};

}  // namespace galpha::server
