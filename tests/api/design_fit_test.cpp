// Issue 19, "Fit any bat": /v1/bat/fit with unknowns named by design-variable paths fits any
// bat (a profile here) through the design optimiser, with the same infeasibility report.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace design_fit_test {
namespace {

using Json = nlohmann::json;

constexpr double kOunce = 0.028349523125;  // kg, exact

Response Post(const std::string& path, const Json& body) {
  return Dispatch({"POST", path, body.dump()}, Context{});
}

TEST(DesignFitTest, AProfilesDensityScaledToThirtyOunces) {
  // The issue's "scale this profile's density to 30 oz", wood-34-ash being a profile preset.
  const Json body = Json::parse(R"({"bat": {"preset": "wood-34-ash"}, "targets": {"mass_oz": 30},
      "unknowns": [{"path": "material.density_kg_m3", "min": 400, "max": 900}]})");
  const Response r = Post("/v1/bat/fit", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["summary"]["termination"], "converged");
  // Ipopt's constraint tolerance is 1e-10 relative: 1e-9 kg bounds it on a 0.85 kg bat.
  EXPECT_NEAR(r.body["properties"]["mass_kg"].get<double>(), 30 * kOunce, 1e-9);
  EXPECT_NEAR(r.body["residuals"]["mass_kg"].get<double>(), 0.0, 1e-9);
  // The mass is linear in the density of a solid bat: the density is 30 oz / 31.485 oz of ash's.
  const Response base = Post("/v1/bat/properties", Json{{"bat", {{"preset", "wood-34-ash"}}}});
  const double scale = 30 * kOunce / base.body["mass_kg"].get<double>();
  const double ash = 672.0000000000001;  // the catalogue's ash, kg/m^3
  EXPECT_NEAR(r.body["unknowns"]["material.density_kg_m3"].get<double>(), scale * ash, 1e-6);
  // The fitted bat re-checks through /v1/bat/properties.
  const Response again = Post("/v1/bat/properties", Json{{"bat", r.body["bat"]}});
  ASSERT_EQ(again.status, 200) << again.body.dump();
  EXPECT_NEAR(again.body["mass_kg"].get<double>(), 30 * kOunce, 1e-9);
}

// Every radius of a solid bat scaled by one factor ("scale_paths") to a target mass: the mass
// of a solid bat is its base mass times s^2, so s = sqrt(M / M0) exactly.
TEST(DesignFitTest, EveryRadiusScaledToATargetMass) {
  Json body = Json::parse(R"({"bat": {"preset": "wood-34-ash"}, "targets": {"mass_kg": 0.85},
      "unknowns": [{"scale_paths": [], "name": "radii", "min": 0.8, "max": 1.2}]})");
  // The preset's knots and mass, from the catalogue.
  const Response presets = Dispatch({"GET", "/v1/presets", ""}, Context{});
  ASSERT_EQ(presets.status, 200);
  Json preset;
  for (const Json& p : presets.body["presets"]) {
    if (p["name"] == "wood-34-ash") preset = p;
  }
  ASSERT_TRUE(preset.is_object());
  const Json& knots = preset["bat"]["profile"]["knots"];
  for (std::size_t k = 0; k < knots.size(); ++k) {
    body["unknowns"][0]["scale_paths"].push_back("profile.knots[" + std::to_string(k) +
                                                 "].radius_m");
  }
  const Response r = Post("/v1/bat/fit", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["summary"]["termination"], "converged");
  const double s = r.body["unknowns"]["radii"];
  // The mass holds to Ipopt's 1e-10 relative constraint tolerance (< 1e-10 kg): s = sqrt(M /
  // M0) to s |dM| / (2 M) < 6e-11; 1e-9 leaves room for rounding.
  EXPECT_NEAR(s, std::sqrt(0.85 / preset["properties"]["mass_kg"].get<double>()), 1e-9);
  for (std::size_t k = 0; k < knots.size(); ++k) {
    const std::string path = "profile.knots[" + std::to_string(k) + "].radius_m";
    // Each field is its base value times the factor, exactly, in the answer and in the bat.
    EXPECT_EQ(r.body["unknowns"][path].get<double>(), knots[k]["radius_m"].get<double>() * s);
    EXPECT_EQ(r.body["bat"]["profile"]["knots"][k]["radius_m"], r.body["unknowns"][path]);
  }
}

TEST(DesignFitTest, TwoTargetsTwoUnknownsAndLinkedKnots) {
  // Mass and balance point from the density and the barrel's two knots linked (one diameter).
  const Json body = Json::parse(R"({"bat": {"profile": {"knots": [
        {"x_m": 0.0, "radius_m": 0.0125}, {"x_m": 0.3, "radius_m": 0.0125},
        {"x_m": 0.6, "radius_m": 0.032}, {"x_m": 0.8636, "radius_m": 0.032}]}, "material": "ash"},
      "targets": {"mass_kg": 0.88, "balance_point_m": 0.59},
      "unknowns": [{"path": "material.density_kg_m3", "min": 400, "max": 900},
                   {"paths": ["profile.knots[2].radius_m", "profile.knots[3].radius_m"],
                    "min": 0.028, "max": 0.034}]})");
  const Response r = Post("/v1/bat/fit", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_NEAR(r.body["properties"]["mass_kg"].get<double>(), 0.88, 1e-9);
  EXPECT_NEAR(r.body["properties"]["balance_point_m"].get<double>(), 0.59, 1e-9);
  EXPECT_EQ(r.body["unknowns"]["profile.knots[2].radius_m"],
            r.body["unknowns"]["profile.knots[3].radius_m"]);
  EXPECT_EQ(r.body["bat"]["profile"]["knots"][2]["radius_m"],
            r.body["bat"]["profile"]["knots"][3]["radius_m"]);
}

TEST(DesignFitTest, InfeasibleTargetsAndBadUnknownsSayWhyInTheFitsNames) {
  Json body = Json::parse(R"({"bat": {"preset": "wood-34-ash"}, "targets": {"mass_oz": 50},
      "unknowns": [{"path": "material.density_kg_m3", "min": 400, "max": 900}]})");
  Response r = Post("/v1/bat/fit", body);
  ASSERT_EQ(r.status, 422) << r.body.dump();
  EXPECT_EQ(r.body["code"], "Infeasible");
  EXPECT_EQ(r.body["field"], "targets");
  EXPECT_NE(r.body["message"].get<std::string>().find("above the heaviest bat"),
            std::string::npos)
      << r.body["message"];
  // The closest bat is the heaviest: the density at its upper bound (to Ipopt's 1e-8).
  EXPECT_NEAR(r.body["closest"]["unknowns"]["material.density_kg_m3"].get<double>(), 900, 1e-6);
  EXPECT_LT(r.body["closest"]["residuals"]["mass_kg"].get<double>(), -0.2);
  body["unknowns"][0]["path"] = "material.density";
  r = Post("/v1/bat/fit", body);
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "unknowns[0].path");
  // A profile bat with the three-segment fit's names: told how to ask.
  r = Post("/v1/bat/fit", Json::parse(R"({"bat": {"preset": "wood-34-ash"},
      "targets": {"mass_kg": 0.85}})"));
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(r.body["message"].get<std::string>().find("design-variable path"), std::string::npos)
      << r.body;
}

}  // namespace
}  // namespace design_fit_test
}  // namespace sweetspot::api
