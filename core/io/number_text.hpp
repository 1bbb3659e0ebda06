// Doubles as text, for every writer of the project's outputs (alphactl's lines and JSON, the
// shapes' WKT, GeoJSON and SVG): the shortest decimal that reads back as the same double.
// std::to_chars without a precision (C++17 <charconv>; Ryu in libstdc++) guarantees the round trip
// (strtod gives the identical bits, -0 and subnormals included) in the fewest characters: plain or
// exponent notation, whichever is shorter ("0.1", "1e+300", "1e-05", "123456"; an integer above
// 2^53 may come out in full, exactly, when that is no longer). It ignores the C locale. printf's
// %.17g, which this replaces, wrote 0.1 as 0.10000000000000001.
#pragma once

#include <cstddef>
#include <string>

namespace galpha {

/// The most characters AppendShortestDouble writes ("-2.2250738585072014e-308" has 24).
inline constexpr size_t kMaxShortestDoubleChars = 32;

/// Appends the shortest decimal text that strtod reads back as exactly `value` ("-0" for -0.0).
/// Not finite: "inf", "-inf" or "nan" (JSON and WKT have no such numbers: their writers decide).
void AppendShortestDouble(std::string& out, double value);

/// AppendShortestDouble's text on its own.
std::string ShortestDouble(double value);

}  // namespace galpha
