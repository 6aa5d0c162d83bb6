// free_bat: collision efficiency, the pivot limit, the BBCOR-style block.
#include "core/collision/free_bat.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "core/collision/rigid_pivot.hpp"
#include "core/numerics/nlopt_search.hpp"
#include "core/sweet_spot/sweet_spot.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace collision_free_bat_test {
namespace {

FreeBatInputs PaperBat() {
  FreeBatInputs in;
  in.bat_mass_kg = 1.0078;
  in.balance_point_m = 0.6090;
  in.moi_centroid_kg_m2 = 0.4122 - 1.0078 * 0.6090 * 0.6090;  // parallel axis from the knob
  return in;
}

TEST(FreeBat, ExitSpeedIsQuPlusOnePlusQVbat) {
  const FreeBatInputs in = PaperBat();
  for (double s : {0.3, 0.6, 0.75, 0.855}) {
    const FreeBatImpact r = FreeBatImpactAt(in, s);
    const double b = s - in.balance_point_m;
    const double rr = in.ball_mass_kg * (1.0 / in.bat_mass_kg + b * b / in.moi_centroid_kg_m2);
    const double q = (in.cor - rr) / (1.0 + rr);
    EXPECT_NEAR(r.recoil_factor, rr, 1e-15);
    EXPECT_NEAR(r.collision_efficiency, q, 1e-15);
    // Two algebraically equal forms: rounding only (eps x 30 m/s).
    EXPECT_NEAR(r.exit_speed_mps, q * in.ball_speed_mps + (1 + q) * in.angular_speed_rad_s * s,
                1e-13);
  }
}

TEST(FreeBat, RecoilFactorWithAPivotGivesTheRigidPivotModel) {
  // For a bat on a pivot, r = m z^2 / I_pivot: q u + (1+q) omega z is rigid_pivot's v2.
  RigidPivotInputs rp;
  rp.bat_mass_kg = 1.0078;
  rp.balance_point_m = 0.6090;
  rp.moi_pivot_kg_m2 = 0.4122;
  for (double z : {0.2, 0.5, 0.7}) {
    const double r = rp.ball_mass_kg * z * z / rp.moi_pivot_kg_m2;
    const double q = CollisionEfficiency(rp.cor, r);
    EXPECT_NEAR(q * rp.ball_speed_mps + (1 + q) * rp.angular_speed_rad_s * z,
                RigidPivotImpactAt(rp, z).exit_speed_mps, 1e-13);
    EXPECT_NEAR(RigidPivotImpactAt(rp, z).collision_efficiency, q, 1e-15);
  }
}

TEST(FreeBat, BbcorStyleRecoversTheCor) {
  const FreeBatInputs in = PaperBat();
  const FreeBatImpact r = FreeBatImpactAt(in, 0.70);
  ASSERT_TRUE(r.bbcor.applies);
  EXPECT_DOUBLE_EQ(r.bbcor.pivot_from_knob_m, kSixInchPivotM);
  const double arm = in.balance_point_m - kSixInchPivotM;
  EXPECT_NEAR(r.bbcor.moi_pivot_kg_m2, in.moi_centroid_kg_m2 + in.bat_mass_kg * arm * arm, 1e-15);
  // e_A < e (the bat recoils) and inverting e_A gives back e to rounding.
  EXPECT_LT(r.bbcor.apparent_cor, in.cor);
  EXPECT_NEAR(r.bbcor.bbcor, in.cor, 1e-15);
  EXPECT_NEAR(r.bbcor.besr, r.bbcor.apparent_cor + 0.5, 1e-15);
  EXPECT_FALSE(FreeBatImpactAt(in, 0.10).bbcor.applies);  // behind the 6-in pivot
}

TEST(FreeBat, HandsFeelNoJoltAtTheCentreOfPercussion) {
  const FreeBatInputs in = PaperBat();
  const double arm = in.balance_point_m - in.hands_from_knob_m;
  const double cop = in.balance_point_m + in.moi_centroid_kg_m2 / (in.bat_mass_kg * arm);
  EXPECT_NEAR(FreeBatImpactAt(in, cop).hands_velocity_change_mps, 0.0, 1e-14);
  EXPECT_LT(FreeBatImpactAt(in, cop - 0.1).hands_velocity_change_mps, 0.0);
  EXPECT_GT(FreeBatImpactAt(in, cop + 0.05).hands_velocity_change_mps, 0.0);
}

TEST(FreeBat, ClosedFormMaximumAgreesWithNlopt) {
  const FreeBatInputs in = PaperBat();
  const ExitSpeedProfile p = FreeBatProfile(in);
  const MaxExitSpeedResult cf = ClosedFormMaxExitSpeed(p, 0.855);
  auto f = [&](double s, double* g) {
    if (g != nullptr) *g = p.DerivativePerS(s - p.origin_from_knob_m);
    return p.ExitSpeedMps(s - p.origin_from_knob_m);
  };
  const ScalarSearchResult nl = MaximizeScalar(f, true, 0.0, 0.855, ScalarSearchOptions{});
  ASSERT_EQ(nl.summary.termination, Termination::kConverged);
  EXPECT_NEAR(nl.x, cf.position_from_knob_m, 1e-9 * cf.position_from_knob_m);  // the bar
  EXPECT_NEAR(nl.value, cf.exit_speed_mps, 1e-9 * cf.exit_speed_mps);
  // The free bat's sweet spot lies nearer the centroid than the pivoted bat's.
  EXPECT_LT(cf.exit_speed_mps, 23.24);
}

}  // namespace
}  // namespace collision_free_bat_test
}  // namespace sweetspot::core
