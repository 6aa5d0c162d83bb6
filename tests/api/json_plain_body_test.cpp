// ReadPlainBody reads a body in JSON's plain subset into the tree nlohmann's parser builds (the
// same types: signed, unsigned and floating numbers told apart; a key given twice keeping its
// last value), and leaves everything else to nlohmann: ParseBody then answers exactly as
// ParseBodyWithNlohmann does, refusals and their messages included. fuzz/entry_points.hpp's
// parse_body target checks the same on what libFuzzer makes.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/json_reader.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

// Equal values of equal types, recursively (nlohmann's == takes 1, 1u and 1.0 as equal).
::testing::AssertionResult SameTree(const Json& a, const Json& b) {
  if (a.type() != b.type()) {
    return ::testing::AssertionFailure()
           << a.dump() << " is a " << a.type_name() << ", " << b.dump() << " a " << b.type_name();
  }
  if (a.is_object()) {
    if (a.size() != b.size())
      return ::testing::AssertionFailure() << a.dump() << " vs " << b.dump();
    for (auto it = a.begin(), jt = b.begin(); it != a.end(); ++it, ++jt) {
      if (it.key() != jt.key())
        return ::testing::AssertionFailure() << it.key() << " vs " << jt.key();
      if (auto same = SameTree(*it, *jt); !same) return same;
    }
    return ::testing::AssertionSuccess();
  }
  if (a.is_array()) {
    if (a.size() != b.size())
      return ::testing::AssertionFailure() << a.dump() << " vs " << b.dump();
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (auto same = SameTree(a[i], b[i]); !same) return same;
    }
    return ::testing::AssertionSuccess();
  }
  if (a.is_number_float()) {  // bit for bit (-0.0 against 0.0 too)
    const double x = a.get<double>();
    const double y = b.get<double>();
    if (std::memcmp(&x, &y, sizeof x) != 0) {
      return ::testing::AssertionFailure() << a.dump() << " vs " << b.dump();
    }
    return ::testing::AssertionSuccess();
  }
  if (a != b) return ::testing::AssertionFailure() << a.dump() << " vs " << b.dump();
  return ::testing::AssertionSuccess();
}

// ParseBody and the reference answer the same: the same tree, or the same refusal.
void ExpectParseBodyIsTheReference(const std::string& body, const ApiLimits& limits) {
  ApiError error;
  ApiError reference_error;
  const auto value = ParseBody(body, limits, &error);
  const auto reference = ParseBodyWithNlohmann(body, limits, &reference_error);
  ASSERT_EQ(value.has_value(), reference.has_value()) << body;
  if (value) {
    EXPECT_TRUE(SameTree(*value, *reference)) << body;
  } else {
    EXPECT_EQ(error.status, reference_error.status) << body;
    EXPECT_EQ(error.code, reference_error.code) << body;
    EXPECT_EQ(error.message, reference_error.message) << body;
  }
}

TEST(JsonPlainBodyTest, PlainBodiesGiveNlohmannsTree) {
  const ApiLimits limits;
  const std::vector<std::string> bodies = {
      R"({"bat": {"preset": "paper-wood"}, "ball": {"mass_kg": 0.145, "radius_m": 0.0366,
          "speed_mps": 27.7}, "swing": {"angular_speed_rad_s": 17.288, "pivot_from_knob_m": 0.0,
          "hands_from_knob_m": 0.1524}, "cor": 0.5, "outputs": ["max_exit_speed"]})",
      "{}",
      "[]",
      " \t\r\n{ } ",
      "[[], {}, [[]]]",
      "0",
      "-0",
      "-0.0",
      "0.0",
      "1",
      "-1",
      "18446744073709551615",
      "-9223372036854775808",
      "9223372036854775808",
      "1.5e300",
      "-2.5E-300",
      "1e2",
      "1E+2",
      "1e-2",
      "0.1",
      "123456789012345678901234.5",
      "true",
      "false",
      "null",
      R"("")",
      R"("plain ~ text with / and ' and `")",
      R"({"a": 1, "b": -1, "c": 1.0, "d": [1, -1, 1.5, true, null, "x"]})",
      R"({"twice": 1, "other": 2, "twice": [3]})",  // the last of a key given twice stays
      R"({"z": {"y": {"x": {"w": []}}}, "a": 0})",
      "\"\x7f\""};
  for (const std::string& body : bodies) {
    Json plain;
    EXPECT_TRUE(ReadPlainBody(body, limits, &plain)) << body;
    const Json reference = Json::parse(body);
    EXPECT_TRUE(SameTree(plain, reference)) << body;
    ExpectParseBodyIsTheReference(body, limits);
  }
}

TEST(JsonPlainBodyTest, EverythingElseIsLeftToNlohmann) {
  const ApiLimits limits;
  const std::vector<std::string> bodies = {
      // Valid JSON outside the subset: escapes, UTF-8, a BOM, numbers past 64 bits or a double.
      R"({"a": "tab\there"})", R"({"a\"b": 1})", "{\"caf\xc3\xa9\": 1}", "\xef\xbb\xbf{}",
      "18446744073709551616", "-9223372036854775809", "1e400", "-1e400",
      // Invalid JSON: nlohmann's refusal, with its message and position.
      "{", "}", "[1,]", R"({"a": 1,})", R"({"a" 1})", R"({a: 1})", "01", "1.", ".5", "+1", "-",
      "1e", "1e+", "tru", "nul", "[1 2]", "{} x", R"("unterminated)", "\"ctrl\x01\"", "-a",
      "\"\xff\"", "[1,\n\n  oops]"};
  for (const std::string& body : bodies) {
    Json plain = "untouched";
    EXPECT_FALSE(ReadPlainBody(body, limits, &plain)) << body;
    EXPECT_EQ(plain, "untouched") << body;
    ExpectParseBodyIsTheReference(body, limits);
  }
  // Underflow (strtod's ERANGE), read by either: the same tree.
  for (const std::string body : {"1e-400", "5e-324", "-2.2250738585072014e-308"}) {
    ExpectParseBodyIsTheReference(body, limits);
  }
}

TEST(JsonPlainBodyTest, TheLimitsAreNlohmannsOnBothSidesOfThem) {
  ApiLimits limits;
  limits.max_json_depth = 3;
  limits.max_array_length = 2;
  limits.max_string_length = 4;
  // At each limit: read plainly. One past it: left to nlohmann, which refuses with the limit.
  const std::vector<std::string> within = {"[[[]]]", R"({"a": {"b": []}})", "[1, 2]", R"("abcd")",
                                           R"({"abcd": 1})"};
  const std::vector<std::string> beyond = {"[[[[]]]]", R"({"a": {"b": {"c": {}}}})", "[1, 2, 3]",
                                           R"("abcde")", R"({"abcde": 1})"};
  for (const std::string& body : within) {
    Json plain;
    EXPECT_TRUE(ReadPlainBody(body, limits, &plain)) << body;
    ExpectParseBodyIsTheReference(body, limits);
  }
  for (const std::string& body : beyond) {
    Json plain;
    EXPECT_FALSE(ReadPlainBody(body, limits, &plain)) << body;
    ApiError error;
    EXPECT_FALSE(ParseBody(body, limits, &error).has_value()) << body;
    EXPECT_EQ(error.status, 413) << body;
    ExpectParseBodyIsTheReference(body, limits);
  }
}

TEST(JsonPlainBodyTest, AnEmptyBodyIsAnEmptyObject) {
  const ApiLimits limits;
  for (const std::string body : {"", "  \n"}) {
    ApiError error;
    const auto value = ParseBody(body, limits, &error);
    ASSERT_TRUE(value.has_value());
    EXPECT_EQ(*value, Json::object());
  }
}

}  // namespace
}  // namespace sweetspot::api
