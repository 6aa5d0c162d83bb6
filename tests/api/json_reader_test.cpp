#include "api/json_reader.hpp"

#include "api/router.hpp"

#include <gtest/gtest.h>
#include <tuple>

#include "tests/refusal_text.hpp"

#include <string>

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace json_reader_test {
namespace {

ApiError ParseError(const std::string& body, const ApiLimits& limits = {}) {
  ApiError error;
  const auto parsed = ParseBody(body, limits, &error);
  EXPECT_FALSE(parsed.has_value()) << body.substr(0, 80);
  return error;
}

TEST(ParseBodyTest, EmptyBodyIsAnEmptyObject) {
  ApiError error;
  const auto parsed = ParseBody("  \n", ApiLimits{}, &error);
  ASSERT_TRUE(parsed.has_value());
  EXPECT_EQ(*parsed, nlohmann::json::object());
}

TEST(ParseBodyTest, InvalidJsonNamesThePosition) {
  const ApiError error = ParseError("{\"a\": }");
  EXPECT_EQ(error.status, 400);
  EXPECT_EQ(error.code, ErrorCode::kInvalidJson);
  EXPECT_EQ(error.message.rfind("body is not valid JSON at byte 7: ", 0), 0u) << error.message;
}

TEST(ParseBodyTest, NanAndInfinityTokensAreInvalidJson) {
  EXPECT_EQ(ParseError("{\"x\": NaN}").code, ErrorCode::kInvalidJson);
  EXPECT_EQ(ParseError("{\"x\": Infinity}").code, ErrorCode::kInvalidJson);
  EXPECT_EQ(ParseError("{\"x\": -Infinity}").code, ErrorCode::kInvalidJson);
}

TEST(ParseBodyTest, NumberOutOfDoubleRangeIsInvalidValue) {
  const ApiError error = ParseError("{\"x\": 1e400}");
  EXPECT_EQ(error.code, ErrorCode::kInvalidValue);
  EXPECT_EQ(error.message, "number 1e400 is out of range of a double");
}

TEST(ParseBodyTest, DeepNestingIsRefusedWithoutBuildingIt) {
  // 200,000 levels would crash nlohmann-json when the value is destroyed
  // (pitfalls.md); the limit stops the parse at depth 33.
  const std::string bomb = std::string(200000, '[') + std::string(200000, ']');
  const ApiError error = ParseError(bomb);
  EXPECT_EQ(error.status, 413);
  EXPECT_EQ(error.code, ErrorCode::kTooBig);
  EXPECT_EQ(error.message, "nesting exceeds the limit max_json_depth = 32 (--max-json-depth)");
}

TEST(ParseBodyTest, DepthAtTheLimitIsAccepted) {
  ApiLimits limits;
  limits.max_json_depth = 4;
  ApiError error;
  EXPECT_TRUE(ParseBody("[[[[1]]]]", limits, &error).has_value()) << error.message;
  EXPECT_EQ(ParseError("[[[[[1]]]]]", limits).code, ErrorCode::kTooBig);
}

TEST(ParseBodyTest, LongArraysAndStringsAreRefused) {
  ApiLimits limits;
  limits.max_array_length = 3;
  limits.max_string_length = 5;
  ApiError error;
  EXPECT_TRUE(ParseBody("[1,2,3]", limits, &error).has_value());
  EXPECT_EQ(ParseError("[1,2,3,4]", limits).message,
            "an array exceeds the limit max_array_length = 3 (--max-array-length)");
  EXPECT_EQ(ParseError("\"abcdef\"", limits).message,
            "a string of 6 bytes exceeds the limit max_string_length = 5 (--max-string-length)");
  EXPECT_EQ(ParseError("{\"abcdef\": 1}", limits).message,
            "a key of 6 bytes exceeds the limit max_string_length = 5 (--max-string-length)");
}

TEST(ObjectReaderTest, ReadsNumbersAndRefusesUnknownFields) {
  const auto value = nlohmann::json::parse(R"({"mass_kg": 0.145, "masss_kg": 1})");
  ApiError error;
  ObjectReader reader(value, "ball", &error);
  double mass = 0;
  EXPECT_TRUE(reader.Number("mass_kg", Positive(), &mass));
  EXPECT_EQ(mass, 0.145);
  EXPECT_FALSE(reader.Finish());
  EXPECT_EQ(error.code, ErrorCode::kUnknownField);
  EXPECT_EQ(error.field, "ball.masss_kg");
  EXPECT_EQ(error.message,
            "ball.masss_kg is not a known field; did you mean mass_kg? (known: mass_kg)");
}

// The "known" list of an unknown-field error: every name asked for, sorted and each once,
// though asked out of order, twice, and through temporaries (the reader keeps its own copy of
// the names; it no longer keeps a set of them). The first member in the object's (sorted)
// order that nobody asked for is the one named; a member asked for is never refused.
TEST(ObjectReaderTest, UnknownFieldListsEveryNameAskedSortedOnce) {
  const auto value = nlohmann::json::parse(R"({"zeta": 1, "alpha": 2, "qqqqq": 3, "ppppp": 4})");
  ApiError error;
  ObjectReader reader(value, "thing", &error);
  double number = 0;
  for (const char* name : {"zeta", "beta", "alpha", "zeta"}) {
    const std::string temporary(name);
    EXPECT_TRUE(reader.OptionalNumber(temporary, AnyNumber(), &number));
  }
  EXPECT_EQ(number, 1);  // zeta, read last
  reader.Skip(std::string("gamma"));
  EXPECT_FALSE(reader.Finish());
  EXPECT_EQ(error.field, "thing.ppppp");
  EXPECT_EQ(error.message, "thing.ppppp is not a known field (known: alpha, beta, gamma, zeta)");
}

// A required field that is absent beside a typo of it, or of one of its trade forms: the
// error names the field as written and the name meant (issue 33, item 2: "lenght_in" was
// reported as "length_m is required"). A field that is no typo of it is still "required".
TEST(ObjectReaderTest, ATypoOfARequiredFieldIsNamedAsWrittenWithTheNameMeant) {
  for (const auto& [body, field, message] :
       std::vector<std::tuple<std::string, std::string, std::string>>{
           {R"({"lenght_in": 33})", "bat.lenght_in",
            "bat.lenght_in is not a known field; did you mean length_in?"},
           {R"({"legnth_m": 0.8})", "bat.legnth_m",
            "bat.legnth_m is not a known field; did you mean length_m?"},
           {R"({"colour": "red"})", "bat.length_m", "bat.length_m is required"}}) {
    const auto value = nlohmann::json::parse(body);
    ApiError error;
    ObjectReader reader(value, "bat", &error);
    double length = 0;
    EXPECT_FALSE(reader.Number("length_m", Positive(), &length));
    EXPECT_EQ(error.field, field);
    EXPECT_EQ(error.message, message);
    EXPECT_EQ(error.code,
              field == "bat.length_m" ? ErrorCode::kMissingField : ErrorCode::kUnknownField);
  }
}

// One typo in a name under 6 characters, two in a longer one; the nearest wins.
TEST(ObjectReaderTest, NearestNameIsATypoAway) {
  const std::vector<std::string> names = {"length_m", "length_in", "x_m", "radius_m"};
  EXPECT_EQ(NearestName("lenght_in", names), "length_in");  // a swap
  EXPECT_EQ(NearestName("lengthh_m", names), "length_m");   // an insertion
  EXPECT_EQ(NearestName("radus_m", names), "radius_m");     // a deletion
  EXPECT_EQ(NearestName("r_m", names), "x_m");              // one change in a short name
  EXPECT_EQ(NearestName("rr_mm", names), "");               // two in a short name: none
  EXPECT_EQ(NearestName("diameter_in", names), "");
  EXPECT_EQ(NearestName("radius_m", names), "");  // itself is no suggestion
}

TEST(ObjectReaderTest, MessagesNameFieldValueAndRule) {
  const auto value =
      nlohmann::json::parse(R"({"speed_mps": -3, "name": 7, "cor": "high", "n": 2.5})");
  {
    ApiError error;
    ObjectReader reader(value, "ball", &error);
    double speed = 0;
    EXPECT_FALSE(reader.Number("speed_mps", NonNegative(200), &speed));
    EXPECT_EQ(error.message, "ball.speed_mps = -3: must be a number in [0, 200]");
    EXPECT_EQ(error.field, "ball.speed_mps");
    EXPECT_EQ(error.code, ErrorCode::kInvalidValue);
  }
  {
    ApiError error;
    ObjectReader reader(value, "", &error);
    std::string name;
    EXPECT_FALSE(reader.OptionalString("name", &name));
    EXPECT_EQ(error.message, "name = 7: must be a string");
  }
  {
    ApiError error;
    ObjectReader reader(value, "", &error);
    double cor = 0;
    EXPECT_FALSE(reader.OptionalNumber("cor", Between(0, 1), &cor));
    EXPECT_EQ(error.message, "cor = \"high\": must be a number");
  }
  {
    ApiError error;
    ObjectReader reader(value, "", &error);
    long long n = 0;
    EXPECT_FALSE(reader.OptionalInteger("n", 1, 10, &n));
    EXPECT_EQ(error.message, "n = 2.5: must be an integer in [1, 10]");
  }
}

// A finite number past the rules' default magnitude (1e300) names that range and the value: it
// was refused as "must be a number", as if it were a string (issue "Under attack", item 11d).
TEST(ObjectReaderTest, NumberBeyondTheDefaultMagnitudeNamesItsRange) {
  const nlohmann::json value =
      nlohmann::json::parse(R"({"cor": 1e301, "speed_mps": -1e301, "length_in": 1e301})");
  {
    ApiError error;
    ObjectReader reader(value, "", &error);
    double cor = 0;
    EXPECT_FALSE(reader.OptionalNumber("cor", AnyNumber(), &cor));
    EXPECT_EQ(error.message, "cor = 1e+301: must be a number in [-1e+300, 1e+300]");
    EXPECT_EQ(error.field, "cor");
    EXPECT_EQ(error.code, ErrorCode::kInvalidValue);
  }
  {
    ApiError error;
    ObjectReader reader(value, "", &error);
    double speed = 0;
    EXPECT_FALSE(reader.OptionalNumber("speed_mps", Positive(), &speed));
    EXPECT_EQ(error.message, "speed_mps = -1e+301: must be a number > 0");  // below its own bound
  }
  {
    ApiError error;
    ObjectReader reader(value, "", &error);
    double length = 0;  // 1e301 in = 2.54e299 m: within [-1e300, 1e300], so accepted by AnyNumber
    EXPECT_TRUE(reader.OptionalNumber("length_m", AnyNumber(), &length));
    EXPECT_FALSE(reader.OptionalNumber("cor", Positive(), &length));
    EXPECT_EQ(error.message, "cor = 1e+301: must be a number in (0, 1e+300]");
  }
  {
    ApiError error;
    const nlohmann::json huge = nlohmann::json::parse(R"({"n": 1e301})");
    ObjectReader reader(huge, "", &error);
    long long n = 0;
    EXPECT_FALSE(reader.OptionalInteger("n", 1, 10, &n));
    EXPECT_EQ(error.message, "n = 1e+301: must be an integer in [1, 10]");
  }
}

// The same through an endpoint: the answer names the field, the value and the range.
TEST(ObjectReaderTest, NumberBeyondTheDefaultMagnitudeThroughAnEndpoint) {
  const Response r =
      Dispatch({"POST", "/v1/bat/properties",
                R"({"bat": {"three_segment": {"length_m": 1e301, "handle_radius_m": 0.0125,
           "barrel_radius_m": 0.033, "taper_start_m": 0.3, "taper_end_m": 0.55}}})"},
               Context{});
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body, (nlohmann::json{{"code", "InvalidValue"},
                                    {"field", "bat.three_segment.length_m"},
                                    {"message",
                                     "bat.three_segment.length_m = 1e+301: must be a "
                                     "number in [-1e+300, 1e+300]"}}));
}

TEST(ObjectReaderTest, MissingRequiredFieldIsMissingField) {
  const auto value = nlohmann::json::object();
  ApiError error;
  ObjectReader reader(value, "bat.three_segment", &error);
  double length = 0;
  EXPECT_FALSE(reader.Number("length_m", Positive(), &length));
  EXPECT_EQ(error.code, ErrorCode::kMissingField);
  EXPECT_EQ(error.message, "bat.three_segment.length_m is required");
}

TEST(ObjectReaderTest, NonObjectIsRefused) {
  const auto value = nlohmann::json::array({1, 2});
  ApiError error;
  ObjectReader reader(value, "swing", &error);
  EXPECT_FALSE(reader.ok());
  EXPECT_EQ(error.message, "swing = [1,2]: must be an object");
}

TEST(ObjectReaderTest, FirstErrorWins) {
  const auto value = nlohmann::json::parse(R"({"a": -1, "b": -1})");
  ApiError error;
  ObjectReader reader(value, "", &error);
  double a = 0, b = 0;
  reader.Number("a", Positive(), &a);
  reader.Number("b", Positive(), &b);
  EXPECT_EQ(error.field, "a");
}

TEST(NumberRuleTest, DescribesIntervals) {
  EXPECT_EQ(Positive().Describe(), "must be a number > 0");
  EXPECT_EQ(NonNegative(5).Describe(), "must be a number in [0, 5]");
  EXPECT_EQ((NumberRule{-1, 0.5, true, true, false}).Describe(), "must be a number in (-1, 0.5)");
  EXPECT_FALSE(Positive().Accepts(0.0));
  EXPECT_FALSE(Positive().Accepts(std::nan("")));
  EXPECT_TRUE(Between(0, 1).Accepts(1.0));
}

TEST(LimitsTest, DefaultsAreValidAndRulesAreNamed) {
  std::string why;
  EXPECT_TRUE(Validates(ApiLimits{}, &why)) << why;
  ApiLimits limits;
  limits.max_json_depth = 1;
  EXPECT_FALSE(Validates(limits, &why));
  EXPECT_EQ(why, "max_json_depth = 1: must be in [2, 512]");
  limits = ApiLimits{};
  limits.max_time_s = 0;
  EXPECT_FALSE(Validates(limits, &why));
  EXPECT_EQ(why, "max_time_s = 0: must be > 0");
}

}  // namespace
}  // namespace json_reader_test
}  // namespace sweetspot::api
