// Hard cases of the collision models: each with its expected value or named refusal.
#include <chrono>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "core/bat/presets.hpp"
#include "core/collision/hertz_contact.hpp"
#include "core/collision/rigid_pivot.hpp"
#include "core/numerics/nlopt_search.hpp"
#include "core/scene/collide.hpp"
#include "core/scene/evaluate_scene.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace hard_cases_collision_test {
namespace {

// A bat given by its mass properties only: M, C, I_cm, length.
Scene BatByProperties(double mass, double balance, double moi_centroid, double length) {
  Scene s;
  MassProperties mp;
  mp.mass_kg = mass;
  mp.balance_point_m = balance;
  mp.moi_centroid_kg_m2 = moi_centroid;
  mp.moi_knob_kg_m2 = moi_centroid + mass * balance * balance;
  s.mass_properties = mp;
  s.length_m = length;
  s.cor = 0.5;
  return s;
}

Scene PaperWood() {
  Scene s;
  s.bat = FindPreset("paper-wood")->bat;
  s.paper_bat = true;  // as the api marks the paper's preset: model auto is the paper's rigid_pivot
  return s;
}

MaxExitSpeedResult Max(const Scene& s, SweetSpotMethod method = SweetSpotMethod::kClosedForm) {
  SceneOptions o;
  o.model = CollisionModel::kRigidPivot;  // the hard cases of the paper's closed form
  o.method = method;
  const SceneResult r = EvaluateScene(s, o);
  EXPECT_TRUE(r.summary.IsSolutionUsable()) << r.summary.message;
  return r.max_exit_speed.value_or(MaxExitSpeedResult{});
}

TEST(HardCases, NoSwingPutsTheSweetSpotAtThePivot) {
  Scene s = PaperWood();
  s.swing.angular_speed_rad_s = 0.0;
  // x* = 0: at the pivot the bat does not recoil, v2 = e u exactly.
  MaxExitSpeedResult m = Max(s);
  EXPECT_EQ(m.position_from_knob_m, 0.0);
  EXPECT_NEAR(m.exit_speed_mps, 0.5 * 27.7, 1e-13);
  EXPECT_EQ(m.placement, Placement::kOnBat);
  s.swing.pivot_from_knob_m = 0.3;
  m = Max(s);
  EXPECT_NEAR(m.position_from_knob_m, 0.3, 1e-15);
  EXPECT_NEAR(m.exit_speed_mps, 0.5 * 27.7, 1e-13);
  // NLopt agrees (the maximum is a smooth interior point).
  EXPECT_NEAR(Max(s, SweetSpotMethod::kNlopt).position_from_knob_m, 0.3, 1e-9);
  s.swing.pivot_from_knob_m = -0.2;  // pivot behind the knob: the maximiser is off the bat
  m = Max(s);
  EXPECT_EQ(m.placement, Placement::kBeforeKnob);
  EXPECT_EQ(m.position_from_knob_m, 0.0);
  EXPECT_LT(m.exit_speed_mps, 0.5 * 27.7);
}

TEST(HardCases, BallSpeedToZero) {
  // Pivot at the centroid with J/m = 0.22^2: with u = 0, x* = sqrt(J/m) and
  // v2max = (1+e) omega sqrt(J/m) / 2.
  Scene s = BatByProperties(1.0, 0.5, 0.22 * 0.22 * 0.145, 0.86);
  s.swing.pivot_from_knob_m = 0.5;
  for (double u : {0.0, 1e-300, 1e-12}) {
    s.ball.speed_mps = u;
    const MaxExitSpeedResult m = Max(s);
    // Closed form with S = omega sqrt(J/m); u <= 1e-12 changes x* by ~u/(omega sqrt(J/m)) ~ 3e-13.
    EXPECT_NEAR(m.position_from_knob_m, 0.72, 1e-12) << u;
    EXPECT_NEAR(m.exit_speed_mps, 1.5 * 17.288 * 0.22 / 2.0, 1e-11) << u;
  }
}

TEST(HardCases, NoSwingAndNoBallIsFlatAndSaysSo) {
  Scene s = PaperWood();
  s.swing.angular_speed_rad_s = 0.0;
  s.ball.speed_mps = 0.0;
  SceneOptions o;
  const SceneResult r = EvaluateScene(s, o);
  ASSERT_EQ(r.summary.termination, Termination::kConverged);
  EXPECT_EQ(r.max_exit_speed->exit_speed_mps, 0.0);
  ASSERT_FALSE(r.max_exit_speed->summary.warnings.empty());
  EXPECT_NE(r.max_exit_speed->summary.warnings[0].find("the same at every impact position"),
            std::string::npos);
  // No contact at all: the contact model refuses, naming the rule.
  const CollisionResult c = Collide(s, 0.7, CollisionModel::kHertz);
  EXPECT_EQ(c.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(c.summary.message,
            "hertz.approach_speed_mps = 0: must be finite and > 0 (the ball and the bat must "
            "approach each other)");
}

TEST(HardCases, CorZeroAndOne) {
  RigidPivotInputs in;
  in.bat_mass_kg = 1.0078;
  in.balance_point_m = 0.609;
  in.moi_pivot_kg_m2 = 0.4122;
  const double u = in.ball_speed_mps, w = in.angular_speed_rad_s;
  const double s = std::sqrt(u * u + w * w * in.moi_pivot_kg_m2 / in.ball_mass_kg);
  in.cor = 0.0;
  ProfileMaximum m = RigidPivotProfile(in).Maximum();
  EXPECT_NEAR(m.exit_speed_mps, (s - u) / 2.0, 1e-13);  // ((1+e)S - (1-e)u)/2 at e = 0
  in.cor = 1.0;
  m = RigidPivotProfile(in).Maximum();
  EXPECT_NEAR(m.exit_speed_mps, s, 1e-13);  // e = 1: v2max = S
  // x* does not depend on e.
  in.cor = 0.0;
  EXPECT_NEAR(RigidPivotProfile(in).Maximum().x_m, m.x_m, 1e-15);
  // The contact model with e = 0 ends at maximum compression and says so.
  Scene sc = PaperWood();
  sc.cor = 0.0;
  const CollisionResult c = Collide(sc, 0.7, CollisionModel::kHertz);
  ASSERT_EQ(c.summary.termination, Termination::kConverged) << c.summary.message;
  EXPECT_EQ(c.hertz->apparent_cor, 0.0);
  ASSERT_FALSE(c.summary.warnings.empty());
  EXPECT_NE(c.summary.warnings.back().find("perfectly plastic"), std::string::npos);
}

TEST(HardCases, HugeAndTinyInertiaPerBallMass) {
  // J/m huge: x* ~ sqrt(J/m) far beyond the tip: the tip, flagged, by both paths.
  Scene big = BatByProperties(1.0, 0.5, 1e6, 0.86);
  MaxExitSpeedResult m = Max(big);
  EXPECT_EQ(m.placement, Placement::kBeyondTip);
  EXPECT_EQ(m.position_from_knob_m, 0.86);
  const MaxExitSpeedResult n = Max(big, SweetSpotMethod::kNlopt);
  EXPECT_EQ(n.position_from_knob_m, 0.86);
  EXPECT_EQ(n.placement, Placement::kBeyondTip);
  EXPECT_NEAR(n.exit_speed_mps, m.exit_speed_mps, 1e-12 * m.exit_speed_mps);
  // J/m tiny (pivot at the centroid, I = 1e-12): x* = omega J/(2 m u) to first order, and the
  // maximum tends to e u.
  Scene tiny = BatByProperties(1.0, 0.5, 1e-12, 0.86);
  tiny.swing.pivot_from_knob_m = 0.5;
  m = Max(tiny);
  const double x_series = 17.288 * 1e-12 / (2.0 * 0.145 * 27.7);
  EXPECT_NEAR(m.position_from_knob_m - 0.5, x_series, 1e-9 * x_series + 1e-16);
  // v2max = e u + (1+e) omega x*/2: 2.8e-11 above e u; rounding of 13.85 is ~2e-15.
  EXPECT_NEAR(m.exit_speed_mps, 0.5 * 27.7 + 1.5 * 17.288 * x_series / 2.0, 1e-13);
  EXPECT_TRUE(std::isfinite(m.exit_speed_mps));
}

TEST(HardCases, ImpactAtTheKnobAndAtTheTip) {
  const Scene s = PaperWood();
  for (CollisionModel model :
       {CollisionModel::kRigidPivot, CollisionModel::kFreeBat, CollisionModel::kHertz}) {
    const CollisionResult knob = Collide(s, 0.0, model);
    const CollisionResult tip = Collide(s, 0.855, model);
    EXPECT_EQ(knob.summary.termination, Termination::kConverged) << knob.summary.message;
    EXPECT_EQ(tip.summary.termination, Termination::kConverged) << tip.summary.message;
  }
  // At the knob (= the pivot) the rigid bat does not recoil: v2 = e u.
  EXPECT_NEAR(Collide(s, 0.0, CollisionModel::kRigidPivot).exit_speed_mps, 0.5 * 27.7, 1e-13);
  const CollisionResult off = Collide(s, 0.8551, CollisionModel::kRigidPivot);
  EXPECT_EQ(off.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(
      off.summary.message,
      "impact_from_knob_m = 0.85509999999999997: must be within the bat [0, 0.85499999999999998]");
}

TEST(HardCases, BallHeavierThanTheBat) {
  Scene s = BatByProperties(0.5, 0.45, 0.03, 0.86);
  s.ball.mass_kg = 5.0;
  const MaxExitSpeedResult cf = Max(s);
  const MaxExitSpeedResult nl = Max(s, SweetSpotMethod::kNlopt);
  EXPECT_NEAR(nl.position_from_knob_m, cf.position_from_knob_m,
              1e-9 * std::max(cf.position_from_knob_m, 1e-3));
  EXPECT_NEAR(nl.exit_speed_mps, cf.exit_speed_mps, 1e-9 * std::abs(cf.exit_speed_mps));
  // The light bat barely stops the ball: q < 0 away from the pivot.
  const CollisionResult c = Collide(s, 0.8, CollisionModel::kRigidPivot);
  EXPECT_LT(c.rigid_pivot->collision_efficiency, 0.0);
  const CollisionResult h = Collide(s, 0.8, CollisionModel::kHertz);
  EXPECT_EQ(h.summary.termination, Termination::kConverged) << h.summary.message;
}

HertzProblem FreeContact(double v0) {
  HertzProblem p;
  p.law = ContactLaw::kBallPowerLaw;
  p.approach_speed_mps = v0;
  p.ball_speed_mps = v0;
  p.ball_mass_kg = 0.145;
  p.c11_per_kg = 1.0 / 0.145 + 1.0 / 0.9 + 0.01 / 0.04;
  p.c12_per_kg = 1.0 / 0.9;
  p.c22_per_kg = 1.0 / 0.9 + 0.2 / 0.04;
  p.ball_stiffness = kDefaultBallStiffness;
  p.ball_exponent = 1.5;
  p.surface_stiffness = 4e9;
  p.cor = 0.5;
  p.hands_stiffness_n_m = 0.0;
  return p;
}

TEST(HardCases, HertzApproachSpeedsFromMicrometresPerSecondTo100) {
  HertzSolverOptions o;
  o.relative_tolerance = 1e-10;
  const HertzImpact ref = SolveHertzImpact(FreeContact(40.0), o);
  ASSERT_EQ(ref.summary.termination, Termination::kConverged);
  for (double v : {1e-6, 100.0}) {
    const HertzImpact r = SolveHertzImpact(FreeContact(v), o);
    ASSERT_EQ(r.summary.termination, Termination::kConverged) << v << r.summary.message;
    // A pure 3/2-power contact (series of two 3/2 springs) scales exactly:
    // t ~ v^{(1-p)/(1+p)} = v^{-1/5}, delta ~ v^{4/5}. The scaled state makes both solves the
    // same dimensionless problem: 1e-8 relative.
    EXPECT_NEAR(r.contact_time_s / (ref.contact_time_s * std::pow(v / 40.0, -0.2)), 1.0, 1e-8);
    EXPECT_NEAR(r.max_compression_m / (ref.max_compression_m * std::pow(v / 40.0, 0.8)), 1.0, 1e-8);
    EXPECT_NEAR(r.apparent_cor, 0.5, 1e-8);
    EXPECT_LT(r.steps, 1000);
  }
}

TEST(HardCases, StiffnessRatioOfAMillionIsBoundedAndFailuresAreReported) {
  // Hands 1e6 times stiffer than the ball's secant contact stiffness at peak (~3e6 N/m):
  // the hands' period becomes ~1000 times shorter than the contact. The explicit integrator
  // must either finish within its step bound or report a failure; never hang or blow up.
  HertzProblem p = FreeContact(40.0);
  p.hands_stiffness_n_m = 3e12;
  HertzSolverOptions o;
  o.refine_check = false;
  const auto t0 = std::chrono::steady_clock::now();
  const HertzImpact r = SolveHertzImpact(p, o);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(seconds, 5.0);
  EXPECT_LE(r.steps, o.max_steps);
  if (r.summary.termination == Termination::kConverged) {
    EXPECT_TRUE(std::isfinite(r.exit_speed_mps));
    EXPECT_GT(r.steps, 100);  // it had to resolve the fast mode
  } else {
    EXPECT_EQ(r.summary.termination, Termination::kFailure);
  }
  // A ratio of 1e9 (hands' period ~30000 times shorter than the contact) exceeds the default
  // step bound: a reported failure, in milliseconds.
  p.hands_stiffness_n_m = 3e15;
  const HertzImpact stiff = SolveHertzImpact(p, o);
  EXPECT_EQ(stiff.summary.termination, Termination::kFailure);
  EXPECT_NE(stiff.summary.message.find("max_steps = 20000"), std::string::npos);
  p.hands_stiffness_n_m = 3e12;
  // With a tight step bound the same problem is a reported failure that names the bound.
  o.max_steps = 50;
  const HertzImpact f = SolveHertzImpact(p, o);
  EXPECT_EQ(f.summary.termination, Termination::kFailure);
  EXPECT_NE(f.summary.message.find("max_steps = 50"), std::string::npos) << f.summary.message;
  EXPECT_FALSE(f.summary.IsSolutionUsable());
  // The paper's constants with K2 a million times K1's scale: bounded as well.
  HertzProblem q;
  q.law = ContactLaw::kPaperConstants;
  q.approach_speed_mps = q.ball_speed_mps = 27.7;
  q.ball_mass_kg = 0.145;
  q.c11_per_kg = 8.0;
  q.c12_per_kg = 1.0;
  q.c22_per_kg = 1.0;
  q.paper.k2 = 7.69e17;
  const HertzImpact g = SolveHertzImpact(q, HertzSolverOptions{});
  EXPECT_TRUE(g.summary.termination == Termination::kConverged ||
              g.summary.termination == Termination::kFailure);
  EXPECT_LE(g.steps, 2 * HertzSolverOptions{}.max_steps);
}

TEST(HardCases, NonFiniteInputsAreRefusedWithTheirName) {
  Scene s = PaperWood();
  s.ball.speed_mps = std::numeric_limits<double>::quiet_NaN();
  const SceneResult r = EvaluateScene(s, SceneOptions{});
  EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(r.summary.message, "ball.speed_mps = nan: must be in [0, 1000]");
  s = PaperWood();
  s.swing.angular_speed_rad_s = std::numeric_limits<double>::infinity();
  EXPECT_EQ(EvaluateScene(s, SceneOptions{}).summary.message,
            "swing.angular_speed_rad_s = inf: must be in [0, 10000]");
}

}  // namespace
}  // namespace hard_cases_collision_test
}  // namespace sweetspot::core
