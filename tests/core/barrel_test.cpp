// barrel: the hoop mode (the closed form against a ring FE model and the energy method), the
// trampoline (its quasi-static closed form against the integrated wall, its rigid limit), BBCOR
// by the NCAA protocol, wood unchanged, the wall as a design variable.
#include "core/collision/barrel.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include "core/ball/ball_catalogue.hpp"
#include "core/bat/presets.hpp"
#include "core/scene/evaluate_scene.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
namespace barrel_test {
namespace {

Bat AluminiumPreset() { return FindPreset("bbcor-33-aluminium")->bat; }

Bat WithWall(Bat bat, double wall_m) {
  bat.wall_thickness_m = wall_m;
  return bat;
}

// 7050 aluminium (the preset's material).
constexpr double kE = 71.7e9, kNu = 0.33, kRho = 2830.0;

TEST(Barrel, RingFormulaIsTheN2CaseOfTheGeneralRingFormula) {
  // omega^2 = 3 E' h^2 / (5 rho R^4) for n = 2, written out independently.
  const double r = 0.032, h = 0.0028;
  const double e_prime = kE / (1.0 - kNu * kNu);
  const double f = std::sqrt(0.6 * e_prime * h * h / (kRho * std::pow(r, 4))) / (2.0 * kPi);
  EXPECT_NEAR(RingModeFrequencyHz(kE, kNu, kRho, r, h), f, 1e-12 * f);
  // n = 3 over n = 2: sqrt(9 * 64 * 5 / (4 * 9 * 10)) = sqrt(8).
  EXPECT_NEAR(RingModeFrequencyHz(kE, kNu, kRho, r, h, 3) / f, std::sqrt(8.0), 1e-12);
}

TEST(Barrel, RingFeModelConvergesToTheClosedForm) {
  // A thin ring (h/R = 0.01): the FE model's extensibility and faceting errors are O((h/R)^2) and
  // O(1/N^2); 128 elements agree to 0.1 %.
  const double r = 0.03, h = 0.0003;
  const double closed = RingModeFrequencyHz(kE, kNu, kRho, r, h);
  EXPECT_NEAR(RingFeHoopFrequencyHz(kE, kNu, kRho, r, h, 128), closed, 1e-3 * closed);
  // The preset's wall (h/R = 0.086) still within 1 %.
  const BarrelWall w = BarrelWallAt(AluminiumPreset(), AluminiumPreset().LengthM() - 0.1524);
  const double fe = RingFeHoopFrequencyHz(kE, kNu, kRho, w.mid_radius_m, w.thickness_m, 128);
  EXPECT_NEAR(fe, w.hoop_frequency_hz, 0.01 * w.hoop_frequency_hz);
}

TEST(Barrel, RingStiffnessFromTheEnergyMethodEqualsModalMassTimesOmegaSquared) {
  const Bat bat = AluminiumPreset();
  const BarrelWall w = BarrelWallAt(bat, bat.LengthM() - 0.1524);
  ASSERT_TRUE(w.hollow);
  const double omega = 2.0 * kPi * w.hoop_frequency_hz;
  EXPECT_NEAR(w.ring_stiffness_n_m, w.modal_mass_kg * omega * omega, 1e-12 * w.ring_stiffness_n_m);
  EXPECT_NEAR(w.stiffness_n_m, kBarrelShellFactor * w.ring_stiffness_n_m, 1e-6);
  EXPECT_NEAR(w.effective_length_m,
              2.0 * w.mid_radius_m * std::sqrt(w.mid_radius_m / w.thickness_m), 1e-15);
}

TEST(Barrel, AluminiumPresetHoopFrequencyIsInThePublishedRange) {
  // D. A. Russell, "Acoustics and vibration of baseball and softball bats", Acoustics Today
  // 13(4), 35 (2017): hollow bats' hoop frequencies lie between 1000 and 2500 Hz.
  const Bat bat = AluminiumPreset();
  const BarrelWall w = BarrelWallAt(bat, bat.LengthM() - 0.1524);
  EXPECT_GT(w.hoop_frequency_hz, 1000.0);
  EXPECT_LT(w.hoop_frequency_hz, 2500.0);
  EXPECT_NEAR(w.hoop_frequency_hz, 1777.5, 0.5);
}

TEST(Barrel, TheShellFactorIsTheOneThatPutsThePresetAtTheLimit) {
  // The calibration re-derived: bisection on c for BBCOR = 0.50 at the preset's wall.
  const Bat bat = AluminiumPreset();
  double lo = 1.0, hi = 50.0;
  for (int i = 0; i < 60; ++i) {
    BarrelOptions o;
    o.shell_factor = std::sqrt(lo * hi);
    (ComputeBbcor(bat, {}, o).value > 0.5 ? lo : hi) = o.shell_factor;
  }
  EXPECT_NEAR(lo, kBarrelShellFactor, 0.05);
  const BbcorResult r = ComputeBbcor(bat);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_NEAR(r.value, 0.50, 0.002);
  EXPECT_LE(r.value, 0.50);
  EXPECT_EQ(r.method, "trampoline_quasi_static");
  EXPECT_EQ(r.ball, "ncaa-nfhs");
  EXPECT_NEAR(r.ball_speed_mps, 136.0 * 0.44704, 1e-12);
  EXPECT_NEAR(r.impact_from_knob_m, bat.LengthM() - 0.1524, 1e-15);
  EXPECT_NEAR(r.pivot_from_knob_m, 0.1524, 1e-15);
  // More than the ball gives off solid wood: the trampoline.
  EXPECT_GT(r.value, r.ball_cor + 0.015);
}

TEST(Barrel, SolidWoodIsUnchanged) {
  for (const char* name : {"wood-34-ash", "paper-wood"}) {
    const Bat bat = FindPreset(name)->bat;
    ASSERT_FALSE(bat.IsHollow());
    EXPECT_FALSE(BarrelWallAt(bat, 0.7).hollow);
    const BbcorResult r = ComputeBbcor(bat);
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_EQ(r.method, "rigid");
    const double e = FindBallPreset("ncaa-nfhs")->cor_law.CorAt(136.0 * 0.44704);
    EXPECT_EQ(r.value, e);
    EXPECT_EQ(r.hoop_frequency_hz, 0.0);
    const TrampolineResult t =
        EffectiveCorAt(bat, ComputeMassProperties(bat), 0.7, 0.145, 0.0366, 4e7, 1.5, 0.5, 40.0);
    EXPECT_TRUE(t.ok);
    EXPECT_EQ(t.effective_cor, 0.5);
  }
}

TEST(Barrel, ThinnerWallGivesHigherBbcor) {
  const Bat bat = AluminiumPreset();
  double previous = 2.0;
  for (double h = 0.0012; h <= 0.008; h += 0.0004) {
    const BbcorResult r = ComputeBbcor(WithWall(bat, h));
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_LT(r.value, previous) << "h = " << h;
    previous = r.value;
  }
}

TEST(Barrel, ThinnestLegalWallByBisectionIsLegalWhenRecomputed) {
  // The design question "thinnest wall with BBCOR <= 0.50", answered through the public function
  // and checked by recomputing on both sides.
  const Bat bat = AluminiumPreset();
  double thin = 0.001, thick = 0.008;  // BBCOR(thin) > 0.50 >= BBCOR(thick)
  ASSERT_GT(ComputeBbcor(WithWall(bat, thin)).value, 0.5);
  ASSERT_LE(ComputeBbcor(WithWall(bat, thick)).value, 0.5);
  while (thick - thin > 1e-7) {
    const double mid = 0.5 * (thin + thick);
    (ComputeBbcor(WithWall(bat, mid)).value > 0.5 ? thin : thick) = mid;
  }
  EXPECT_LE(ComputeBbcor(WithWall(bat, thick)).value, 0.5);
  EXPECT_GT(ComputeBbcor(WithWall(bat, thick - 1e-6)).value, 0.5);
  // The preset sits at the limit (its wall is the calibration point).
  EXPECT_NEAR(thick, bat.wall_thickness_m, 1e-4);
}

TrampolineProblem PresetProblem(double modal_mass_kg) {
  const Bat bat = AluminiumPreset();
  const BarrelWall w = BarrelWallAt(bat, bat.LengthM() - 0.1524);
  TrampolineProblem p;
  p.ball_mass_kg = 0.14529;
  p.ball_stiffness = 4e7;
  p.surface_stiffness = BatSurfaceHertzStiffness(kE, kNu, 0.03689, w.outer_radius_m);
  p.ball_cor = 0.479;
  p.bat_effective_mass_kg = 0.6;
  p.approach_speed_mps = 60.8;
  p.barrel_stiffness_n_m = w.stiffness_n_m;
  p.barrel_modal_mass_kg = modal_mass_kg;
  return p;
}

TEST(Barrel, IntegratedWallTendsToTheQuasiStaticClosedFormAsItsMassVanishes) {
  for (double k : {2e6, 2e7, 2e8}) {
    TrampolineProblem p = PresetProblem(1e-4);
    p.barrel_stiffness_n_m = k;
    const TrampolineResult dynamic = TrampolineImpact(p);
    ASSERT_TRUE(dynamic.ok) << dynamic.message;
    const TrampolineResult closed = QuasiStaticTrampoline(p);
    ASSERT_TRUE(closed.ok);
    EXPECT_NEAR(dynamic.effective_cor, closed.effective_cor, 2e-3) << "k_b = " << k;
    EXPECT_NEAR(dynamic.peak_force_n, closed.peak_force_n, 0.01 * closed.peak_force_n);
  }
}

TEST(Barrel, StiffBarrelGivesTheBallsCor) {
  TrampolineProblem p = PresetProblem(1e-4);
  p.barrel_stiffness_n_m = 1e13;
  EXPECT_NEAR(QuasiStaticTrampolineCor(p), p.ball_cor, 1e-4);
  // A lossless barrel in a lossless ball: e_eff = 1 whatever the split.
  p.ball_cor = 1.0;
  p.barrel_stiffness_n_m = 1e7;
  EXPECT_NEAR(QuasiStaticTrampolineCor(p), 1.0, 1e-12);
  // All the loss in the barrel, e = 1 for the ball: e_eff^2 = 1 - loss * (barrel's share).
  p.barrel_loss = 0.2;
  const TrampolineResult r = QuasiStaticTrampoline(p);
  EXPECT_NEAR(r.effective_cor * r.effective_cor, 1.0 - 0.2 * r.barrel_energy_fraction, 1e-12);
}

TEST(Barrel, OptionsAreCheckedWithTheirField) {
  EXPECT_TRUE(BarrelOptions{}.Validate(nullptr));
  BarrelOptions o;
  o.barrel_loss = 1.0;
  std::string why;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "barrel.barrel_loss = 1: must be in [0, 1)");
  const BbcorResult r = ComputeBbcor(AluminiumPreset(), {}, o);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.message, why);
}

}  // namespace
}  // namespace barrel_test
}  // namespace sweetspot::core

namespace sweetspot::core {
namespace barrel_test {
namespace {

TEST(BarrelScene, OutputsNeedTheBatsGeometryAndSolidBatsKeepTheirCor) {
  Scene s;
  s.bat = FindPreset("wood-34-ash")->bat;
  s.length_m = s.bat->LengthM();
  s.outputs = {SceneOutput::kMaxExitSpeed};
  const SceneResult plain = EvaluateScene(s, {});
  s.outputs = {SceneOutput::kMaxExitSpeed, SceneOutput::kBarrel, SceneOutput::kBbcor};
  const SceneResult with = EvaluateScene(s, {});
  ASSERT_EQ(with.summary.termination, Termination::kConverged) << with.summary.message;
  EXPECT_EQ(with.cor, plain.cor);
  EXPECT_EQ(with.max_exit_speed->exit_speed_mps, plain.max_exit_speed->exit_speed_mps);
  ASSERT_TRUE(with.barrel.has_value());
  EXPECT_FALSE(with.barrel->hollow);
  EXPECT_EQ(with.barrel->effective_cor, *with.cor);
  ASSERT_TRUE(with.bbcor.has_value());
  EXPECT_EQ(with.bbcor->method, "flexible_scan_max");
  EXPECT_EQ(with.bbcor->estimate_method, "rigid");
  // Only mass properties: refused, naming the bat.
  Scene no_bat = s;
  no_bat.mass_properties = ComputeMassProperties(*s.bat);
  no_bat.bat.reset();
  for (SceneOutput o : {SceneOutput::kBarrel, SceneOutput::kBbcor}) {
    no_bat.outputs = {o};
    const SceneResult r = EvaluateScene(no_bat, {});
    EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
    EXPECT_EQ(r.refused_field, "bat");
  }
  // A reused evaluator resets the barrel outputs.
  SceneEvaluator evaluator({});
  SceneResult reused;
  evaluator.Evaluate(s, &reused);
  s.outputs = {SceneOutput::kMaxExitSpeed};
  evaluator.Evaluate(s, &reused);
  EXPECT_FALSE(reused.barrel.has_value());
  EXPECT_FALSE(reused.bbcor.has_value());
}

}  // namespace
}  // namespace barrel_test
}  // namespace sweetspot::core
