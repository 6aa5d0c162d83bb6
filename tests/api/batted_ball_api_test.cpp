// The batted_ball scene output through the router: head-on it is max_exit_speed's impact
// launched level; an undercut gives backspin and lift; the new scene fields are refused out of
// range or as the wrong model, naming the field as written.
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
      {R"(, "swing": {"bat_speed_mph": 70, "attack_angle_deg": -120})",
       "swing.attack_angle_deg"},
      {R"(, "contact": {"undercut_m": "x"})", "contact.undercut_m"},
  };
  for (const auto& c : cases) {
    const Response r = Post(Scene("free_bat", c.extra));
    EXPECT_EQ(r.status, 400) << c.extra << r.body.dump();
    EXPECT_NE(r.body.dump().find(c.field), std::string::npos) << c.extra << r.body.dump();
  }
}

TEST(BattedBallApiTest, RefusesAModelItCannotFeed) {
  const Response r = Post(Scene("hertz", ""));
  EXPECT_GE(r.status, 400) << r.body.dump();
  EXPECT_LT(r.status, 500) << r.body.dump();
  EXPECT_NE(r.body.dump().find("options.model"), std::string::npos) << r.body.dump();
}

TEST(BattedBallApiTest, ExploreSweepsTheUndercut) {
  const Response r = Dispatch(
      {"POST", "/v1/explore",
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

}  // namespace
}  // namespace batted_ball_api_test
}  // namespace sweetspot::api
