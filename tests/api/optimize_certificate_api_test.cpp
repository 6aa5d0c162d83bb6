// POST /v1/optimize's certificate (summary.certificate) and merged constraints
// (summary.merged_constraints) through the router; the certificate's tolerances refused by name.
#include <gtest/gtest.h>

#include <string>

#include "api/router.hpp"
#include "tests/contract_example.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace optimize_certificate_api_test {
namespace {

using Json = nlohmann::json;

Response Post(const Json& body) {
  return Dispatch({"POST", "/v1/optimize", body.dump()}, Context{});
}

// A 33 in three-segment ash bat at 30 oz under bbcor, whose drop (<= 3) repeats the weight.
Json BbcorThirtyOunces() {
  return Json::parse(R"({
    "bat": {"three_segment": {"length_in": 33, "handle_radius_m": 0.0125, "barrel_radius_m": 0.032,
                              "taper_start_m": 0.3, "taper_end_m": 0.55}, "material": "ash"},
    "variables": [{"path": "three_segment.taper_start_m", "min": 0.1, "max": 0.5},
                  {"path": "three_segment.barrel_radius_m", "min": 0.028, "max": 0.0331}],
    "constraints": {"mass_oz": 30, "rules": "bbcor"},
    "options": {"model": "rigid_pivot"}})");
}

TEST(OptimizeCertificateTest, ContractExampleIsCertified) {
  const Response r = Post(sweetspot::testing::ContractOptimisation());
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& c = r.body["summary"]["certificate"];
  EXPECT_EQ(r.body["summary"]["termination"], "converged");
  EXPECT_TRUE(c["checked"].get<bool>());
  EXPECT_TRUE(c["certified"].get<bool>());
  // Ipopt's tol is 1e-9 on the scaled problem: the certificate's residuals are well below the
  // default tolerances (1e-6), which the answer states.
  EXPECT_LE(c["stationarity"].get<double>(), 1e-8);
  EXPECT_LE(c["feasibility"].get<double>(), 1e-8);
  EXPECT_LE(c["complementarity"].get<double>(), 1e-8);
  EXPECT_EQ(c["stationarity_tolerance"].get<double>(), 1e-6);
  EXPECT_EQ(c["feasibility_tolerance"].get<double>(), 1e-6);
  EXPECT_EQ(c["complementarity_tolerance"].get<double>(), 1e-6);
  EXPECT_EQ(c["failed"], "");
  EXPECT_EQ(r.body["summary"]["error_estimate"], c["stationarity"]);
  EXPECT_FALSE(r.body["summary"].contains("merged_constraints"));
}

TEST(OptimizeCertificateTest, DropRepeatingTheWeightIsMergedAndReported) {
  const Response r = Post(BbcorThirtyOunces());
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& s = r.body["summary"];
  EXPECT_EQ(s["termination"], "converged");
  ASSERT_TRUE(s.contains("merged_constraints")) << s.dump();
  ASSERT_EQ(s["merged_constraints"].size(), 1u);
  EXPECT_EQ(s["merged_constraints"][0]["name"], "rules.bbcor.drop");
  EXPECT_EQ(s["merged_constraints"][0]["into"], "mass_kg");
  bool warned = false;
  for (const auto& w : s["warnings"]) {
    warned = warned || w.get<std::string>().find("rules.bbcor.drop") != std::string::npos;
  }
  EXPECT_TRUE(warned);
  for (const auto& a : s["active_constraints"]) {
    EXPECT_NE(a["name"], "rules.bbcor.drop");
    EXPECT_TRUE(a["multiplier"].is_number()) << a.dump();  // unique once merged
  }
  EXPECT_TRUE(s["certificate"]["multipliers_unique"].get<bool>());
}

TEST(OptimizeCertificateTest, ATighterStationarityToleranceThanTheAnswerFailsIt) {
  // 1e-300: no solve reaches it unless its residual is exactly 0; then certified stays true.
  Json body = sweetspot::testing::ContractOptimisation();
  body["options"]["stationarity_tolerance"] = 1e-300;
  const Response r = Post(body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& c = r.body["summary"]["certificate"];
  EXPECT_EQ(c["stationarity_tolerance"].get<double>(), 1e-300);
  if (c["stationarity"].get<double>() > 1e-300) {
    EXPECT_FALSE(c["certified"].get<bool>());
    EXPECT_EQ(r.body["summary"]["termination"], "no_convergence");
    EXPECT_NE(r.body["summary"]["message"].get<std::string>().find("not certified"),
              std::string::npos);
  }
}

TEST(OptimizeCertificateTest, TolerancesOutOfRangeAreRefusedByName) {
  for (const char* name :
       {"stationarity_tolerance", "feasibility_tolerance", "complementarity_tolerance"}) {
    Json body = sweetspot::testing::ContractOptimisation();
    body["options"][name] = 0;
    const Response r = Post(body);
    EXPECT_EQ(r.status, 400) << r.body.dump();
    EXPECT_EQ(r.body["field"], std::string("options.") + name) << r.body.dump();
  }
}

}  // namespace
}  // namespace optimize_certificate_api_test
}  // namespace sweetspot::api
