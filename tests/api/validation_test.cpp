// Issue 18, "Validation": the models against published measurements (docs/validation.md has
// the table and the sources). Each bound is the measurement's spread, not a tolerance of ours;
// where the model cannot match, the test pins by how much, so a change that moves it shows.
#include <gtest/gtest.h>

#include <string>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace validation_test {
namespace {

using Json = nlohmann::json;

constexpr double kInch = 0.0254;  // m

Json Post(const std::string& path, const Json& body) {
  const Response r = Dispatch({"POST", path, body.dump()}, Context{});
  EXPECT_EQ(r.status, 200) << r.body.dump();
  return r.body;
}

// D. A. Russell, "Vibrational modes of a baseball bat" (Penn State Acoustics and Vibration):
// the first free-free bending mode of a bat "usually occurs at a frequency around 170 Hz"; its
// barrel-end node, a sweet spot, is "usually 5-7 inches from the barrel end"; another node
// is about 6 in from the handle end.
TEST(ValidationTest, FirstBendingModeAndItsNodesOfWoodBats) {
  const Json paper = Post("/v1/sweet-spot", Json{{"bat", {{"preset", "paper-wood"}}},
                                                {"outputs", {"vibration_node"}}});
  // "around 170 Hz": within 15 % (the spread of Russell's wood bats, 165-215 Hz).
  EXPECT_NEAR(paper["vibration_node"]["frequency_hz"].get<double>(), 170.0, 0.15 * 170.0);
  const Json ash = Post("/v1/sweet-spot", Json{{"bat", {{"preset", "wood-34-ash"}}},
                                              {"outputs", {"vibration_node"}}});
  const double length = ash["properties"]["length_m"].get<double>();
  const double node_from_tip =
      (length - ash["vibration_node"]["position_from_knob_m"].get<double>()) / kInch;
  EXPECT_GE(node_from_tip, 5.0);
  EXPECT_LE(node_from_tip, 7.0);
  const double handle_node = ash["vibration_node"]["other_node_from_knob_m"].get<double>() / kInch;
  EXPECT_NEAR(handle_node, 6.0, 2.0);  // "about 6 inches": +-2 in
  // Not matched: wood-34-ash rings at 116 Hz, 32 % below "around 170 Hz" (its handle, a
  // straight taper to 0.0125 m, is thinner over more of its length than a turned pro bat's).
  // Pinned to +-5 % so a change of the preset or the beam shows here and in validation.md.
  EXPECT_NEAR(ash["vibration_node"]["frequency_hz"].get<double>(), 116.1, 0.05 * 116.1);
}

// The max-exit-speed point of a swung bat: 5-7 in from the barrel end (Russell, "What is the
// sweet spot of a baseball bat?"). The default model (free_bat) is there; the paper's pinned bat
// puts it at the tip (docs/models.md, "Which model").
TEST(ValidationTest, MaxExitSpeedPointOfASwungBat) {
  const Json r = Post("/v1/sweet-spot", Json{{"bat", {{"preset", "wood-34-ash"}}},
                                            {"ball", {{"speed_mps", 40}}},
                                            {"swing", {{"angular_speed_rad_s", 45}}}});
  const double from_tip = (r["properties"]["length_m"].get<double>() -
                           r["max_exit_speed"]["position_from_knob_m"].get<double>()) /
                          kInch;
  EXPECT_GE(from_tip, 5.0);
  EXPECT_LE(from_tip, 7.0);
}

// Contact time and peak force of a game-speed impact: about 0.6-1 ms and 20-40 kN (A. M.
// Nathan, "Dynamics of the baseball-bat collision", Am. J. Phys. 68, 979 (2000): ~0.6-0.7 ms at
// the sweet spot; R. K. Adair, "The Physics of Baseball": a peak force of about 8000 lbf,
// 36 kN). Approach speed here 39.8 m/s (89 mph), below a game's 60 m/s, hence the longer, softer
// contact: the bounds are wide on purpose.
TEST(ValidationTest, ContactTimeAndPeakForce) {
  const Json r = Post("/v1/collision", Json{{"bat", {{"preset", "wood-34-ash"}}},
                                           {"impact_from_knob_m", 0.70},
                                           {"model", "hertz"}});
  const double contact_ms = r["hertz"]["contact_time_s"].get<double>() * 1e3;
  EXPECT_GE(contact_ms, 0.5);
  EXPECT_LE(contact_ms, 1.0);
  const double peak_kn = r["hertz"]["peak_force_n"].get<double>() * 1e-3;
  EXPECT_GE(peak_kn, 20.0);
  EXPECT_LE(peak_kn, 45.0);
}

}  // namespace
}  // namespace validation_test
}  // namespace sweetspot::api
