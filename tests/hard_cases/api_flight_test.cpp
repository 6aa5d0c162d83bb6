// Endpoint hard cases of POST /v1/flight: extreme but legal launches and environments answer 200
// with finite numbers in bounded ranges; hostile values are the named 4xx refusal; never a 500,
// never NaN or Infinity (checked on every row by CheckApiCase).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tests/hard_cases/hard_case.hpp"

namespace sweetspot::hard_cases {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace api_flight_test {
namespace {

constexpr double kG = 9.80665;

std::vector<ApiCase> FlightCases() {
  const std::string p = "/v1/flight";
  return {
      // Vacuum from the ground at 45°: v²/g exactly (a Dormand–Prince step is exact on a
      // quadratic; 1e-9 m of round-off over ~160 m).
      Ok("VacuumRangeFromTheGround", p,
         R"({"launch": {"exit_speed_mps": 40, "launch_angle_deg": 45, "height_m": 0,
             "start_y_m": 0, "backspin_rpm": 0, "sidespin_rpm": 0}, "aero": {"model": "vacuum"}})",
         {Near("/distance_m", 1600.0L / kG, 1e-9), Near("/apex_m", 400.0L / kG, 1e-9)}),
      // Straight down from 5 m: lands at once beside the start, no apex above the start.
      Ok("StraightDown", p,
         R"({"launch": {"exit_speed_mps": 30, "launch_angle_deg": -90, "height_m": 5}})",
         {Between("/hang_time_s", 0.1, 0.2), Near("/apex_m", 5, 1e-12),
          Between("/distance_m", 0.5, 0.7)}),
      // Launched along the ground from height 0 pointing down: the landing is the start.
      Ok("FromTheGroundPointingDown", p,
         R"({"launch": {"exit_speed_mps": 30, "launch_angle_deg": -10, "height_m": 0}})",
         {Near("/hang_time_s", 0, 1e-9), Near("/distance_m", 0.6096, 1e-9)}),
      // Straight up at the top speed: comes back down near the plate (spin from the relation
      // bends it a little), hang time under the vacuum's 2v/g = 18.4 s.
      Ok("StraightUpAtTheTopSpeed", p,
         R"({"launch": {"exit_speed_mps": 90, "launch_angle_deg": 90}})",
         {Between("/hang_time_s", 5, 18.4), Between("/apex_m", 50, 413)}),
      // The smallest legal exit speed: it drops from 3 ft.
      Ok("TinyExitSpeed", p, R"({"launch": {"exit_speed_mps": 1e-9, "launch_angle_deg": 0}})",
         {Between("/hang_time_s", 0.43, 0.44), Between("/distance_m", 0.6, 0.62)}),
      // The thinnest air offered (5000 m, 60 °C, 800 hPa, saturated) and the thickest.
      Ok("ThinnestAir", p,
         R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28},
             "environment": {"elevation_m": 5000, "temperature_c": 60, "pressure_hpa": 800,
                             "relative_humidity_pct": 100}})",
         {Between("/air_density_kg_m3", 0.3, 0.6), Between("/distance_m", 140, 230)}),
      Ok("ThickestAir", p,
         R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28},
             "environment": {"elevation_m": -500, "temperature_c": -40, "pressure_hpa": 1100,
                             "relative_humidity_pct": 0}})",
         {Between("/air_density_kg_m3", 1.6, 1.8), Between("/distance_m", 80, 120)}),
      // A 50 m/s head wind at its limit: the ball is blown back behind the plate, and lands.
      Ok("GaleBlowingIn", p,
         R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28},
             "environment": {"wind": {"speed_mps": 50, "direction_deg": 180}}})",
         {Between("/hang_time_s", 1, 10), Is("/numerics/termination", "landed")}),
      // The largest spins: 10,000 rpm back and side.
      Ok("LargestSpins", p,
         R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28, "backspin_rpm": 10000,
             "sidespin_rpm": -10000}})",
         {Between("/distance_m", 50, 200)}),
      // A ball still up at the time limit is a 422 naming the limit, not a hang.
      Refusal("StillUpAtTheTimeLimit", p,
              R"({"launch": {"exit_speed_mps": 90, "launch_angle_deg": 80},
                  "options": {"max_flight_time_s": 1}})",
              422, "ModelFailed", "options.max_flight_time_s"),
      // Custom lift ten times Nathan's and no drag: the ball loops, but it lands (or is stopped
      // by the limit): bounded either way.
      Ok("LiftTenTimesNoDrag", p,
         R"({"launches": [{"exit_speed_mps": 90, "launch_angle_deg": 80, "backspin_rpm": 10000,
             "sidespin_rpm": 0}], "aero": {"model": "custom", "cd0": 0, "cd_spin_per_krpm": 0,
             "lift_law": "linear", "cl_per_spin_factor": 10, "spin_decay_s": 1e6},
             "options": {"max_flight_time_s": 600}})",
         {Between("/flights/0/numerics/steps", 1, 20000)}),
      // The contract's hostile values, each named.
      Refusal("LaunchAngle120", p, R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 120}})",
              400, "InvalidValue", "launch.launch_angle_deg"),
      Refusal("MillionRpm", p,
              R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 20, "backspin_rpm": 1e6,
                  "sidespin_rpm": 0}})",
              400, "InvalidValue", "launch.backspin_rpm"),
      Refusal("Wind500Mph", p,
              R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 20},
                  "environment": {"wind": {"speed_mph": 500}}})",
              400, "InvalidValue", "environment.wind.speed_mph"),
      Refusal("Humidity150", p,
              R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 20},
                  "environment": {"relative_humidity_pct": 150}})",
              400, "InvalidValue", "environment.relative_humidity_pct"),
      Refusal("HugeNumber", p, R"({"launch": {"exit_speed_mph": 1e308, "launch_angle_deg": 20}})",
              400, "InvalidValue", "launch.exit_speed_mph"),
      Refusal("SpeedAsAString", p, R"({"launch": {"exit_speed_mph": "fast", "launch_angle_deg": 20}})",
              400, "InvalidValue", "launch.exit_speed_mph"),
      // The flight sweep (/v1/explore with "flight"): the corners of every swept range at
      // once, the rows in JSON; a launch past 90° is a row, not a failure.
      Ok("SweepCornersOfEveryRange", "/v1/explore",
         R"({"flight": {"launch": {"exit_speed_mps": 40, "launch_angle_deg": 28,
                                   "backspin_rpm": 0, "sidespin_rpm": 0}},
             "parameters": [{"path": "launch.exit_speed_mps", "min": 1e-9, "max": 90},
                            {"path": "launch.launch_angle_deg", "min": -90, "max": 90},
                            {"path": "launch.backspin_rpm", "min": -10000, "max": 10000},
                            {"path": "environment.wind.speed_mps", "min": 0, "max": 50},
                            {"path": "environment.elevation_m", "min": -500, "max": 5000}]})",
         {Near("/summary/designs", 32, 0), Between("/summary/landed", 1, 32)}),
      Ok("SweepAngleThroughTheLimit", "/v1/explore",
         R"({"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28}},
             "parameters": [{"path": "launch.launch_angle_deg", "min": 85, "max": 125,
                             "count": 3}]})",
         {Is("/rows/2/flight/numerics/termination", "invalid_input"),
          Is("/rows/0/flight/numerics/termination", "landed")}),
      Refusal("SweepOfAnUnknownPath", "/v1/explore",
              R"({"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28}},
                  "parameters": [{"path": "launch.spin_rpm", "min": 0, "max": 1}]})",
              400, "InvalidValue", "parameters[0].path"),
      Refusal("TwoFormsOfOneQuantity", p,
              R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 20},
                  "environment": {"temperature_c": 20, "temperature_f": 68}})",
              400, "InvalidValue", "environment.temperature_f"),
  };
}

class HardCaseFlightEndpoint : public testing::TestWithParam<ApiCase> {};
TEST_P(HardCaseFlightEndpoint, Answers) { CheckApiCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Api, HardCaseFlightEndpoint, testing::ValuesIn(FlightCases()),
                         RowName<ApiCase>);

}  // namespace
}  // namespace api_flight_test
}  // namespace sweetspot::hard_cases
