// The paper's analyses regenerated (paper-notes.md section 2 gives every expected value).
#include "core/scene/paper_analyses.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace paper_analyses_test {
namespace {

TEST(PaperTable5, ReproducesPrintedNumbersWithTheNotesConventions) {
  const auto rows = PaperTable5();
  ASSERT_EQ(rows.size(), 6u);
  for (const auto& r : rows) {
    SCOPED_TRACE(r.moi_pivot_kg_m2);
    // Positions are printed to 3 decimals and the notes' parameters (41.69, 0.1403, 0.1838)
    // are themselves rounded: 0.001 m is the reproduction the notes claim.
    EXPECT_NEAR(r.position_from_knob_m, r.printed_position_m, 1e-3);
    // Speeds are printed to 3 decimals: half a unit of the last digit (0.0005 m/s) is the
    // rounding; with the rounded parameters the largest deviation is 0.0003 m/s.
    EXPECT_NEAR(r.speed_mps, r.printed_speed_mps, 5e-4);
  }
}

TEST(PaperTable5, SpeedIsLinearInPositionWithSlopeHalfOnePlusEOmega) {
  // v2max = e u + (1+e) omega x*/2 for any J: consecutive rows differ by (1+e) omega / 2 per
  // metre of sweet-spot shift. Closed-form algebra: 1e-9 covers rounding.
  const auto rows = PaperTable5();
  const PaperTable5Conventions c;
  for (size_t i = 1; i < rows.size(); ++i) {
    const double slope = (rows[i].speed_mps - rows[i - 1].speed_mps) /
                         (rows[i].position_from_knob_m - rows[i - 1].position_from_knob_m);
    EXPECT_NEAR(slope, (1.0 + c.cor) * c.angular_speed_rad_s / 2.0, 1e-9);
  }
  // The consistent model (Table 3 kinematics) has slope 1.5 x 17.288 / 2 = 12.966, not 25.92.
  const double slope3 =
      (rows[5].consistent_speed_mps - rows[0].consistent_speed_mps) /
      (rows[5].consistent_position_from_pivot_m - rows[0].consistent_position_from_pivot_m);
  EXPECT_NEAR(slope3, 1.5 * 17.288 / 2.0, 1e-9);
}

TEST(PaperTable4, CorkDeltasFromFirstPrinciples) {
  const auto rows = PaperTable4();
  ASSERT_EQ(rows.size(), 2u);
  // paper-notes: dM 42.3 / 50.1 g, dC 0.52 / 0.62 cm, dJ 0.0227 / 0.0268 about the knob,
  // paper-convention dv 1.085 / 1.638, consistent dv about 0.28 / 0.34. Tolerances are half a
  // unit of the notes' last printed digit.
  EXPECT_NEAR(rows[0].delta_mass_kg * 1000.0, 42.3, 0.05);
  EXPECT_NEAR(rows[1].delta_mass_kg * 1000.0, 50.1, 0.05);
  EXPECT_NEAR(rows[0].delta_balance_m * 100.0, 0.52, 0.005);
  EXPECT_NEAR(rows[1].delta_balance_m * 100.0, 0.62, 0.005);
  EXPECT_NEAR(rows[0].delta_moi_knob_kg_m2, 0.0227, 5e-5);
  EXPECT_NEAR(rows[1].delta_moi_knob_kg_m2, 0.0268, 5e-5);
  EXPECT_NEAR(rows[0].delta_speed_paper_mps, 1.085, 5e-4);
  EXPECT_NEAR(rows[1].delta_speed_paper_mps, 1.638, 5e-4);
  EXPECT_NEAR(rows[0].delta_speed_consistent_mps, 0.28, 0.005);
  EXPECT_NEAR(rows[1].delta_speed_consistent_mps, 0.34, 0.005);
  for (const auto& r : rows) {
    // The bore's closed form and the general mass-properties code must agree to rounding
    // (both exact integrals; 1e-12 kg m^2 leaves room for a few hundred ulps of 0.41).
    EXPECT_NEAR(r.delta_moi_knob_kg_m2, r.delta_moi_knob_check_kg_m2, 1e-12);
  }
}

TEST(PaperClaims, SixtySixAndSeventyCentimetres) {
  const auto claims = PaperSweetSpotClaims();
  ASSERT_EQ(claims.size(), 2u);
  // paper-notes: 0.648 m (M = 0.885) and 0.724 m (M = 1.008), printed to 3 decimals.
  EXPECT_EQ(claims[0].preset, "paper-wood-m885");
  EXPECT_NEAR(claims[0].mass_kg, 0.885, 5e-4);
  EXPECT_NEAR(claims[0].position_from_knob_m, 0.648, 5e-4);
  EXPECT_EQ(claims[1].preset, "paper-wood");
  EXPECT_NEAR(claims[1].mass_kg, 1.0078, 5e-5);
  EXPECT_NEAR(claims[1].moi_knob_kg_m2, 0.4122, 5e-5);
  EXPECT_NEAR(claims[1].position_from_knob_m, 0.724, 5e-4);
  // The full rigid-body J (disk term) moves the sweet spot only slightly outwards.
  EXPECT_GT(claims[1].rigid_body_position_from_knob_m, claims[1].position_from_knob_m);
  EXPECT_LT(claims[1].rigid_body_position_from_knob_m - claims[1].position_from_knob_m, 2e-3);
}

TEST(PaperMaterials, HollowAluminiumIsLighterAndHasASmallerSweetSpotDistance) {
  const auto rows = PaperWoodVsAluminium();
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].wall_thickness_m, 0.0);
  EXPECT_GT(rows[1].wall_thickness_m, 0.0);
  EXPECT_LT(rows[1].mass_kg, rows[0].mass_kg);
  EXPECT_LT(rows[1].moi_knob_kg_m2, rows[0].moi_knob_kg_m2);
  // Same e: a smaller J means a sweet spot nearer the pivot and a lower maximum speed.
  EXPECT_LT(rows[1].position_from_knob_m, rows[0].position_from_knob_m);
  EXPECT_LT(rows[1].exit_speed_mps, rows[0].exit_speed_mps);
}

}  // namespace
}  // namespace paper_analyses_test
}  // namespace sweetspot::core
