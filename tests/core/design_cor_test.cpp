// core::ResolveDesignCor, the optimiser's COR policy as a value (moved from the api, issue 33
// item 4), and core::SanityWarnings on the mass properties a request computed once.
#include <string>

#include <gtest/gtest.h>

#include "core/ball/ball_catalogue.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/bat/presets.hpp"
#include "core/optimize/design_cor.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/scene/sanity.hpp"
#include "core/scene/scene.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace design_cor_test {
namespace {

constexpr double kMph = 0.44704;  // m/s per mph

struct Case {
  Scene scene;
  DesignProblem problem;
  MassProperties properties;
};

// A preset bat optimised for its maximum exit speed, with an MLB ball (and its COR law) at
// 90 mph unless `law` is false.
Case Make(const char* preset, bool law) {
  Case c;
  if (law) ApplyBallPreset(*FindBallPreset("mlb"), &c.scene.ball);
  c.scene.ball.speed_mps = 90.0 * kMph;
  c.scene.swing.bat_speed_mps = 70.0 * kMph;
  c.problem.bat = FindPreset(preset)->bat;
  c.problem.objective = DesignObjective::kMaxExitSpeed;
  c.properties = ComputeMassProperties(c.problem.bat, c.scene.inertia_model);
  return c;
}

TEST(DesignCorTest, TheScenesCorIsHeldFixed) {
  Case c = Make("wood-34-ash", true);
  c.scene.cor = 0.5;
  const DesignCorPolicy policy = ResolveDesignCor(c.scene, c.properties, &c.problem);
  EXPECT_EQ(policy.kind, DesignCorPolicyKind::kScene);
  EXPECT_EQ(policy.Describe("ash"), "scene");
  EXPECT_FALSE(c.problem.cor_from_barrel);
}

TEST(DesignCorTest, ASolidBaseTakesTheBallsLawAtItsImpactSpeed) {
  Case c = Make("wood-34-ash", true);
  const long long before = MassPropertiesComputationsOnThisThread();
  const DesignCorPolicy policy = ResolveDesignCor(c.scene, c.properties, &c.problem);
  // The base's mass properties are the caller's: none computed here.
  EXPECT_EQ(MassPropertiesComputationsOnThisThread() - before, 0);
  EXPECT_EQ(policy.kind, DesignCorPolicyKind::kBaseDesign);
  EXPECT_EQ(policy.base_source, "ball:mlb");
  ASSERT_TRUE(c.problem.cor.has_value());
  EXPECT_GT(*c.problem.cor, 0.0);
  EXPECT_GT(policy.base_impact_speed_mps, 0.0);
  EXPECT_EQ(policy.Describe("ash").rfind("ball:mlb at the base design's impact speed (", 0), 0u)
      << policy.Describe("ash");
}

TEST(DesignCorTest, AHollowDesignRecomputesItsBarrelsCorForEveryDesign) {
  Case c = Make("bbcor-33-aluminium", true);
  const DesignCorPolicy policy = ResolveDesignCor(c.scene, c.properties, &c.problem);
  EXPECT_EQ(policy.kind, DesignCorPolicyKind::kBarrelPerDesign);
  EXPECT_TRUE(c.problem.cor_from_barrel);
  EXPECT_FALSE(c.problem.cor.has_value());
  EXPECT_EQ(policy.Describe("aluminium")
                .rfind("barrel:mlb recomputed for every design at 0.1524 "
                       "m from its tip",
                       0),
            0u)
      << policy.Describe("aluminium");
}

TEST(DesignCorTest, WithoutALawTheMaterialsCor) {
  Case c = Make("wood-34-ash", false);
  const DesignCorPolicy policy = ResolveDesignCor(c.scene, c.properties, &c.problem);
  EXPECT_EQ(policy.kind, DesignCorPolicyKind::kMaterial);
  EXPECT_EQ(policy.Describe("ash"), "material:ash");
  EXPECT_FALSE(c.problem.cor.has_value());
  EXPECT_FALSE(c.problem.cor_from_barrel);
}

TEST(CoreSanityTest, TheBatsMassIsTheGivenPropertiesNotComputedAgain) {
  const Bat bat = FindPreset("wood-34-ash")->bat;
  MassProperties heavy = ComputeMassProperties(bat);
  heavy.mass_kg = 5.0;
  const long long before = MassPropertiesComputationsOnThisThread();
  const std::vector<std::string> warnings = SanityWarnings(&bat, &heavy, nullptr, nullptr);
  EXPECT_EQ(MassPropertiesComputationsOnThisThread() - before, 0);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].rfind("bat mass = 5 kg: no bat weighs more than 2 kg", 0), 0u)
      << warnings[0];
  // Without properties the mass is not checked.
  EXPECT_TRUE(SanityWarnings(&bat, nullptr, nullptr, nullptr).empty());
}

}  // namespace
}  // namespace design_cor_test
}  // namespace sweetspot::core
