// POST /v1/flight through the router: the contract's names, Nathan's worked case in the trade's
// units, many launches, the trajectory, report_units' feet, and the refusals naming the field
// (NaN, a launch angle of 120°, 10⁶ rpm, a 500 mph wind, 150 % humidity, a ball that never
// lands).
#include <gtest/gtest.h>

#include <string>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace flight_api_test {
namespace {

Response Post(const std::string& body, const Context& context = Context{}) {
  return Dispatch({"POST", "/v1/flight", body}, context);
}

// Nathan's sheet, tab BattedBallTrajectory-2, written as a weather report gives it: 103 mph,
// 27.5°, 2500 rpm, 70 °F, 15 ft, 50 %, 29.92 inHg: 421.49 ft by the sheet's 0.01 s steps; the
// converged flight is 422.18 ft (tests/core/flight_test.cpp), so 2 ft.
TEST(FlightApiTest, NathanCaseInTradeUnits) {
  const Response r = Post(R"({"launch": {"exit_speed_mph": 103, "launch_angle_deg": 27.5,
      "backspin_rpm": 2500, "sidespin_rpm": 0, "height_ft": 3, "start_y_ft": 2},
      "environment": {"temperature_f": 70, "elevation_ft": 15, "relative_humidity_pct": 50,
                      "pressure_inhg": 29.92},
      "report_units": "imperial"})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const auto& b = r.body;
  EXPECT_NEAR(b["distance_ft"].get<double>(), 421.49, 2.0);
  EXPECT_NEAR(b["distance_m"].get<double>() / 0.3048, b["distance_ft"].get<double>(), 1e-9);
  EXPECT_NEAR(b["hang_time_s"].get<double>(), 5.52, 0.02);
  EXPECT_NEAR(b["air_density_kg_m3"].get<double>(), 1.19377, 1e-4);
  EXPECT_TRUE(b["landing"].contains("y_ft"));
  EXPECT_TRUE(b.contains("apex_ft"));
  EXPECT_EQ(b["spin_source"], "given");
  EXPECT_EQ(b["aero_model"], "nathan-2016");
  EXPECT_TRUE(b["classification"]["barrel"].get<bool>());
  EXPECT_TRUE(b["classification"]["hard_hit"].get<bool>());
  EXPECT_TRUE(b["classification"]["sweet_spot_launch"].get<bool>());
  EXPECT_EQ(b["numerics"]["method"], "dormand_prince_5_4");
  EXPECT_EQ(b["numerics"]["termination"], "landed");
  EXPECT_LT(b["numerics"]["error_estimate_m"].get<double>(), 0.03);
  EXPECT_EQ(b["models_used"], nlohmann::json::array({"flight:nathan-2016"}));
  EXPECT_TRUE(b.contains("timing_s"));
}

TEST(FlightApiTest, SpinIsEstimatedWhenNotGivenAndManyLaunchesKeepTheirOrder) {
  const Response r = Post(R"({"launches": [
      {"exit_speed_mps": 44.704, "launch_angle_deg": 27.5},
      {"exit_speed_mps": 44.704, "launch_angle_deg": 27.5, "batter_hand": "left"},
      {"exit_speed_mps": 30, "launch_angle_deg": 5, "spray_angle_deg": -20}],
      "aero": {"spin_decay_s": 10000}})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const auto& f = r.body["flights"];
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0]["spin_source"], "statcast_relation");
  EXPECT_DOUBLE_EQ(f[0]["backspin_rpm"].get<double>(), 2537.0);
  EXPECT_DOUBLE_EQ(f[0]["sidespin_rpm"].get<double>(), -849.0);
  // The sheet's tab BattedBallTrajectory-1: 400.55 ft at bearing 5.87° (2 ft, 0.1°: its steps).
  EXPECT_NEAR(f[0]["distance_m"].get<double>() / 0.3048, 400.55, 2.0);
  EXPECT_NEAR(f[0]["bearing_deg"].get<double>(), 5.866, 0.1);
  EXPECT_NEAR(f[1]["bearing_deg"].get<double>(), -f[0]["bearing_deg"].get<double>(), 1e-9);
  EXPECT_LT(f[2]["distance_m"].get<double>(), 60.0);
}

TEST(FlightApiTest, TrajectoryAndVacuum) {
  const Response r = Post(R"({"launch": {"exit_speed_mps": 40, "launch_angle_deg": 45,
      "backspin_rpm": 0, "sidespin_rpm": 0, "height_m": 0, "start_y_m": 0},
      "aero": {"model": "vacuum"}, "outputs": ["trajectory"]})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  // v²/g from the ground at 45°, to round-off.
  EXPECT_NEAR(r.body["distance_m"].get<double>(), 1600.0 / 9.80665, 1e-9);
  EXPECT_EQ(r.body["air_density_kg_m3"].get<double>(), 0.0);
  const auto& t = r.body["trajectory"];
  ASSERT_GT(t.size(), 50u);
  EXPECT_EQ(t.back()["z_m"].get<double>(), 0.0);
}

TEST(FlightApiTest, CustomAndSawickiModels) {
  Response r = Post(R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28},
      "aero": {"model": "custom", "cd0": 0.35, "lift_law": "linear", "cl_per_spin_factor": 1.0,
               "spin_decay_s": 25}})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["aero_model"], "custom");
  r = Post(R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28},
      "aero": {"model": "sawicki-2003"}})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["models_used"], nlohmann::json::array({"flight:sawicki-2003"}));
  // Its drag curve is not the paper's numbers: the answer warns (the other models do not).
  ASSERT_TRUE(r.body.contains("warnings")) << r.body.dump();
  EXPECT_NE(r.body["warnings"][0].get<std::string>().find("not validated"), std::string::npos);
  r = Post(R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28}})");
  EXPECT_FALSE(r.body.contains("warnings")) << r.body.dump();
  // A custom coefficient with another model would be ignored: refused.
  r = Post(R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28},
      "aero": {"model": "nathan-2016", "cd0": 0.35}})");
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "aero.cd0");
}

struct Bad {
  const char* body;
  const char* field;
  int status;
};

TEST(FlightApiTest, BadInputIsRefusedNamingTheField) {
  const Bad cases[] = {
      // NaN is no JSON: the parser refuses it.
      {R"({"launch": {"exit_speed_mph": NaN, "launch_angle_deg": 20}})", "", 400},
      {R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 120}})", "launch.launch_angle_deg",
       400},
      {R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 20, "backspin_rpm": 1e6,
          "sidespin_rpm": 0}})",
       "launch.backspin_rpm", 400},
      {R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 20},
          "environment": {"wind": {"speed_mph": 500}}})",
       "environment.wind.speed_mph", 400},
      {R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 20},
          "environment": {"relative_humidity_pct": 150}})",
       "environment.relative_humidity_pct", 400},
      {R"({"launch": {"exit_speed_mph": 1000, "launch_angle_deg": 20}})", "launch.exit_speed_mph",
       400},
      {R"({"launch": {"launch_angle_deg": 20}})", "launch.exit_speed_mps", 400},
      {R"({"launch": {"exit_speed_mps": 40, "exit_speed_mph": 90, "launch_angle_deg": 20}})",
       "launch.exit_speed_mph", 400},
      {R"({"launch": {"exit_speed_mps": 40, "launch_angle_deg": 20, "backspin_rpm": 2000}})",
       "launch.sidespin_rpm", 400},
      {R"({"launch": {"exit_speed_mps": 40, "launch_angle_deg": 20, "spin": 2000}})", "launch.spin",
       400},
      {R"({"launches": []})", "launches", 400},
      {R"({"launch": {"exit_speed_mps": 40, "launch_angle_deg": 20},
          "environment": {"temperature_f": 500}})",
       "environment.temperature_f", 400},
      {R"({"launch": {"exit_speed_mps": 40, "launch_angle_deg": 20},
          "environment": {"pressure_hpa": 5}})",
       "environment.pressure_hpa", 400},
      {R"({"launch": {"exit_speed_mps": 40, "launch_angle_deg": 20}, "outputs": ["spin"]})",
       "outputs", 400},
  };
  for (const Bad& c : cases) {
    const Response r = Post(c.body);
    EXPECT_EQ(r.status, c.status) << c.body << "\n" << r.body.dump();
    if (*c.field != '\0') {
      EXPECT_EQ(r.body["field"], c.field) << r.body.dump();
    }
  }
  // The message names the field as written, its value and the SI rule.
  const Response wind = Post(cases[3].body);
  EXPECT_EQ(wind.body["message"],
            "environment.wind.speed_mph = 500: must be in [0, 50] as speed_mps (223.52)");
  EXPECT_EQ(Post(cases[12].body).body["message"],
            "environment.pressure_hpa = 5: must be in [80000, 110000] as sea_level_pressure_pa "
            "(500)");
}

TEST(FlightApiTest, TooManyLaunchesIs413) {
  Context context;
  context.limits.max_launches = 2;
  const Response r = Post(R"({"launches": [{"exit_speed_mps": 40, "launch_angle_deg": 20},
      {"exit_speed_mps": 40, "launch_angle_deg": 20},
      {"exit_speed_mps": 40, "launch_angle_deg": 20}]})",
                          context);
  EXPECT_EQ(r.status, 413);
  EXPECT_EQ(r.body["code"], "TooBig");
  EXPECT_EQ(r.body["field"], "launches");
  // Trajectories are bounded over all launches: 4 x (30 s / 0.001 s + 2) samples is too many.
  const Response t = Post(R"({"launches": [{"exit_speed_mps": 40, "launch_angle_deg": 20},
      {"exit_speed_mps": 40, "launch_angle_deg": 20},
      {"exit_speed_mps": 40, "launch_angle_deg": 20},
      {"exit_speed_mps": 40, "launch_angle_deg": 20}], "outputs": ["trajectory"],
      "options": {"trajectory_interval_s": 0.001}})");
  EXPECT_EQ(t.status, 413);
  EXPECT_EQ(t.body["field"], "outputs");
}

// A ball that never lands within the time limit: a clear 422, not a hang; in a batch, its row.
TEST(FlightApiTest, ABallStillUpAtTheTimeLimitIsAnError) {
  Response r = Post(R"({"launch": {"exit_speed_mps": 40, "launch_angle_deg": 60},
      "options": {"max_flight_time_s": 1}})");
  EXPECT_EQ(r.status, 422) << r.body.dump();
  EXPECT_EQ(r.body["code"], "ModelFailed");
  EXPECT_EQ(r.body["field"], "options.max_flight_time_s");
  EXPECT_EQ(r.body["message"],
            "launch: the ball was still in the air at max_flight_time_s = 1 s (no landing)");
  r = Post(R"({"launches": [{"exit_speed_mps": 40, "launch_angle_deg": 60},
      {"exit_speed_mps": 40, "launch_angle_deg": 1}], "options": {"max_flight_time_s": 1}})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["flights"][0]["numerics"]["termination"], "time_limit");
  EXPECT_FALSE(r.body["flights"][0].contains("distance_m"));
  EXPECT_TRUE(r.body["flights"][1].contains("distance_m"));
}

// Many balls that never come down: a custom lift with no drag and no spin decay holds each one
// up (it drifts sideways on a looping path) until max_flight_time_s = 600 s, ~6,700 steps
// (~3 ms) each. The request's budget of 2,000,000 steps over all its launches bounds the work:
// once it is spent, each later launch flies with the smallest step limit (10) and its row says
// why it did not land. Without the budget, 4096 such launches would take ~25 s of CPU.
TEST(FlightApiTest, BallsThatNeverLandStopAtTheRequestsStepBudget) {
  constexpr int kLaunches = 400;  // ~6,700 steps each: the budget is spent after ~300
  std::string launches;
  for (int i = 0; i < kLaunches; ++i) {
    launches += std::string(i ? "," : "") +
                R"({"exit_speed_mps": 20, "launch_angle_deg": 0, "backspin_rpm": 10000,
                    "sidespin_rpm": 0})";
  }
  const Response r = Post(R"({"launches": [)" + launches + R"(],
      "aero": {"model": "custom", "cd0": 0, "cd_spin_per_krpm": 0, "lift_law": "linear",
               "cl_per_spin_factor": 10, "spin_decay_s": 1e6},
      "options": {"max_flight_time_s": 600}})");
  ASSERT_EQ(r.status, 200) << r.body.dump().substr(0, 500);
  const auto& flights = r.body["flights"];
  ASSERT_EQ(flights.size(), static_cast<std::size_t>(kLaunches));
  long long total = 0;
  for (const auto& f : flights) {
    total += f["numerics"]["steps"].get<long long>() + f["numerics"]["rejected_steps"].get<long long>();
    EXPECT_FALSE(f.contains("distance_m"));
  }
  // The budget, plus at most the 10-step minimum for each launch after it was spent.
  EXPECT_LE(total, 2000000 + 10LL * kLaunches);
  EXPECT_GT(total, 2000000 - 20000);  // it was spent (the last full flight took < 20,000)
  EXPECT_EQ(flights[0]["numerics"]["termination"], "time_limit");
  EXPECT_EQ(flights[kLaunches - 1]["numerics"]["termination"], "step_limit");
  EXPECT_EQ(flights[kLaunches - 1]["message"],
            "the integrator took max_steps = 10 steps before the ball landed (the request's "
            "budget of 2000000 integrator steps over all its launches was spent by the launches "
            "before it)");
}

}  // namespace
}  // namespace flight_api_test
}  // namespace sweetspot::api
