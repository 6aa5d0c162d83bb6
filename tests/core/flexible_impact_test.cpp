// The flexible collision: energy balance, the rigid limit, the residual flexibility, realistic
// contact figures, sting, error estimates, and hard cases.
#include "core/collision/flexible_impact.hpp"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include "tests/refusal_text.hpp"

#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"
#include "core/collision/hertz_contact.hpp"
#include "core/flexible/beam_model.hpp"
#include "core/flexible/modes.hpp"
#include "core/flexible/static_flexibility.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace flexible_impact_test {
namespace {

// The modes an impact uses by default (12 modes to 1e-3), computed once per bat.
const BatModes& ModesOf(const std::string& preset) {
  static const BatModes paper = [] {
    BeamModesOptions o;
    o.num_modes = 12;
    o.relative_tolerance = 1e-3;
    return ComputeBatModes(FindPreset("paper-wood")->bat, o);
  }();
  static const BatModes bbcor = [] {
    BeamModesOptions o;
    o.num_modes = 12;
    o.relative_tolerance = 1e-3;
    return ComputeBatModes(FindPreset("bbcor-33-aluminium")->bat, o);
  }();
  return preset == "paper-wood" ? paper : bbcor;
}

// The paper's kinematics at impact position s (27.7 m/s pitch, 17.288 rad/s about the knob).
FlexibleImpactInputs Inputs(const Bat& bat, double s) {
  FlexibleImpactInputs in;
  in.impact_from_knob_m = s;
  in.approach_speed_mps = 27.7 + 17.288 * s;
  in.surface_stiffness = BatSurfaceHertzStiffness(
      bat.material.youngs_modulus_pa, bat.material.poissons_ratio, 0.0366, bat.RadiusAtM(s));
  return in;
}

TEST(FlexibleImpactOptions, DefaultsAreValidAndRulesAreNamed) {
  std::string why;
  EXPECT_TRUE(Validates(FlexibleImpactOptions{}, &why)) << why;
  FlexibleImpactOptions o;
  o.cutoff_factor = 0.5;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "flexible.cutoff_factor = 0.5: must be in [1, 1000]");
  o = {};
  o.max_modes = 51;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "flexible.max_modes = 51: must be in [1, 50]");
  FlexibleImpactInputs in;
  in.approach_speed_mps = 0.0;
  EXPECT_FALSE(Validates(in, &why));
  EXPECT_EQ(why,
            "approach_speed_mps = 0: must be finite and > 0 (the ball and the bat must approach "
            "each other)");
}

TEST(FlexibleImpact, EnergyBalanceOfTheUndampedCollision) {
  // initial = ball + bat rigid-body + vibration + contact loss, the loss from the hysteresis in
  // closed form ((1 - e^2) x loading work): nothing else dissipates. Dopri5 at 1e-8 on a state
  // scaled to O(1) and events located to 52 bits leave ~1e-8 of the initial energy (measured
  // 1.2e-8); 1e-6 keeps a 50x margin at -O1 as at -O2.
  for (const auto& [preset, s] : {std::pair<std::string, double>{"paper-wood", 0.7},
                                  {"paper-wood", 0.5},
                                  {"paper-wood", 0.855},
                                  {"bbcor-33-aluminium", 0.6}}) {
    const Bat bat = FindPreset(preset)->bat;
    const FlexibleImpactResult r = SolveFlexibleImpact(bat, ModesOf(preset), Inputs(bat, s), {});
    ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
    const double sum =
        r.ball_energy_j + r.rigid_body_energy_j + r.vibration_energy_j + r.contact_loss_j;
    EXPECT_NEAR(sum / r.initial_energy_j, 1.0, 1e-6) << preset << " at " << s;
    EXPECT_NEAR(r.energy_balance_error_j / r.initial_energy_j, 0.0, 1e-6);
    // The integrated contact work agrees with the closed-form loss (same tolerance).
    EXPECT_NEAR(r.contact_work_j / r.contact_loss_j, 1.0, 1e-6);
    EXPECT_GT(r.vibration_energy_j, 0.0);
    double modal = 0.0;
    for (double e : r.modal_energies_j) modal += e;
    EXPECT_NEAR(modal, r.vibration_energy_j, 1e-12 * r.initial_energy_j);
  }
}

TEST(FlexibleImpact, RecoversTheRigidFreeBatAsTheBatStiffens) {
  // E (and G with it) x 10^4 and x 10^6: the bending modes leave the contact's bandwidth and the
  // bat's static compliance falls as 1/E, so the exit speed tends to the free rigid bat's with
  // the same e and mass properties (rigid_exit_speed_mps, exact closed form) like 1/E.
  const Bat base = FindPreset("paper-wood")->bat;
  for (double s : {0.5, 0.7}) {
    std::vector<double> diffs;
    for (double scale : {1e4, 1e6}) {
      Bat bat = base;
      bat.material.youngs_modulus_pa *= scale;
      BeamModesOptions mo;
      mo.num_modes = 12;
      mo.relative_tolerance = 1e-3;
      const BatModes modes = ComputeBatModes(bat, mo);
      ASSERT_TRUE(modes.summary.IsSolutionUsable()) << modes.summary.message;
      const FlexibleImpactResult r = SolveFlexibleImpact(bat, modes, Inputs(bat, s), {});
      ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
      diffs.push_back(std::abs(r.exit_speed_mps - r.rigid_exit_speed_mps));
      EXPECT_EQ(r.modes_used, 0);  // the fundamental is above the cutoff
    }
    // 1/E: 100x less for 100x stiffer (50x allows the integrator's 1e-8 floor).
    EXPECT_LT(diffs[1], diffs[0] / 50.0) << s;
    // At E x 1e6 within 1e-6 of the approach speed (measured 1e-6 m/s at 0.7 m, 1e-4 at 0.5 m
    // where the barrel is thinner... no: where the handle-side compliance is larger).
    EXPECT_LT(diffs[1], 1e-5 * (27.7 + 17.288 * s)) << s;
  }
}

TEST(FlexibleImpact, ContactTimeAndPeakForceAreRealisticAndTheSweetSpotIsNarrow) {
  const Bat bat = FindPreset("paper-wood")->bat;
  const BatModes& modes = ModesOf("paper-wood");
  const FlexibleImpactResult at = SolveFlexibleImpact(bat, modes, Inputs(bat, 0.7), {});
  ASSERT_EQ(at.summary.termination, Termination::kConverged) << at.summary.message;
  // Game-speed baseball-bat contacts last 0.6-1 ms with peak forces of a few 10^4 N
  // (docs/models.md, the hertz calibration); the flexible bat lengthens the contact a little.
  EXPECT_GT(at.contact_time_s, 0.6e-3);
  EXPECT_LT(at.contact_time_s, 1.0e-3);
  EXPECT_GT(at.peak_force_n, 2e4);
  EXPECT_LT(at.peak_force_n, 4e4);
  EXPECT_EQ(at.contacts, 1);
  // Near the node the flexible exit speed is within 2 % of the rigid bat's; 0.2 m towards the
  // handle it loses a third: vibrations take the energy (Nathan, Am. J. Phys. 68 (2000) 979).
  EXPECT_NEAR(at.exit_speed_mps / at.rigid_exit_speed_mps, 1.0, 0.02);
  const FlexibleImpactResult handle = SolveFlexibleImpact(bat, modes, Inputs(bat, 0.5), {});
  EXPECT_LT(handle.exit_speed_mps, 0.7 * handle.rigid_exit_speed_mps);
  EXPECT_GT(handle.vibration_energy_j, 4.0 * at.vibration_energy_j);
  EXPECT_GT(handle.hands_vibration_energy_j, 3.0 * at.hands_vibration_energy_j);
  const FlexibleImpactResult tip = SolveFlexibleImpact(bat, modes, Inputs(bat, 0.855), {});
  EXPECT_GT(tip.vibration_energy_j, 4.0 * at.vibration_energy_j);
}

TEST(FlexibleImpact, StaticCorrectionMakesTheExitSpeedConvergeWithFewModes) {
  // Reference: 40 modes with the correction. With the correction 4 modes are within 0.05 m/s
  // and 12 within 0.005 m/s (measured 0.026 and 0.0002); without it 4 modes miss by > 0.3 m/s.
  const Bat bat = FindPreset("paper-wood")->bat;
  auto exit_with = [&](int modes_count, bool correction) {
    BeamModesOptions mo;
    mo.num_modes = modes_count;
    mo.relative_tolerance = 1e-4;
    const BatModes modes = ComputeBatModes(bat, mo);
    FlexibleImpactOptions o;
    o.cutoff_factor = 1000.0;  // use every computed mode
    o.static_correction = correction;
    o.refine_check = false;
    return SolveFlexibleImpact(bat, modes, Inputs(bat, 0.7), o).exit_speed_mps;
  };
  const double reference = exit_with(40, true);
  EXPECT_NEAR(exit_with(4, true), reference, 0.05);
  EXPECT_NEAR(exit_with(12, true), reference, 0.005);
  EXPECT_GT(std::abs(exit_with(4, false) - reference), 0.3);
}

TEST(FlexibleImpact, InertiaReliefFlexibilityIsTheSumOverEveryMode) {
  // G(s) = sum over all flexible FE modes of phi_k(s)^2 / omega_k^2, from a dense solve of the
  // same mesh (Euler-Bernoulli: well conditioned; 1e-8 relative covers its rounding).
  const Bat bat = FindPreset("paper-wood")->bat;
  BeamModesOptions mo;
  mo.theory = BeamTheory::kEulerBernoulli;
  mo.num_modes = 2;
  const BatModes modes = ComputeBatModes(bat, mo);
  BeamMesh mesh;
  mesh.nodes_m = modes.nodes_m;
  mesh.breakpoints_m = modes.breakpoints_m;
  const BeamMatrices mats = AssembleBeam(bat, mesh, BeamTheory::kEulerBernoulli, false);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(
      Eigen::MatrixXd(mats.stiffness), Eigen::MatrixXd(mats.mass),
      Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
  // At mesh nodes the static solve uses the modes' own mesh, so the sums must agree.
  for (double s :
       {modes.nodes_m[5], modes.nodes_m[modes.nodes_m.size() / 2], modes.nodes_m.back()}) {
    double sum = 0.0;
    for (Eigen::Index k = 2; k < es.eigenvalues().size(); ++k) {
      const double phi = modes.Displacement(es.eigenvectors().col(k), s);
      sum += phi * phi / es.eigenvalues()[k];
    }
    EXPECT_NEAR(InertiaReliefFlexibility(bat, modes, s) / sum, 1.0, 1e-8) << s;
  }
  // Between nodes a node is put at the load, so G converges like the static deflection
  // (h^2 in the shear part once the kink sits on a node): the default 2-mode mesh and one at
  // least twice as fine agree to 1e-4 (measured 2.6e-5; without the node at the load it was
  // 3.5e-3), i.e. ~1e-5 of the exit speed.
  BeamModesOptions fine = mo;
  fine.theory = BeamTheory::kTimoshenko;
  const BatModes coarse_t = ComputeBatModes(bat, fine);
  fine.relative_tolerance = 1e-7;
  const BatModes fine_t = ComputeBatModes(bat, fine);
  ASSERT_GT(fine_t.Elements(), 2 * coarse_t.Elements() - 1);
  EXPECT_NEAR(InertiaReliefFlexibility(bat, coarse_t, 0.7123) /
                  InertiaReliefFlexibility(bat, fine_t, 0.7123),
              1.0, 1e-4);
}

TEST(FlexibleImpact, InertiaReliefFlexibilityReusesTheModesElementsBitForBit) {
  // The modes keep their final mesh's element parts; the static solve's mesh (a node put at or
  // moved to the load) takes the elements it keeps from them. Same numbers, bit for bit, as
  // integrating every element again: at a node, beside one (moved), between two (inserted), at
  // the ends; both theories, a hollow bat and a filled one.
  for (const char* preset : {"wood-34-ash", "bbcor-33-aluminium", "paper-wood"}) {
    for (const BeamTheory theory : {BeamTheory::kTimoshenko, BeamTheory::kEulerBernoulli}) {
      Bat bat = FindPreset(preset)->bat;
      if (std::string(preset) == "paper-wood") {
        bat.fill = Fill{FindMaterial("cork").value(), 0.0254, 0.254};
      }
      BeamModesOptions mo;
      mo.theory = theory;
      mo.num_modes = 6;
      const BatModes modes = ComputeBatModes(bat, mo);
      ASSERT_EQ(modes.element_parts.size(), static_cast<std::size_t>(modes.Elements())) << preset;
      BatModes without = modes;
      without.element_parts.clear();
      const std::vector<double>& n = modes.nodes_m;
      const double h = n[6] - n[5];
      for (const double x : {n[5], n[5] + 0.1 * h, n[5] + 0.5 * h, n[n.size() / 2] - 0.2 * h, 0.0,
                             n.back(), 0.5 * n.back()}) {
        const double reused = InertiaReliefFlexibility(bat, modes, x);
        EXPECT_TRUE(std::isfinite(reused) && reused > 0.0) << preset << " " << x;
        EXPECT_EQ(reused, InertiaReliefFlexibility(bat, without, x)) << preset << " " << x;
      }
    }
  }
}

TEST(FlexibleImpact, ElasticContactTimeMatchesTheHertzIntegrator) {
  // A rigid-bat elastic impact (e = 1, rigid surface, no hands): the contact model integrates
  // the same 1-DOF power law; its contact time at tolerance 1e-10 agrees to 1e-7.
  HertzProblem p;
  p.approach_speed_mps = 40.0;
  p.ball_speed_mps = 27.7;
  p.ball_mass_kg = 0.145;
  p.c11_per_kg = 1.0 / 0.145 + 1.0;
  p.c12_per_kg = 1.0;
  p.c22_per_kg = 1.0;
  p.ball_stiffness = 4e7;
  p.ball_exponent = 1.5;
  p.cor = 1.0;
  HertzSolverOptions so;
  so.relative_tolerance = 1e-10;
  const HertzImpact h = SolveHertzImpact(p, so);
  ASSERT_TRUE(h.summary.IsSolutionUsable()) << h.summary.message;
  EXPECT_NEAR(ElasticContactTimeS(p.c11_per_kg, 4e7, 1.5, 40.0) / h.contact_time_s, 1.0, 1e-7);
}

TEST(FlexibleImpact, ErrorEstimatesCoverTheDifferenceToAFinerSolve) {
  // Integration: tolerance 1e-8 against 1e-11; truncation: 12 modes against 30 (both with the
  // static correction). The reported estimate must cover the actual difference (x 2: the
  // estimate is a difference of two approximations, not a bound).
  const Bat bat = FindPreset("paper-wood")->bat;
  const FlexibleImpactResult r =
      SolveFlexibleImpact(bat, ModesOf("paper-wood"), Inputs(bat, 0.7), {});
  BeamModesOptions mo;
  mo.num_modes = 30;
  mo.relative_tolerance = 1e-4;
  const BatModes many = ComputeBatModes(bat, mo);
  FlexibleImpactOptions o;
  o.relative_tolerance = 1e-11;
  o.cutoff_factor = 1000.0;
  o.refine_check = false;
  const FlexibleImpactResult ref = SolveFlexibleImpact(bat, many, Inputs(bat, 0.7), o);
  EXPECT_LE(std::abs(r.exit_speed_mps - ref.exit_speed_mps), 2.0 * r.error_estimate_exit_speed_mps);
  EXPECT_LT(r.error_estimate_exit_speed_mps, 0.01);
  EXPECT_LE(std::abs(r.hands_vibration_energy_j - ref.hands_vibration_energy_j),
            2.0 * r.error_estimate_hands_energy_j + 1e-3 * ref.hands_vibration_energy_j);
}

// ---------------------------------------------------------------------------- hard cases

TEST(FlexibleImpactHardCases, PerfectlyPlasticEndsAtMaximumCompressionAndBalances) {
  const Bat bat = FindPreset("paper-wood")->bat;
  FlexibleImpactInputs in = Inputs(bat, 0.7);
  in.cor = 0.0;
  const FlexibleImpactResult r = SolveFlexibleImpact(bat, ModesOf("paper-wood"), in, {});
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  ASSERT_FALSE(r.summary.warnings.empty());
  EXPECT_EQ(r.summary.warnings[0].rfind("cor = 0: perfectly plastic", 0), 0u);
  // The whole loading work is lost; the balance holds as for e > 0 (same tolerance).
  EXPECT_NEAR(r.energy_balance_error_j / r.initial_energy_j, 0.0, 1e-6);
}

TEST(FlexibleImpactHardCases, ImpactsAtTheKnobAndTheTipGiveFiniteAnswers) {
  const Bat bat = FindPreset("paper-wood")->bat;
  for (double s : {0.0, 0.855}) {
    const FlexibleImpactResult r =
        SolveFlexibleImpact(bat, ModesOf("paper-wood"), Inputs(bat, s), {});
    ASSERT_TRUE(r.summary.IsSolutionUsable()) << s << ": " << r.summary.message;
    EXPECT_TRUE(std::isfinite(r.exit_speed_mps));
    EXPECT_NEAR(r.energy_balance_error_j / r.initial_energy_j, 0.0, 1e-6);
  }
}

TEST(FlexibleImpactHardCases, OffTheBatAndUnusableModesAreRefused) {
  const Bat bat = FindPreset("paper-wood")->bat;
  const FlexibleImpactResult off =
      SolveFlexibleImpact(bat, ModesOf("paper-wood"), Inputs(bat, 0.9), {});
  EXPECT_EQ(off.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(off.summary.message,
            "impact_from_knob_m = 0.90000000000000002: must be within the bat [0, "
            "0.85499999999999998]");
  BatModes none;
  none.summary.termination = Termination::kInvalidInput;
  none.summary.message = "bat.length_m = 0.001: ...";
  const FlexibleImpactResult r = SolveFlexibleImpact(bat, none, Inputs(bat, 0.7), {});
  EXPECT_EQ(r.summary.termination, Termination::kFailure);
  EXPECT_EQ(r.summary.message, "the bat's modes are not usable: bat.length_m = 0.001: ...");
}

TEST(FlexibleImpactHardCases, AVerySoftBatStillBalancesItsEnergy) {
  // E / 1000: the fundamental drops to ~6 Hz, every computed mode is below the cutoff and the
  // static correction carries the rest; the answer stays physical (the ball barely rebounds).
  Bat bat = FindPreset("paper-wood")->bat;
  bat.material.youngs_modulus_pa /= 1000.0;
  BeamModesOptions mo;
  mo.num_modes = 12;
  mo.relative_tolerance = 1e-3;
  const BatModes modes = ComputeBatModes(bat, mo);
  ASSERT_TRUE(modes.summary.IsSolutionUsable()) << modes.summary.message;
  const FlexibleImpactResult r = SolveFlexibleImpact(bat, modes, Inputs(bat, 0.7), {});
  ASSERT_TRUE(r.summary.IsSolutionUsable()) << r.summary.message;
  EXPECT_EQ(r.modes_used, 12);
  EXPECT_LT(r.exit_speed_mps, r.rigid_exit_speed_mps);
  EXPECT_NEAR(r.energy_balance_error_j / r.initial_energy_j, 0.0, 1e-6);
}

}  // namespace
}  // namespace flexible_impact_test
}  // namespace sweetspot::core
