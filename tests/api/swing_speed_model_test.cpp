// Issue 35 item 2 at the api: swing.bat_speed_from_tip_m "sweet_spot" and swing.speed_model
// "swing_weight" in every scene endpoint, their field errors, and the answers that report each
// bat's own bat speed.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "api/router.hpp"
#include "core/scene/swing_speed.hpp"

namespace sweetspot::api {
namespace swing_speed_model_test {
namespace {

using Json = nlohmann::json;

Response Post(const std::string& path, const Json& body) {
  return Dispatch({"POST", path, body.dump()}, Context{});
}

bool Mentions(const Response& r, const std::string& text) {
  return r.body.value("message", std::string()).find(text) != std::string::npos;
}

TEST(SwingSpeedModelTest, SweetSpotInEveryTradeForm) {
  for (const char* key : {"bat_speed_from_tip_m", "bat_speed_from_tip_in"}) {
    const Response r = Post("/v1/sweet-spot", {{"bat", {{"preset", "bbcor-33-aluminium"}}},
                                               {"swing", {{"bat_speed_mph", 70}, {key, "sweet_spot"}}}});
    ASSERT_EQ(r.status, 200) << r.body.dump();
    const Json& swing = r.body["swing"];
    EXPECT_EQ(swing["bat_speed_point"], "sweet_spot");
    EXPECT_EQ(swing["bat_speed_point_model"], "free_bat");
    const double x = r.body["max_exit_speed"]["position_from_knob_m"];
    const double v = swing["angular_speed_rad_s"].get<double>() * x;
    // The closed-form root: the speed at the reported maximum is the given one (1e-9 relative).
    EXPECT_NEAR(v, 70 * 0.44704, 1e-9 * 70 * 0.44704) << key;
  }
}

TEST(SwingSpeedModelTest, FieldErrorsNameTheFieldTheValueAndTheRule) {
  const Json bat = {{"preset", "wood-34-ash"}};
  Response r = Post("/v1/sweet-spot",
                    {{"bat", bat}, {"swing", {{"bat_speed_mph", 70}, {"bat_speed_from_tip_m", "tip"}}}});
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "swing.bat_speed_from_tip_m");
  EXPECT_TRUE(Mentions(r, "\"tip\"")) << r.body.dump();
  EXPECT_TRUE(Mentions(r, "sweet_spot")) << r.body.dump();

  r = Post("/v1/sweet-spot", {{"bat", bat},
                              {"swing", {{"bat_speed_mph", 70}, {"bat_speed_from_tip_m", "sweet_spot"},
                                         {"bat_speed_from_tip_in", 6}}}});
  EXPECT_EQ(r.status, 400) << r.body.dump();
  EXPECT_TRUE(Mentions(r, "both are given")) << r.body.dump();

  r = Post("/v1/sweet-spot", {{"bat", bat}, {"swing", {{"bat_speed_mph", 70}, {"speed_model", "heavy"}}}});
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "swing.speed_model");
  EXPECT_TRUE(Mentions(r, "swing_weight")) << r.body.dump();

  // Each setting needs a bat speed.
  r = Post("/v1/sweet-spot", {{"bat", bat}, {"swing", {{"speed_model", "swing_weight"}}}});
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "swing.speed_model");
  EXPECT_TRUE(Mentions(r, "needs swing.bat_speed_mps")) << r.body.dump();
  r = Post("/v1/collision", {{"bat", bat}, {"impact_from_knob_m", 0.7},
                             {"swing", {{"bat_speed_from_tip_m", "sweet_spot"}}}});
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "swing.bat_speed_from_tip_m");

  // The swing weight's settings without its model would do nothing: refused, in the unit given.
  r = Post("/v1/sweet-spot", {{"bat", bat},
                              {"swing", {{"bat_speed_mph", 70}, {"reference_moi_oz_in2", 12000}}}});
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "swing.reference_moi_oz_in2") << r.body.dump();
  EXPECT_TRUE(Mentions(r, "applies only with swing.speed_model = swing_weight")) << r.body.dump();
  r = Post("/v1/sweet-spot", {{"bat", bat},
                              {"swing", {{"bat_speed_mph", 70}, {"speed_model", "swing_weight"},
                                         {"swing_weight_exponent", 0.75}}}});
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "swing.swing_weight_exponent");
  EXPECT_TRUE(Mentions(r, "= 0.75: must be in [0, 0.5]")) << r.body.dump();

  // The optimiser takes neither (its swing weight is an objective's).
  r = Post("/v1/optimize", {{"bat", {{"preset", "paper-wood"}}},
                            {"swing", {{"bat_speed_mph", 70}, {"speed_model", "swing_weight"}}},
                            {"variables", {{{"path", "three_segment.taper_start_m"}, {"min", 0.1},
                                            {"max", 0.5}}}}});
  EXPECT_EQ(r.status, 400) << r.body.dump();
  EXPECT_EQ(r.body["field"], "swing.speed_model");
  EXPECT_TRUE(Mentions(r, "max_exit_speed_swing_weight")) << r.body.dump();
}

TEST(SwingSpeedModelTest, CompareSameBatterReportsEachBatsSpeed) {
  const Json body = {{"baseline", {{"preset", "wood-34-ash"}}},
                     {"variants", {{{"name", "alloy"}, {"bat", {{"preset", "bbcor-33-aluminium"}}}}}},
                     {"ball", {{"preset", "mlb"}, {"speed_mph", 90}}},
                     {"swing", {{"bat_speed_mph", 70}, {"speed_model", "swing_weight"}}},
                     {"outputs", {"max_exit_speed"}}};
  const Response r = Post("/v1/compare", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& wood = r.body["rows"][0];
  const Json& alloy = r.body["rows"][1];
  const double given = 70 * 0.44704;
  // The reference bat swings at the given speed (its MOI is the reference's to 1e-9).
  EXPECT_NEAR(wood["swing"]["bat_speed_mps"].get<double>(), given, 1e-9 * given);
  EXPECT_EQ(wood["swing"]["swing_weight"]["reference_bat"], core::kSwingWeightReferenceBat);
  const double i = alloy["properties"]["moi_six_inch_kg_m2"];
  const double expected = given * std::pow(i / core::kSwingWeightReferenceMoiKgM2, -0.27);
  EXPECT_NEAR(alloy["swing"]["bat_speed_mps"].get<double>(), expected, 1e-12 * expected);
  EXPECT_EQ(alloy["swing"]["swing_weight"]["given_bat_speed_mps"], given);
  // Same batter: the lighter swing weight is swung faster and hits harder.
  EXPECT_GT(alloy["deltas"]["bat_speed_mps"].get<double>(), 2.0);
  EXPECT_GT(alloy["deltas"]["max_exit_speed_mps"].get<double>(), 0.0);
  // The fixed model (default): the same speed for both, no bat-speed delta.
  Json fixed = body;
  fixed["swing"].erase("speed_model");
  const Response f = Post("/v1/compare", fixed);
  ASSERT_EQ(f.status, 200) << f.body.dump();
  EXPECT_EQ(f.body["rows"][1]["swing"]["bat_speed_mps"], given);
  EXPECT_FALSE(f.body["rows"][1]["deltas"].contains("bat_speed_mps"));
  EXPECT_FALSE(f.body["rows"][1]["swing"].contains("speed_model"));
}

TEST(SwingSpeedModelTest, ExploreAndCollisionTakeTheModel) {
  // A sweep of the reference MOI: the bat's speed falls as the reference falls (a weaker
  // batter), exactly as the power law says.
  const Json body = {{"bat", {{"preset", "wood-34-ash"}}},
                     {"swing", {{"bat_speed_mps", 30.0}, {"speed_model", "swing_weight"}}},
                     {"parameters", {{{"path", "swing.reference_moi_kg_m2"}, {"min", 0.15},
                                      {"max", 0.30}, {"count", 3}}}}};
  const Response r = Post("/v1/explore", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  ASSERT_EQ(r.body["rows"].size(), 3u);
  double last = 0.0;
  for (const Json& row : r.body["rows"]) {
    const double ref = row["parameters"]["swing.reference_moi_kg_m2"];
    const double v = row["swing"]["bat_speed_mps"];
    const double expected = 30.0 * std::pow(core::kSwingWeightReferenceMoiKgM2 / ref, -0.27);
    EXPECT_NEAR(v, expected, 1e-9 * expected) << ref;  // MOI to rounding, then one power
    EXPECT_GT(v, last);
    last = v;
  }
  const Response c = Post("/v1/collision", {{"bat", {{"preset", "bbcor-33-aluminium"}}},
                                            {"impact_from_knob_m", 0.7},
                                            {"swing", {{"bat_speed_mph", 70},
                                                       {"speed_model", "swing_weight"}}}});
  ASSERT_EQ(c.status, 200) << c.body.dump();
  EXPECT_GT(c.body["swing"]["bat_speed_mps"].get<double>(), 70 * 0.44704);
}

}  // namespace
}  // namespace swing_speed_model_test
}  // namespace sweetspot::api
