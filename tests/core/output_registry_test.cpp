// The table of scene outputs (core/scene/output_registry.hpp): one declaration per id, names
// that parse back, an output read by another computed before it, and what ModelsFor and the
// workload classes say read from the declarations.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "core/scene/output_registry.hpp"

namespace sweetspot::core {
namespace output_registry_test {
namespace {

TEST(OutputRegistryTest, EveryIdHasOneDeclarationWhoseNameParsesBack) {
  const auto& table = SceneOutputTable();
  ASSERT_EQ(table.size(), kSceneOutputCount);
  std::set<int> ids;
  std::set<std::string> names;
  for (const SceneOutputDecl* d : table) {
    ASSERT_NE(d, nullptr);
    EXPECT_TRUE(ids.insert(static_cast<int>(d->id)).second) << d->name;
    EXPECT_TRUE(names.insert(d->name).second) << d->name;
    EXPECT_EQ(&SceneOutputDeclaration(d->id), d);
    EXPECT_EQ(ParseSceneOutput(d->name), d->id);
    EXPECT_STREQ(SceneOutputName(d->id), d->name);
    EXPECT_NE(d->compute, nullptr) << d->name;
    EXPECT_NE(d->present, nullptr) << d->name;
    EXPECT_NE(d->reset, nullptr) << d->name;
    EXPECT_TRUE(d->uses_exit_model || d->models[0] != nullptr) << d->name << ": no models";
    if (d->modes != OutputModes::kNone) {
      EXPECT_TRUE(d->needs_geometry) << d->name << ": the modes need the bat's geometry";
    }
  }
  EXPECT_FALSE(ParseSceneOutput("sweetspot").has_value());
  EXPECT_EQ(SceneOutputNameList(),
            "max_exit_speed, center_of_percussion, vibration_node, sweet_zone, exit_speed_curve, "
            "least_sting_zone, barrel, bbcor, bbcor_scan, batted_ball, distance_sweet_spot, "
            "carry_map");
}

// An output another reads (needs_output) is computed first: the loop runs in table order.
TEST(OutputRegistryTest, AnOutputReadByAnotherComesBeforeIt) {
  std::set<SceneOutput> seen;
  for (const SceneOutputDecl* d : SceneOutputTable()) {
    if (d->needs_output != d->id) {
      EXPECT_TRUE(seen.count(d->needs_output)) << d->name;
      const SceneOutput read = d->needs_output;
      EXPECT_EQ(SceneOutputDeclaration(read).needs_output, read)
          << d->name << ": one level of needs_output only";
    }
    seen.insert(d->id);
  }
}

TEST(OutputRegistryTest, WorkloadClassFollowsTheModels) {
  for (const SceneOutputDecl* d : SceneOutputTable()) {
    for (const CollisionModel m :
         {CollisionModel::kAuto, CollisionModel::kRigidPivot, CollisionModel::kFreeBat,
          CollisionModel::kHertz, CollisionModel::kFlexible}) {
      // The distance searches fly hundreds of balls whatever the model: compute too.
      bool iterative = d->id == SceneOutput::kDistanceSweetSpot || d->id == SceneOutput::kCarryMap;
      for (const std::string& model : ModelsFor(d->id, m)) {
        iterative =
            iterative || model == kFlexibleBeamModel || model == "flexible" || model == "hertz";
      }
      EXPECT_EQ(WorkloadOf(d->id, m) == OutputWorkload::kCompute, iterative)
          << d->name << " with " << CollisionModelName(m);
    }
  }
}

}  // namespace
}  // namespace output_registry_test
}  // namespace sweetspot::core
