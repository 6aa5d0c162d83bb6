// The batted ball of a scene (core/scene/batted_ball.hpp) and its outputs batted_ball,
// distance_sweet_spot and carry_map: head-on it is each collision model's own impact; the
// tabulated normal law against the exact one; the distance sweet spot against the best of a
// fine carry map; symmetry and monotonic checks; the scene's environment and aero.
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/bat/presets.hpp"
#include "core/scene/batted_ball.hpp"
#include "core/scene/collide.hpp"
#include "core/scene/evaluate_scene.hpp"
#include "core/scene/scene_models.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace batted_ball_test {
namespace {

// A 90 mph pitch met by a 70 mph swing (at 6 in from the tip) with a wood bat.
Scene GameScene(std::vector<SceneOutput> outputs) {
  Scene s;
  s.bat = FindPreset("wood-34-ash")->bat;
  s.ball.speed_mps = 90.0 * 0.44704;
  s.swing.bat_speed_mps = 70.0 * 0.44704;
  s.outputs = std::move(outputs);
  return s;
}

SceneOptions WithModel(CollisionModel model) {
  SceneOptions o;
  o.model = model;
  return o;
}

constexpr CollisionModel kAllModels[] = {CollisionModel::kRigidPivot, CollisionModel::kFreeBat,
                                         CollisionModel::kHertz, CollisionModel::kFlexible};

TEST(BattedBall, HeadOnIsEachModelsOwnImpact) {
  for (CollisionModel model : kAllModels) {
    SCOPED_TRACE(CollisionModelName(model));
    const Scene scene = GameScene({SceneOutput::kBattedBall});
    const SceneResult r = EvaluateScene(scene, WithModel(model));
    ASSERT_TRUE(r.summary.IsSolutionUsable()) << r.summary.message;
    ASSERT_TRUE(r.batted_ball.has_value());
    const BattedBallResult& b = *r.batted_ball;
    // The model's own impact at the same point: Collide (the COR resolved there, as the scene's
    // is, from the material: wood-34-ash has no ball COR law in this scene).
    CollisionOptions co;
    const CollisionResult c = Collide(scene, b.impact_from_knob_m, model, co);
    ASSERT_TRUE(c.summary.IsSolutionUsable()) << c.summary.message;
    ASSERT_EQ(c.cor, *r.cor);
    // Closed forms: the same formula up to rounding. hertz, flexible: the same ODE at the same
    // approach speed with the same tolerances, so the same impulse; the exit speeds differ by
    // the rounding of -u + J/m against the oblique impact's vector sum (~1e-14 relative).
    EXPECT_NEAR(b.impact.exit_speed_mps, c.exit_speed_mps, 1e-9 * c.exit_speed_mps);
    EXPECT_NEAR(b.impact.launch_angle_deg, 0.0, 1e-12);  // level paths: w.y is exactly 0
    EXPECT_NEAR(b.impact.backspin_rpm, 0.0, 1e-12);      // no slip: no tangential impulse
    EXPECT_EQ(b.impact.regime, TangentialRegime::kNoSlip);
    EXPECT_TRUE(b.flight.Landed());
    if (model == CollisionModel::kHertz || model == CollisionModel::kFlexible) {
      ASSERT_NE(b.normal_model, nullptr);
      EXPECT_EQ(std::string(b.normal_model), CollisionModelName(model));
    } else {
      EXPECT_EQ(b.normal_model, nullptr);
      EXPECT_EQ(b.normal_cor, *r.cor);
    }
  }
}

TEST(BattedBall, UndercutSymmetryAndMonotonicSpin) {
  // Level paths, no pitch spin: an overcut is the undercut's mirror image (launch angle and
  // spin change sign, the speed is the same), to rounding.
  ResolvedScene r;
  Summary s;
  TimingBook book;
  Scene scene = GameScene({SceneOutput::kBattedBall});
  ASSERT_TRUE(ResolveScene(scene, true, &book, &r, &s)) << s.message;
  SceneOptions o;
  BattedBallModel model(scene, r, CollisionModel::kFreeBat, o.hertz, o.flexible, nullptr, &book);
  const double x = 0.7;
  double previous_spin = -1e9;
  for (double d = -0.03; d <= 0.0301; d += 0.005) {
    BattedBallResult up, down;
    Refusal why;
    std::string failure;
    ASSERT_TRUE(model.Evaluate(x, d, &up, &why, &failure)) << failure << why.Message();
    ASSERT_TRUE(model.Evaluate(x, -d, &down, &why, &failure)) << failure << why.Message();
    EXPECT_NEAR(up.impact.exit_speed_mps, down.impact.exit_speed_mps, 1e-12);
    EXPECT_NEAR(up.impact.launch_angle_deg, -down.impact.launch_angle_deg, 1e-10);
    EXPECT_NEAR(up.impact.backspin_rpm, -down.impact.backspin_rpm, 1e-8);
    // Spin grows with the undercut (strictly: the grip regime throughout this range).
    EXPECT_GT(up.impact.backspin_rpm, previous_spin) << d;
    previous_spin = up.impact.backspin_rpm;
  }
}

TEST(BattedBall, TabulatedNormalLawMatchesTheModel) {
  for (CollisionModel m : {CollisionModel::kHertz, CollisionModel::kFlexible}) {
    SCOPED_TRACE(CollisionModelName(m));
    Scene scene = GameScene({SceneOutput::kBattedBall});
    scene.swing.attack_angle_deg = 10.0;
    scene.ball.descent_angle_deg = 6.0;
    scene.ball.spin_rpm = 2000.0;
    ResolvedScene r;
    Summary s;
    TimingBook book;
    ASSERT_TRUE(ResolveScene(scene, true, &book, &r, &s)) << s.message;
    SceneOptions o;
    FlexibleModes flexible_modes(scene, o.flexible, &book);
    const BatModes* modes =
        m == CollisionModel::kFlexible ? flexible_modes.Impact().get() : nullptr;
    BattedBallModel model(scene, r, m, o.hertz, o.flexible, modes, &book);
    const double lo = 0.5 * r.length_m, hi = r.length_m;
    std::string failure;
    ASSERT_TRUE(model.TabulateNormalLaw(lo, hi, 41, -0.0254, 0.0508, 5, &failure)) << failure;
    EXPECT_EQ(model.table_impacts(), 41 * 5);
    double worst = 0.0;
    const flight::FlightOptions fo;
    for (double x : {0.62, 0.7, 0.7513, 0.8, lo + 26 * (hi - lo) / 40, lo + 30 * (hi - lo) / 40}) {
      for (double d : {-0.02, 0.0, 0.013, 0.025, 0.035}) {
        BattedBallResult exact, table;
        Refusal why;
        ASSERT_TRUE(model.Evaluate(x, d, &exact, &why, &failure)) << failure;
        const double c = model.CarryAt(x, d, fo, &table);
        ASSERT_TRUE(std::isfinite(c)) << x << " " << d;
        worst =
            std::max(worst, std::abs(table.impact.exit_speed_mps - exact.impact.exit_speed_mps));
      }
    }
    std::cout << CollisionModelName(m) << ": worst |exit speed (table) - exact| = " << worst
              << " m/s\n";
    // 5 Chebyshev speeds and a cubic in x over 41 positions (the defaults). hertz: its
    // effective COR barely moves with v_n and x (measured 4e-6 m/s): 1e-4. flexible: measured
    // 1.5e-3 m/s between the table's positions (the beam's exit speed bends along the barrel
    // on a scale of a few cm: 21 positions gave 6.6e-3, 41 a fourth of that), 3e-4 at its own
    // positions (the table's impacts skip the refinement run; the speed interpolation): 3e-3
    // m/s, about 1 cm of carry.
    EXPECT_LT(worst, m == CollisionModel::kHertz ? 1e-4 : 3e-3);
  }
}

TEST(DistanceSweetSpot, AgreesWithTheBestOfAFineCarryMap) {
  Scene scene = GameScene({SceneOutput::kDistanceSweetSpot, SceneOutput::kCarryMap});
  scene.swing.attack_angle_deg = 10.0;
  scene.ball.descent_angle_deg = 6.0;
  SceneOptions o = WithModel(CollisionModel::kFreeBat);
  o.distance.map_positions = 81;
  o.distance.map_undercuts = 61;
  const SceneResult r = EvaluateScene(scene, o);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  ASSERT_TRUE(r.distance_sweet_spot.has_value());
  ASSERT_TRUE(r.carry_map.has_value());
  const DistanceSweetSpotResult& d = *r.distance_sweet_spot;
  const CarryMapResult& m = *r.carry_map;
  const double cell_x = (m.positions_from_knob_m.back() - m.positions_from_knob_m.front()) / 80;
  const double cell_d = (m.undercuts_m.back() - m.undercuts_m.front()) / 60;
  // The optimum lies within one cell of the map's best point (the map's best is the grid point
  // nearest the top of a smooth hill, at most one cell away in each direction).
  EXPECT_LE(std::abs(d.position_from_knob_m - m.best_position_from_knob_m), cell_x);
  EXPECT_LE(std::abs(d.undercut_m - m.best_undercut_m), cell_d);
  // It carries at least as far as any grid point, up to the map's flight tolerance (0.1 ft,
  // its default: 3 cm), and not much farther: within a cell of a smooth maximum the carry
  // changes by (curvature) cell^2 / 2, a few cm here.
  EXPECT_GE(d.distance_m, m.best_distance_m - 0.03);
  EXPECT_LE(d.distance_m, m.best_distance_m + 0.2);
  EXPECT_FALSE(d.at_position_bound);
  EXPECT_FALSE(d.at_undercut_bound);
  EXPECT_EQ(d.normal_law, "closed_form");
  std::cout << "distance_sweet_spot: x " << d.position_from_knob_m << " m, D " << d.undercut_m
            << " m, " << d.distance_m << " m (" << d.evaluations << " carries, "
            << d.summary.message << "); map best: x " << m.best_position_from_knob_m << ", D "
            << m.best_undercut_m << ", " << m.best_distance_m << " m\n";
  // A backspin-launched fly ball (the undercut that carries farthest is not zero).
  EXPECT_GT(d.undercut_m, 0.0);
  EXPECT_GT(d.launch_angle_deg, 10.0);
  EXPECT_GT(d.backspin_rpm, 500.0);
}

TEST(DistanceSweetSpot, FartherWithAFasterSwing) {
  double previous = 0.0;
  for (double mph : {60.0, 70.0, 80.0}) {
    Scene scene = GameScene({SceneOutput::kDistanceSweetSpot});
    scene.swing.bat_speed_mps = mph * 0.44704;
    scene.swing.attack_angle_deg = 10.0;
    const SceneResult r = EvaluateScene(scene, WithModel(CollisionModel::kFreeBat));
    ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
    EXPECT_GT(r.distance_sweet_spot->distance_m, previous + 5.0) << mph;
    previous = r.distance_sweet_spot->distance_m;
  }
}

TEST(DistanceSweetSpot, TabulatedModelsReportTheirTable) {
  Scene scene = GameScene({SceneOutput::kDistanceSweetSpot});
  scene.swing.attack_angle_deg = 10.0;
  const SceneResult r = EvaluateScene(scene, WithModel(CollisionModel::kHertz));
  ASSERT_TRUE(r.summary.IsSolutionUsable()) << r.summary.message;
  const DistanceSweetSpotResult& d = *r.distance_sweet_spot;
  EXPECT_EQ(d.normal_law, "tabulated");
  EXPECT_EQ(d.normal_table_positions, 41);
  EXPECT_EQ(d.normal_table_speeds, 5);
  // The table's carry at the optimum against the exact law's (the test above bounds the exit
  // speed to 1e-3 m/s: a few mm).
  EXPECT_LT(std::abs(d.normal_table_error_m), 0.02);
  // The free bat and hertz (its hands aside, the same rigid bat) agree on the optimum.
  const SceneResult f = EvaluateScene(scene, WithModel(CollisionModel::kFreeBat));
  EXPECT_NEAR(d.position_from_knob_m, f.distance_sweet_spot->position_from_knob_m, 0.02);
  EXPECT_NEAR(d.undercut_m, f.distance_sweet_spot->undercut_m, 0.002);
}

TEST(BattedBall, TheScenesEnvironmentAndAero) {
  Scene scene = GameScene({SceneOutput::kBattedBall});
  scene.contact.undercut_m = 0.02;
  scene.swing.attack_angle_deg = 10.0;
  const SceneResult sea = EvaluateScene(scene, {});
  scene.environment.elevation_m = 1600.0;  // Denver
  const SceneResult denver = EvaluateScene(scene, {});
  ASSERT_TRUE(sea.batted_ball && denver.batted_ball);
  EXPECT_LT(denver.batted_ball->flight.air_density_kg_m3,
            0.85 * sea.batted_ball->flight.air_density_kg_m3);
  EXPECT_GT(denver.batted_ball->flight.distance_m, sea.batted_ball->flight.distance_m + 5.0);
  EXPECT_FALSE(denver.batted_ball->default_environment);
  // No air: the closed-form range of the same launch.
  scene.environment = flight::Environment{};
  scene.aero.model = flight::AeroModel::kVacuum;
  const SceneResult vacuum = EvaluateScene(scene, {});
  ASSERT_TRUE(vacuum.batted_ball.has_value()) << vacuum.summary.message;
  flight::Launch launch;
  launch.exit_speed_mps = vacuum.batted_ball->impact.exit_speed_mps;
  launch.launch_angle_deg = vacuum.batted_ball->impact.launch_angle_deg;
  const flight::FlightResult closed = flight::VacuumFlight(launch);
  // The flight's default tolerance: 0.1 ft (3 cm).
  EXPECT_NEAR(vacuum.batted_ball->flight.distance_m, closed.distance_m, 0.03);
  // Refused by core with the scene's name.
  scene.environment.relative_humidity_pct = 150.0;
  const SceneResult bad = EvaluateScene(scene, {});
  ASSERT_TRUE(bad.summary.refusal.has_value());
  EXPECT_EQ(bad.summary.refusal->field, "environment.relative_humidity_pct");
}

TEST(DistanceSweetSpot, RefusesARegionOffTheBat) {
  Scene scene = GameScene({SceneOutput::kCarryMap});
  SceneOptions o;
  o.distance.position_max_from_knob_m = 2.0;
  const SceneResult r = EvaluateScene(scene, o);
  ASSERT_TRUE(r.summary.refusal.has_value()) << r.summary.message;
  EXPECT_EQ(r.summary.refusal->field, "distance.position_max_from_knob_m");
  o.distance = DistanceOptions{};
  o.distance.undercut_min_m = 0.05;
  o.distance.undercut_max_m = 0.01;
  const SceneResult u = EvaluateScene(scene, o);
  ASSERT_TRUE(u.summary.refusal.has_value()) << u.summary.message;
  EXPECT_EQ(u.summary.refusal->field, "distance.undercut_max_m");
}

}  // namespace
}  // namespace batted_ball_test
}  // namespace sweetspot::core
