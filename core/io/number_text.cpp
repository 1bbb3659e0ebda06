#include "core/io/number_text.hpp"

#include <charconv>
#include <string>
#include <system_error>

namespace galpha {

void AppendShortestDouble(std::string& out, double value) {
  char text[kMaxShortestDoubleChars];
  const std::to_chars_result result = std::to_chars(text, text + sizeof text, value);
  // Cannot fail: the longest shortest form of a double has 24 characters.
  if (result.ec == std::errc()) out.append(text, result.ptr);
}

std::string ShortestDouble(double value) {
  std::string out;
  AppendShortestDouble(out, value);
  return out;
}

}  // namespace galpha
