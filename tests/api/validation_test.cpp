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
  // Not matched: wood-34-ash rings at 116 Hz, 32 % below "around 170 Hz". Pinned to +-5 % so a
  // change of the preset or the beam shows here and in validation.md.
  EXPECT_NEAR(ash["vibration_node"]["frequency_hz"].get<double>(), 116.1, 0.05 * 116.1);
  // Where the 32 % comes from (validation.md): the material and the profile about equally.
  // wood-34-ash's profile in paper-wood's material (E = 18.14 GPa, 649 kg/m3) rings at 145.7 Hz,
  // and paper-wood's profile in ash (the Wood Handbook's 12.0 GPa, 672 kg/m3) at 140.9 Hz. These
  // are the model's own numbers, pinned at +-1 % (the doc quotes them to 0.1 Hz; a change of the
  // beam model moves them by more).
  const auto frequency_of = [](const char* preset, const char* material) {
    const Json r = Post("/v1/sweet-spot", Json{{"bat", {{"preset", preset}, {"material", material}}},
                                              {"outputs", {"vibration_node"}}});
    return r["vibration_node"]["frequency_hz"].get<double>();
  };
  EXPECT_NEAR(frequency_of("wood-34-ash", "paper-wood"), 145.7, 0.01 * 145.7);
  EXPECT_NEAR(frequency_of("paper-wood", "ash"), 140.9, 0.01 * 140.9);
}

// Issue 35, "wood bats that ring like wood bats": a turned pro maple bat in the bat-grade
// billet values of Appl. Sci. 12(7), 3494 (2022) (material "maple-bat-billet", E = 15.16 GPa at
// 637 kg/m3) rings at 143.1 Hz, 16 % below Russell's "around 170 Hz": outside +-10 %, for the
// reason validation.md gives (with these moduli a medium handle tapering from 11 in rings
// near 143 Hz; 170 Hz needs E = 21.4 GPa on this profile, or a thick handle and a taper from
// 9 in). Pinned at
// +-1 % (the model's own number; a change of the preset, the material or the beam moves it by
// more), with the material's share the row quotes (the Wood Handbook's hard maple on this
// profile: 124.0 Hz).
TEST(ValidationTest, TurnedMapleBatRingsWithBatGradeBillets) {
  const auto mode_of = [](const Json& bat) {
    return Post("/v1/sweet-spot", Json{{"bat", bat}, {"outputs", {"vibration_node"}}});
  };
  const Json maple = mode_of(Json{{"preset", "wood-34-maple-turned"}});
  const double f1 = maple["vibration_node"]["frequency_hz"].get<double>();
  EXPECT_NEAR(f1, 143.1, 0.01 * 143.1);
  EXPECT_NEAR(f1, 170.0, 0.20 * 170.0);  // within 20 % of the measurement: the row's verdict
  EXPECT_GT(f1, 116.1 * 1.2);            // and 23 % above wood-34-ash
  const double length = maple["properties"]["length_m"].get<double>();
  const double node_from_tip =
      (length - maple["vibration_node"]["position_from_knob_m"].get<double>()) / kInch;
  EXPECT_GE(node_from_tip, 5.0);  // Russell's barrel node, 5-7 in from the end
  EXPECT_LE(node_from_tip, 7.5);  // 7.1 in: 0.1 in past "usually 5-7 inches"
  EXPECT_NEAR(maple["properties"]["imperial"]["weight_oz"].get<double>(), 32.05, 0.01);
  // The material alone: the handbook's small clear hard maple (12.6 GPa, 706 kg/m3).
  const Json handbook = mode_of(Json{{"preset", "wood-34-maple-turned"}, {"material", "maple"}});
  EXPECT_NEAR(handbook["vibration_node"]["frequency_hz"].get<double>(), 124.0, 0.01 * 124.0);
}

// Issue 35, "bats as they are built": the hollow presets' max-exit point against Russell's
// 5-7 in from the barrel end (the row above), in the scene (90 mph pitch, 70 mph bat
// speed). The open tube (bbcor-33-aluminium) sits at 7.7 in; closed by a 1-oz end cap and a
// 1-oz knob with its handle wall solved for the same 30 oz (bbcor-33-alloy-capped) it is at
// 6.8 in, inside; the end cap is the lever (validation.md). The model's own numbers are pinned
// at +-0.05 in (a change of the presets, the barrel or the exit model moves them by more);
// the BBCOR scan's maximum location and the hoop frequency at +-0.1 in and +-1 %.
TEST(ValidationTest, BuiltHollowBatsMaxExitPointAndHoopFrequency) {
  struct Row {
    Json bat;
    double max_exit_from_tip_in, scan_max_from_tip_in, hoop_hz;
  };
  const Json cap = {{"mass_oz", 1.0}, {"length_in", 0.5}};
  const Row rows[] = {
      {Json{{"preset", "bbcor-33-aluminium"}}, 7.73, 6.01, 1777.5},
      {Json{{"preset", "bbcor-33-alloy-capped"}}, 6.83, 5.43, 1777.5},
      {Json{{"preset", "composite-33-bbcor"}}, 7.12, 5.56, 4105.0},
      {Json{{"preset", "bbcor-33-aluminium"}, {"end_cap", cap}}, 7.12, 5.44, 1777.5},
  };
  double from_tip[4];
  for (int i = 0; i < 4; ++i) {
    const Row& row = rows[i];
    const Json r =
        Post("/v1/sweet-spot", Json{{"bat", row.bat},
                                    {"ball", {{"speed_mph", 90}}},
                                    {"swing", {{"bat_speed_mph", 70}}},
                                    {"outputs", {"max_exit_speed", "bbcor_scan", "barrel"}}});
    const double length = r["properties"]["length_m"].get<double>();
    from_tip[i] = (length - r["max_exit_speed"]["position_from_knob_m"].get<double>()) / kInch;
    EXPECT_NEAR(from_tip[i], row.max_exit_from_tip_in, 0.05) << row.bat.dump();
    // The scan's maximum is flat, its location the least certain of the three: +-0.1 in (the
    // scan's polished search moves the open tube's by 0.009 in against this single parabola).
    EXPECT_NEAR(r["bbcor_scan"]["max_from_tip_m"].get<double>() / kInch, row.scan_max_from_tip_in,
                0.1)
        << row.bat.dump();
    EXPECT_NEAR(r["barrel"]["hoop_frequency_hz"].get<double>(), row.hoop_hz, 0.01 * row.hoop_hz)
        << row.bat.dump();
  }
  EXPECT_GT(from_tip[0], 7.0);  // the open tube: outside Russell's 5-7 in
  EXPECT_GE(from_tip[1], 5.0);  // as built: inside
  EXPECT_LE(from_tip[1], 7.0);
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

// The ball's COR at the MLB test: 0.514 to 0.578 at 85 ft/s (58 mph) against northern white
// ash (D. Ropeik, "Squeezing the 'juice' out of baseballs", msnbc.com 2003, the UMass Lowell
// test; D. Kagan and D. Atkinson, "The coefficient of restitution of baseballs as a function of
// relative humidity" (docslib.org copy): "0.546 +/- 0.032"). The catalogue's MLB ball at the
// test speed, and the law across the test's speed, must sit in that band.
TEST(ValidationTest, MlbBallCorAtTheSpecificationTest) {
  const Response r = Dispatch({"GET", "/v1/balls", ""}, Context{});
  ASSERT_EQ(r.status, 200);
  const Json& mlb = r.body["balls"][0];
  ASSERT_EQ(mlb["name"], "mlb");
  EXPECT_NEAR(mlb["cor_test_speed_mps"].get<double>(), 85 * 0.3048, 1e-12);
  const double e = mlb["cor"].get<double>();
  EXPECT_GE(e, 0.514);
  EXPECT_LE(e, 0.578);
  EXPECT_NEAR(e, 0.546, 1e-15);  // the specification's centre, exactly
  // The collision at the test (a ball at 85 ft/s onto a wood bat at rest, at the bat's centre
  // of percussion region) takes its COR from the law at 85 ft/s: the same band.
  const Json c = Post("/v1/collision", Json{{"bat", {{"preset", "wood-34-ash"}}},
                                            {"ball", {{"preset", "mlb"}, {"speed_mps", 25.908}}},
                                            {"swing", {{"angular_speed_rad_s", 0}}},
                                            {"impact_from_knob_m", 0.70},
                                            {"model", "free_bat"}});
  EXPECT_NEAR(c["cor"].get<double>(), 0.546, 1e-12);
}

// BBCOR of solid wood bats: the NCAA set its 0.500 limit from measurements of wood bats so that
// non-wood bats perform like wood ("established the performance standard based on data
// collected from available wooden bats", NCAA Baseball Rules Committee, College Baseball Daily,
// 8 Oct 2008; the limit is "only slightly higher than that of a wood bat", BatWarehouse, "BBCOR
// Certification"). No measured BBCOR of a named wood bat was found, so the bound is the
// statement itself: at or below 0.50, and "slightly" read as within 0.05 of it. The model's
// wood bat is rigid (no bending loss), so its BBCOR is the NCAA ball's COR at 136 mph, 0.479.
TEST(ValidationTest, SolidWoodBbcorIsJustBelowTheLimit) {
  for (const char* preset : {"wood-34-ash", "paper-wood"}) {
    const Json r = Post("/v1/sweet-spot", Json{{"bat", {{"preset", preset}}},
                                              {"outputs", {"bbcor"}}});
    // THE BBCOR (issue 35): the flexible scan's maximum, below the rigid estimate (bending
    // takes energy); the estimate is the NCAA ball's COR.
    const double bbcor = r["bbcor"]["value"].get<double>();
    EXPECT_EQ(r["bbcor"]["method"], "flexible_scan_max") << preset;
    EXPECT_EQ(r["bbcor"]["estimate"]["method"], "rigid") << preset;
    EXPECT_LE(bbcor, 0.50) << preset;
    EXPECT_GE(bbcor, 0.45) << preset;
    EXPECT_LT(bbcor, r["bbcor"]["estimate"]["value"].get<double>()) << preset;
    // pinned: 0.555 - 0.001 (136 - 60)
    EXPECT_NEAR(r["bbcor"]["estimate"]["value"].get<double>(), 0.479, 1e-12) << preset;
  }
}

// Hollow bats: the lowest hoop mode. D. A. Russell, "Acoustics of baseball bats", Acoustics
// Today (Winter 2017), p. 42: the hoop-mode frequency of softball bats (his Figure 3) "ranges
// from 1,000 Hz to 2,500 Hz". No range for BBCOR baseball bats was found; the softball range is
// the bound. A. M. Nathan, J. J. Crisco, R. M. Greenwald, D. A. Russell, L. V. Smith, "A
// comparative study of baseball bat performance", Sports Eng. 13, 153 (2011): "the BBCOR is
// strongly correlated with the frequency of the lowest hoop mode of the hollow bats, as
// predicted by models of the trampoline effect"; Russell, "Hoop frequency as a predictor of
// performance for softball bats": "higher performance bats ... tend to have lower hoop
// frequencies". The model must show that trend over the walls of real alloy bats.
TEST(ValidationTest, HoopFrequencyOfHollowBatsAndItsLinkToBbcor) {
  const Json preset = Post("/v1/sweet-spot", Json{{"bat", {{"preset", "bbcor-33-aluminium"}}},
                                                 {"ball", {{"preset", "ncaa-nfhs"}}},
                                                 {"outputs", {"barrel", "bbcor"}}});
  const double hoop = preset["barrel"]["hoop_frequency_hz"].get<double>();
  EXPECT_GE(hoop, 1000.0);
  EXPECT_LE(hoop, 2500.0);
  EXPECT_NEAR(hoop, 1777.5, 0.5);  // pinned (closed form; docs/validation.md)
  // Walls of 2.0 to 3.5 mm: every one in the published range, and BBCOR falls as the hoop
  // frequency rises (a strict ordering: the published trend is a correlation, the model's is
  // monotone).
  double previous_hoop = 0.0, previous_bbcor = 1.0;
  for (const double wall_mm : {2.0, 2.5, 3.0, 3.5}) {
    const Json r =
        Post("/v1/sweet-spot",
             Json{{"bat", {{"preset", "bbcor-33-aluminium"}, {"wall_thickness_m", wall_mm / 1e3}}},
                  {"ball", {{"preset", "ncaa-nfhs"}}},
                  {"outputs", {"barrel", "bbcor"}}});
    const double f = r["barrel"]["hoop_frequency_hz"].get<double>();
    const double bbcor = r["bbcor"]["value"].get<double>();
    EXPECT_GE(f, 1000.0) << wall_mm;
    EXPECT_LE(f, 2500.0) << wall_mm;
    EXPECT_GT(f, previous_hoop) << wall_mm;
    EXPECT_LT(bbcor, previous_bbcor) << wall_mm;
    previous_hoop = f;
    previous_bbcor = bbcor;
  }
}

// BBCOR of a legal hollow bat: at most 0.500 (the NCAA limit; legal bats are designed up to it).
// For the model this is the CALIBRATION (the shell factor c = 7 is fitted so this preset gives
// 0.500, docs/models.md "Barrel"), not a prediction: the test pins that the calibration holds
// with the catalogue's NCAA ball (0.479 at 136 mph), to the 0.0001 the fit was rounded to. The
// calibration is of the fixed-point ESTIMATE; THE BBCOR (the flexible scan's maximum, issue 35)
// of the preset is 0.4867 (tolerance 5e-4: three times the scan's error estimate, 1.5e-4).
TEST(ValidationTest, HollowBbcorPresetSitsAtTheLimitByCalibration) {
  const Json r = Post("/v1/sweet-spot", Json{{"bat", {{"preset", "bbcor-33-aluminium"}}},
                                            {"outputs", {"bbcor"}}});
  EXPECT_EQ(r["bbcor"]["method"], "flexible_scan_max");
  EXPECT_EQ(r["bbcor"]["estimate"]["method"], "trampoline_quasi_static");
  EXPECT_NEAR(r["bbcor"]["ball_cor"].get<double>(), 0.479, 1e-12);
  EXPECT_NEAR(r["bbcor"]["estimate"]["value"].get<double>(), 0.50, 1e-4);
  EXPECT_LE(r["bbcor"]["value"].get<double>(), 0.50);
  EXPECT_NEAR(r["bbcor"]["value"].get<double>(), 0.4867, 5e-4);
}

}  // namespace
}  // namespace validation_test
}  // namespace sweetspot::api
