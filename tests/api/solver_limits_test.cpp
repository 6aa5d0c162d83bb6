// The solver limits of ApiLimits (max_iterations, max_time_s,
// max_integration_steps) bound what a request may ask for, and the defaults
// of every solver are lowered to them when the server is configured tighter.
#include <gtest/gtest.h>

#include <string>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace solver_limits_test {
namespace {

using Json = nlohmann::json;

Response Post(const std::string& path, const std::string& body, const Context& context) {
  return Dispatch({"POST", path, body}, context);
}

TEST(SolverLimitsTest, IntegrationStepsAboveTheLimitAreRefusedWithTheField) {
  Context context;
  context.limits.max_integration_steps = 5000;
  const Response hertz = Post("/v1/collision",
                              R"({"bat": {"preset": "paper-wood"}, "impact_from_knob_m": 0.7,
                                  "model": "hertz", "hertz": {"max_steps": 5001}})",
                              context);
  EXPECT_EQ(hertz.status, 400) << hertz.body.dump();
  EXPECT_EQ(hertz.body["field"], "hertz.max_steps");
  EXPECT_EQ(hertz.body["message"], "hertz.max_steps = 5001: must be an integer in [10, 5000]");

  const Response flexible = Post("/v1/sweet-spot",
                                 R"({"bat": {"preset": "paper-wood"}, "outputs": ["max_exit_speed"],
                                     "options": {"flexible": {"max_steps": 5001}}})",
                                 context);
  EXPECT_EQ(flexible.status, 400) << flexible.body.dump();
  EXPECT_EQ(flexible.body["field"], "options.flexible.max_steps");

  // At the limit it is accepted.
  const Response at = Post("/v1/collision",
                           R"({"bat": {"preset": "paper-wood"}, "impact_from_knob_m": 0.7,
                               "model": "hertz", "hertz": {"max_steps": 5000}})",
                           context);
  EXPECT_EQ(at.status, 200) << at.body.dump();
}

TEST(SolverLimitsTest, DefaultStepBoundIsLoweredToTheLimit) {
  // The Hertz default is 20000 steps; a contact at 1e-10 relative tolerance
  // needs more than 30 of them, so a server limited to 30 steps must answer
  // the documented 422 ModelFailed instead of silently running 20000.
  Context context;
  context.limits.max_integration_steps = 30;
  const Response r = Post("/v1/collision",
                          R"({"bat": {"preset": "paper-wood"}, "impact_from_knob_m": 0.7,
                              "model": "hertz", "hertz": {"relative_tolerance": 1e-10}})",
                          context);
  EXPECT_EQ(r.status, 422) << r.body.dump();
  EXPECT_EQ(r.body["code"], "ModelFailed");

  // The same request under the default limits succeeds.
  const Response ok = Post("/v1/collision",
                           R"({"bat": {"preset": "paper-wood"}, "impact_from_knob_m": 0.7,
                               "model": "hertz", "hertz": {"relative_tolerance": 1e-10}})",
                           Context{});
  EXPECT_EQ(ok.status, 200) << ok.body.dump();
}

TEST(SolverLimitsTest, DefaultSolverBudgetsFollowTheLimits) {
  // /v1/bat/fit reports the options it ran with: a server limited to 0.25 s
  // and 50 evaluations runs its default fit with those, not 5 s and 20000.
  Context context;
  context.limits.max_time_s = 0.25;
  context.limits.max_iterations = 50;
  const Response r = Post("/v1/bat/fit",
                          R"({"bat": {"three_segment": {"length_m": 0.855,
                                "handle_radius_m": 0.0125, "barrel_radius_m": 0.035,
                                "taper_start_m": 0.3, "taper_end_m": 0.6}, "material": "ash"},
                              "targets": {"mass_kg": 0.9, "balance_point_m": 0.6}})",
                          context);
  // 50 evaluations are not enough for this fit (it converges with the
  // default 20000), so the answer is the budget's 422 with the best bat found.
  ASSERT_EQ(r.status, 422) << r.body.dump();
  EXPECT_EQ(r.body["code"], "Timeout");
  const Json& closest = r.body["closest"];
  ASSERT_TRUE(closest.contains("provenance")) << r.body.dump();
  EXPECT_EQ(closest["provenance"]["options"]["max_time_s"].get<double>(), 0.25);
  EXPECT_EQ(closest["provenance"]["options"]["max_evaluations"].get<int>(), 50);
  EXPECT_EQ(closest["summary"]["evaluations"].get<int>(), 50);

  // Asking for more than the limit is a 400 naming the field.
  const Response over = Post("/v1/bat/fit",
                             R"({"bat": {"preset": "paper-wood"},
                                 "targets": {"mass_kg": 0.9, "balance_point_m": 0.6},
                                 "options": {"max_time_s": 0.5}})",
                             context);
  EXPECT_EQ(over.status, 400) << over.body.dump();
  EXPECT_EQ(over.body["field"], "options.max_time_s");
}

}  // namespace
}  // namespace solver_limits_test
}  // namespace sweetspot::api
