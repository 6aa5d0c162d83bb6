// The ball catalogue (core/ball/ball_catalogue.hpp): its numbers against the cited rule books and
// test conditions, the COR law (monotone, clamped), the stiffness conversions, and how a scene
// takes its COR from a ball preset (cor_source) while scenes without one are unchanged.
#include "core/ball/ball_catalogue.hpp"

#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include "core/bat/presets.hpp"
#include "core/scene/collide.hpp"
#include "core/scene/evaluate_scene.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace ball_catalogue_test {
namespace {

constexpr double kOz = 0.028349523125;  // kg, exact
constexpr double kIn = 0.0254;          // m, exact
constexpr double kMph = 0.44704;        // m/s, exact
constexpr double kPi = 3.14159265358979323846;

BallPreset Get(const char* name) {
  const auto b = FindBallPreset(name);
  EXPECT_TRUE(b.has_value()) << name;
  return b.value_or(BallPreset{});
}

TEST(BallCatalogue, NamesAreUniqueAndEveryEntryIsSourcedAndValid) {
  std::set<std::string> names;
  for (const BallPreset& b : BallCatalogue()) {
    EXPECT_TRUE(names.insert(b.name).second) << b.name;
    EXPECT_FALSE(b.source.empty()) << b.name;
    EXPECT_FALSE(b.cor_test.empty()) << b.name;
    EXPECT_FALSE(b.stiffness_basis.empty()) << b.name;
    Refusal why;
    EXPECT_TRUE(b.cor_law.Validate(&why)) << b.name << ": " << why.Message();
    Ball ball;
    ApplyBallPreset(b, &ball);
    std::string message;
    EXPECT_TRUE(Validates(ball, &message)) << b.name << ": " << message;
    EXPECT_GE(b.mass_kg, b.mass_min_kg);
    EXPECT_LE(b.mass_kg, b.mass_max_kg);
  }
  EXPECT_EQ(BallPresetNames(),
            "mlb, ncaa-nfhs, softball-12-fastpitch, softball-12-slowpitch-44, "
            "softball-12-slowpitch-52");
  EXPECT_FALSE(FindBallPreset("MLB").has_value());  // names are exact
}

TEST(BallCatalogue, BaseballsMatchTheRuleBooksAndTheCorSpecifications) {
  // Official Baseball Rules 3.01 (and NFHS 1-3-1): 5 to 5 1/4 oz, 9 to 9 1/4 in. The preset
  // is the midpoint; 1e-15 relative: only the unit conversions' rounding.
  for (const char* name : {"mlb", "ncaa-nfhs"}) {
    const BallPreset b = Get(name);
    EXPECT_NEAR(b.mass_kg, 5.125 * kOz, 1e-15 * b.mass_kg) << name;
    EXPECT_NEAR(b.mass_min_kg, 5.0 * kOz, 1e-15) << name;
    EXPECT_NEAR(b.mass_max_kg, 5.25 * kOz, 1e-15) << name;
    EXPECT_NEAR(b.radius_m, 9.125 * kIn / (2 * kPi), 1e-15) << name;
    // The project's calibrated baseball contact law (docs/models.md), exactly.
    EXPECT_EQ(b.stiffness, 4.0e7) << name;
    EXPECT_EQ(b.stiffness_exponent, 1.5) << name;
  }
  // MLB: 0.546 +/- 0.032 at 85 ft/s on northern white ash (UMass Lowell's test); exact values.
  const BallCorLaw mlb = Get("mlb").cor_law;
  EXPECT_EQ(mlb.cor_at_reference, 0.546);
  EXPECT_NEAR(mlb.reference_speed_mps, 25.908, 1e-12);  // 85 ft/s exactly
  // NCAA/NFHS: at most 0.555 by ASTM F1887 at 60 mph.
  const BallCorLaw ncaa = Get("ncaa-nfhs").cor_law;
  EXPECT_EQ(ncaa.cor_at_reference, 0.555);
  EXPECT_NEAR(ncaa.reference_speed_mps, 60 * kMph, 1e-12);
  // MLB: 0.0005 per mph, fitted to issue 18's two points; NCAA/NFHS: 0.001 per mph, kept so a
  // solid wood bat passes BBCOR (the catalogue's comments). Exact up to the mph conversion.
  EXPECT_NEAR(mlb.slope_per_mps * kMph, 0.0005, 1e-15);
  EXPECT_NEAR(ncaa.slope_per_mps * kMph, 0.001, 1e-15);
  for (const BallCorLaw& law : {mlb, ncaa}) {
    EXPECT_NEAR(law.min_speed_mps, 30 * kMph, 1e-12);
    EXPECT_NEAR(law.max_speed_mps, 160 * kMph, 1e-12);
  }
}

TEST(BallCatalogue, MlbLawMeetsTheIssuesTwoPoints) {
  // Issue 18: "about 0.55 at 58 mph on ash, falling with speed to about 0.50 at game speeds".
  // 58 mph: 0.546 (the spec's centre; 85 ft/s is 57.95 mph, so 0.05 mph of slope: 2.5e-5).
  const BallCorLaw mlb = Get("mlb").cor_law;
  EXPECT_NEAR(mlb.CorAt(58 * kMph), 0.546, 1e-4);
  // Game speeds: a 90-100 mph pitch on a 60-70 mph bat is 150-170 mph relative; the law is
  // held above 160 mph. 0.546 - 0.0005 (160 - 57.95) = 0.4950 exactly (1e-12: rounding);
  // "about 0.50" read as +/- 0.01.
  const double game = mlb.CorAt(160 * kMph);
  EXPECT_NEAR(game, 0.546 - 0.0005 * (160 - 25.908 / kMph), 1e-12);
  EXPECT_NEAR(game, 0.50, 0.01);
  EXPECT_EQ(mlb.CorAt(170 * kMph), game);  // held above the range
}

TEST(BallCatalogue, BaseballLawsAgainstTheWoodLikeBbcorLimit) {
  // At the NCAA BBCOR test speed (136 mph) a near-rigid wood bat's BBCOR is the ball's COR on
  // wood; the NCAA set the non-wood limit at 0.500 from wood bats. The NCAA ball (the one the
  // BBCOR protocol fires) gives 0.555 - 0.001 (136 - 60) = 0.479: under the limit.
  const double ncaa = Get("ncaa-nfhs").cor_law.CorAt(136 * kMph);
  EXPECT_NEAR(ncaa, 0.479, 1e-12);
  EXPECT_LE(ncaa, 0.50);
  // The MLB fit gives 0.507 there: 0.007 ABOVE the limit (documented in docs/validation.md:
  // the fit to the issue's points and the limit disagree by that much, for a rigid bat).
  const double mlb = Get("mlb").cor_law.CorAt(136 * kMph);
  EXPECT_NEAR(mlb, 0.546 - 0.0005 * (136 - 25.908 / kMph), 1e-12);
  EXPECT_NEAR(mlb - 0.50, 0.007, 0.0005);  // 0.00698, to the digit quoted
  // The NCAA slope is the smallest that keeps its rule maximum under the limit, plus margin:
  // 0.555 - s 76 <= 0.50 needs s >= 0.000724 per mph.
  EXPECT_GE(Get("ncaa-nfhs").cor_law.slope_per_mps * kMph, (0.555 - 0.50) / 76);
}

TEST(BallCatalogue, SoftballsMatchTheRuleAndTheStaticCompression) {
  // USA Softball 12 in ball: 6 1/4 to 7 oz, 11 7/8 to 12 1/8 in; COR and compression limits
  // .47/375 (fast pitch), .44/375 and .52/300 (slow pitch), COR by ASTM F1887 at 60 mph.
  struct Row {
    const char* name;
    double cor;
    double compression_lbf;
  };
  for (const Row& row :
       {Row{"softball-12-fastpitch", 0.47, 375}, Row{"softball-12-slowpitch-44", 0.44, 375},
        Row{"softball-12-slowpitch-52", 0.52, 300}}) {
    const BallPreset b = Get(row.name);
    EXPECT_NEAR(b.mass_kg, 6.625 * kOz, 1e-15) << row.name;
    EXPECT_NEAR(b.radius_m, 12.0 * kIn / (2 * kPi), 1e-15) << row.name;
    EXPECT_EQ(b.cor_law.cor_at_reference, row.cor) << row.name;
    EXPECT_NEAR(b.cor_law.reference_speed_mps, 60 * kMph, 1e-12) << row.name;
    // No sourced speed dependence: constant at the rule's value.
    EXPECT_EQ(b.cor_law.slope_per_mps, 0.0) << row.name;
    EXPECT_EQ(b.cor_law.CorAt(10.0), row.cor) << row.name;
    EXPECT_EQ(b.cor_law.CorAt(70.0), row.cor) << row.name;
    // ASTM F1888: the compression force shortens the diameter by 0.25 in, so each plate
    // compresses the ball 0.125 in: F = k (0.125 in)^1.5. 1e-12 relative: pow's rounding.
    const double force_n = row.compression_lbf * 4.4482216152605;
    EXPECT_NEAR(b.stiffness * std::pow(0.125 * kIn, 1.5), force_n, 1e-12 * force_n) << row.name;
  }
  // 375 lbf: k = 1668.08 N / (3.175 mm)^1.5 = 9.32e6 N/m^1.5 (hand computation, 3 digits).
  EXPECT_NEAR(Get("softball-12-fastpitch").stiffness, 9.32e6, 0.01e6);
}

TEST(BallCorLaw, IsMonotoneAndClampedToItsSpeedRange) {
  for (const BallPreset& b : BallCatalogue()) {
    const BallCorLaw& law = b.cor_law;
    EXPECT_EQ(law.CorAt(law.reference_speed_mps), law.cor_at_reference) << b.name;
    double previous = law.CorAt(0.0);
    for (double v = 0.0; v <= 120.0; v += 0.25) {
      const double e = law.CorAt(v);
      EXPECT_LE(e, previous) << b.name << " at " << v;  // non-increasing
      EXPECT_GE(e, 0.0);
      EXPECT_LE(e, 1.0);
      previous = e;
    }
    // Held constant outside [min, max].
    EXPECT_EQ(law.CorAt(0.0), law.CorAt(law.min_speed_mps)) << b.name;
    EXPECT_EQ(law.CorAt(500.0), law.CorAt(law.max_speed_mps)) << b.name;
  }
  // The MLB law's ends: 0.546 + 0.0005 (57.95 - 30) = 0.5600 and 0.546 - 0.0005 (160 - 57.95)
  // = 0.4950 (1e-12: the mph conversion's rounding).
  const BallCorLaw mlb = FindBallPreset("mlb")->cor_law;
  EXPECT_NEAR(mlb.CorAt(0.0), 0.546 + 0.0005 * (25.908 / kMph - 30), 1e-12);
  EXPECT_NEAR(mlb.CorAt(1e3), 0.546 - 0.0005 * (160 - 25.908 / kMph), 1e-12);
  // A law whose line leaves [0, 1] inside its range is clamped to it.
  BallCorLaw steep{0.5, 20.0, 0.1, 0.0, 100.0};
  EXPECT_EQ(steep.CorAt(100.0), 0.0);
  EXPECT_EQ(steep.CorAt(0.0), 1.0);
  Refusal why;
  steep.min_speed_mps = 30.0;
  EXPECT_FALSE(steep.Validate(&why));
  EXPECT_EQ(why.Message(), "ball.cor_law.min_speed_mps = 30: must be in [0, reference_speed_mps]");
}

TEST(BallStiffness, DynamicStiffnessRoundTripsAndMatchesTheDocumentedDefault) {
  // docs/models.md: k = 4.0e7 N/m^1.5 is DS about 4.0e6 N/m in F2845 terms (60 mph, 0.145 kg);
  // the document gives two digits, hence 1 %.
  EXPECT_NEAR(DynamicStiffnessOf(4.0e7, 1.5, 0.145, 60 * kMph), 4.0e6, 0.04e6);
  // Round trip for several exponents; 1e-12 relative: pow's rounding.
  for (const double p : {1.0, 1.25, 1.5, 2.0}) {
    const double k = StiffnessFromDynamicStiffness(1.2e6, 0.15, 26.8, p);
    EXPECT_NEAR(DynamicStiffnessOf(k, p, 0.15, 26.8), 1.2e6, 1.2e6 * 1e-12) << p;
  }
  // p = 1 is a linear spring: k = DS exactly (to rounding).
  EXPECT_NEAR(StiffnessFromDynamicStiffness(1.2e6, 0.15, 26.8, 1.0), 1.2e6, 1.2e6 * 1e-12);
}

Scene Wood(const char* ball_preset) {
  Scene s;
  s.bat = FindPreset("paper-wood")->bat;
  if (ball_preset != nullptr) ApplyBallPreset(*FindBallPreset(ball_preset), &s.ball);
  return s;
}

TEST(SceneBallCor, APresetGivesTheBallsCorAtTheScenesImpactSpeed) {
  const SceneResult r = EvaluateScene(Wood("mlb"), {});
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  EXPECT_EQ(r.cor_source, "ball:mlb");
  // Evaluated 6 in from the tip: 27.7 + 17.288 (0.855 - 0.1524) m/s.
  const double v = 27.7 + 17.288 * (0.855 - 0.1524);
  ASSERT_TRUE(r.cor_impact_speed_mps.has_value());
  EXPECT_NEAR(*r.cor_impact_speed_mps, v, 1e-12);
  EXPECT_NEAR(*r.cor, 0.546 - 0.0005 / kMph * (v - 25.908), 1e-12);
  // The preset's ball is used: its mass changes the sweet spot against the default ball's.
  EXPECT_EQ(Wood("mlb").ball.mass_kg, FindBallPreset("mlb")->mass_kg);
}

TEST(SceneBallCor, WithoutAPresetNothingChanges) {
  const SceneResult r = EvaluateScene(Wood(nullptr), {});
  EXPECT_EQ(r.cor, 0.5);
  EXPECT_EQ(r.cor_source, "material:paper-wood");
  EXPECT_FALSE(r.cor_impact_speed_mps.has_value());
  EXPECT_TRUE(r.summary.warnings.empty());
}

TEST(SceneBallCor, TheRequestsCorWinsAndAHollowBatTakesTheTrampoline) {
  Scene s = Wood("mlb");
  s.cor = 0.42;
  SceneResult r = EvaluateScene(s, {});
  EXPECT_EQ(r.cor, 0.42);
  EXPECT_EQ(r.cor_source, "scene");
  EXPECT_FALSE(r.cor_impact_speed_mps.has_value());
  // A hollow aluminium bat (issue 18 item 2; formerly the material's COR with a warning): the
  // ball's law at the reference point's speed, through the barrel model: more than the ball's.
  Scene hollow;
  hollow.bat = FindPreset("bbcor-33-aluminium")->bat;
  ApplyBallPreset(*FindBallPreset("mlb"), &hollow.ball);
  r = EvaluateScene(hollow, {});
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  EXPECT_EQ(r.cor_source, "barrel:mlb");
  ASSERT_TRUE(r.cor_impact_speed_mps.has_value());
  EXPECT_GT(*r.cor, hollow.ball.cor_law->CorAt(*r.cor_impact_speed_mps));
  EXPECT_TRUE(r.summary.warnings.empty());
  // A hollow bat whose material has no COR: the same.
  hollow.bat->material.cor.reset();
  r = EvaluateScene(hollow, {});
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  EXPECT_EQ(r.cor_source, "barrel:mlb");
}

TEST(SceneBallCor, ACollisionEvaluatesTheLawAtItsOwnApproachSpeed) {
  for (const double x : {0.4, 0.7, 0.85}) {
    const CollisionResult c = Collide(Wood("ncaa-nfhs"), x, CollisionModel::kFreeBat);
    ASSERT_EQ(c.summary.termination, Termination::kConverged) << c.summary.message;
    EXPECT_EQ(c.cor_source, "ball:ncaa-nfhs");
    ASSERT_TRUE(c.cor_impact_speed_mps.has_value());
    EXPECT_EQ(*c.cor_impact_speed_mps, c.approach_speed_mps);
    EXPECT_EQ(c.cor, FindBallPreset("ncaa-nfhs")->cor_law.CorAt(c.approach_speed_mps));
  }
  // Farther out, faster, so a lower COR.
  EXPECT_GT(Collide(Wood("mlb"), 0.4, CollisionModel::kFreeBat).cor,
            Collide(Wood("mlb"), 0.8, CollisionModel::kFreeBat).cor);
}

TEST(SceneBallCor, MassPropertiesOnlyScenesCanUseTheBallsLaw) {
  Scene s;
  s.mass_properties = ComputeMassProperties(FindPreset("paper-wood")->bat);
  s.length_m = 0.855;
  SceneResult r = EvaluateScene(s, {});
  EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);  // as before: no COR anywhere
  ApplyBallPreset(*FindBallPreset("softball-12-fastpitch"), &s.ball);
  r = EvaluateScene(s, {});
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  EXPECT_EQ(r.cor, 0.47);
  EXPECT_EQ(r.cor_source, "ball:softball-12-fastpitch");
}

}  // namespace
}  // namespace ball_catalogue_test
}  // namespace sweetspot::core
