// The batted_ball scene output through the router: head-on it is max_exit_speed's impact
// launched level; an undercut gives backspin and lift; the new scene fields are refused out of
// range, naming the field as written; hertz and flexible give their own normal impulse; the
// scene's environment and aero; /v1/collision's batted_ball; distance_sweet_spot and carry_map.
#include <gtest/gtest.h>

#include <string>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace batted_ball_api_test {
namespace {

Response Post(const std::string& body) {
  return Dispatch({"POST", "/v1/sweet-spot", body}, Context{});
}

std::string Scene(const std::string& model, const std::string& extra) {
  return R"({"bat": {"preset": "wood-34-ash"}, "ball": {"speed_mph": 90},
             "swing": {"bat_speed_mph": 70}, "options": {"model": ")" +
         model + R"("}, "outputs": ["max_exit_speed", "batted_ball"])" + extra + "}";
}

TEST(BattedBallApiTest, HeadOnIsMaxExitSpeedLaunchedLevel) {
  for (const char* model : {"free_bat", "rigid_pivot"}) {
    const Response r = Post(Scene(model, ""));
    ASSERT_EQ(r.status, 200) << r.body.dump();
    const auto& b = r.body["batted_ball"];
    const double exit = r.body["max_exit_speed"]["exit_speed_mps"].get<double>();
    EXPECT_NEAR(b["exit_speed_mps"].get<double>(), exit, 1e-9) << model;
    EXPECT_NEAR(b["launch_angle_deg"].get<double>(), 0.0, 1e-9) << model;
    EXPECT_NEAR(b["backspin_rpm"].get<double>(), 0.0, 1e-9) << model;
    EXPECT_EQ(b["impact_from_knob_m"], r.body["max_exit_speed"]["position_from_knob_m"]);
    EXPECT_GT(b["distance_m"].get<double>(), 0.0);
    EXPECT_GT(b["hang_time_s"].get<double>(), 0.0);
    EXPECT_EQ(b["spin_source"], "oblique_impact");
  }
}

TEST(BattedBallApiTest, HalfInchUndercutGivesBackspinAndLift) {
  const Response r = Post(Scene("free_bat", R"(, "contact": {"undercut_in": 0.5})"));
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const auto& b = r.body["batted_ball"];
  EXPECT_GT(b["backspin_rpm"].get<double>(), 0.0);
  EXPECT_GT(b["launch_angle_deg"].get<double>(), 0.0);
  EXPECT_NEAR(b["undercut_m"].get<double>(), 0.0127, 1e-15);
  EXPECT_GT(b["apex_m"].get<double>(), 0.9144);
  // An overcut: topspin and a ball driven down.
  const Response o = Post(Scene("free_bat", R"(, "contact": {"undercut_in": -0.5})"));
  ASSERT_EQ(o.status, 200) << o.body.dump();
  EXPECT_LT(o.body["batted_ball"]["backspin_rpm"].get<double>(), 0.0);
  EXPECT_LT(o.body["batted_ball"]["launch_angle_deg"].get<double>(), 0.0);
}

TEST(BattedBallApiTest, ImperialTwins) {
  const Response r = Post(Scene("free_bat", R"(, "report_units": "imperial")"));
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const auto& b = r.body["batted_ball"];
  EXPECT_TRUE(b.contains("exit_speed_mph"));
  EXPECT_TRUE(b.contains("distance_ft"));
  EXPECT_TRUE(b["landing"].contains("y_ft"));
}

TEST(BattedBallApiTest, RefusesOutOfRangeNamingTheFieldAsWritten) {
  const struct {
    const char* extra;
    const char* field;
  } cases[] = {
      {R"(, "contact": {"undercut_in": 9})", "contact.undercut_in"},
      {R"(, "contact": {"undercut_m": -0.2})", "contact.undercut_m"},
      {R"(, "ball": {"spin_rpm": 1e6})", "ball.spin_rpm"},
      {R"(, "ball": {"descent_angle_deg": 95})", "ball.descent_angle_deg"},
      {R"(, "swing": {"bat_speed_mph": 70, "attack_angle_deg": -120})", "swing.attack_angle_deg"},
      {R"(, "contact": {"undercut_m": "x"})", "contact.undercut_m"},
  };
  for (const auto& c : cases) {
    const Response r = Post(Scene("free_bat", c.extra));
    EXPECT_EQ(r.status, 400) << c.extra << r.body.dump();
    EXPECT_NE(r.body.dump().find(c.field), std::string::npos) << c.extra << r.body.dump();
  }
}

TEST(BattedBallApiTest, HertzAndFlexibleGiveTheirOwnNormalImpulse) {
  for (const char* model : {"hertz", "flexible"}) {
    const Response r = Post(Scene(model, ""));
    ASSERT_EQ(r.status, 200) << r.body.dump();
    const auto& b = r.body["batted_ball"];
    EXPECT_EQ(b["impact"]["normal_model"], model);
    // Head-on: the model's own exit speed at max_exit_speed's point (the same ODE at the same
    // approach speed; 1e-6 m/s covers max_exit_speed's own evaluation being a search's).
    const Response c = Dispatch({"POST", "/v1/collision",
                                 R"({"bat": {"preset": "wood-34-ash"}, "ball": {"speed_mph": 90},
             "swing": {"bat_speed_mph": 70}, "model": ")" +
                                     std::string(model) + R"(", "impact_from_knob_m": )" +
                                     b["impact_from_knob_m"].dump() + "}"},
                                Context{});
    ASSERT_EQ(c.status, 200) << c.body.dump();
    EXPECT_NEAR(b["exit_speed_mps"].get<double>(), c.body["exit_speed_mps"].get<double>(), 1e-9)
        << model;
    EXPECT_NEAR(b["launch_angle_deg"].get<double>(), 0.0, 1e-12) << model;
  }
}

TEST(BattedBallApiTest, TheScenesEnvironmentAndAero) {
  const Response sea = Post(Scene("free_bat", R"(, "contact": {"undercut_in": 0.75})"));
  const Response coors = Post(
      Scene("free_bat", R"(, "contact": {"undercut_in": 0.75}, "environment": {"elevation_ft": 5200,
                     "temperature_f": 85}, "aero": {"model": "nathan-2016"})"));
  ASSERT_EQ(sea.status, 200) << sea.body.dump();
  ASSERT_EQ(coors.status, 200) << coors.body.dump();
  EXPECT_EQ(sea.body["batted_ball"]["flight"]["environment"], "default");
  EXPECT_EQ(coors.body["batted_ball"]["flight"]["environment"], "scene");
  // A mile up, warmer: more than 5 % farther (the rule of thumb: ~5 % per 5000 ft alone).
  EXPECT_GT(coors.body["batted_ball"]["distance_m"].get<double>(),
            1.05 * sea.body["batted_ball"]["distance_m"].get<double>());
  const Response vacuum =
      Post(Scene("free_bat", R"(, "contact": {"undercut_in": 0.75}, "aero": {"model": "vacuum"})"));
  ASSERT_EQ(vacuum.status, 200) << vacuum.body.dump();
  EXPECT_EQ(vacuum.body["batted_ball"]["flight"]["aero_model"], "vacuum");
  EXPECT_GT(vacuum.body["batted_ball"]["distance_m"].get<double>(),
            sea.body["batted_ball"]["distance_m"].get<double>());
  // Refusals name the field as written, as /v1/flight's do.
  const struct {
    const char* extra;
    const char* field;
  } cases[] = {
      {R"(, "environment": {"relative_humidity_pct": 150})", "environment.relative_humidity_pct"},
      {R"(, "environment": {"wind": {"speed_mph": 500}})", "environment.wind.speed_mph"},
      {R"(, "environment": {"temperature_c": 20, "temperature_f": 70})",
       "environment.temperature_f"},
      {R"(, "aero": {"model": "nathan-2016", "cd0": 0.3})", "aero.cd0"},
      {R"(, "aero": {"model": "magic"})", "aero.model"},
      {R"(, "environment": {"altitude_m": 10})", "environment.altitude_m"},
  };
  for (const auto& c : cases) {
    const Response r = Post(Scene("free_bat", c.extra));
    EXPECT_EQ(r.status, 400) << c.extra << r.body.dump();
    EXPECT_EQ(r.body["field"], c.field) << c.extra << r.body.dump();
  }
}

TEST(BattedBallApiTest, CollisionAnswersTheBattedBallAtItsPoint) {
  const std::string body = R"({"bat": {"preset": "wood-34-ash"}, "ball": {"speed_mph": 90},
      "swing": {"bat_speed_mph": 70, "attack_angle_deg": 10}, "contact": {"undercut_in": 0.75},
      "model": "free_bat", "impact_from_knob_in": 28, "outputs": ["batted_ball"],
      "report_units": "imperial"})";
  const Response r = Dispatch({"POST", "/v1/collision", body}, Context{});
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const auto& b = r.body["batted_ball"];
  EXPECT_NEAR(b["impact_from_knob_m"].get<double>(), 28 * 0.0254, 1e-12);
  EXPECT_GT(b["backspin_rpm"].get<double>(), 0.0);
  EXPECT_TRUE(b.contains("distance_ft"));
  EXPECT_TRUE(r.body["error_estimate"].contains("batted_ball"));
  // Without outputs: no block (the answer as before).
  const Response plain = Dispatch(
      {"POST", "/v1/collision",
       R"({"bat": {"preset": "wood-34-ash"}, "model": "free_bat", "impact_from_knob_m": 0.7})"},
      Context{});
  ASSERT_EQ(plain.status, 200) << plain.body.dump();
  EXPECT_FALSE(plain.body.contains("batted_ball"));
  const Response bad = Dispatch(
      {"POST", "/v1/collision",
       R"({"bat": {"preset": "wood-34-ash"}, "impact_from_knob_m": 0.7, "outputs": ["carry"]})"},
      Context{});
  EXPECT_EQ(bad.status, 400) << bad.body.dump();
  EXPECT_EQ(bad.body["field"], "outputs") << bad.body.dump();
}

TEST(BattedBallApiTest, DistanceSweetSpotAndCarryMap) {
  const Response r = Post(R"({"bat": {"preset": "wood-34-ash"}, "ball": {"speed_mph": 90,
      "descent_angle_deg": 6}, "swing": {"bat_speed_mph": 70, "attack_angle_deg": 10},
      "options": {"model": "free_bat", "distance": {"map_positions": 5, "map_undercuts": 4}},
      "outputs": ["distance_sweet_spot", "carry_map"], "report_units": "imperial"})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const auto& d = r.body["distance_sweet_spot"];
  for (const char* key : {"position_from_knob_m", "position_from_knob_in", "position_from_tip_in",
                          "undercut_m", "undercut_in", "distance_m", "distance_ft",
                          "exit_speed_mps", "exit_speed_mph", "launch_angle_deg", "backspin_rpm"}) {
    EXPECT_TRUE(d.contains(key)) << key << d.dump();
  }
  EXPECT_EQ(d["search"]["normal_law"], "closed_form");
  EXPECT_EQ(d["search"]["termination"], "converged");
  EXPECT_FALSE(d["search"].contains("normal_table_speeds"));
  const auto& m = r.body["carry_map"];
  ASSERT_EQ(m["undercuts_m"].size(), 4u);
  ASSERT_EQ(m["positions"].size(), 5u) << m.dump();
  ASSERT_EQ(m["positions"][0]["distance_m"].size(), 4u);
  EXPECT_TRUE(m["positions"][0].contains("position_from_tip_in"));
  // The lists get their trade twins element by element (the explorer's heat map in feet),
  // nulls kept: 1 in = 0.0254 m and 1 ft = 0.3048 m exactly, so each twin is the SI number
  // divided once (1e-12 relative: one division's rounding, and the test's own).
  ASSERT_EQ(m["undercuts_in"].size(), 4u);
  for (std::size_t j = 0; j < 4; ++j) {
    EXPECT_NEAR(m["undercuts_in"][j].get<double>(), m["undercuts_m"][j].get<double>() / 0.0254,
                1e-12);
  }
  int nulls = 0;
  for (const auto& row : m["positions"]) {
    ASSERT_EQ(row["distance_ft"].size(), 4u) << row.dump();
    for (std::size_t j = 0; j < 4; ++j) {
      if (row["distance_m"][j].is_null()) {
        EXPECT_TRUE(row["distance_ft"][j].is_null()) << row.dump();
        ++nulls;
        continue;
      }
      const double m_value = row["distance_m"][j].get<double>();
      EXPECT_NEAR(row["distance_ft"][j].get<double>(), m_value / 0.3048, 1e-12 * m_value / 0.3048);
    }
  }
  EXPECT_GT(nulls, 0) << "the 2-in undercut column should hold misses (the null branch)";
  EXPECT_LE(m["best"]["distance_m"].get<double>(), d["distance_m"].get<double>() + 0.03);
  // options.distance's fields are refused by name.
  const struct {
    const char* distance;
    const char* field;
  } cases[] = {
      {R"({"map_positions": 1})", "options.distance.map_positions"},
      {R"({"undercut_max_m": 0.5})", "options.distance.undercut_max_m"},
      {R"({"position_min_from_knob_m": 0.8, "position_max_from_knob_m": 0.7})",
       "options.distance.position_max_from_knob_m"},
      {R"({"normal_table_speeds": 40})", "options.distance.normal_table_speeds"},
      {R"({"grid": 3})", "options.distance.grid"},
  };
  for (const auto& c : cases) {
    const Response bad = Post(std::string(R"({"bat": {"preset": "wood-34-ash"},
        "outputs": ["carry_map"], "options": {"distance": )") +
                              c.distance + "}}");
    EXPECT_EQ(bad.status, 400) << c.distance << bad.body.dump();
    EXPECT_EQ(bad.body["field"], c.field) << c.distance << bad.body.dump();
  }
}

TEST(BattedBallApiTest, ExploreSweepsTheUndercut) {
  const Response r = Dispatch({"POST", "/v1/explore",
                               R"({"bat": {"preset": "wood-34-ash"}, "ball": {"speed_mph": 90},
           "swing": {"bat_speed_mph": 70}, "options": {"model": "free_bat"},
           "outputs": ["batted_ball"],
           "parameters": [{"path": "contact.undercut_in", "min": 0, "max": 1, "count": 3}]})"},
                              Context{});
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const auto& rows = r.body["rows"];
  ASSERT_EQ(rows.size(), 3u) << r.body.dump();
  double previous = -1.0;
  for (const auto& row : rows) {  // backspin grows with the undercut
    const double spin = row["batted_ball"]["backspin_rpm"].get<double>();
    EXPECT_GT(spin, previous) << row.dump();
    previous = spin;
  }
}

TEST(BattedBallApiTest, ExploreColumnsOfTheBattedBallOutputs) {
  nlohmann::json body = nlohmann::json::parse(
      R"({"bat": {"preset": "wood-34-ash"}, "ball": {"speed_mph": 90, "descent_angle_deg": 6},
          "swing": {"bat_speed_mph": 70, "attack_angle_deg": 10},
          "contact": {"undercut_in": 0.5}, "options": {"model": "free_bat"},
          "outputs": ["batted_ball", "distance_sweet_spot"],
          "parameters": [{"path": "swing.attack_angle_deg", "min": 5, "max": 15, "count": 3}]})");
  const Response full = Dispatch({"POST", "/v1/explore", body.dump()}, Context{});
  ASSERT_EQ(full.status, 200) << full.body.dump();
  body["columns"] = {"batted_ball.distance_m", "batted_ball.launch_angle_deg",
                     "distance_sweet_spot.position_from_knob_m", "distance_sweet_spot.undercut_in",
                     "distance_sweet_spot.search.evaluations"};
  const Response cols = Dispatch({"POST", "/v1/explore", body.dump()}, Context{});
  ASSERT_EQ(cols.status, 200) << cols.body.dump();
  ASSERT_EQ(cols.body["rows"].size(), 3u);
  double previous_launch = -90.0;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& row = full.body["rows"][i];
    const auto& flat = cols.body["rows"][i];
    EXPECT_EQ(flat["batted_ball.distance_m"], row["batted_ball"]["distance_m"]) << i;
    EXPECT_EQ(flat["distance_sweet_spot.position_from_knob_m"],
              row["distance_sweet_spot"]["position_from_knob_m"])
        << i;
    EXPECT_NEAR(flat["distance_sweet_spot.undercut_in"].get<double>(),
                row["distance_sweet_spot"]["undercut_m"].get<double>() / 0.0254, 1e-12);
    EXPECT_EQ(flat["distance_sweet_spot.search.evaluations"],
              row["distance_sweet_spot"]["search"]["evaluations"]);
    // A steeper swing launches the same contact higher.
    EXPECT_GT(flat["batted_ball.launch_angle_deg"].get<double>(), previous_launch) << i;
    previous_launch = flat["batted_ball.launch_angle_deg"].get<double>();
  }
}

}  // namespace
}  // namespace batted_ball_api_test
}  // namespace sweetspot::api
