// The barrel's spring in the flexible contact (FlexibleImpactInputs::barrel_compliance_m_n):
// without bending modes it is the quasi-static trampoline (barrel.hpp) exactly; with the modes
// of ever stiffer bats it tends to it; zero is the former behaviour.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include "core/ball/ball_catalogue.hpp"
#include "core/bat/presets.hpp"
#include "core/collision/barrel.hpp"
#include "core/collision/contact_law.hpp"
#include "core/collision/flexible_impact.hpp"
#include "core/flexible/modes.hpp"
#include "core/scene/scene.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace flexible_barrel_spring_test {
namespace {

constexpr double kSixInches = 0.1524;

// e_eff of the aluminium preset 6 in from the tip (the NCAA ball at 136 mph onto the bat at
// rest), its barrel spring in series, with the bat's moduli raised `stiffening` times (k_b and
// the surface's Hertz K kept from the real bat), from the flexible model and from the
// quasi-static trampoline on the same free rigid bat.
struct SpringCase {
  double flexible = 0.0;            // e_eff from the flexible exit speed
  double quasi_static = 0.0;        // barrel_loss 0: the wall elastic, as in the flexible model
  double quasi_static_lossy = 0.0;  // the default barrel_loss 0.01
};

SpringCase BarrelSpringCase(double stiffening, bool without_modes) {
  const Bat bat = FindPreset("bbcor-33-aluminium")->bat;
  const double x = bat.LengthM() - kSixInches;
  const BarrelWall wall = BarrelWallAt(bat, x);
  const BallPreset ball = *FindBallPreset("ncaa-nfhs");
  const double u = 136.0 * 0.44704;
  Bat stiff = bat;
  stiff.material.youngs_modulus_pa *= stiffening;
  stiff.material.shear_modulus_pa *= stiffening;
  BatModes modes = ComputeBatModes(stiff, FlexibleOptions{}.ImpactModes());
  FlexibleImpactOptions options = FlexibleOptions{}.impact;
  if (without_modes) {
    // Every bending mode far above the cutoff (none is used) and no static correction: the
    // rigid free bat with the barrel spring in series, the quasi-static trampoline's model.
    for (auto& mode : modes.modes) mode.frequency_hz *= 1e6;
    options.static_correction = false;
  }
  FlexibleImpactInputs in;
  in.impact_from_knob_m = x;
  in.ball_mass_kg = ball.mass_kg;
  in.ball_speed_mps = u;
  in.approach_speed_mps = u;
  in.ball_stiffness = ball.stiffness;
  in.ball_exponent = ball.stiffness_exponent;
  in.surface_stiffness =
      BatSurfaceHertzStiffness(bat.material.youngs_modulus_pa, bat.material.poissons_ratio,
                               ball.radius_m, wall.outer_radius_m);
  in.cor = ball.cor_law.CorAt(u);
  in.barrel_compliance_m_n = 1.0 / wall.stiffness_n_m;
  const FlexibleImpactResult fr = SolveFlexibleImpact(stiff, modes, in, options);
  EXPECT_TRUE(fr.summary.IsSolutionUsable()) << fr.summary.message;
  if (without_modes) {
    EXPECT_EQ(fr.modes_used, 0);
  }
  const double b = x - modes.balance_point_m;
  const double inverse_mass = 1.0 / modes.mass_kg + b * b / modes.moi_centroid_kg_m2;
  SpringCase c;
  // exit = -u + (1 + e_eff) v0 / (1 + m / M_e) with v0 = u.
  c.flexible = (fr.exit_speed_mps + u) * (1.0 + ball.mass_kg * inverse_mass) / u - 1.0;
  TrampolineProblem p;
  p.ball_mass_kg = ball.mass_kg;
  p.ball_stiffness = ball.stiffness;
  p.ball_exponent = ball.stiffness_exponent;
  p.surface_stiffness = in.surface_stiffness;
  p.ball_cor = in.cor;
  p.bat_effective_mass_kg = 1.0 / inverse_mass;
  p.approach_speed_mps = u;
  p.barrel_stiffness_n_m = wall.stiffness_n_m;
  p.barrel_modal_mass_kg = wall.modal_mass_kg;
  p.barrel_loss = 0.0;
  c.quasi_static = QuasiStaticTrampolineCor(p);
  p.barrel_loss = BarrelOptions{}.barrel_loss;
  c.quasi_static_lossy = QuasiStaticTrampolineCor(p);
  return c;
}

TEST(FlexibleBarrelSpring, WithoutBendingModesItIsTheQuasiStaticTrampoline) {
  // Two bodies, the ball's hysteretic law in series with an elastic spring: at maximum
  // compression mu v0^2 / 2 is stored, the ball returns e^2 of its share, the spring all of its
  // own, which is the closed form's e_eff^2 exactly. Measured: 7.2e-9 apart (0.500211746 against
  // 0.500211754), the integration tolerance 1e-8; 1e-7 allows a platform's rounding.
  const SpringCase c = BarrelSpringCase(1.0, true);
  EXPECT_NEAR(c.flexible, c.quasi_static, 1e-7);
  EXPECT_NEAR(c.quasi_static, 0.5002118, 1e-7);
  // The barrel_loss the flexible contact leaves out is worth 2.7e-4 of e_eff here.
  EXPECT_NEAR(c.quasi_static - c.quasi_static_lossy, 2.7e-4, 0.1e-4);
}

TEST(FlexibleBarrelSpring, StifferBatsTendToTheQuasiStaticTrampoline) {
  // With the modes, bending takes energy: e_eff below the closed form, by 1.14e-2 for the real
  // bat, 6.0e-3 at 10 x its moduli and 9.1e-4 at 100 x (1e13 Pa, the material bound, stops it).
  double previous_gap = 1.0;
  for (double stiffening : {1.0, 10.0, 100.0}) {
    const SpringCase c = BarrelSpringCase(stiffening, false);
    const double gap = c.quasi_static - c.flexible;
    EXPECT_GT(gap, 0.0) << stiffening;
    EXPECT_LT(gap, previous_gap) << stiffening;
    previous_gap = gap;
  }
  EXPECT_LT(previous_gap, 1e-3);
}

TEST(FlexibleBarrelSpring, ZeroComplianceIsTheSolidSurfaceBitForBit) {
  const Bat bat = FindPreset("paper-wood")->bat;
  const BatModes modes = ComputeBatModes(bat, FlexibleOptions{}.ImpactModes());
  FlexibleImpactInputs in;
  in.impact_from_knob_m = 0.7;
  in.approach_speed_mps = 27.7 + 17.288 * 0.7;
  FlexibleImpactInputs with = in;
  with.barrel_compliance_m_n = 0.0;
  const FlexibleImpactResult a = SolveFlexibleImpact(bat, modes, in, FlexibleOptions{}.impact);
  const FlexibleImpactResult b = SolveFlexibleImpact(bat, modes, with, FlexibleOptions{}.impact);
  ASSERT_TRUE(a.summary.IsSolutionUsable()) << a.summary.message;
  EXPECT_EQ(a.exit_speed_mps, b.exit_speed_mps);
  EXPECT_EQ(a.vibration_energy_j, b.vibration_energy_j);
  EXPECT_EQ(a.error_estimate_exit_speed_mps, b.error_estimate_exit_speed_mps);
  // A negative compliance is refused, naming the field.
  with.barrel_compliance_m_n = -1e-9;
  std::string why;
  EXPECT_FALSE(Validates(with, &why));
  EXPECT_EQ(why, "barrel_compliance_m_n = -1.0000000000000001e-09: must be finite and >= 0");
}

}  // namespace
}  // namespace flexible_barrel_spring_test
}  // namespace sweetspot::core
