// The scene output `bbcor_scan` through the router: its fields, models_used, and `bbcor`
// unchanged beside it.
#include <gtest/gtest.h>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace bbcor_scan_api_test {
namespace {

Response Post(const std::string& path, const std::string& body) {
  return Dispatch({"POST", path, body}, Context{});
}

TEST(BbcorScanApiTest, AluminiumPresetScanBesideTheFixedPointBbcor) {
  const Response plain = Post("/v1/sweet-spot", R"({"bat": {"preset": "bbcor-33-aluminium"},
      "outputs": ["bbcor"]})");
  const Response r = Post("/v1/sweet-spot", R"({"bat": {"preset": "bbcor-33-aluminium"},
      "outputs": ["bbcor", "bbcor_scan"]})");
  ASSERT_EQ(plain.status, 200) << plain.body.dump();
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["bbcor"], plain.body["bbcor"]);
  const auto& s = r.body["bbcor_scan"];
  ASSERT_EQ(s["points"].size(), 9u) << s.dump();
  EXPECT_NEAR(s["points"][0]["position_from_tip_m"].get<double>(), 4 * 0.0254, 1e-15);
  EXPECT_NEAR(s["points"][8]["position_from_tip_m"].get<double>(), 8 * 0.0254, 1e-15);
  EXPECT_EQ(s["fixed_point_value"], plain.body["bbcor"]["estimate"]["value"]);
  EXPECT_EQ(s["max_value"], plain.body["bbcor"]["value"]);  // THE BBCOR (issue 35)
  EXPECT_EQ(s["method"], "flexible_free_free");
  EXPECT_EQ(s["ball"], "ncaa-nfhs");
  double largest = 0.0;
  for (const auto& p : s["points"]) {
    largest = std::max(largest, p["value"].get<double>());
    EXPECT_GT(p["barrel_stiffness_n_m"].get<double>(), 1e8);
  }
  EXPECT_GE(s["max_value"].get<double>(), largest);
  EXPECT_TRUE(r.body["error_estimate"]["bbcor_scan"]["value"].is_number());
  EXPECT_EQ(r.body["models_used"],
            nlohmann::json::array({"mass_properties", "flexible_beam", "flexible", "barrel"}))
      << r.body["models_used"].dump();
  // Not asked: not in the answer (bbcor computes the scan, but shows only its maximum).
  EXPECT_FALSE(plain.body.contains("bbcor_scan"));
  auto sorted = [](nlohmann::json a) {
    std::sort(a.begin(), a.end());
    return a;
  };
  EXPECT_EQ(sorted(plain.body["models_used"]), sorted(r.body["models_used"]));
}

TEST(BbcorScanApiTest, ExploreRowsAreTheSweetSpotAnswers) {
  // Two walls of the aluminium preset: each row's scan is the single request's.
  const Response r = Post("/v1/explore", R"({"bat": {"preset": "bbcor-33-aluminium"},
      "parameters": [{"path": "wall_thickness_m", "min": 0.0025, "max": 0.003, "count": 2}],
      "outputs": ["bbcor_scan"]})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  ASSERT_EQ(r.body["rows"].size(), 2u) << r.body.dump();
  for (const auto& row : r.body["rows"]) {
    nlohmann::json single = nlohmann::json::parse(R"({"bat": {"preset": "bbcor-33-aluminium"},
        "outputs": ["bbcor_scan"]})");
    single["bat"]["wall_thickness_m"] = row["parameters"]["wall_thickness_m"];
    const Response s = Post("/v1/sweet-spot", single.dump());
    ASSERT_EQ(s.status, 200) << s.body.dump();
    EXPECT_EQ(row["bbcor_scan"]["max_value"], s.body["bbcor_scan"]["max_value"]) << row.dump();
  }
  // The thinner wall has the higher maximum.
  EXPECT_GT(r.body["rows"][0]["bbcor_scan"]["max_value"].get<double>(),
            r.body["rows"][1]["bbcor_scan"]["max_value"].get<double>());
}

TEST(BbcorScanApiTest, UnknownOutputMessageNamesIt) {
  const Response r = Post("/v1/sweet-spot", R"({"bat": {"preset": "wood-34-ash"},
      "outputs": ["bbcor_scans"]})");
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(r.body.dump().find("bbcor_scan"), std::string::npos) << r.body.dump();
}

}  // namespace
}  // namespace bbcor_scan_api_test
}  // namespace sweetspot::api
