// JSON text for the project's outputs (alphactl's summaries, the shapes' GeoJSON): documents are
// built as nlohmann::ordered_json (keys stay in insertion order) and written here, compact (no
// spaces), with nlohmann-json escaping the strings and keys (invalid UTF-8, as a file name may
// hold, becomes U+FFFD rather than an exception) and every floating-point number written by
// AppendShortestDouble (core/io/number_text.hpp), so that JSON, CSV-like lines and WKT print one
// double alike. nlohmann's own dump does not: it writes 1.0 as "1.0" where the other writers say
// "1", and its Grisu2 is round-trip but not always shortest. Non-finite numbers are null (JSON has
// no NaN or infinity), as nlohmann writes them.
#pragma once

#include <string>

#include "nlohmann/json.hpp"

namespace galpha {

/// Appends `value` as compact JSON text. Linear in the size of the text.
void AppendJsonText(std::string& out, const nlohmann::ordered_json& value);

/// AppendJsonText's text on its own.
std::string JsonText(const nlohmann::ordered_json& value);

}  // namespace galpha
