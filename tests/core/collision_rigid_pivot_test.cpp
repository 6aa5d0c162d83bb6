// rigid_pivot: closed forms against the paper's formula, and against NLopt on random scenes.
#include "core/collision/rigid_pivot.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/numerics/nlopt_search.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace collision_rigid_pivot_test {
namespace {

// The paper-wood bat by hand (paper-notes: M = 1.0078 kg, C = 0.6090 m, slender-rod
// J_knob = 0.4122 kg m^2), so these tests do not depend on the geometry code.
RigidPivotInputs PaperBatAtKnob() {
  RigidPivotInputs in;
  in.bat_mass_kg = 1.0078;
  in.balance_point_m = 0.6090;
  in.moi_pivot_kg_m2 = 0.4122;
  in.pivot_from_knob_m = 0.0;
  return in;  // ball 0.145 kg at 27.7 m/s, omega 17.288, e 0.5 (defaults)
}

// The paper's formula, literally.
double PaperV2(const RigidPivotInputs& in, double x) {
  const double u = in.ball_speed_mps, j = in.moi_pivot_kg_m2, m = in.ball_mass_kg;
  return -u + j * (1.0 + in.cor) * (u + in.angular_speed_rad_s * x) / (j + m * x * x);
}

TEST(RigidPivot, ExitSpeedMatchesThePaperFormula) {
  const RigidPivotInputs in = PaperBatAtKnob();
  for (double s : {0.0, 0.2, 0.5, 0.7, 0.855}) {
    // Same expression evaluated in the same order up to association: 4 ulps.
    EXPECT_NEAR(RigidPivotImpactAt(in, s).exit_speed_mps, PaperV2(in, s), 1e-13);
  }
}

TEST(RigidPivot, SweetSpotOfThePaperBatIs0724) {
  const MaxExitSpeedResult r = ClosedFormMaxExitSpeed(RigidPivotProfile(PaperBatAtKnob()), 0.855);
  // paper-notes: 0.724 m with M = 1.008 (J = 0.4122 printed to 4 digits: +-0.0005 m).
  EXPECT_NEAR(r.position_from_knob_m, 0.724, 5e-4);
  EXPECT_EQ(r.placement, Placement::kOnBat);
  EXPECT_EQ(r.summary.termination, Termination::kConverged);
  // v2max = ((1+e)S - (1-e)u)/2 and = e u + (1+e) omega x*/2: the two forms agree to rounding.
  const double alt = 0.5 * 27.7 + 1.5 * 17.288 * r.position_from_knob_m / 2.0;
  EXPECT_NEAR(r.exit_speed_mps, alt, 1e-12);
  EXPECT_NEAR(r.exit_speed_mps, PaperV2(PaperBatAtKnob(), r.position_from_knob_m), 1e-12);
}

TEST(RigidPivot, DerivativeIsExactAndZeroAtTheMaximum) {
  const ExitSpeedProfile p = RigidPivotProfile(PaperBatAtKnob());
  for (double x : {0.1, 0.4, 0.7, 0.85}) {
    const double h = 1e-5;
    const double fd = (p.ExitSpeedMps(x + h) - p.ExitSpeedMps(x - h)) / (2 * h);
    // Central difference: truncation h^2 f'''/6 ~ 1e-9, rounding eps f / h ~ 1e-10.
    EXPECT_NEAR(p.DerivativePerS(x), fd, 1e-8);
  }
  const ProfileMaximum mx = p.Maximum();
  // f'(x*) = c (omega J - m x*(omega x* + 2u)) / D^2: the bracket cancels to ~eps (omega J).
  EXPECT_NEAR(p.DerivativePerS(mx.x_m), 0.0, 1e-12);
  EXPECT_LT(mx.curvature_per_m_s, 0.0);
}

TEST(RigidPivot, StableFormBeatsTheTextbookFormAtSmallOmega) {
  RigidPivotInputs in = PaperBatAtKnob();
  in.angular_speed_rad_s = 1e-5;
  const ProfileMaximum mx = RigidPivotProfile(in).Maximum();
  // Reference by the series x* = omega J / (2 m u) (1 - omega^2 J/(4 m u^2) + ...): the second
  // term is ~1e-13 here, so the first term is exact to 1e-13 relative.
  const double series =
      in.angular_speed_rad_s * in.moi_pivot_kg_m2 / (2.0 * in.ball_mass_kg * in.ball_speed_mps);
  EXPECT_NEAR(mx.x_m / series, 1.0, 1e-12);
  // The textbook (-u + S)/omega cancels catastrophically (paper-notes: ~4e-4 relative).
  const double u = in.ball_speed_mps, w = in.angular_speed_rad_s;
  const double s = std::sqrt(u * u + w * w * in.moi_pivot_kg_m2 / in.ball_mass_kg);
  const double textbook = (-u + s) / w;
  EXPECT_GT(std::abs(textbook / series - 1.0), 1e-6);
}

TEST(RigidPivot, DeficitIdentityMatchesTheDirectDifference) {
  const ExitSpeedProfile p = RigidPivotProfile(PaperBatAtKnob());
  const ProfileMaximum mx = p.Maximum();
  for (double x : {0.0, 0.3, 0.6, 0.8}) {
    // Direct difference loses ~eps x 23 m/s absolute: 1e-13.
    EXPECT_NEAR(p.DeficitMps(x), mx.exit_speed_mps - p.ExitSpeedMps(x), 1e-13);
  }
}

TEST(RigidPivot, PivotImpulseVanishesAtTheCentreOfPercussionAboutThePivot) {
  RigidPivotInputs in = PaperBatAtKnob();
  in.pivot_from_knob_m = 0.1524;
  in.moi_pivot_kg_m2 = 0.4122 - 2 * 0.1524 * 1.0078 * 0.6090 + 1.0078 * 0.1524 * 0.1524;
  const double cop =
      in.pivot_from_knob_m +
      in.moi_pivot_kg_m2 / (in.bat_mass_kg * (in.balance_point_m - in.pivot_from_knob_m));
  const RigidPivotImpact at = RigidPivotImpactAt(in, cop);
  EXPECT_NEAR(at.pivot_impulse_n_s / at.ball_impulse_n_s, 0.0, 1e-14);  // rounding of 1 - 1
  EXPECT_GT(RigidPivotImpactAt(in, cop - 0.1).pivot_impulse_n_s, 0.0);
  EXPECT_LT(RigidPivotImpactAt(in, cop + 0.1).pivot_impulse_n_s, 0.0);
  // Angular momentum about the pivot is conserved: J dw = -impulse x.
  EXPECT_NEAR(in.moi_pivot_kg_m2 * (at.angular_speed_after_rad_s - in.angular_speed_rad_s),
              -at.ball_impulse_n_s * at.x_from_pivot_m, 1e-13);
}

// Thousands of random scenes (seeded): the closed form and NLopt (LD_SLSQP with the exact
// derivative) agree to 1e-9 relative in position and speed.
TEST(RigidPivot, ClosedFormAndNloptAgreeOnRandomScenes) {
  std::mt19937_64 rng(20240604);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int clipped = 0;
  for (int i = 0; i < 2000; ++i) {
    RigidPivotInputs in;
    const double length = 0.6 + 0.4 * unit(rng);
    in.bat_mass_kg = 0.5 + 1.0 * unit(rng);
    in.balance_point_m = length * (0.5 + 0.25 * unit(rng));
    in.pivot_from_knob_m = -0.3 + 0.5 * unit(rng);
    const double rg = 0.15 + 0.15 * unit(rng);  // radius of gyration about the centroid
    const double arm = in.balance_point_m - in.pivot_from_knob_m;
    in.moi_pivot_kg_m2 = in.bat_mass_kg * (rg * rg + arm * arm);
    in.ball_mass_kg = 0.1 + 0.1 * unit(rng);
    in.ball_speed_mps = 1.0 + 50.0 * unit(rng);
    in.angular_speed_rad_s = 1.0 + 60.0 * unit(rng);
    in.cor = unit(rng);
    const ExitSpeedProfile p = RigidPivotProfile(in);
    const MaxExitSpeedResult cf = ClosedFormMaxExitSpeed(p, length);
    ScalarSearchOptions opt;
    auto f = [&](double s, double* g) {
      if (g != nullptr) *g = p.DerivativePerS(s - in.pivot_from_knob_m);
      return p.ExitSpeedMps(s - in.pivot_from_knob_m);
    };
    const ScalarSearchResult nl = MaximizeScalar(f, true, 0.0, length, opt);
    SCOPED_TRACE(i);
    ASSERT_TRUE(nl.summary.IsSolutionUsable()) << nl.summary.FullReport();
    if (cf.placement != Placement::kOnBat) ++clipped;
    EXPECT_NEAR(nl.x, cf.position_from_knob_m, 1e-9 * std::max(1e-3, cf.position_from_knob_m));
    EXPECT_NEAR(nl.value, cf.exit_speed_mps, 1e-9 * std::abs(cf.exit_speed_mps) + 1e-12);
  }
  EXPECT_GT(clipped, 0);  // the set includes maximisers beyond the tip
}

}  // namespace
}  // namespace collision_rigid_pivot_test
}  // namespace sweetspot::core
