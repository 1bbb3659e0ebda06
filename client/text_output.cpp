#include "client/text_output.hpp"

#include <charconv>
#include <cmath>

namespace galpha::alphactl {

namespace {
constexpr size_t kChunkBytes = size_t{1} << 20;
}  // namespace

ChunkedWriter::ChunkedWriter(std::FILE* out) : out_(out) { buffer_.reserve(kChunkBytes + 256); }

void ChunkedWriter::Append(absl::string_view text) {
  buffer_.append(text.data(), text.size());
  MaybeFlush();
}

void ChunkedWriter::Append(char c) {
  buffer_ += c;
  MaybeFlush();
}

void ChunkedWriter::AppendUint(uint64_t value) {
  char digits[24];
  const auto result = std::to_chars(digits, digits + sizeof digits, value);
  buffer_.append(digits, result.ptr);
  MaybeFlush();
}

void ChunkedWriter::AppendDouble(double value) { Append(FormatDouble(value)); }

void ChunkedWriter::MaybeFlush() {
  if (buffer_.size() < kChunkBytes) return;
  if (!failed_ && std::fwrite(buffer_.data(), 1, buffer_.size(), out_) != buffer_.size()) failed_ = true;
  buffer_.clear();
}

bool ChunkedWriter::Finish() {
  if (!failed_ && !buffer_.empty() && std::fwrite(buffer_.data(), 1, buffer_.size(), out_) != buffer_.size()) {
    failed_ = true;
  }
  buffer_.clear();
  if (std::fflush(out_) != 0) failed_ = true;
  return !failed_;
}

std::string FormatDouble(double value) {
  char text[32];
  const int n = std::snprintf(text, sizeof text, "%.17g", value);
  return std::string(text, static_cast<size_t>(n));
}

std::string JsonNumber(double value) { return std::isfinite(value) ? FormatDouble(value) : "null"; }

std::string JsonString(absl::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", static_cast<unsigned>(c));
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

const char* EndpointName(Endpoint endpoint) {
  switch (endpoint) {
    case Endpoint::kRho:
      return "RHO";
    case Endpoint::kMuLow:
      return "MU_LOW";
    case Endpoint::kMuHigh:
      return "MU_HIGH";
  }
  return "UNKNOWN";
}

std::string ClassCountsJson(const std::array<uint64_t, 4>& counts) {
  std::string json = "{";
  for (size_t c = 0; c < counts.size(); ++c) {
    json += c > 0 ? ",\"" : "\"";
    json += SimplexClassName(static_cast<SimplexClass>(c));
    json += "\":";
    json += std::to_string(counts[c]);
  }
  return json + "}";
}

}  // namespace galpha::alphactl
