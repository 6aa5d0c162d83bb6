// The sweet spots, the sweet zone and the exit-speed curve.
#include "core/sweet_spot/sweet_spot.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "core/bat/presets.hpp"
#include "core/collision/rigid_pivot.hpp"
#include "core/scene/collide.hpp"
#include "core/scene/evaluate_scene.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace sweet_spot_test {
namespace {

Scene PaperWoodScene(std::vector<SceneOutput> outputs) {
  Scene s;
  s.bat = FindPreset("paper-wood")->bat;
  s.paper_bat = true;  // as the api marks the paper's preset: model auto is the paper's rigid_pivot
  s.outputs = std::move(outputs);
  return s;
}

TEST(CenterOfPercussion, IsWhereThePivotImpulseVanishesForAPivotAtTheHands) {
  const SceneResult r = EvaluateScene(PaperWoodScene({SceneOutput::kCenterOfPercussion}), {});
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  ASSERT_TRUE(r.center_of_percussion.has_value());
  const MassProperties& mp = r.mass_properties;
  const double h = 0.1524;
  const double ih = mp.MoiAboutKgM2(h);
  // CoP = h + I_h / (M (C - h)): the textbook form; both are a few operations: 1e-13 m.
  EXPECT_NEAR(r.center_of_percussion->position_from_knob_m,
              h + ih / (mp.mass_kg * (mp.balance_point_m - h)), 1e-13);
  EXPECT_NEAR(r.center_of_percussion->moi_hands_kg_m2, ih, 1e-13);
  // Independent check: the rigid-pivot model with the pivot at the hands feels no impulse there.
  RigidPivotInputs in;
  in.bat_mass_kg = mp.mass_kg;
  in.balance_point_m = mp.balance_point_m;
  in.pivot_from_knob_m = h;
  in.moi_pivot_kg_m2 = ih;
  const RigidPivotImpact at = RigidPivotImpactAt(in, r.center_of_percussion->position_from_knob_m);
  EXPECT_NEAR(at.pivot_impulse_n_s / at.ball_impulse_n_s, 0.0, 1e-13);
  // Only the mass properties were needed.
  EXPECT_EQ(r.summary.models_used, std::vector<std::string>{"mass_properties"});
}

TEST(CenterOfPercussion, RefusedWhenTheHandsAreNotBeforeTheBalancePoint) {
  MassProperties mp;
  mp.mass_kg = 1.0;
  mp.balance_point_m = 0.6;
  mp.moi_centroid_kg_m2 = 0.05;
  std::string why;
  EXPECT_FALSE(CenterOfPercussion(mp, 0.6, 0.86, &why).has_value());
  EXPECT_EQ(why,
            "swing.hands_from_knob_m = 0.59999999999999998: must be closer to the knob than "
            "the balance point (0.59999999999999998 m) for a centre of percussion to exist");
}

TEST(VibrationNode, IsTheBarrelSideNodeOfTheFundamentalMode) {
  const SceneResult r =
      EvaluateScene(PaperWoodScene({SceneOutput::kMaxExitSpeed, SceneOutput::kVibrationNode}), {});
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  ASSERT_TRUE(r.vibration_node.has_value());
  const VibrationNodeResult& n = *r.vibration_node;
  // A free-free beam's mode 1 has two nodes; the barrel-side one lies beyond
  // the handle-side one, inside the bat (a uniform beam: 0.224 L and 0.776 L).
  EXPECT_GT(n.position_from_knob_m, n.other_node_from_knob_m);
  EXPECT_GT(n.position_from_knob_m, 0.5 * 0.855);
  EXPECT_LT(n.position_from_knob_m, 0.855);
  EXPECT_GT(n.frequency_hz, 0.0);
  EXPECT_GT(n.second_mode_frequency_hz, n.frequency_hz);
  EXPECT_TRUE(r.max_exit_speed.has_value());
}

TEST(SweetZone, EdgesAreWhereTheSpeedDropsByTheTolerance) {
  SceneOptions o;
  o.sweet_zone_tolerance = 0.2;  // the tip is 0.244 m/s below the maximum: not clipped
  Scene s = PaperWoodScene({SceneOutput::kSweetZone, SceneOutput::kMaxExitSpeed});
  const SceneResult r = EvaluateScene(s, o);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  ASSERT_TRUE(r.sweet_zone.has_value());
  const SweetZoneResult& z = *r.sweet_zone;
  EXPECT_EQ(z.method, "closed_form");
  EXPECT_FALSE(z.clipped_at_knob);
  EXPECT_FALSE(z.clipped_at_tip);
  EXPECT_LT(z.from_knob_m, r.max_exit_speed->position_from_knob_m);
  EXPECT_GT(z.to_knob_m, r.max_exit_speed->position_from_knob_m);
  // At each edge v2 = max - 0.2 (the quadratic's roots; slope ~5 m/s per m: rounding 1e-13).
  for (double x : {z.from_knob_m, z.to_knob_m}) {
    const CollisionResult c = Collide(s, x, CollisionModel::kRigidPivot);
    EXPECT_NEAR(c.exit_speed_mps, r.max_exit_speed->exit_speed_mps - 0.2, 1e-12);
  }
  EXPECT_LT(z.error_estimate_m, 1e-12);
  // The independent path (NLopt maximum, TOMS 748 roots) agrees.
  o.method = SweetSpotMethod::kNlopt;
  const SceneResult n = EvaluateScene(s, o);
  ASSERT_TRUE(n.sweet_zone.has_value()) << n.summary.message;
  EXPECT_EQ(n.sweet_zone->method, "root_finding");
  EXPECT_NEAR(n.sweet_zone->from_knob_m, z.from_knob_m, 1e-9);
  EXPECT_NEAR(n.sweet_zone->to_knob_m, z.to_knob_m, 1e-9);
}

TEST(SweetZone, PercentZeroAndClipped) {
  SceneOptions o;
  o.sweet_zone_unit = ToleranceUnit::kPercent;
  o.sweet_zone_tolerance = 1.0;
  Scene s = PaperWoodScene({SceneOutput::kSweetZone, SceneOutput::kMaxExitSpeed});
  SceneResult r = EvaluateScene(s, o);
  ASSERT_TRUE(r.sweet_zone.has_value());
  EXPECT_NEAR(r.sweet_zone->tolerance_mps, 0.01 * r.max_exit_speed->exit_speed_mps, 1e-15);
  o.sweet_zone_tolerance = 0.0;  // zero tolerance: the sweet spot itself
  r = EvaluateScene(s, o);
  EXPECT_EQ(r.sweet_zone->from_knob_m, r.max_exit_speed->position_from_knob_m);
  EXPECT_EQ(r.sweet_zone->to_knob_m, r.max_exit_speed->position_from_knob_m);
  o.sweet_zone_unit = ToleranceUnit::kMetersPerSecond;
  o.sweet_zone_tolerance = 100.0;  // everything qualifies
  r = EvaluateScene(s, o);
  EXPECT_EQ(r.sweet_zone->from_knob_m, 0.0);
  EXPECT_EQ(r.sweet_zone->to_knob_m, 0.855);
  EXPECT_TRUE(r.sweet_zone->clipped_at_knob);
  EXPECT_TRUE(r.sweet_zone->clipped_at_tip);
}

TEST(SweetZone, AroundATipMaximum) {
  // Maximiser beyond the tip: the zone ends at the tip and starts where v2 = v2(tip) - tol.
  Scene s = PaperWoodScene({SceneOutput::kSweetZone, SceneOutput::kMaxExitSpeed});
  s.swing.pivot_from_knob_m = -1.0;
  SceneOptions o;
  o.sweet_zone_tolerance = 0.2;
  const SceneResult r = EvaluateScene(s, o);
  ASSERT_EQ(r.max_exit_speed->placement, Placement::kBeyondTip);
  EXPECT_EQ(r.sweet_zone->to_knob_m, 0.855);
  const CollisionResult c = Collide(s, r.sweet_zone->from_knob_m, CollisionModel::kRigidPivot);
  EXPECT_NEAR(c.exit_speed_mps, r.max_exit_speed->exit_speed_mps - 0.2, 1e-12);
}

TEST(ExitSpeedCurve, SamplesAndExplicitPositions) {
  Scene s = PaperWoodScene({SceneOutput::kExitSpeedCurve});
  SceneOptions o;
  o.curve_samples = 5;
  SceneResult r = EvaluateScene(s, o);
  ASSERT_TRUE(r.exit_speed_curve.has_value());
  ASSERT_EQ(r.exit_speed_curve->points.size(), 5u);
  EXPECT_EQ(r.exit_speed_curve->points.front().position_from_knob_m, 0.0);
  EXPECT_EQ(r.exit_speed_curve->points.back().position_from_knob_m, 0.855);
  for (const auto& p : r.exit_speed_curve->points) {
    EXPECT_EQ(p.exit_speed_mps,
              Collide(s, p.position_from_knob_m, CollisionModel::kRigidPivot).exit_speed_mps);
  }
  o.curve_positions_from_knob_m = {0.7, 0.1};
  r = EvaluateScene(s, o);
  ASSERT_EQ(r.exit_speed_curve->points.size(), 2u);
  EXPECT_EQ(r.exit_speed_curve->points[0].position_from_knob_m, 0.7);
  o.curve_positions_from_knob_m = {0.9};
  r = EvaluateScene(s, o);
  EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(r.summary.message,
            "curve_positions_from_knob_m[0] = 0.90000000000000002: must be "
            "within the bat [0, 0.85499999999999998]");
}

TEST(OutputNames, RoundTrip) {
  for (SceneOutput o :
       {SceneOutput::kMaxExitSpeed, SceneOutput::kCenterOfPercussion, SceneOutput::kVibrationNode,
        SceneOutput::kSweetZone, SceneOutput::kExitSpeedCurve}) {
    EXPECT_EQ(ParseSceneOutput(SceneOutputName(o)), o);
  }
  EXPECT_FALSE(ParseSceneOutput("sweetspot").has_value());
  EXPECT_STREQ(PlacementName(Placement::kBeyondTip), "beyond_tip");
}

}  // namespace
}  // namespace sweet_spot_test
}  // namespace sweetspot::core
