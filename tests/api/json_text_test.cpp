// api::AppendJson writes exactly nlohmann's compact dump, and api::JsonFnv1a64 hashes exactly
// those bytes (the provenance's input hash): over every kind of value, strings that take
// nlohmann's escaping, and texts longer than the writer's 1 KiB buffer.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "api/handlers/handlers.hpp"
#include "api/json_text.hpp"

namespace sweetspot::api {
namespace {

std::string Dump(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::uint64_t Fnv1a64(const std::string& text) {
  std::uint64_t hash = 1469598103934665603ULL;
  for (const char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ULL;
  }
  return hash;
}

nlohmann::json Values() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  nlohmann::json values = nlohmann::json::array({nullptr,
                                                 true,
                                                 false,
                                                 0,
                                                 -1,
                                                 std::numeric_limits<std::int64_t>::min(),
                                                 std::numeric_limits<std::uint64_t>::max(),
                                                 -0.0,
                                                 1e-300,
                                                 23.23759724121471,
                                                 nan,
                                                 5e-324,
                                                 1e21,
                                                 "",
                                                 "plain text",
                                                 "quote \" and \\",
                                                 "tab\tnewline\n\x01\x1f\x7f",
                                                 "caf\xc3\xa9 \xe2\x82\xac",
                                                 "bad \xff\xfe utf-8 \xc3",
                                                 nlohmann::json::object(),
                                                 nlohmann::json::binary({1, 2, 3})});
  values.push_back({{"b", 1}, {"a", {{"z", nullptr}, {"\xc3\xa9", "x"}}}, {"bad\xff", 2}});
  values.push_back(std::string(3000, 'x'));  // longer than the buffer
  values.push_back(nlohmann::json::array({std::string(1000, 'y'), 1.5, "z"}));  // across it
  return values;
}

TEST(JsonTextTest, AppendJsonWritesTheDumpAndTheHashIsItsFnv) {
  const nlohmann::json values = Values();
  for (const auto& value : values) {
    std::string out = "x";
    AppendJson(value, &out);
    EXPECT_EQ(out.substr(1), Dump(value)) << Dump(value).substr(0, 80);
    EXPECT_EQ(JsonFnv1a64(value), Fnv1a64(Dump(value))) << Dump(value).substr(0, 80);
  }
  std::string all;
  AppendJson(values, &all);
  EXPECT_EQ(all, Dump(values));
  EXPECT_EQ(JsonFnv1a64(values), Fnv1a64(Dump(values)));
}

// The contract's example body keeps the input hash the answers have always carried
// (docs/http-bench.md, WireBytesTest).
TEST(JsonTextTest, TheExampleBodyKeepsItsInputHash) {
  const auto body = nlohmann::json::parse(
      R"({"bat": {"preset": "paper-wood"}, "ball": {"mass_kg": 0.145, "radius_m": 0.0366,)"
      R"( "speed_mps": 27.7}, "swing": {"angular_speed_rad_s": 17.288, "pivot_from_knob_m":)"
      R"( 0.0, "hands_from_knob_m": 0.1524}, "cor": 0.5, "outputs": ["max_exit_speed"]})");
  EXPECT_EQ(InputHash(body), "fnv1a64:d8e19095744680ec");
}

}  // namespace
}  // namespace sweetspot::api
