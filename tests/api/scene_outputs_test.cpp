// The api's half of the scene outputs (api/outputs/): every output of core's table has one,
// renders under its name, and is emptied by SceneResult::Reset (its core declaration's reset).
#include <gtest/gtest.h>

#include <vector>

#include "api/outputs/scene_outputs.hpp"
#include "core/scene/output_registry.hpp"

namespace sweetspot::api {
namespace scene_outputs_test {
namespace {

std::vector<core::SceneOutput> AllOutputs() {
  std::vector<core::SceneOutput> all;
  for (const core::SceneOutputDecl* d : core::SceneOutputTable()) all.push_back(d->id);
  return all;
}

TEST(SceneOutputsTest, EveryOutputHasItsApiHalfRenderedUnderItsName) {
  ASSERT_EQ(ApiOutputTable().size(), core::SceneOutputTable().size());
  const core::SceneResult probe = ProbeResult(AllOutputs());
  const nlohmann::json rendered = SceneResultToJson(probe);
  for (const core::SceneOutputDecl* d : core::SceneOutputTable()) {
    const ApiOutputDecl& api = ApiOutputDeclaration(d->id);
    EXPECT_EQ(api.id, d->id) << d->name;
    EXPECT_TRUE(d->present(probe)) << d->name << ": its probe fills its slot";
    ASSERT_TRUE(rendered.contains(d->name)) << d->name;
    for (const DirectField* f = api.direct_begin; f != api.direct_end; ++f) {
      EXPECT_TRUE(rendered[d->name].contains(f->name)) << d->name << "." << f->name;
    }
  }
}

TEST(SceneOutputsTest, ResetEmptiesEveryOutputsSlot) {
  core::SceneResult result = ProbeResult(AllOutputs());
  result.Reset();
  for (const core::SceneOutputDecl* d : core::SceneOutputTable()) {
    EXPECT_FALSE(d->present(result)) << d->name;
  }
  const nlohmann::json rendered = SceneResultToJson(result);
  for (const core::SceneOutputDecl* d : core::SceneOutputTable()) {
    EXPECT_FALSE(rendered.contains(d->name)) << d->name;
  }
}

}  // namespace
}  // namespace scene_outputs_test
}  // namespace sweetspot::api
