// The one mapping from core's refusals (core/refusal.hpp) to the request's fields
// (api/json_reader.hpp: CoreRefusal).
#include <gtest/gtest.h>

#include <string>

#include "api/json_reader.hpp"
#include "core/refusal.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace refusal_mapping_test {
namespace {

TEST(RefusalMappingTest, ACoreFieldMapsToTheRequestPath) {
  ApiError error;
  EXPECT_FALSE(CoreRefusal(
      core::NumberRefusal("wall_thickness_m", -0.001, "must be non-negative (0 = solid)"), "bat",
      &error));
  EXPECT_EQ(error.status, 400);
  EXPECT_EQ(error.code, ErrorCode::kInvalidValue);
  EXPECT_EQ(error.field, "bat.wall_thickness_m");
  EXPECT_EQ(error.message, "bat.wall_thickness_m = -0.001: must be non-negative (0 = solid)");

  // Without a prefix the core field is the request's field.
  error = ApiError{};
  CoreRefusal(core::NumberRefusal("shard.index", 3, "must be below shard.count = 2"), "", &error);
  EXPECT_EQ(error.field, "shard.index");
  EXPECT_EQ(error.message, "shard.index = 3: must be below shard.count = 2");

  // A refusal that names no field names the object it was found in.
  error = ApiError{};
  CoreRefusal(core::TextRefusal("", "objective: not a known objective"), "options", &error);
  EXPECT_EQ(error.field, "options");
  EXPECT_EQ(error.message, "options: objective: not a known objective");

  // A field without a quoted value still names the field (the text parse named
  // "options.derivative_check: Ipopt's checker needs backend").
  error = ApiError{};
  CoreRefusal(core::TextRefusal("derivative_check", "Ipopt's checker needs backend = ipopt"),
              "options", &error);
  EXPECT_EQ(error.field, "options.derivative_check");
  EXPECT_EQ(error.message, "options.derivative_check: Ipopt's checker needs backend = ipopt");

  // The first error recorded wins.
  CoreRefusal(core::NumberRefusal("other", 1, "r"), "", &error);
  EXPECT_EQ(error.field, "options.derivative_check");
  EXPECT_EQ(RequestField(core::NumberRefusal("knots[2].x_m", 1, "r"), "bat.profile"),
            "bat.profile.knots[2].x_m");
}

TEST(RefusalMappingTest, TheTableRenamesCoreFieldsTheRequestNamesOtherwise) {
  EXPECT_EQ(RequestName("hertz.paper.k3"), "hertz.paper_constants.k3");
  EXPECT_EQ(RequestName("hertz.hands_stiffness_n_m"), "hertz.hands_stiffness_n_m");
  EXPECT_EQ(RequestName("ball.mass_kg"), "ball.mass_kg");
  // A field entry renames that field only: the exponent keeps its name.
  EXPECT_EQ(RequestName("ball.stiffness"), "ball.stiffness_n_m_p");
  EXPECT_EQ(RequestName("ball.stiffness_exponent"), "ball.stiffness_exponent");
  EXPECT_EQ(RequestName("flexible.impact.frequency_tolerance"),
            "flexible.mode_frequency_tolerance");
  EXPECT_EQ(RequestName("flexible.frequency_tolerance"), "flexible.frequency_tolerance");
  ApiError error;
  CoreRefusal(core::Number17Refusal("hertz.paper.k3", -1, "must be in [0, 1e20]"), "options",
              &error);
  EXPECT_EQ(error.field, "options.hertz.paper_constants.k3");
  EXPECT_EQ(error.message, "options.hertz.paper_constants.k3 = -1: must be in [0, 1e20]");
}

TEST(RefusalMappingTest, ARuleSetIsAnEntryOfTheRequestsConstraintsRules) {
  // core::RuleAllowsDesign names the rule set ("rules.mlb-wood"), which is no request path.
  ApiError error;
  CoreRefusal(core::TextRefusal("rules.mlb-wood",
                                "one piece of solid wood: wall_thickness_m = 0.003 makes a "
                                "hollow shell"),
              "", &error);
  EXPECT_EQ(error.field, "constraints.rules");
  EXPECT_EQ(error.message,
            "constraints.rules = \"mlb-wood\": one piece of solid wood: wall_thickness_m = 0.003 "
            "makes a hollow shell");
  // A limit of a rule set is a constraint's name, not a refusal field: left as it is.
  EXPECT_EQ(RequestField(core::TextRefusal("rules.bbcor.drop", "x"), ""), "rules.bbcor.drop");
}

TEST(RefusalMappingTest, SceneFieldsAreTheSceneHeads) {
  for (const char* field :
       {"bat", "ball.mass_kg", "swing.hands_from_knob_m", "cor", "outputs", "inertia_model"}) {
    EXPECT_TRUE(IsSceneField(field)) << field;
  }
  for (const char* field : {"", "curve_samples", "flexible.max_elements", "hertz.k3", "bats"}) {
    EXPECT_FALSE(IsSceneField(field)) << field;
  }
}

}  // namespace
}  // namespace refusal_mapping_test
}  // namespace sweetspot::api
