// The scene outputs `barrel` and `bbcor` through the router (issue 18 item 2): the contract's
// names, the aluminium preset's figures, a solid wood bat unchanged.
#include <gtest/gtest.h>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace barrel_api_test {
namespace {

Response Post(const std::string& path, const std::string& body) {
  return Dispatch({"POST", path, body}, Context{});
}

TEST(BarrelApiTest, AluminiumPresetHasAHoopModeAndABbcorAtTheLimit) {
  const Response r = Post("/v1/sweet-spot", R"({"bat": {"preset": "bbcor-33-aluminium"},
      "ball": {"preset": "ncaa-nfhs"}, "outputs": ["barrel", "bbcor"]})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const auto& b = r.body["barrel"];
  EXPECT_TRUE(b["hollow"].get<bool>());
  EXPECT_NEAR(b["hoop_frequency_hz"].get<double>(), 1777.5, 0.5);
  EXPECT_GT(b["barrel_stiffness_n_m"].get<double>(), 1e8);
  EXPECT_LT(b["barrel_stiffness_n_m"].get<double>(), 3e8);
  EXPECT_EQ(b["method"], "trampoline_quasi_static");
  // The trampoline: more than the ball's own COR at every point of the barrel.
  ASSERT_EQ(b["effective_cor_curve"].size(), 10u);
  for (const auto& p : b["effective_cor_curve"]) {
    EXPECT_GT(p["effective_cor"].get<double>(), p["ball_cor"].get<double>());
  }
  const auto& c = r.body["bbcor"];
  EXPECT_NEAR(c["value"].get<double>(), 0.50, 0.002);
  EXPECT_EQ(c["ball"], "ncaa-nfhs");
  EXPECT_NEAR(c["ball_speed_mps"].get<double>(), 60.79744, 1e-9);
  EXPECT_NEAR(c["pivot_from_knob_m"].get<double>(), 0.1524, 1e-15);
  EXPECT_NEAR(c["impact_from_knob_m"].get<double>(), 33 * 0.0254 - 0.1524, 1e-12);
  EXPECT_EQ(r.body["models_used"], nlohmann::json::array({"mass_properties", "barrel"}));
}

TEST(BarrelApiTest, SolidWoodIsUnchanged) {
  const std::string scene = R"({"bat": {"preset": "wood-34-ash"}, "outputs": ["max_exit_speed"]})";
  const Response before = Post("/v1/sweet-spot", scene);
  const Response with = Post("/v1/sweet-spot", R"({"bat": {"preset": "wood-34-ash"},
      "outputs": ["max_exit_speed", "barrel", "bbcor"]})");
  ASSERT_EQ(before.status, 200) << before.body.dump();
  ASSERT_EQ(with.status, 200) << with.body.dump();
  EXPECT_EQ(with.body["max_exit_speed"], before.body["max_exit_speed"]);
  EXPECT_EQ(with.body["cor"], before.body["cor"]);
  const auto& b = with.body["barrel"];
  EXPECT_FALSE(b["hollow"].get<bool>());
  EXPECT_TRUE(b["hoop_frequency_hz"].is_null());
  EXPECT_TRUE(b["barrel_stiffness_n_m"].is_null());
  EXPECT_EQ(b["effective_cor"], with.body["cor"]);
  EXPECT_EQ(with.body["bbcor"]["method"], "rigid");
  EXPECT_NEAR(with.body["bbcor"]["value"].get<double>(), 0.555 - 0.001 * 76, 1e-12);
}

}  // namespace
}  // namespace barrel_api_test
}  // namespace sweetspot::api
