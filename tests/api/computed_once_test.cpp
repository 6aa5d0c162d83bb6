// Issue 33, item 4 "Computed once": every endpoint computes a bat's mass properties once per
// request (per bat for /v1/compare, per design for /v1/explore). Counted with core's test
// probe MassPropertiesComputationsOnThisThread (the handlers run on the calling thread; a
// sweep's designs too, with Context's default of one explore thread).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "api/router.hpp"
#include "core/bat/mass_properties.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace computed_once_test {
namespace {

struct Counted {
  int status = 0;
  long long computations = 0;
};

Counted Post(const std::string& path, const std::string& body) {
  const long long before = core::MassPropertiesComputationsOnThisThread();
  const Response r = Dispatch({"POST", path, body}, Context{});
  return {r.status, core::MassPropertiesComputationsOnThisThread() - before};
}

struct Case {
  const char* name;
  const char* path;
  const char* body;
  int status;              // the answer's status
  long long computations;  // the mass-property computations the request runs
};

const char* const kThreeSegment =
    R"({"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
        "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
        "material": "ash"})";

std::string With(const char* pattern) {
  std::string s = pattern;
  const std::string key = "$BAT";
  for (std::size_t at = s.find(key); at != std::string::npos; at = s.find(key)) {
    s.replace(at, key.size(), kThreeSegment);
  }
  return s;
}

const std::vector<Case>& Cases() {
  static const std::vector<Case> cases = {
      // One bat, once.
      {"properties", "/v1/bat/properties", R"({"bat": {"preset": "paper-wood"}})", 200, 1},
      {"properties_slender", "/v1/bat/properties",
       R"({"bat": {"preset": "paper-wood"}, "inertia_model": "slender_rod"})", 200, 1},
      {"sweet_spot", "/v1/sweet-spot", R"({"bat": {"preset": "wood-34-ash"}})", 200, 1},
      {"sweet_spot_closed_forms", "/v1/sweet-spot",
       R"({"bat": {"preset": "paper-wood"}, "outputs": ["max_exit_speed",
           "center_of_percussion"]})",
       200, 1},
      {"sweet_spot_barrel", "/v1/sweet-spot",
       R"({"bat": {"preset": "bbcor-33-aluminium"}, "ball": {"preset": "ncaa-nfhs"}})", 200, 1},
      {"collision", "/v1/collision",
       R"({"bat": {"preset": "wood-34-ash"}, "impact_from_knob_m": 0.70, "model": "rigid_pivot"})",
       200, 1},
      {"modes", "/v1/bat/modes", R"({"bat": {"preset": "wood-34-ash"}})", 200, 1},
      {"sweet_spot_hertz", "/v1/sweet-spot",
       R"({"bat": {"preset": "wood-34-ash"}, "options": {"model": "hertz"}})", 200, 1},
      {"sweet_spot_flexible", "/v1/sweet-spot",
       R"({"bat": {"preset": "wood-34-ash"}, "options": {"model": "flexible"}})", 200, 1},
      {"sweet_spot_least_sting", "/v1/sweet-spot",
       R"({"bat": {"preset": "wood-34-ash"}, "outputs": ["least_sting_zone"]})", 200, 1},
      {"sweet_spot_bbcor_scan", "/v1/sweet-spot",
       R"({"bat": {"preset": "bbcor-33-aluminium"}, "outputs": ["bbcor", "bbcor_scan"]})", 200, 1},
      {"collision_flexible", "/v1/collision",
       R"({"bat": {"preset": "wood-34-ash"}, "impact_from_knob_m": 0.70, "model": "flexible"})",
       200, 1},
      {"properties_three_segment", "/v1/bat/properties",
       R"({"bat": {"three_segment": {"length_in": 33, "handle_diameter_in": 0.95,
           "barrel_diameter_in": 2.5, "taper_start_in": 12, "taper_end_in": 22},
           "material": "hard-maple"}, "pivot_from_knob_m": 0.1})",
       200, 1},
      // Two bats, each once.
      {"compare", "/v1/compare",
       R"({"baseline": {"preset": "paper-wood"}, "variants": [{"name": "cork-320",
           "bat": {"preset": "paper-wood", "fill": {"material": {"density_kg_m3": 320,
           "youngs_modulus_pa": 2e7}, "diameter_m": 0.0254, "depth_m": 0.254}}}]})",
       200, 2},
  };
  return cases;
}

TEST(ComputedOnceTest, OneMassPropertiesComputationPerBat) {
  for (const Case& c : Cases()) {
    const Counted r = Post(c.path, c.body);
    EXPECT_EQ(r.status, c.status) << c.name;
    EXPECT_EQ(r.computations, c.computations) << c.name;
  }
}

TEST(ComputedOnceTest, SolversAndSweepsComputeEachBatOnce) {
  // Each bat once: the request's own (ParseBat's check, whose numbers the request then uses),
  // and each other bat once (the fitted bat, the optimiser's model of its base design and its
  // answer, each design of a sweep that changes the bat).
  const std::vector<Case> cases = {
      {"fit: its bat and the fitted bat", "/v1/bat/fit",
       R"({"bat": {"preset": "paper-wood"}, "targets": {"mass_kg": 0.95, "balance_point_m": 0.60}})",
       200, 2},
      {"explore: 3 designs of one bat", "/v1/explore",
       R"({"bat": {"preset": "wood-34-ash"}, "outputs": ["max_exit_speed"],
           "parameters": [{"path": "ball.speed_mps", "min": 30, "max": 40, "count": 3}]})",
       200, 1},
  };
  for (const Case& c : cases) {
    const Counted r = Post(c.path, c.body);
    EXPECT_EQ(r.status, c.status) << c.name;
    EXPECT_EQ(r.computations, c.computations) << c.name;
  }
  const std::string sweep = With(R"({"bat": $BAT, "outputs": ["max_exit_speed", "properties"],
      "parameters": [{"path": "three_segment.barrel_radius_m", "min": 0.03, "max": 0.033,
                      "count": 3}]})");
  const Counted explore = Post("/v1/explore", sweep);
  EXPECT_EQ(explore.status, 200);
  EXPECT_EQ(explore.computations, 1 + 3) << "the template's bat, then each design's";
  const std::string optimize = With(R"({"bat": $BAT, "variables": [{"path":
      "three_segment.taper_start_m", "min": 0.1, "max": 0.5}], "constraints": {"mass_kg":
      {"max": 0.95}}, "objective": "max_exit_speed", "cor": 0.5,
      "options": {"backend": "nlopt_slsqp"}})");
  const Counted optimized = Post("/v1/optimize", optimize);
  EXPECT_EQ(optimized.status, 200);
  EXPECT_EQ(optimized.computations, 1 + 1) << "the base design's, the answer's";
  // The COR from the ball's law at the base design (core::ResolveDesignCor): from the base
  // design's properties, not computed again.
  const Counted ball_law = Post("/v1/optimize", With(R"({"bat": $BAT, "ball": {"preset": "mlb"},
      "variables": [{"path": "three_segment.taper_start_m", "min": 0.1, "max": 0.5}],
      "constraints": {"mass_kg": {"max": 0.95}}, "objective": "max_exit_speed",
      "options": {"backend": "nlopt_slsqp"}})"));
  EXPECT_EQ(ball_law.status, 200);
  EXPECT_EQ(ball_law.computations, 1 + 1) << "the base design's, the answer's";
  // The general fit (unknowns by path) is the optimiser's.
  const Counted design_fit = Post("/v1/bat/fit", R"({"bat": {"preset": "wood-34-ash"},
      "unknowns": [{"path": "material.density_kg_m3", "min": 400, "max": 900}],
      "targets": {"mass_oz": 30}})");
  EXPECT_EQ(design_fit.status, 200);
  EXPECT_EQ(design_fit.computations, 1 + 1) << "the base design's, the answer's";
  // The bbcor rule re-checks the answer's BBCOR (twice: the constraint and the rule) with the
  // answer's mass properties.
  const Counted bbcor = Post("/v1/optimize", R"({"bat": {"preset": "bbcor-33-aluminium"},
      "variables": [{"path": "wall_thickness_m", "min": 0.0015, "max": 0.004},
                    {"paths": ["profile.knots[4].radius_m", "profile.knots[5].radius_m"],
                     "min": 0.0105, "max": 0.0135}],
      "objective": "min_moi", "constraints": {"rules": "bbcor"}})");
  EXPECT_EQ(bbcor.status, 200);
  EXPECT_EQ(bbcor.computations, 1 + 1) << "the base design's, the answer's";
}

}  // namespace
}  // namespace computed_once_test
}  // namespace sweetspot::api
