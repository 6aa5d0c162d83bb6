// The bat's geometry: three-segment knots, validity rules and their messages,
// radius lookups.
#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/bat/bat.hpp"
#include "core/bat/material.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace geometry_test {
namespace {

std::vector<std::pair<double, double>> Pairs(const std::vector<ProfileKnot>& knots) {
  std::vector<std::pair<double, double>> out;
  for (const auto& k : knots) out.push_back({k.x_m, k.radius_m});
  return out;
}

using P = std::vector<std::pair<double, double>>;

TEST(GeometryThreeSegment, KnotsMergeCoincidentPoints) {
  const double L = 0.855, a = 0.0125, b = 0.035;
  EXPECT_EQ(Pairs(ThreeSegmentShape{L, a, b, 0.3459, 0.6423}.Knots()),
            (P{{0, a}, {0.3459, a}, {0.6423, b}, {L, b}}));
  EXPECT_EQ(Pairs(ThreeSegmentShape{L, a, b, 0.0, 0.6423}.Knots()),
            (P{{0, a}, {0.6423, b}, {L, b}}));  // x1 = 0: no handle cylinder
  EXPECT_EQ(Pairs(ThreeSegmentShape{L, a, b, 0.2, L}.Knots()),
            (P{{0, a}, {0.2, a}, {L, b}}));  // x2 = L: no barrel cylinder
  EXPECT_EQ(Pairs(ThreeSegmentShape{L, a, b, 0.0, L}.Knots()), (P{{0, a}, {L, b}}));
  EXPECT_EQ(Pairs(ThreeSegmentShape{L, a, b, 0.0, 0.0}.Knots()), (P{{0, b}, {L, b}}));
  EXPECT_EQ(Pairs(ThreeSegmentShape{L, a, b, L, L}.Knots()), (P{{0, a}, {L, a}}));
  EXPECT_EQ(Pairs(ThreeSegmentShape{L, b, b, 0.4, 0.4}.Knots()), (P{{0, b}, {0.4, b}, {L, b}}));
}

TEST(GeometryThreeSegment, ZeroLengthTaperIsATinyStep) {
  const ThreeSegmentShape shape{0.855, 0.0125, 0.035, 0.4, 0.4};
  const auto knots = shape.Knots();
  ASSERT_EQ(knots.size(), 4u);
  const double half = 0.5 * ThreeSegmentShape::kStepWidth * 0.855;
  EXPECT_DOUBLE_EQ(knots[1].x_m, 0.4 - half);
  EXPECT_DOUBLE_EQ(knots[2].x_m, 0.4 + half);
  EXPECT_LT(knots[1].x_m, knots[2].x_m);
  EXPECT_EQ(knots[1].radius_m, 0.0125);
  EXPECT_EQ(knots[2].radius_m, 0.035);
  const Bat bat = MakeThreeSegmentBat(shape, *FindMaterial("paper-wood"));
  std::string why;
  EXPECT_TRUE(Validates(bat, &why)) << why;
}

TEST(GeometryThreeSegment, Validity) {
  std::string why;
  EXPECT_TRUE(Validates(ThreeSegmentShape{0.855, 0.0125, 0.035, 0.3459, 0.6423}, &why)) << why;
  struct Case {
    ThreeSegmentShape shape;
    const char* message;
  } cases[] = {
      {{0.0, 0.0125, 0.035, 0.0, 0.0}, "length_m = 0: must be positive"},
      {{0.855, -0.0125, 0.035, 0.3, 0.6}, "handle_radius_m = -0.0125: must be positive"},
      {{0.855, 0.0125, 0.0, 0.3, 0.6}, "barrel_radius_m = 0: must be positive"},
      {{0.855, 0.0125, 0.035, -0.1, 0.6}, "taper_start_m = -0.1: must be non-negative"},
      {{0.855, 0.0125, 0.035, 0.7, 0.6}, "taper_start_m = 0.7: must not exceed taper_end_m = 0.6"},
      {{0.855, 0.0125, 0.035, 0.3, 0.9}, "taper_end_m = 0.9: must not exceed length_m = 0.855"},
      {{std::numeric_limits<double>::quiet_NaN(), 0.0125, 0.035, 0.3, 0.6},
       "length_m = nan: must be finite"},
  };
  for (const Case& c : cases) {
    EXPECT_FALSE(Validates(c.shape, &why)) << c.message;
    EXPECT_EQ(why, c.message);
  }
}

Bat PaperBat() {
  return MakeThreeSegmentBat(ThreeSegmentShape{0.855, 0.0125, 0.035, 0.3459, 0.6423},
                             *FindMaterial("paper-wood"));
}

TEST(GeometryThreeSegment, SizesGivenFromOutsideAreCapped) {
  // Core computes beyond the caps (tests/hard_cases: a megametre bat); ValidateSize holds a
  // shape given from outside to them.
  Refusal r;
  EXPECT_TRUE((ThreeSegmentShape{0.855, 0.0125, 0.035, 0.3459, 0.6423}.ValidateSize(&r)));
  EXPECT_TRUE((ThreeSegmentShape{100.0, 10.0, 10.0, 0.0, 100.0}.ValidateSize(&r)));  // bounds
  struct Case {
    ThreeSegmentShape shape;
    const char* message;
  } cases[] = {
      {{200.0, 0.0125, 0.035, 0.3, 0.6}, "length_m = 200: must be in (0, 100]"},
      {{0.855, 10.5, 0.035, 0.3, 0.6}, "handle_radius_m = 10.5: must be in (0, 10]"},
      {{0.855, 0.0125, 11.0, 0.3, 0.6}, "barrel_radius_m = 11: must be in (0, 10]"},
      {{0.0, 0.0125, 0.035, 0.0, 0.0}, "length_m = 0: must be positive"},  // Validate's rule
  };
  for (const Case& c : cases) {
    EXPECT_FALSE(c.shape.ValidateSize(&r)) << c.message;
    EXPECT_EQ(r.Message(), c.message);
  }
}

TEST(GeometryBat, SizesGivenFromOutsideAreCapped) {
  struct Case {
    void (*edit)(Bat&);
    const char* message;
  } cases[] = {
      {[](Bat& b) {
         b.knots = {{0, 0.02}, {50.0, 0.02}, {150.0, 0.03}, {250.0, 0.03}};
       },
       "knots[2].x_m = 150: must be in [0, 100]"},
      {[](Bat& b) { b.knots[2].radius_m = 10.5; }, "knots[2].radius_m = 10.5: must be in (0, 10]"},
      {[](Bat& b) {
         b.knots = {{0, 20.0}, {0.8, 20.0}};
         b.wall_thickness_m = 11.0;  // below the smallest radius; that radius is capped
       },
       "knots[0].radius_m = 20: must be in (0, 10]"},
      {[](Bat& b) {
         b.knots = {{0, 10.0}, {0.8, 10.0}};
         b.fill = Fill{*FindMaterial("cork"), 15.0, 0.2};  // inside the radius, over the cap
       },
       "fill.diameter_m = 15: must be in [0, 10]"},
      {[](Bat& b) {
         b.knots = {{0, 10.0}, {50.0, 10.0}};
         b.wall_thickness_m = 9.0;
         b.fill = Fill{*FindMaterial("cork"), 0.02, 40.0};
         b.fill->material.density_kg_m3 = 2e5;
       },
       "fill.material.density_kg_m3 = 2e+05: must be in (0, 1e+05]"},
      {[](Bat& b) { b.material.youngs_modulus_pa = 2e13; },
       "material.youngs_modulus_pa = 2e+13: must be in (0, 1e+13]"},
      {[](Bat& b) { b.knots[1].radius_m = 0.0; },
       "knots[1].radius_m = 0: must be positive"},  // Validate's rule first
  };
  for (const Case& c : cases) {
    Bat bat = PaperBat();
    c.edit(bat);
    Refusal r;
    EXPECT_FALSE(bat.ValidateSize(&r)) << c.message;
    EXPECT_EQ(r.Message(), c.message);
    EXPECT_FALSE(bat.ValidateSize(nullptr)) << c.message;
  }
  Refusal r;
  EXPECT_TRUE(PaperBat().ValidateSize(&r)) << r.Message();
  Bat big = PaperBat();  // every size at its bound is accepted
  big.knots = {{0, kMaxBatRadiusM}, {kMaxBatLengthM, kMaxBatRadiusM}};
  big.wall_thickness_m = 9.0;
  big.fill = Fill{*FindMaterial("cork"), 0.5, kMaxBatLengthM};
  EXPECT_TRUE(big.ValidateSize(&r)) << r.Message();
}

TEST(GeometryBat, RefusalsNameFieldValueAndRule) {
  struct Case {
    void (*edit)(Bat&);
    const char* message;
  } cases[] = {
      {[](Bat& b) { b.knots.resize(1); }, "knots.size() = 1: must be at least 2"},
      {[](Bat& b) { b.knots[2].x_m = std::numeric_limits<double>::infinity(); },
       "knots[2].x_m = inf: must be finite"},
      {[](Bat& b) { b.knots[1].radius_m = std::numeric_limits<double>::quiet_NaN(); },
       "knots[1].radius_m = nan: must be finite"},
      {[](Bat& b) { b.knots[0].x_m = 0.1; },
       "knots[0].x_m = 0.1: must be 0 (positions are measured from the knob)"},
      {[](Bat& b) {
         b.knots = {{0, 0.02}, {0.1, 0.02}, {0.3, 0.02}, {0.3, 0.03}, {0.8, 0.03}};
       },
       "knots[3].x_m = 0.3: must be greater than knots[2].x_m = 0.3"},
      {[](Bat& b) {
         b.knots = {{0, 0.02}, {0.1, 0.02}, {0.3, 0.02}, {0.2, 0.03}, {0.8, 0.03}};
       },
       "knots[3].x_m = 0.2: must be greater than knots[2].x_m = 0.3"},
      {[](Bat& b) { b.knots[3].radius_m = 0.0; }, "knots[3].radius_m = 0: must be positive"},
      {[](Bat& b) { b.material.density_kg_m3 = 0.0; },
       "material.density_kg_m3 = 0: must be positive"},
      {[](Bat& b) { b.wall_thickness_m = 0.05; },
       "wall_thickness_m = 0.05: must be less than the smallest outer radius 0.0125"},
      {[](Bat& b) { b.wall_thickness_m = 0.0125; },
       "wall_thickness_m = 0.0125: must be less than the smallest outer radius 0.0125"},
      {[](Bat& b) { b.wall_thickness_m = -0.001; },
       "wall_thickness_m = -0.001: must be non-negative (0 = solid)"},
      {[](Bat& b) {
         b.fill = Fill{*FindMaterial("cork"), 0.0254, 1.0};
       },
       "fill.depth_m = 1: must not exceed the bat's length 0.855"},
      {[](Bat& b) {
         b.fill = Fill{*FindMaterial("cork"), 0.0254, -0.1};
       },
       "fill.depth_m = -0.1: must be non-negative"},
      {[](Bat& b) {
         b.fill = Fill{*FindMaterial("cork"), -0.01, 0.1};
       },
       "fill.diameter_m = -0.01: must be non-negative"},
      {[](Bat& b) {
         b.fill = Fill{*FindMaterial("cork"), 0.08, 0.1};
       },
       "fill.diameter_m = 0.08: the bore radius 0.04 must be less than the outer radius 0.035 "
       "at x_m = 0.755 (over the fill's depth)"},
      // 0.4 m deep, the bore's bottom is in the taper, where the wood is thinnest:
      // r(0.455) = 0.0125 + 0.0225 (0.455 - 0.3459) / 0.2964 = 0.0207819 (0.855 - 0.4
      // is 0.45499999999999996 in double).
      {[](Bat& b) {
         b.fill = Fill{*FindMaterial("cork"), 0.045, 0.4};
       },
       "fill.diameter_m = 0.045: the bore radius 0.0225 must be less than the outer radius "
       "0.020781882591093117 at x_m = 0.45499999999999996 (over the fill's depth)"},
      {[](Bat& b) {
         b.wall_thickness_m = 0.005;
         b.fill = Fill{*FindMaterial("cork"), 0.0625, 0.1};
       },
       "fill.diameter_m = 0.0625: the bore radius 0.03125 must be less than the inner radius "
       "0.030000000000000002 at x_m = 0.755 (over the fill's depth)"},
      {[](Bat& b) {
         Material m = *FindMaterial("cork");
         m.youngs_modulus_pa = 0.0;
         b.fill = Fill{m, 0.0254, 0.1};
       },
       "fill.material.youngs_modulus_pa = 0: must be positive"},
      {[](Bat& b) {
         Material m = EmptyFillMaterial();
         m.density_kg_m3 = -1.0;
         b.fill = Fill{m, 0.0254, 0.1};
       },
       "fill.material.density_kg_m3 = -1: must be non-negative (0 = empty bore)"},
  };
  for (const Case& c : cases) {
    Bat bat = PaperBat();
    c.edit(bat);
    std::string why;
    EXPECT_FALSE(Validates(bat, &why)) << c.message;
    EXPECT_EQ(why, c.message);
    EXPECT_FALSE(bat.Validate(nullptr)) << c.message;
  }
}

TEST(GeometryBat, AcceptedCases) {
  std::string why;
  Bat bat = PaperBat();
  EXPECT_TRUE(Validates(bat, &why)) << why;
  EXPECT_TRUE(bat.Validate(nullptr));
  // A step: two knots 1e-12 m apart.
  bat.knots = {{0, 0.015}, {0.5, 0.015}, {0.5 + 1e-12, 0.033}, {0.86, 0.033}};
  EXPECT_TRUE(Validates(bat, &why)) << why;
  // A bat 1 mm long and one 10 m long; micrometre radii.
  bat.knots = {{0, 1e-4}, {1e-3, 2e-4}};
  EXPECT_TRUE(Validates(bat, &why)) << why;
  bat.knots = {{0, 0.02}, {10.0, 0.05}};
  EXPECT_TRUE(Validates(bat, &why)) << why;
  bat.knots = {{0, 1e-6}, {0.86, 1e-6}};
  EXPECT_TRUE(Validates(bat, &why)) << why;
  // Hollow with a fill inside the cavity; an empty bore (cupped end); a fill
  // exactly as deep as the bat; a zero-size fill.
  bat = PaperBat();
  bat.wall_thickness_m = 0.003;
  bat.fill = Fill{*FindMaterial("rubber"), 0.018, 0.2};
  EXPECT_TRUE(Validates(bat, &why)) << why;
  bat = PaperBat();
  bat.fill = Fill{EmptyFillMaterial(), 0.03, 0.02};
  EXPECT_TRUE(Validates(bat, &why)) << why;
  bat.fill = Fill{*FindMaterial("cork"), 0.02, 0.855};
  EXPECT_TRUE(Validates(bat, &why)) << why;
  bat.fill = Fill{*FindMaterial("cork"), 0.0, 0.0};
  EXPECT_TRUE(Validates(bat, &why)) << why;
}

TEST(GeometryBat, RadiusLookups) {
  Bat bat = PaperBat();
  EXPECT_EQ(bat.LengthM(), 0.855);
  EXPECT_EQ(bat.RadiusAtM(0.0), 0.0125);
  EXPECT_EQ(bat.RadiusAtM(0.2), 0.0125);
  EXPECT_EQ(bat.RadiusAtM(0.3459), 0.0125);
  EXPECT_NEAR(bat.RadiusAtM(0.5 * (0.3459 + 0.6423)), 0.5 * (0.0125 + 0.035), 1e-17);
  EXPECT_EQ(bat.RadiusAtM(0.6423), 0.035);
  EXPECT_EQ(bat.RadiusAtM(0.855), 0.035);
  EXPECT_EQ(bat.RadiusAtM(-1e-9), 0.0);
  EXPECT_EQ(bat.RadiusAtM(0.856), 0.0);
  EXPECT_EQ(bat.RadiusAtM(std::numeric_limits<double>::quiet_NaN()), 0.0);
  EXPECT_EQ(bat.MinRadiusM(), 0.0125);
  EXPECT_FALSE(bat.IsHollow());
  EXPECT_EQ(bat.InnerRadiusAtM(0.5), 0.0);
  bat.wall_thickness_m = 0.002;
  EXPECT_TRUE(bat.IsHollow());
  EXPECT_NEAR(bat.InnerRadiusAtM(0.8), 0.033, 1e-17);
  EXPECT_EQ(bat.InnerRadiusAtM(1.0), 0.0);
  // Across a 1e-12 m step the radius stays between the two sides.
  bat.knots = {{0, 0.015}, {0.5, 0.015}, {0.5 + 1e-12, 0.033}, {0.86, 0.033}};
  const double mid = bat.RadiusAtM(0.5 + 0.5e-12);
  EXPECT_GT(mid, 0.015);
  EXPECT_LT(mid, 0.033);
  EXPECT_EQ(bat.RadiusAtM(0.6), 0.033);
  EXPECT_EQ(Bat{}.LengthM(), 0.0);
  EXPECT_EQ(Bat{}.RadiusAtM(0.0), 0.0);
}

}  // namespace
}  // namespace geometry_test
}  // namespace sweetspot::core
