// alphactl's output for scripts: a buffered writer for line-per-simplex output (millions of lines),
// numbers as their shortest round-trip decimal (core/io/number_text.hpp) and one-line JSON objects
// built with nlohmann-json (core/io/json_text.hpp).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "absl/strings/string_view.h"
#include "core/family/alpha_family.hpp"
#include "core/family/alpha_ranks.hpp"
#include "nlohmann/json.hpp"

namespace galpha::alphactl {

/// Collects text in a large buffer and writes it to `out` with fwrite in chunks of about 1 MiB.
class ChunkedWriter {
 public:
  explicit ChunkedWriter(std::FILE* out);
  ChunkedWriter(const ChunkedWriter&) = delete;
  ChunkedWriter& operator=(const ChunkedWriter&) = delete;

  void Append(absl::string_view text);
  void Append(char c);
  void AppendUint(uint64_t value);
  /// The shortest decimal that reads back as exactly `value` (ShortestDouble).
  void AppendDouble(double value);
  /// Writes what is buffered and flushes `out`. False when a write failed (the writer stops
  /// writing after the first failure).
  bool Finish();

 private:
  void MaybeFlush();

  std::FILE* out_;
  std::string buffer_;
  bool failed_ = false;
};

/// `json` as one compact line of JSON text, newline included (JsonText: doubles as
/// ShortestDouble, null when not finite).
std::string JsonLine(const nlohmann::ordered_json& json);

/// Appends KIND and the vertex indices: "v 3", "e 1 4", "t 0 2 5".
template <size_t N>
void AppendSimplex(ChunkedWriter& out, char kind, const std::array<uint32_t, N>& vertices) {
  out.Append(kind);
  for (uint32_t v : vertices) {
    out.Append(' ');
    out.AppendUint(v);
  }
}

/// "RHO", "MU_LOW", "MU_HIGH".
const char* EndpointName(Endpoint endpoint);

/// {"EXTERIOR":n,"SINGULAR":n,"REGULAR":n,"INTERIOR":n}, indexed by SimplexClass.
nlohmann::ordered_json ClassCountsJson(const std::array<uint64_t, 4>& counts);

}  // namespace galpha::alphactl
