// The flexible model's max-exit-speed sweet spot by the bracketing search (issue 17): the same
// answer as the NLopt search within the reported error, an error estimate that bounds the
// distance to a tight reference, few evaluations, hard cases; least_sting_zone with its fewer
// samples against the former 41.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include "core/bat/bat.hpp"
#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"
#include "core/scene/evaluate_scene.hpp"
#include "core/sweet_spot/numeric.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace flexible_sweet_spot_test {
namespace {

Scene Ash(std::vector<SceneOutput> outputs, double ball_mps = 27.7, double omega = 17.288) {
  Scene s;
  s.bat = FindPreset("wood-34-ash")->bat;
  s.outputs = std::move(outputs);
  s.ball.speed_mps = ball_mps;
  s.swing.angular_speed_rad_s = omega;
  return s;
}

SceneOptions Flexible() {
  SceneOptions o;
  o.model = CollisionModel::kFlexible;
  return o;
}

// The converged maximiser of the same model (same modes and cutoff): NLopt to 1e-12 m on
// impacts integrated to 1e-11.
MaxExitSpeedResult Reference(const Scene& scene) {
  SceneOptions o = Flexible();
  o.method = SweetSpotMethod::kNlopt;
  o.flexible.impact.relative_tolerance = 1e-11;
  o.flexible.impact.refine_check = false;
  // A reference must converge whatever the machine's load: NLopt's default 1 s budget ran out
  // under AddressSanitizer on a loaded 2-core machine (termination no_convergence).
  o.nlopt.max_time_s = 60.0;
  const SceneResult r = EvaluateScene(scene, o);
  EXPECT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  return r.max_exit_speed.value_or(MaxExitSpeedResult{});
}

TEST(FlexibleSweetSpot, TheBracketingSearchIsTheDefaultAndUsesFewEvaluations) {
  const SceneResult r = EvaluateScene(Ash({SceneOutput::kMaxExitSpeed}), Flexible());
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  ASSERT_TRUE(r.max_exit_speed.has_value());
  const MaxExitSpeedResult& m = *r.max_exit_speed;
  EXPECT_EQ(m.method, "bracket_brent");
  EXPECT_EQ(m.summary.backend, "bracket_brent");
  EXPECT_EQ(m.model, "flexible");
  EXPECT_EQ(m.placement, Placement::kOnBat);
  // 9 samples + Brent from a two-sample bracket to 1e-5 m + one checked impact (measured 19;
  // the NLopt search took 40, each with the refinement check).
  EXPECT_LE(m.summary.evaluations, 25);
  EXPECT_GT(m.error_estimate_m, 0.0);
  // The noise term of a 1e-8 integration on this curvature is ~5e-5 m: a few 1e-4 m at most.
  EXPECT_LT(m.error_estimate_m, 3e-4);
  EXPECT_GT(m.error_estimate_mps, 0.0);
  EXPECT_EQ(r.summary.models_used,
            (std::vector<std::string>{"mass_properties", "flexible_beam", "flexible"}));
}

TEST(FlexibleSweetSpot, TheErrorEstimateBoundsTheDistanceToATightReference) {
  // Default speeds and a game swing (40 m/s pitch, 45 rad/s).
  for (const auto& [ball, omega] :
       std::vector<std::pair<double, double>>{{27.7, 17.288}, {40.0, 45.0}}) {
    const Scene scene = Ash({SceneOutput::kMaxExitSpeed}, ball, omega);
    const SceneResult fast = EvaluateScene(scene, Flexible());
    ASSERT_TRUE(fast.max_exit_speed.has_value()) << fast.summary.message;
    const MaxExitSpeedResult ref = Reference(scene);
    const MaxExitSpeedResult& m = *fast.max_exit_speed;
    // The estimate is an upper bound of the actual error (measured 3e-6 and 8e-7 m against
    // estimates of ~4.5e-5 m).
    EXPECT_LE(std::abs(m.position_from_knob_m - ref.position_from_knob_m), m.error_estimate_m)
        << "ball " << ball;
    // The speed: the estimate holds the integration and mode-truncation errors at the answer
    // (the reference has the same modes, so only the integration share and the flat top's
    // f'' dx^2 / 2 separate the two).
    EXPECT_LE(std::abs(m.exit_speed_mps - ref.exit_speed_mps), m.error_estimate_mps)
        << "ball " << ball;
  }
}

TEST(FlexibleSweetSpot, TheNloptSearchStaysAvailableAndAgreesWithinTheEstimates) {
  const Scene scene = Ash({SceneOutput::kMaxExitSpeed});
  SceneOptions o = Flexible();
  o.method = SweetSpotMethod::kNlopt;
  const SceneResult nlopt = EvaluateScene(scene, o);
  const SceneResult fast = EvaluateScene(scene, Flexible());
  ASSERT_TRUE(nlopt.max_exit_speed && fast.max_exit_speed);
  EXPECT_EQ(nlopt.max_exit_speed->method, "nlopt:LN_BOBYQA");
  // Both are answers of the same model: they differ by less than the sum of their estimates
  // (NLopt's own estimate is its x tolerance only; the bracketing search's covers the noise).
  EXPECT_LE(std::abs(nlopt.max_exit_speed->position_from_knob_m -
                     fast.max_exit_speed->position_from_knob_m),
            nlopt.max_exit_speed->error_estimate_m + fast.max_exit_speed->error_estimate_m);
  EXPECT_NEAR(nlopt.max_exit_speed->exit_speed_mps, fast.max_exit_speed->exit_speed_mps,
              nlopt.max_exit_speed->error_estimate_mps + fast.max_exit_speed->error_estimate_mps);
}

TEST(FlexibleSweetSpot, LowAndHighBallSpeedsStillAnswer) {
  for (const auto& [ball, omega] :
       std::vector<std::pair<double, double>>{{1.0, 17.288}, {0.2, 30.0}, {60.0, 17.288}}) {
    const SceneResult r = EvaluateScene(Ash({SceneOutput::kMaxExitSpeed}, ball, omega), Flexible());
    ASSERT_EQ(r.summary.termination, Termination::kConverged)
        << "ball " << ball << ": " << r.summary.message;
    const MaxExitSpeedResult& m = *r.max_exit_speed;
    // On the barrel, where the first modes' nodes are (wood-34-ash: 0.70-0.76 m measured).
    EXPECT_GT(m.position_from_knob_m, 0.6) << "ball " << ball;
    EXPECT_LE(m.position_from_knob_m, r.length_m) << "ball " << ball;
    EXPECT_GT(m.exit_speed_mps, 0.0) << "ball " << ball;
    EXPECT_LT(m.error_estimate_m, 1e-3) << "ball " << ball;
  }
}

TEST(FlexibleSweetSpot, AnOptimumAtTheTipIsTheTipExactly) {
  // A short, heavy steel club (0.4 m, 3 cm radius, 8.8 kg: almost no recoil, a fundamental of
  // several kHz) and a slow ball: the exit speed rises all the way to the tip, as the free
  // rigid bat's closed form says (its maximiser is beyond the tip). An ash club of the same
  // shape is too light: its optimum is at 0.32 m (the free bat's at 0.33 m).
  Material steel = *FindMaterial("ash");
  steel.name = "steel";
  steel.density_kg_m3 = 7800.0;
  steel.youngs_modulus_pa = 2e11;
  steel.shear_modulus_pa = 2e11 / 2.6;
  Scene s;
  s.bat = MakeThreeSegmentBat(ThreeSegmentShape{0.4, 0.03, 0.03, 0.1, 0.3}, steel);
  s.outputs = {SceneOutput::kMaxExitSpeed};
  s.ball.speed_mps = 1.0;
  const SceneResult r = EvaluateScene(s, Flexible());
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  const MaxExitSpeedResult& m = *r.max_exit_speed;
  EXPECT_EQ(m.position_from_knob_m, r.length_m);
  EXPECT_EQ(m.placement, Placement::kBeyondTip);
  EXPECT_LT(m.error_estimate_m, 1e-4);
}

TEST(FlexibleSweetSpot, BracketSearchOptionsAreChecked) {
  EXPECT_TRUE(BracketSearchOptions{}.Validate(nullptr));
  std::string why;
  BracketSearchOptions o;
  o.samples = 2;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "samples = 2: must be in [3, 1001]");
  o = {};
  o.x_tolerance_m = 0.0;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_NE(why.find("x_tolerance_m"), std::string::npos);
  o = {};
  o.max_iterations = 4;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "max_iterations = 4: must be in [5, 1000]");
  // Through the scene: named with its prefix, and the solve refused.
  SceneOptions so = Flexible();
  so.flexible.search.samples = 2;
  const SceneResult r = EvaluateScene(Ash({SceneOutput::kMaxExitSpeed}), so);
  EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
  EXPECT_NE(r.summary.message.find("flexible.search.samples"), std::string::npos)
      << r.summary.message;
}

TEST(FlexibleSweetSpot, TheLeastStingZoneWithFewerSamplesMatchesTheFormer41) {
  const Scene scene = Ash({SceneOutput::kLeastStingZone});
  const SceneResult now = EvaluateScene(scene, SceneOptions{});
  SceneOptions former;
  former.flexible.sting_samples = 41;
  const SceneResult before = EvaluateScene(scene, former);
  ASSERT_TRUE(now.least_sting_zone && before.least_sting_zone) << now.summary.message;
  const LeastStingZoneResult& a = *now.least_sting_zone;
  const LeastStingZoneResult& b = *before.least_sting_zone;
  EXPECT_EQ(a.curve.size(), 21u);
  // The same minimum and ends to within the two estimates (measured: 4e-6 m apart, estimates
  // ~2e-5 m).
  const double tol = a.error_estimate_m + b.error_estimate_m;
  EXPECT_NEAR(a.min_position_from_knob_m, b.min_position_from_knob_m, tol);
  EXPECT_NEAR(a.from_knob_m, b.from_knob_m, tol);
  EXPECT_NEAR(a.to_knob_m, b.to_knob_m, tol);
  EXPECT_GT(a.error_estimate_m, 0.0);
  EXPECT_LT(a.error_estimate_m, 1e-3);
  // The least-sting impact is checked with the refinement: its hands' energy error is known.
  EXPECT_GT(a.exit_speed_at_min_mps, 0.0);
}

}  // namespace
}  // namespace flexible_sweet_spot_test
}  // namespace sweetspot::core
