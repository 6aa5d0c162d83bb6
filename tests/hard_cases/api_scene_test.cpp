// Endpoint hard cases of the scene endpoints: POST /v1/sweet-spot, /v1/collision (each model)
// and /v1/compare. Each nasty request must answer 200 with finite numbers in a bounded range,
// or the named 4xx refusal; never a 500, never NaN or Infinity (checked on every row).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "tests/hard_cases/hard_case.hpp"

namespace sweetspot::hard_cases {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace api_scene_test {
namespace {

// A paper-wood request with more top-level fields (`rest`, with a leading comma).
std::string Paper(const std::string& rest = "") {
  return R"({"bat": {"preset": "paper-wood"})" + rest + "}";
}

// paper-wood (rigid body, pivot at the knob): J = 0.4124286926652587 kg m^2; the paper's scene
// u = 27.7 m/s, omega = 17.288 rad/s, m = 0.145 kg. S = sqrt(u^2 + omega^2 J / m).
constexpr double kJ = 0.4124286926652587;
const double kS = std::sqrt(27.7 * 27.7 + 17.288 * 17.288 * kJ / 0.145);
// x* = omega J / (m (u + S)) (independent of e): 0.724016446183458 m.
const double kSweetSpot = 17.288 * kJ / (0.145 * (27.7 + kS));
// Closed forms through JSON: a few eps of ~40 m/s; 1e-12 leaves room and still pins them.
constexpr double kTight = 1e-12;

// POST /v1/sweet-spot.
std::vector<ApiCase> SweetSpotCases() {
  const std::string p = "/v1/sweet-spot";
  return {
      // Known bug being fixed in api/scene_json.cpp: a subnormal ball mass made 1/m infinite in
      // the free-bat model (NaN in the answer). It must be refused by the ball's rule.
      AsJob(Refusal("SubnormalBallMassFreeBat", p,
                    Paper(R"(, "ball": {"mass_kg": 5e-324}, "options": {"model": "free_bat"})"),
                    400, "InvalidValue", "ball.mass_kg")),
      Refusal("BallMassBelowTheFloor", p, Paper(R"(, "ball": {"mass_kg": 1e-7})"), 400,
              "InvalidValue", "ball.mass_kg"),
      // 1 mg: the maximiser is ~640 m beyond the tip; the tip is reported exactly.
      Ok("BallMassAtTheFloorFreeBat", p,
         Paper(R"(, "ball": {"mass_kg": 1e-6}, "options": {"model": "free_bat"})"),
         {Near("/max_exit_speed/position_from_knob_m", 0.855, 0),
          Is("/max_exit_speed/placement", "beyond_tip"),
          Between("/max_exit_speed/exit_speed_mps", 27.7, 60.0)}),
      // A 1000 kg ball against a 1 kg bat on a fixed pivot: the pivot takes the blow, v2max is
      // just above e u = 13.85 m/s, near the pivot.
      Ok("BallOf1000Kg", p, Paper(R"(, "ball": {"mass_kg": 1000})"),
         {Between("/max_exit_speed/exit_speed_mps", 13.85, 13.86),
          Between("/max_exit_speed/position_from_knob_m", 0, 1e-3)}),
      // No swing, no ball: 0 everywhere, said so; the zone is the whole bat.
      Ok("NoSwingNoBall", p,
         Paper(R"(, "ball": {"speed_mps": 0}, "swing": {"angular_speed_rad_s": 0},
                  "outputs": ["max_exit_speed", "sweet_zone", "exit_speed_curve"],
                  "options": {"curve_samples": 3})"),
         {Near("/max_exit_speed/exit_speed_mps", 0, 0), Near("/sweet_zone/from_knob_m", 0, 0),
          Near("/sweet_zone/to_knob_m", 0.855, 0),
          Near("/exit_speed_curve/2/exit_speed_mps", 0, 0)}),
      // e = 0: v2max = (S - u) / 2; e = 1: v2max = S; x* does not depend on e.
      Ok("CorZero", p, Paper(R"(, "cor": 0)"),
         {Near("/max_exit_speed/exit_speed_mps", (kS - 27.7) / 2, kTight),
          Near("/max_exit_speed/position_from_knob_m", kSweetSpot, kTight)}),
      Ok("CorOne", p, Paper(R"(, "cor": 1)"),
         {Near("/max_exit_speed/exit_speed_mps", kS, kTight),
          Near("/max_exit_speed/position_from_knob_m", kSweetSpot, kTight)}),
      // Hands at the centroid: the centre of percussion is at infinity: refused on the hands.
      Refusal(
          "HandsAtTheCentroid", p,
          Paper(
              R"(, "swing": {"hands_from_knob_m": 0.6089948432432433}, "outputs": ["center_of_percussion"])"),
          400, "InvalidValue", "swing.hands_from_knob_m"),
      // Hands 1e-9 m before it: CoP = C + I_cm / (M 1e-9) = 3.835e7 m, beyond the tip, finite.
      Ok("HandsANanometreBeforeTheCentroid", p,
         Paper(
             R"(, "swing": {"hands_from_knob_m": 0.6089948422432433}, "outputs": ["center_of_percussion"])"),
         {Between("/center_of_percussion/position_from_knob_m", 3.8e7, 3.9e7),
          Is("/center_of_percussion/placement", "beyond_tip")}),
      // omega = 1e4 rad/s, u = 1000 m/s (both at their limits): the tip, ~1.04e4 m/s.
      Ok("FastestSwingAndBall", p,
         Paper(R"(, "swing": {"angular_speed_rad_s": 1e4}, "ball": {"speed_mps": 1000},
                  "outputs": ["max_exit_speed", "sweet_zone"])"),
         {Between("/max_exit_speed/exit_speed_mps", 1e4, 1.1e4),
          Between("/sweet_zone/to_knob_m", 0, 0.855)}),
      // A pivot 100 m beyond the knob: the maximiser (362 m) is clamped to the tip, which must
      // be the tip exactly, and the zone must stay on the bat.
      Ok("PivotAHundredMetresAway", p,
         Paper(R"(, "swing": {"pivot_from_knob_m": 100, "angular_speed_rad_s": 1e4},
                  "outputs": ["max_exit_speed", "sweet_zone"])"),
         {Near("/max_exit_speed/position_from_knob_m", 0.855, 0),
          Between("/sweet_zone/from_knob_m", 0, 0.855),
          Between("/sweet_zone/to_knob_m", 0, 0.855)}),
      Refusal("SwingAbove1e4", p, Paper(R"(, "swing": {"angular_speed_rad_s": 1e5})"), 400,
              "InvalidValue", "swing.angular_speed_rad_s"),
      // The bat speed at the sweet spot (issue 35): no speed gives omega 0; the largest speed a
      // finite omega; a pivot beyond the tip has no point beyond it (refused, not NaN).
      Ok("SweetSpotZeroBatSpeed", p,
         Paper(R"(, "swing": {"bat_speed_mps": 0, "bat_speed_from_tip_m": "sweet_spot"})"),
         {Near("/swing/angular_speed_rad_s", 0, 0),
          Between("/max_exit_speed/position_from_knob_m", 0, 0.855)}),
      Ok("SweetSpotLargestBatSpeed", p,
         Paper(R"(, "swing": {"bat_speed_mps": 1000, "bat_speed_from_tip_m": "sweet_spot"},
                  "outputs": ["max_exit_speed", "sweet_zone"])"),
         {Between("/swing/angular_speed_rad_s", 1000, 1e4),
          Between("/max_exit_speed/position_from_knob_m", 0, 0.855)}),
      Refusal("SweetSpotPivotBeyondTheTip", p,
              Paper(R"(, "swing": {"bat_speed_mps": 30, "bat_speed_from_tip_m": "sweet_spot",
                       "pivot_from_knob_m": 100})"),
              400, "InvalidValue", "swing.pivot_from_knob_m"),
      // The swing-weight law at its extremes: a reference of 1e-300 kg m^2 swings the bat at
      // ~1e-80 of the given speed (finite); the largest reference and exponent give 200 times the
      // speed, over the omega limit: refused on the bat speed.
      Ok("SwingWeightTinyReference", p,
         Paper(R"(, "swing": {"bat_speed_mps": 30, "speed_model": "swing_weight",
                  "reference_moi_kg_m2": 1e-300})"),
         {Between("/swing/bat_speed_mps", 0, 1e-70)}),
      Refusal("SwingWeightOverTheOmegaLimit", p,
              Paper(R"(, "swing": {"bat_speed_mps": 1000, "speed_model": "swing_weight",
                       "reference_moi_kg_m2": 1e4, "swing_weight_exponent": 0.5})"),
              400, "InvalidValue", "swing.bat_speed_mps"),
      // NLopt on flat objectives (the core table runs every algorithm).
      Ok("GnAgsOnNoMotion", p,
         Paper(R"(, "ball": {"speed_mps": 0}, "swing": {"angular_speed_rad_s": 0},
                  "options": {"method": "nlopt", "nlopt": {"algorithm": "GN_AGS"}})"),
         {Near("/max_exit_speed/exit_speed_mps", 0, 0),
          Between("/max_exit_speed/position_from_knob_m", 0, 0.855)}),
      Ok("LnCobylaCorZeroNoSwing", p, Paper(R"(, "cor": 0, "swing": {"angular_speed_rad_s": 0},
                  "options": {"method": "nlopt", "nlopt": {"algorithm": "LN_COBYLA"}})"),
         {Between("/max_exit_speed/exit_speed_mps", -1e-7, 0)}),
      // x tolerance 1e-300: NLopt stops on its own round-off; the closed form's x* to 1e-9 m.
      Ok("XToleranceOf1e-300", p,
         Paper(R"(, "options": {"method": "nlopt", "nlopt": {"x_tolerance_m": 1e-300}})"),
         {Near("/max_exit_speed/position_from_knob_m", kSweetSpot, 1e-9)}),
      // The contact model has no impact at all when nothing moves: the search names the cause.
      Refusal("HertzNoMotion", p,
              Paper(R"(, "ball": {"speed_mps": 0}, "swing": {"angular_speed_rad_s": 0},
                       "options": {"model": "hertz"})"),
              422, "ModelFailed", "outputs"),
      Ok("HertzSweetSpot", p,
         Paper(R"(, "outputs": ["max_exit_speed", "sweet_zone"], "options": {"model": "hertz"})"),
         {Between("/max_exit_speed/position_from_knob_m", 0.6, 0.75),
          Between("/max_exit_speed/exit_speed_mps", 22.0, 24.0)}),
      Ok("FlexibleSweetSpotFewModes", p,
         Paper(R"(, "options": {"model": "flexible", "flexible": {"max_modes": 4}})"),
         {Between("/max_exit_speed/position_from_knob_m", 0.65, 0.75),
          Between("/max_exit_speed/exit_speed_mps", 20.0, 24.0)}),
      Refusal(
          "VibrationNodeOfAStubbyBat", p,
          R"({"bat": {"three_segment": {"length_m": 0.1, "handle_radius_m": 0.035, "barrel_radius_m": 0.035,
                  "taper_start_m": 0, "taper_end_m": 0}}, "swing": {"hands_from_knob_m": 0.05},
                  "outputs": ["vibration_node"]})",
          400, "InvalidValue", "bat.length_m"),
      Ok("LeastStingWithThreeSamples", p,
         Paper(
             R"(, "outputs": ["least_sting_zone"], "options": {"flexible": {"sting_samples": 3}})"),
         {Between("/least_sting_zone/from_knob_m", 0.1524, 0.855),
          Between("/least_sting_zone/to_knob_m", 0.1524, 0.855)}),
      Ok("TenThousandCurveSamples", p,
         Paper(
             R"(, "outputs": ["exit_speed_curve"], "options": {"curve_samples": 10000, "model": "free_bat"})"),
         {Near("/exit_speed_curve/9999/position_from_knob_m", 0.855, 0),
          Between("/exit_speed_curve/9999/exit_speed_mps", 0, 30)}),
      // Zone tolerance 0: the zone is the maximiser, to the double root's 1e-7 m.
      Ok("SweetZoneOfZeroTolerance", p,
         Paper(R"(, "outputs": ["sweet_zone"], "options": {"sweet_zone_tolerance_mps": 0})"),
         {Between("/sweet_zone/from_knob_m", kSweetSpot - 1e-7, kSweetSpot + 1e-12),
          Between("/sweet_zone/to_knob_m", kSweetSpot - 1e-12, kSweetSpot + 1e-7)}),
      Ok("SweetZoneOfAHundredPercent", p,
         Paper(R"(, "outputs": ["sweet_zone"], "options": {"sweet_zone_tolerance_percent": 100})"),
         {Near("/sweet_zone/from_knob_m", 0, 0), Near("/sweet_zone/to_knob_m", 0.855, 0)}),
      Refusal("SweetZoneToleranceOf1e6", p,
              Paper(R"(, "outputs": ["sweet_zone"], "options": {"sweet_zone_tolerance_mps": 1e6})"),
              400, "InvalidValue", "options.sweet_zone_tolerance_mps"),
      Ok("HundredMetreBat", p,
         R"({"bat": {"three_segment": {"length_m": 100, "handle_radius_m": 10, "barrel_radius_m": 10,
             "taper_start_m": 0, "taper_end_m": 0}}})",
         {Between("/max_exit_speed/position_from_knob_m", 0, 100),
          Between("/max_exit_speed/exit_speed_mps", 13.85, 1e4)}),
      // A 1 um bat (2e-15 kg) held at the knob: the fixed pivot takes the blow, v2 = e u there.
      // The pinned bat (the paper's model) bounces the ball back at e u = 13.85 m/s however
      // small it is; the free bat (the default) of ~1e-15 kg leaves the ball going on at its
      // own -27.7 m/s (the bat's share is below rounding).
      Ok("MicrometreBat", p,
         R"({"bat": {"three_segment": {"length_m": 1e-6, "handle_radius_m": 1e-6, "barrel_radius_m": 1e-6,
             "taper_start_m": 0, "taper_end_m": 0}}, "swing": {"hands_from_knob_m": 0},
             "options": {"model": "rigid_pivot"}})",
         {Near("/max_exit_speed/exit_speed_mps", 13.85, 1e-9),
          Between("/max_exit_speed/position_from_knob_m", 0, 1e-6)}),
      Ok("MicrometreFreeBat", p,
         R"({"bat": {"three_segment": {"length_m": 1e-6, "handle_radius_m": 1e-6, "barrel_radius_m": 1e-6,
             "taper_start_m": 0, "taper_end_m": 0}}, "swing": {"hands_from_knob_m": 0}})",
         {Near("/max_exit_speed/exit_speed_mps", -27.7, 1e-9),
          Between("/max_exit_speed/position_from_knob_m", 0, 1e-6)}),
      Refusal(
          "MicrometreBatWithTheStandardGrip", p,
          R"({"bat": {"three_segment": {"length_m": 1e-6, "handle_radius_m": 1e-6, "barrel_radius_m": 1e-6,
                  "taper_start_m": 0, "taper_end_m": 0}}})",
          400, "InvalidValue", "swing.hands_from_knob_m"),
  };
}

class HardCaseSweetSpotEndpoint : public testing::TestWithParam<ApiCase> {};
TEST_P(HardCaseSweetSpotEndpoint, Answers) { CheckApiCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Api, HardCaseSweetSpotEndpoint, testing::ValuesIn(SweetSpotCases()),
                         RowName<ApiCase>);

// A collision request with `model` at `impact` plus more fields.
std::string Collision(const std::string& model, double impact, const std::string& rest = "",
                      const std::string& bat = R"({"preset": "paper-wood"})") {
  char at[32];
  std::snprintf(at, sizeof at, "%.17g", impact);
  return R"({"bat": )" + bat + R"(, "model": ")" + model + R"(", "impact_from_knob_m": )" + at +
         rest + "}";
}

// The free rigid bat's exit speed at 0.7 m in the paper's scene (paper-wood), m/s: what the
// contact models give with a free bat and what the flexible model tends to when rigid.
constexpr double kFreeBatAt07 = 23.1130;

// POST /v1/collision, every model.
std::vector<ApiCase> CollisionCases() {
  const std::string p = "/v1/collision";
  const std::string custom_rigid =
      R"({"preset": "paper-wood", "material": {"density_kg_m3": 649, "youngs_modulus_pa": 1e13}})";
  const std::string custom_soft =
      R"({"preset": "paper-wood", "material": {"density_kg_m3": 649, "youngs_modulus_pa": 1e4}})";
  return {
      // rigid_pivot: an impact at the pivot does not move the bat: e u exactly.
      Ok("RigidPivotImpactAtAPivotAtTheTip", p,
         Collision("rigid_pivot", 0.855, R"(, "swing": {"pivot_from_knob_m": 0.855})"),
         {Near("/exit_speed_mps", 13.85, 4 * kEps * 27.7)}),
      Ok("RigidPivotImpactAtAPivotAtTheCentroid", p,
         Collision("rigid_pivot", 0.6089948432432433,
                   R"(, "swing": {"pivot_from_knob_m": 0.6089948432432433})"),
         {Near("/exit_speed_mps", 13.85, 4 * kEps * 27.7)}),
      Refusal("RigidPivotImpactBeyondTheTip", p, Collision("rigid_pivot", 0.8551), 400,
              "InvalidValue", "impact_from_knob_m"),
      // free_bat with a 1000 kg ball and e = 1: the bat is knocked away, the ball nearly keeps
      // its speed; BBCOR = e_A (1 + r6) + r6 = 1 to 4 eps r6 (r6 = 1205).
      Ok("FreeBatBallOf1000KgCorOne", p,
         Collision("free_bat", 0.7, R"(, "ball": {"mass_kg": 1000}, "cor": 1)"),
         {Between("/exit_speed_mps", -27.7, -27.6),
          Near("/free_bat/bbcor_style/bbcor", 1.0, 4 * kEps * 1206)}),
      Ok("FreeBatPivotAHundredMetresBehind", p,
         Collision("free_bat", 0.1524, R"(, "swing": {"pivot_from_knob_m": -100})"),
         {Between("/exit_speed_mps", 1000, 2000)}),
      Refusal("FreeBatSubnormalBallMass", p,
              Collision("free_bat", 0.7, R"(, "ball": {"mass_kg": 5e-324})"), 400, "InvalidValue",
              "ball.mass_kg"),
      // hertz: stiff and soft contacts; exit speed within 0.01 m/s of the free bat's whatever
      // the stiffness (the hands barely act during the contact).
      Ok("HertzStiffBall1e15", p, Collision("hertz", 0.7, R"(, "ball": {"stiffness_n_m_p": 1e15})"),
         {Near("/exit_speed_mps", kFreeBatAt07, 0.01),
          Between("/hertz/contact_time_s", 1e-5, 5e-4)}),
      Ok("HertzSoftBallOf1NPerMetre", p,
         Collision("hertz", 0.7, R"(, "ball": {"stiffness_n_m_p": 1})"),
         {Near("/exit_speed_mps", kFreeBatAt07, 0.01), Between("/hertz/contact_time_s", 0.5, 1.0)}),
      Ok("HertzCubicSoftBall", p,
         Collision("hertz", 0.7, R"(, "ball": {"stiffness_n_m_p": 1e3, "stiffness_exponent": 3})"),
         {Near("/exit_speed_mps", kFreeBatAt07, 0.01)}),
      // So soft (1e-300) that the contact would last ~1e123 s: the step bound stops it, named.
      AsJob(Refusal("HertzBallStiffnessOf1e-300", p,
                    Collision("hertz", 0.7, R"(, "ball": {"stiffness_n_m_p": 1e-300})"), 422,
                    "ModelFailed", "model")),
      Ok("HertzStiffHands1e12", p,
         Collision("hertz", 0.7, R"(, "hertz": {"hands_stiffness_n_m": 1e12})"),
         {Between("/exit_speed_mps", 23.0, 23.3)}),
      Ok("HertzTolerance1e-13", p,
         Collision("hertz", 0.7, R"(, "hertz": {"relative_tolerance": 1e-13})"),
         {Near("/exit_speed_mps", kFreeBatAt07, 0.01)}),
      Refusal("HertzTenSteps", p, Collision("hertz", 0.7, R"(, "hertz": {"max_steps": 10})"), 422,
              "ModelFailed", "model"),
      Ok("HertzCorZero", p, Collision("hertz", 0.7, R"(, "cor": 0)"),
         {Near("/hertz/apparent_cor", 0, 0), Between("/exit_speed_mps", 5, 7)}),
      Ok("HertzCorOne", p, Collision("hertz", 0.7, R"(, "cor": 1)"),
         {Near("/hertz/apparent_cor", 1, 1e-5)}),
      // u = 1e-9 m/s, no swing: a contact of 0.1 s at 1e-9 m/s, exit e u-ish and finite.
      Ok("HertzBallAt1e-9MetresPerSecond", p,
         Collision("hertz", 0.7,
                   R"(, "ball": {"speed_mps": 1e-9}, "swing": {"angular_speed_rad_s": 0})"),
         {Between("/exit_speed_mps", 0, 1e-9), Between("/hertz/contact_time_s", 0.01, 1)}),
      Ok("HertzBallOf1000Kg", p, Collision("hertz", 0.7, R"(, "ball": {"mass_kg": 1000})"),
         {Between("/exit_speed_mps", -27.7, -27.6)}),
      Ok("HertzBallOf1e-6Kg", p, Collision("hertz", 0.7, R"(, "ball": {"mass_kg": 1e-6})"),
         {Between("/exit_speed_mps", 27.7, 60)}),
      Ok("HertzFastestSwingAndBall", p,
         Collision("hertz", 0.7,
                   R"(, "ball": {"speed_mps": 1000}, "swing": {"angular_speed_rad_s": 1e4})"),
         {Between("/exit_speed_mps", 8000, 1e4)}),
      // flexible: E = 1e13 Pa (550 times paper-wood's) is nearly the free rigid bat (the gap
      // falls like 1/E: 2.5e-3 m/s here).
      AsJob(Ok("FlexibleNearlyRigidMaterial", p,
               Collision("flexible", 0.7, R"(, "cor": 0.5)", custom_rigid),
               {Near("/exit_speed_mps", kFreeBatAt07, 5e-3)})),
      // E = 1e4 Pa: a wet noodle; the ball leaves slower than from the rigid bat, not below -u.
      Ok("FlexibleVerySoftMaterial", p, Collision("flexible", 0.7, R"(, "cor": 0.5)", custom_soft),
         {Between("/exit_speed_mps", -27.7, kFreeBatAt07)}),
      Ok("FlexibleCorZero", p, Collision("flexible", 0.7, R"(, "cor": 0)"),
         {Between("/exit_speed_mps", -27.7, kFreeBatAt07)}),
      Ok("FlexibleCorOneAtTheTip", p, Collision("flexible", 0.855, R"(, "cor": 1)"),
         {Between("/exit_speed_mps", -27.7, 45)}),
      // At the knob: several contacts; the energy balance still closes to 1e-6 of the initial.
      Ok("FlexibleImpactAtTheKnob", p, Collision("flexible", 0.0),
         {Between("/exit_speed_mps", -27.7, 13.85),
          Between("/flexible/energy/balance_error_j", -6e-5, 6e-5),
          Between("/flexible/contacts", 1, 10)}),
      Ok("FlexibleBallOf1e-6Kg", p, Collision("flexible", 0.7, R"(, "ball": {"mass_kg": 1e-6})"),
         {Between("/exit_speed_mps", 27.7, 60)}),
      Ok("FlexibleBallOf1000Kg", p, Collision("flexible", 0.7, R"(, "ball": {"mass_kg": 1000})"),
         {Between("/exit_speed_mps", -27.7, -27.6)}),
      Ok("FlexibleStiffBall1e12", p,
         Collision("flexible", 0.7, R"(, "ball": {"stiffness_n_m_p": 1e12})"),
         {Between("/exit_speed_mps", -27.7, kFreeBatAt07)}),
      Ok("FlexibleSoftBallOf1NPerMetre", p,
         Collision("flexible", 0.7, R"(, "ball": {"stiffness_n_m_p": 1})"),
         {Near("/exit_speed_mps", kFreeBatAt07, 1e-3)}),
      Refusal("FlexibleMeshBoundOfTwoElements", p,
              Collision("flexible", 0.7, R"(, "flexible": {"max_elements": 2})"), 400,
              "InvalidValue", "flexible.max_elements"),
      Ok("FlexibleTolerance1e-13", p,
         Collision("flexible", 0.7, R"(, "flexible": {"relative_tolerance": 1e-13})"),
         {Between("/exit_speed_mps", 22.7, 22.9)}),
      Refusal("FlexibleTenSteps", p,
              Collision("flexible", 0.7, R"(, "flexible": {"max_steps": 10})"), 422, "ModelFailed",
              "model"),
      Refusal("AutoContactDetailsBeyondTheTip", p,
              Collision("auto", 0.8551, R"(, "contact_details": true)"), 400, "InvalidValue",
              "impact_from_knob_m"),
  };
}

class HardCaseCollisionEndpoint : public testing::TestWithParam<ApiCase> {};
TEST_P(HardCaseCollisionEndpoint, Answers) { CheckApiCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Api, HardCaseCollisionEndpoint, testing::ValuesIn(CollisionCases()),
                         RowName<ApiCase>);

// POST /v1/compare: nasty variants against the paper's bat.
std::vector<ApiCase> CompareCases() {
  const std::string p = "/v1/compare";
  std::string many = R"({"baseline": {"preset": "paper-wood"}, "variants": [)";
  for (int i = 0; i < 65; ++i) {
    many += std::string(i ? ", " : "") + R"({"name": "v", "bat": {"preset": "paper-wood"}})";
  }
  many += "]}";
  return {
      Ok("ThinShellAndHundredMetreVariants", p,
         R"({"baseline": {"preset": "paper-wood"}, "variants": [
             {"name": "thin", "bat": {"preset": "paper-wood", "wall_thickness_m": 1e-11}},
             {"name": "huge", "bat": {"three_segment": {"length_m": 100, "handle_radius_m": 10,
              "barrel_radius_m": 10, "taper_start_m": 0, "taper_end_m": 0}}}]})",
         {Near("/rows/1/deltas/mass_kg", -1.0078187508438627, 1e-8),
          Between("/rows/2/deltas/mass_kg", 2e7, 2.1e7)}),
      Refusal("VariantWallEqualToTheRadius", p,
              R"({"baseline": {"preset": "paper-wood"}, "variants": [
                  {"name": "bad", "bat": {"preset": "paper-wood", "wall_thickness_m": 0.0125}}]})",
              400, "InvalidValue", "variants[0].bat.wall_thickness_m"),
      Ok("NoVariants", p, R"({"baseline": {"preset": "paper-wood"}, "variants": []})",
         {Near("/rows/0/max_exit_speed/position_from_knob_m", kSweetSpot, kTight)}),
      Ok("NoMotionDeltasAreZero", p,
         R"({"baseline": {"preset": "paper-wood"}, "variants": [{"name": "same", "bat": {"preset": "paper-wood"}}],
             "outputs": ["max_exit_speed", "center_of_percussion", "sweet_zone"],
             "swing": {"angular_speed_rad_s": 0}, "ball": {"speed_mps": 0}})",
         {Near("/rows/1/deltas/max_exit_speed_mps", 0, 0), Near("/rows/1/deltas/mass_kg", 0, 0)}),
      // A 0.3 m variant balances before the hands: its centre of percussion does not exist.
      Refusal(
          "VariantBalancingBeforeTheHands", p,
          R"({"baseline": {"preset": "paper-wood"}, "variants": [{"name": "short", "bat": {"three_segment":
                  {"length_m": 0.3, "handle_radius_m": 0.03, "barrel_radius_m": 0.03, "taper_start_m": 0,
                  "taper_end_m": 0}}}], "outputs": ["center_of_percussion"]})",
          400, "InvalidValue", "swing.hands_from_knob_m"),
      Refusal(
          "HertzStepBoundOnTheBaseline", p,
          R"({"baseline": {"preset": "paper-wood"}, "variants": [{"name": "h", "bat": {"preset": "paper-wood"}}],
                  "options": {"model": "hertz", "hertz": {"max_steps": 10}}})",
          422, "ModelFailed", "baseline"),
      Refusal(
          "CustomMaterialWithoutACor", p,
          R"({"baseline": {"preset": "paper-wood"}, "variants": [{"name": "c", "bat": {"preset": "paper-wood",
                  "material": {"density_kg_m3": 649, "youngs_modulus_pa": 1e13}}}]})",
          400, "InvalidValue", "variants[0]"),
      Refusal("SixtyFiveVariants", p, many, 413, "TooBig", "variants"),
  };
}

class HardCaseCompareEndpoint : public testing::TestWithParam<ApiCase> {};
TEST_P(HardCaseCompareEndpoint, Answers) { CheckApiCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Api, HardCaseCompareEndpoint, testing::ValuesIn(CompareCases()),
                         RowName<ApiCase>);

}  // namespace
}  // namespace api_scene_test
}  // namespace sweetspot::hard_cases
