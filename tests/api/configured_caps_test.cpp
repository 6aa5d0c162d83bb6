// Caps that were written as constants are the configured limits:
// max_curve_samples is the only cap on an exit-speed curve's points, and
// max_design_variables bounds /v1/optimize's variables.
#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include <string>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace configured_caps_test {
namespace {

using Json = nlohmann::json;

Response Post(const std::string& path, const Json& body, const Context& context) {
  return Dispatch({"POST", path, body.dump()}, context);
}

Json CurveScene(const Json& options) {
  return {{"bat", {{"preset", "paper-wood"}}},
          {"outputs", {"exit_speed_curve"}},
          {"options", options}};
}

TEST(ConfiguredCapsTest, CurveLimitAboveTenThousandIsHonoured) {
  Context context;
  context.limits.max_curve_samples = 12000;
  const Response r =
      Post("/v1/sweet-spot", CurveScene({{"curve_samples", 12000}}), context);
  ASSERT_EQ(r.status, 200) << r.body.dump().substr(0, 400);
  EXPECT_EQ(r.body.at("exit_speed_curve").size(), 12000u);
  // One past the configured limit is refused, naming field, value and rule.
  const Response over =
      Post("/v1/sweet-spot", CurveScene({{"curve_samples", 12001}}), context);
  EXPECT_EQ(over.status, 400);
  EXPECT_EQ(over.body.at("code"), "InvalidValue");
  EXPECT_EQ(over.body.at("field"), "options.curve_samples");
  EXPECT_EQ(over.body.at("message"),
            "options.curve_samples = 12001: must be an integer in [2, 12000]");
}

TEST(ConfiguredCapsTest, CurveLimitBelowTheDefaultIsEnforced) {
  Context context;
  context.limits.max_curve_samples = 100;
  const Response at = Post("/v1/sweet-spot", CurveScene({{"curve_samples", 100}}), context);
  ASSERT_EQ(at.status, 200) << at.body.dump().substr(0, 400);
  EXPECT_EQ(at.body.at("exit_speed_curve").size(), 100u);

  const Response samples = Post("/v1/sweet-spot", CurveScene({{"curve_samples", 101}}), context);
  EXPECT_EQ(samples.status, 400);
  EXPECT_EQ(samples.body.at("field"), "options.curve_samples");
  EXPECT_EQ(samples.body.at("message"),
            "options.curve_samples = 101: must be an integer in [2, 100]");

  const Json positions(101, 0.5);
  const Response listed = Post(
      "/v1/sweet-spot", CurveScene({{"curve_positions_from_knob_m", positions}}), context);
  EXPECT_EQ(listed.status, 413);
  EXPECT_EQ(listed.body.at("code"), "TooBig");
  EXPECT_EQ(listed.body.at("field"), "options.curve_positions_from_knob_m");
  const std::string message = listed.body.at("message");
  EXPECT_EQ(message.rfind("options.curve_positions_from_knob_m = [0.5,", 0), 0u) << message;
  const std::string rule =
      ": has 101 positions, over the limit max_curve_samples = 100 (--max-curve-samples)";
  ASSERT_GE(message.size(), rule.size());
  EXPECT_EQ(message.substr(message.size() - rule.size()), rule) << message;
}

TEST(ConfiguredCapsTest, DefaultCurveLimitIsTenThousand) {
  EXPECT_EQ(ApiLimits{}.max_curve_samples, 10000u);
  const Response r = Post("/v1/sweet-spot", CurveScene({{"curve_samples", 10001}}), Context{});
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body.at("message"),
            "options.curve_samples = 10001: must be an integer in [2, 10000]");
}

Json OptimizeWith(int variables) {
  Json list = Json::array();
  for (int i = 0; i < variables; ++i) {
    list.push_back({{"path", "three_segment.taper_start_m"}, {"min", 0.1}, {"max", 0.5}});
  }
  return {{"bat",
           {{"three_segment",
             {{"length_m", 0.8636},
              {"handle_radius_m", 0.0125},
              {"barrel_radius_m", 0.033},
              {"taper_start_m", 0.30},
              {"taper_end_m", 0.55}}},
            {"material", "ash"}}},
          {"variables", list},
          {"objective", "max_exit_speed"}};
}

TEST(ConfiguredCapsTest, DesignVariablesFollowTheConfiguredLimit) {
  const Json two = OptimizeWith(2);
  Context context;
  context.limits.max_design_variables = 1;
  const Response tight = Post("/v1/optimize", two, context);
  EXPECT_EQ(tight.status, 400);
  EXPECT_EQ(tight.body.at("code"), "InvalidValue");
  EXPECT_EQ(tight.body.at("field"), "variables");
  EXPECT_EQ(tight.body.at("message"),
            "variables = " + two.at("variables").dump().substr(0, 57) +
                "...: must be an array of 1 to 1 {\"path\", \"min\", \"max\"}");

  // The default keeps the optimiser's 1000.
  EXPECT_EQ(ApiLimits{}.max_design_variables, 1000u);
  const Response many = Post("/v1/optimize", OptimizeWith(1001), Context{});
  EXPECT_EQ(many.status, 400);
  EXPECT_EQ(many.body.at("field"), "variables");
  const std::string message = many.body.at("message");
  const std::string rule = "must be an array of 1 to 1000 {\"path\", \"min\", \"max\"}";
  ASSERT_GE(message.size(), rule.size());
  EXPECT_EQ(message.substr(message.size() - rule.size()), rule) << message;
}

TEST(ConfiguredCapsTest, AVariableLimitBelow200IsEnforced) {
  // The limit also reaches core (DesignOptions::max_variables): 4 variables over a limit of 3.
  Context context;
  context.limits.max_design_variables = 3;
  const Response r = Post("/v1/optimize", OptimizeWith(4), context);
  EXPECT_EQ(r.status, 400) << r.body.dump();
  EXPECT_EQ(r.body.at("code"), "InvalidValue");
  EXPECT_EQ(r.body.at("field"), "variables");
  const std::string message = r.body.at("message");
  EXPECT_NE(message.find(": must be an array of 1 to 3 "), std::string::npos) << message;
}

TEST(ConfiguredCapsTest, LimitsRefuseCurvesOfFewerThanTwoPointsAndZeroVariables) {
  ApiLimits limits;
  std::string why;
  limits.max_curve_samples = 1;
  EXPECT_FALSE(Validates(limits, &why));
  EXPECT_EQ(why, "max_curve_samples = 1: must be at least 2 (a curve has two ends)");
  limits = ApiLimits{};
  limits.max_design_variables = 0;
  EXPECT_FALSE(Validates(limits, &why));
  EXPECT_EQ(why, "max_design_variables = 0: must be at least 1");
  EXPECT_TRUE(Validates(ApiLimits{}, &why)) << why;
}

}  // namespace
}  // namespace configured_caps_test
}  // namespace sweetspot::api
