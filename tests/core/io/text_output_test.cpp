// The outputs' number and JSON text: every double's shortest decimal reads back bit for bit (random
// bit patterns, subnormals, the extremes, +-0), no shorter decimal reads back, and JSON documents
// print their doubles with the same text (not nlohmann's own, which differs) and null for NaN and
// infinity.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/io/json_text.hpp"
#include "core/io/number_text.hpp"
#include "nlohmann/json.hpp"

namespace galpha {
namespace {

uint64_t Bits(double value) {
  uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

double FromBits(uint64_t bits) {
  double value = 0.0;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

// strtod of the whole text: the way every reader of our outputs (C, Python, GEOS, nlohmann) parses.
double ReadBack(const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  EXPECT_EQ(end, text.c_str() + text.size()) << text;
  return value;
}

void ExpectRoundTrip(double value) {
  const std::string text = ShortestDouble(value);
  ASSERT_LE(text.size(), 24u) << text;
  EXPECT_EQ(Bits(ReadBack(text)), Bits(value)) << text;
  // Shortest: no decimal with one significant digit fewer reads back as `value` (so %.*g with one
  // digit fewer, the nearest such decimal, must not).
  std::string digits;
  for (const char c : text.substr(0, text.find('e'))) {
    if (c >= '0' && c <= '9') digits += c;
  }
  digits.erase(0, digits.find_first_not_of('0'));
  digits.erase(digits.find_last_not_of('0') + 1);
  const int significant = static_cast<int>(digits.size());
  // to_chars minimizes characters, not digits: a large integer may be printed in full, exactly,
  // when that is no longer than exponent notation ("-69211800857188784", 17 digits where 16 would
  // read back, is shorter than "-6.921180085718878e+16"). Below 2^53 every integer is a double and
  // its digits are all needed; above, shortness in digits is not the promise.
  const bool long_integer = text.find_first_of(".e") == std::string::npos && std::fabs(value) >= 0x1p53;
  if (significant > 1 && value != 0.0 && !long_integer) {
    char shorter[400];
    std::snprintf(shorter, sizeof shorter, "%.*g", significant - 1, value);
    EXPECT_NE(Bits(std::strtod(shorter, nullptr)), Bits(value)) << text << " vs " << shorter;
  }
}

TEST(NumberTextTest, SpecialValues) {
  EXPECT_EQ(ShortestDouble(0.0), "0");
  EXPECT_EQ(ShortestDouble(-0.0), "-0");
  EXPECT_EQ(ShortestDouble(1.0), "1");
  EXPECT_EQ(ShortestDouble(0.1), "0.1");
  EXPECT_EQ(ShortestDouble(0.25), "0.25");
  EXPECT_EQ(ShortestDouble(100.0 / 9.0), "11.11111111111111");
  EXPECT_EQ(ShortestDouble(1e308), "1e+308");
  EXPECT_EQ(ShortestDouble(1e-5), "1e-05");
  EXPECT_EQ(ShortestDouble(123456.0), "123456");
  EXPECT_EQ(ShortestDouble(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(ShortestDouble(-std::numeric_limits<double>::infinity()), "-inf");
  for (const double value :
       {0.0, -0.0, 1.0, -1.0, 0.1, 1e308, -1e308, 1e-308, std::numeric_limits<double>::max(),
        std::numeric_limits<double>::lowest(), std::numeric_limits<double>::min(),
        std::numeric_limits<double>::denorm_min(), -std::numeric_limits<double>::denorm_min(),
        std::nextafter(std::numeric_limits<double>::min(), 0.0), std::numeric_limits<double>::epsilon(),
        9007199254740993.0, 4503599627370497.5, 0.30000000000000004, 2.2250738585072011e-308}) {
    SCOPED_TRACE(value);
    ExpectRoundTrip(value);
  }
}

TEST(NumberTextTest, RandomDoublesReadBackBitForBit) {
  std::mt19937_64 rng(20);
  constexpr uint64_t kExponentMask = uint64_t{0x7ff} << 52;
  for (int i = 0; i < 200000; ++i) {
    // Every bit pattern but NaN and infinity: uniform over the bits, so over every binade.
    uint64_t bits = rng();
    if ((bits & kExponentMask) == kExponentMask) bits &= ~(uint64_t{1} << 62);
    ExpectRoundTrip(FromBits(bits));
    if (::testing::Test::HasFailure()) return;
  }
  for (int i = 0; i < 20000; ++i) {
    // Subnormals: exponent field 0.
    ExpectRoundTrip(FromBits(rng() & ~kExponentMask));
    // Coordinates as users write them: a few decimal digits, large offsets.
    const double decimal = static_cast<double>(static_cast<int64_t>(rng() % 2000000000) - 1000000000) / 1000.0;
    ExpectRoundTrip(decimal);
    EXPECT_LE(ShortestDouble(decimal).size(), 12u) << ShortestDouble(decimal);
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(NumberTextTest, AppendsToWhatIsThere) {
  std::string out = "x=";
  AppendShortestDouble(out, 2.5);
  out += ' ';
  AppendShortestDouble(out, -3e-300);
  EXPECT_EQ(out, "x=2.5 -3e-300");
}

TEST(JsonTextTest, CompactInInsertionOrderWithTheSameNumbers) {
  nlohmann::ordered_json j;
  j["zeta"] = 1.0;
  j["alpha"] = 0.1;
  j["count"] = uint64_t{18446744073709551615u};
  j["negative"] = int64_t{-3};
  j["name"] = "a \"quoted\"\\ name\n\x01";
  j["flags"] = {true, false, nullptr};
  j["nested"] = {{"b", nlohmann::ordered_json::array({1e308, -0.0, 5e-324})}, {"a", nlohmann::ordered_json::object()}};
  EXPECT_EQ(JsonText(j),
            "{\"zeta\":1,\"alpha\":0.1,\"count\":18446744073709551615,\"negative\":-3,"
            "\"name\":\"a \\\"quoted\\\"\\\\ name\\n\\u0001\",\"flags\":[true,false,null],"
            "\"nested\":{\"b\":[1e+308,-0,5e-324],\"a\":{}}}");
  // It reads back to the same document.
  EXPECT_EQ(nlohmann::ordered_json::parse(JsonText(j)), j);
}

TEST(JsonTextTest, NotFiniteIsNull) {
  const nlohmann::ordered_json j =
      nlohmann::ordered_json::array({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                                     -std::numeric_limits<double>::infinity()});
  EXPECT_EQ(JsonText(j), "[null,null,null]");
}

TEST(JsonTextTest, InvalidUtf8IsReplacedNotThrown) {
  // A file name is bytes: one that is not UTF-8 still gives valid JSON.
  const nlohmann::ordered_json j = {{"file", std::string("caf\xe9.csv")}};
  EXPECT_EQ(JsonText(j), "{\"file\":\"caf\xef\xbf\xbd.csv\"}");
  EXPECT_EQ(JsonText(nlohmann::ordered_json("caf\xc3\xa9")), "\"caf\xc3\xa9\"");
}

TEST(JsonTextTest, NumbersAgreeWithTheOtherWritersNotWithNlohmannsDump) {
  // Why json_text exists: nlohmann's dump writes 1.0 as "1.0" and is not always shortest.
  EXPECT_EQ(nlohmann::ordered_json(1.0).dump(), "1.0");
  EXPECT_EQ(JsonText(1.0), ShortestDouble(1.0));
  std::mt19937_64 rng(5);
  for (int i = 0; i < 20000; ++i) {
    uint64_t bits = rng();
    if ((bits & (uint64_t{0x7ff} << 52)) == (uint64_t{0x7ff} << 52)) continue;
    const double value = FromBits(bits);
    const std::string text = JsonText(value);
    ASSERT_EQ(text, ShortestDouble(value));
    ASSERT_EQ(Bits(nlohmann::json::parse(text).get<double>()), Bits(value)) << text;
  }
}

}  // namespace
}  // namespace galpha
