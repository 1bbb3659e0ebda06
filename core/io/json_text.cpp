#include "core/io/json_text.hpp"

#include <cmath>
#include <string>

#include "core/io/number_text.hpp"
#include "nlohmann/json.hpp"

namespace galpha {
namespace {

// nlohmann's own text of a string, integer, boolean or null: strings escaped, invalid UTF-8
// replaced (never thrown).
void AppendLeaf(std::string& out, const nlohmann::ordered_json& leaf) {
  out += leaf.dump(-1, ' ', /*ensure_ascii=*/false, nlohmann::ordered_json::error_handler_t::replace);
}

}  // namespace

void AppendJsonText(std::string& out, const nlohmann::ordered_json& value) {
  switch (value.type()) {
    case nlohmann::ordered_json::value_t::object: {
      out += '{';
      bool first = true;
      for (auto member = value.begin(); member != value.end(); ++member) {
        if (!first) out += ',';
        first = false;
        AppendLeaf(out, nlohmann::ordered_json(member.key()));
        out += ':';
        AppendJsonText(out, member.value());
      }
      out += '}';
      return;
    }
    case nlohmann::ordered_json::value_t::array: {
      out += '[';
      bool first = true;
      for (const auto& element : value) {
        if (!first) out += ',';
        first = false;
        AppendJsonText(out, element);
      }
      out += ']';
      return;
    }
    case nlohmann::ordered_json::value_t::number_float: {
      const double number = value.get<double>();
      if (std::isfinite(number)) {
        AppendShortestDouble(out, number);
      } else {
        out += "null";
      }
      return;
    }
    default:
      AppendLeaf(out, value);
      return;
  }
}

std::string JsonText(const nlohmann::ordered_json& value) {
  std::string out;
  AppendJsonText(out, value);
  return out;
}

}  // namespace galpha
