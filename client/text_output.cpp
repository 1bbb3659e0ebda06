#include "client/text_output.hpp"

#include <charconv>

#include "core/io/json_text.hpp"
#include "core/io/number_text.hpp"

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

void ChunkedWriter::AppendDouble(double value) {
  AppendShortestDouble(buffer_, value);
  MaybeFlush();
}

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

std::string JsonLine(const nlohmann::ordered_json& json) {
  std::string line = JsonText(json);
  line += '\n';
  return line;
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

nlohmann::ordered_json ClassCountsJson(const std::array<uint64_t, 4>& counts) {
  nlohmann::ordered_json json = nlohmann::ordered_json::object();
  for (size_t c = 0; c < counts.size(); ++c) json[SimplexClassName(static_cast<SimplexClass>(c))] = counts[c];
  return json;
}

}  // namespace galpha::alphactl
