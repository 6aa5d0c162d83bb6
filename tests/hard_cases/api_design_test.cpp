// Endpoint hard cases of the design endpoints: POST /v1/optimize, /v1/explore and the jobs
// (POST /v1/jobs, then the job's result). Each nasty request must answer 2xx with finite
// numbers in a bounded range, or the named 4xx refusal; never a 500, never NaN or Infinity.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/hard_cases/hard_case.hpp"

namespace sweetspot::hard_cases {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace api_design_test {
namespace {

// The contract's example family (api.md): ash, 34 in, x1 in [0.1, 0.5], r2 in [0.028, 0.0331];
// within those bounds the mass spans [0.7294, 1.2858] kg. `start` is the base design's
// (taper_start_m, barrel_radius_m); `rest` more top-level fields with a leading comma.
std::string Design(const std::string& start, const std::string& rest) {
  return R"({"bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125, )" + start +
         R"(, "taper_end_m": 0.55}, "material": "ash"},
            "variables": [{"path": "three_segment.taper_start_m", "min": 0.1, "max": 0.5},
                          {"path": "three_segment.barrel_radius_m", "min": 0.028, "max": 0.0331}],
            "cor": 0.5)" +
         rest + "}";
}
const char* const kMiddle = R"("taper_start_m": 0.3, "barrel_radius_m": 0.033)";
const char* const kHeaviest = R"("taper_start_m": 0.1, "barrel_radius_m": 0.0331)";
const char* const kLightest = R"("taper_start_m": 0.5, "barrel_radius_m": 0.028)";

// Ipopt's constraint tolerance (1e-10 relative) re-checked through the mass properties.
constexpr double kMassTolerance = 1e-9;

// POST /v1/optimize.
std::vector<ApiCase> OptimizeCases() {
  const std::string p = "/v1/optimize";
  return {
      // Started at the heaviest corner (1.2858 kg), asked for 0.74 kg (0.0106 above the
      // lightest design), and the reverse.
      Ok("FromTheHeaviestCornerToNearlyTheLightest", p,
         Design(kHeaviest, R"(, "constraints": {"mass_kg": 0.74})"),
         {Is("/summary/termination", "converged"),
          Near("/properties/mass_kg", 0.74, kMassTolerance)}),
      AsJob(Ok("FromTheLightestCornerToNearlyTheHeaviest", p,
               Design(kLightest, R"(, "constraints": {"mass_kg": 1.28})"),
               {Is("/summary/termination", "converged"),
                Near("/properties/mass_kg", 1.28, kMassTolerance)})),
      Ok("NloptSlsqpFromTheHeaviestCorner", p,
         Design(kHeaviest,
                R"(, "constraints": {"mass_kg": 0.74}, "options": {"backend": "nlopt_slsqp"})"),
         {Near("/properties/mass_kg", 0.74, kMassTolerance)}),
      // Infeasible: below the lightest design; the conflict says by how much (0.2294 kg).
      AsJob(Refusal("MassBelowTheLightestDesign", p,
                    Design(kMiddle, R"(, "constraints": {"mass_kg": 0.5})"), 422, "Infeasible",
                    "constraints")),
      Refusal("LengthNoVariableChanges", p,
              Design(kMiddle, R"(, "constraints": {"mass_kg": 0.88, "length_m": 0.5})"), 422,
              "Infeasible", "constraints"),
      // Flat objective, nothing moves: refused before solving.
      Refusal("NothingMoves", p,
              Design(kMiddle, R"(, "ball": {"speed_mps": 0}, "swing": {"angular_speed_rad_s": 0})"),
              400, "InvalidValue", "ball.speed_mps"),
      // Flat objective e = 0, no swing, the pinned bat: every design's best exit speed is 0
      // (at the pivot). (The free bat's is -u m/(M + m), which depends on the design.)
      Ok("NloptSlsqpOnAFlatZeroObjective", p,
         Design(kMiddle, R"(, "cor": 0, "swing": {"angular_speed_rad_s": 0},
                   "options": {"backend": "nlopt_slsqp", "model": "rigid_pivot"})"),
         {Near("/objective_value", 0, 0)}),
      Ok("IpoptOnAFlatZeroObjective", p,
         Design(kMiddle, R"(, "cor": 0, "swing": {"angular_speed_rad_s": 0},
                   "options": {"model": "rigid_pivot"})"),
         {Near("/objective_value", 0, 0)}),
      Ok("OneIteration", p,
         Design(kHeaviest,
                R"(, "constraints": {"mass_kg": 0.74}, "options": {"max_iterations": 1})"),
         {Is("/summary/termination", "no_convergence"), Between("/objective_value", 13.85, 30)}),
      Refusal(
          "EqualVariableBounds", p,
          R"({"bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125, "barrel_radius_m": 0.033,
                  "taper_start_m": 0.3, "taper_end_m": 0.55}, "material": "ash"},
                  "variables": [{"path": "three_segment.taper_start_m", "min": 0.1, "max": 0.1}], "cor": 0.5})",
          400, "InvalidValue", "variables[0].max"),
      // Density over eleven decades for a 1 g bat: rho = M* / V = 0.6045 kg/m^3.
      Ok("DensityAcrossElevenDecades", p,
         R"({"bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125, "barrel_radius_m": 0.033,
             "taper_start_m": 0.3, "taper_end_m": 0.55}, "material": "ash"},
             "variables": [{"path": "material.density_kg_m3", "min": 1e-6, "max": 1e5}],
             "constraints": {"mass_kg": 1e-3}, "cor": 0.5})",
         {Near("/properties/mass_kg", 1e-3, 1e-12),
          Near("/bat/material/density_kg_m3", 0.6045413187906, 1e-9)}),
      // A zone tolerance of 1e-9 m/s: the zone is ~1e-5 m wide, still finite and positive.
      Ok("WidestSweetZoneOfANanometrePerSecond", p,
         Design(kMiddle, R"(, "constraints": {"mass_kg": 0.88}, "objective": "widest_sweet_zone",
                "sweet_zone_tolerance_mps": 1e-9)"),
         {Between("/objective_value", 1e-7, 1e-3)}),
  };
}

class HardCaseOptimizeEndpoint : public testing::TestWithParam<ApiCase> {};
TEST_P(HardCaseOptimizeEndpoint, Answers) { CheckApiCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Api, HardCaseOptimizeEndpoint, testing::ValuesIn(OptimizeCases()),
                         RowName<ApiCase>);

// POST /v1/explore: a design the model refuses is a row with feasible false and its error,
// never a failed sweep.
std::vector<ApiCase> ExploreCases() {
  const std::string p = "/v1/explore";
  return {
      Ok("BallMassFromANanogramToATonne", p,
         R"({"bat": {"preset": "paper-wood"}, "parameters": [{"path": "ball.mass_kg", "min": 1e-9, "max": 1000,
             "count": 3}], "outputs": ["properties", "max_exit_speed"]})",
         {Is("/rows/0/feasible", "false"), Is("/rows/0/error/field", "ball.mass_kg"),
          Is("/rows/2/feasible", "true"),
          Between("/rows/2/max_exit_speed/exit_speed_mps", 13.85, 13.86)}),
      Ok("WallUpToTheRadius", p,
         R"({"bat": {"preset": "paper-wood", "wall_thickness_m": 0.001}, "parameters": [{"path": "wall_thickness_m",
             "min": 0, "max": 0.0125, "count": 3}], "outputs": ["properties", "max_exit_speed", "collision_efficiency"]})",
         {Is("/rows/0/feasible", "true"), Is("/rows/2/feasible", "false"),
          Is("/rows/2/error/field", "bat.wall_thickness_m"),
          Between("/rows/1/collision_efficiency", -1, 1)}),
      Ok("SwingAndBallSpeedCorners", p,
         R"({"bat": {"preset": "paper-wood"}, "parameters": [{"path": "swing.angular_speed_rad_s", "min": 0, "max": 1e4,
             "count": 2}, {"path": "ball.speed_mps", "min": 0, "max": 1000, "count": 2}],
             "outputs": ["max_exit_speed", "sweet_zone", "center_of_percussion", "collision_efficiency"]})",
         {Near("/rows/0/max_exit_speed/exit_speed_mps", 0, 0),
          Between("/rows/3/max_exit_speed/exit_speed_mps", 1e4, 1.1e4),
          Is("/summary/failed", "0")}),
      Ok("CorFromZeroToOne", p,
         R"({"bat": {"preset": "paper-wood"}, "cor": 0.5, "parameters": [{"path": "cor", "min": 0, "max": 1, "count": 2}],
             "outputs": ["max_exit_speed", "collision_efficiency"]})",
         {Near("/rows/0/max_exit_speed/exit_speed_mps", 6.25839816080981, 1e-12),
          Near("/rows/1/max_exit_speed/exit_speed_mps", 40.21679632161962, 1e-12)}),
      Ok("DensityFrom1e-300", p,
         R"({"bat": {"preset": "paper-wood", "material": {"density_kg_m3": 649, "youngs_modulus_pa": 1e10, "cor": 0.5}},
             "parameters": [{"path": "material.density_kg_m3", "min": 1e-300, "max": 1e5, "count": 2}],
             "outputs": ["properties", "max_exit_speed"]})",
         {Is("/rows/0/feasible", "true"),
          Near("/rows/0/properties/balance_point_m", 0.6089948432432433, 1e-15)}),
      Ok("SubnormalDensities", p,
         R"({"bat": {"preset": "paper-wood", "material": {"density_kg_m3": 649, "youngs_modulus_pa": 1e10, "cor": 0.5}},
             "parameters": [{"path": "material.density_kg_m3", "min": 0, "max": 4e-320, "count": 2}],
             "outputs": ["properties", "max_exit_speed"]})",
         {Is("/rows/0/error/field", "bat.material.density_kg_m3"), Is("/rows/1/error/field", "bat"),
          Is("/summary/failed", "2")}),
      // Knot 2 swept onto knot 1 (a zero-length segment) and to 1e-12 m beyond it.
      Ok("KnotOntoItsNeighbour", p,
         R"({"bat": {"profile": {"knots": [{"x_m": 0, "radius_m": 0.0125}, {"x_m": 0.4, "radius_m": 0.0125},
             {"x_m": 0.41, "radius_m": 0.035}, {"x_m": 0.86, "radius_m": 0.035}]}},
             "parameters": [{"path": "profile.knots[2].x_m", "min": 0.4, "max": 0.400000000001, "count": 3}],
             "outputs": ["max_exit_speed"]})",
         {Is("/rows/0/error/field", "bat.profile.knots[2].x_m"), Is("/rows/2/feasible", "true")}),
      Ok("BallSpeedOverTwelveDecades", p,
         R"({"bat": {"preset": "paper-wood"}, "parameters": [{"path": "ball.speed_mps", "min": 1e-6, "max": 1e6,
             "count": 2}]})",
         {Is("/rows/0/feasible", "true"), Is("/rows/1/feasible", "false"),
          Is("/rows/1/error/field", "ball.speed_mps")}),
      Refusal(
          "ZeroCount", p,
          R"({"bat": {"preset": "paper-wood"}, "parameters": [{"path": "ball.speed_mps", "min": 10, "max": 20, "count": 0}]})",
          400, "InvalidValue", "parameters[0].count"),
      Refusal(
          "MaxBelowMin", p,
          R"({"bat": {"preset": "paper-wood"}, "parameters": [{"path": "ball.speed_mps", "min": 20, "max": 10, "count": 2}]})",
          400, "InvalidValue", "parameters[0].max"),
      Refusal(
          "ABillionDesigns", p,
          R"({"bat": {"preset": "paper-wood"}, "parameters": [{"path": "ball.speed_mps", "min": 10, "max": 20,
                  "count": 1000000000}]})",
          413, "TooBig", "parameters"),
  };
}

class HardCaseExploreEndpoint : public testing::TestWithParam<ApiCase> {};
TEST_P(HardCaseExploreEndpoint, Answers) { CheckApiCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Api, HardCaseExploreEndpoint, testing::ValuesIn(ExploreCases()),
                         RowName<ApiCase>);

// POST /v1/jobs itself with nasty submissions (the as_job rows of the other tables run nasty
// requests through jobs and compare the job's result with the direct answer).
std::vector<ApiCase> JobCases() {
  const std::string p = "/v1/jobs";
  return {
      Refusal("JobOfAJob", p, R"({"path": "/v1/jobs", "body": {}})", 400, "InvalidValue", "path"),
      Refusal("JobOfAnUnknownPath", p, R"({"path": "/v1/nothing", "body": {}})", 400,
              "InvalidValue", "path"),
      Refusal("JobBodyIsAnArray", p, R"({"path": "/v1/sweet-spot", "body": []})", 400,
              "InvalidValue", "body"),
      Refusal("JobWithoutABody", p, R"({"path": "/v1/sweet-spot"})", 400, "MissingField", "body"),
      // A job whose inner request its endpoint refuses is refused at submit with the
      // endpoint's own answer (issue 19); no job is made.
      Refusal("JobOfASubnormalBallMass", p,
              R"({"path": "sweet-spot", "body": {"bat": {"preset": "paper-wood"}, "ball": {"mass_kg": 5e-324}}})",
              400, "InvalidValue", "ball.mass_kg"),
  };
}

class HardCaseJobsEndpoint : public testing::TestWithParam<ApiCase> {};
TEST_P(HardCaseJobsEndpoint, Answers) { CheckApiCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Api, HardCaseJobsEndpoint, testing::ValuesIn(JobCases()),
                         RowName<ApiCase>);

}  // namespace
}  // namespace api_design_test
}  // namespace sweetspot::hard_cases
