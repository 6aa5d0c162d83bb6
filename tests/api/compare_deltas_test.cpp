// /v1/compare's deltas come from the core results; they must equal, to the
// last bit, the differences of the values each row renders.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace compare_deltas_test {
namespace {

using Json = nlohmann::json;

Json Compare(const std::string& outputs) {
  const std::string body = R"({"baseline": {"preset": "paper-wood"},
      "variants": [{"name": "corked", "bat": {"preset": "paper-wood",
                    "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}}},
                   {"name": "shallow", "bat": {"preset": "paper-wood",
                    "fill": {"material": "cork", "diameter_m": 0.02, "depth_m": 0.15}}}],
      "outputs": )" + outputs + "}";
  const Response r = Dispatch({"POST", "/v1/compare", body}, Context{});
  EXPECT_EQ(r.status, 200) << r.body.dump().substr(0, 400);
  return r.body;
}

double At(const Json& row, const char* object, const char* key) {
  return row.at(object).at(key).get<double>();
}

TEST(CompareDeltasTest, DeltasAreTheDifferencesOfTheRenderedRows) {
  const Json body = Compare(R"(["max_exit_speed", "center_of_percussion"])");
  ASSERT_EQ(body.at("rows").size(), 3u);
  const Json& base = body["rows"][0];
  for (std::size_t i = 1; i < 3; ++i) {
    const Json& row = body["rows"][i];
    const Json& deltas = row.at("deltas");
    std::set<std::string> keys;
    for (const auto& item : deltas.items()) keys.insert(item.key());
    EXPECT_EQ(keys, (std::set<std::string>{"balance_point_m", "center_of_percussion_m",
                                           "mass_kg", "max_exit_speed_mps",
                                           "max_exit_speed_position_m", "moi_centroid_kg_m2",
                                           "moi_knob_kg_m2", "moi_six_inch_kg_m2"}));
    // Exact: the same doubles subtracted in the same order.
    for (const char* key : {"mass_kg", "balance_point_m", "moi_knob_kg_m2", "moi_six_inch_kg_m2",
                            "moi_centroid_kg_m2"}) {
      EXPECT_EQ(deltas.at(key).get<double>(),
                At(row, "properties", key) - At(base, "properties", key))
          << key;
    }
    EXPECT_EQ(deltas.at("max_exit_speed_position_m").get<double>(),
              At(row, "max_exit_speed", "position_from_knob_m") -
                  At(base, "max_exit_speed", "position_from_knob_m"));
    EXPECT_EQ(deltas.at("max_exit_speed_mps").get<double>(),
              At(row, "max_exit_speed", "exit_speed_mps") -
                  At(base, "max_exit_speed", "exit_speed_mps"));
    EXPECT_EQ(deltas.at("center_of_percussion_m").get<double>(),
              At(row, "center_of_percussion", "position_from_knob_m") -
                  At(base, "center_of_percussion", "position_from_knob_m"));
  }
}

TEST(CompareDeltasTest, OnlyTheRequestedSweetSpotsHaveDeltas) {
  const Json body = Compare(R"(["center_of_percussion"])");
  const Json& deltas = body.at("rows").at(1).at("deltas");
  EXPECT_TRUE(deltas.contains("center_of_percussion_m"));
  EXPECT_FALSE(deltas.contains("max_exit_speed_mps"));
  EXPECT_FALSE(deltas.contains("max_exit_speed_position_m"));
  EXPECT_TRUE(deltas.contains("mass_kg"));
}

}  // namespace
}  // namespace compare_deltas_test
}  // namespace sweetspot::api
