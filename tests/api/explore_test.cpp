// POST /v1/explore: sweeps, shards, seeds, failed designs, Pareto fronts, limits.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "api/explore/design.hpp"
#include "api/fields.hpp"
#include "api/json_path.hpp"
#include "api/router.hpp"
#include "core/bat/presets.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace explore_test {
namespace {

using Json = nlohmann::json;

Response Explore(const Json& body, const Context& context = {}) {
  return Dispatch({"POST", "/v1/explore", body.dump()}, context);
}

Json CorkSweep() {
  return Json::parse(R"({
    "bat": {"preset": "paper-wood",
            "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}},
    "parameters": [{"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": 31}],
    "outputs": ["max_exit_speed", "properties"]})");
}

TEST(ExploreTest, GridRowsMatchSingleRequests) {
  const Response r = Explore(CorkSweep());
  ASSERT_EQ(r.status, 200) << r.body.dump();
  ASSERT_EQ(r.body["rows"].size(), 31u);
  EXPECT_EQ(r.body["summary"]["designs_total"], 31);
  const Json& row = r.body["rows"][10];
  EXPECT_EQ(row["index"], 10);
  EXPECT_NEAR(row["parameters"]["fill.depth_m"].get<double>(), 0.1, 1e-15);
  // The same design through /v1/sweet-spot gives the same numbers (same code path).
  Json single = Json::parse(R"({"bat": {"preset": "paper-wood",
      "fill": {"material": "cork", "diameter_m": 0.0254}}})");
  single["bat"]["fill"]["depth_m"] = row["parameters"]["fill.depth_m"];
  const Response s = Dispatch({"POST", "/v1/sweet-spot", single.dump()}, Context{});
  ASSERT_EQ(s.status, 200);
  EXPECT_EQ(row["max_exit_speed"]["exit_speed_mps"], s.body["max_exit_speed"]["exit_speed_mps"]);
  EXPECT_EQ(row["properties"]["mass_kg"], s.body["properties"]["mass_kg"]);
  // Deeper cork: lighter bat (Table 4's direction).
  EXPECT_LT(r.body["rows"][30]["properties"]["mass_kg"].get<double>(),
            r.body["rows"][0]["properties"]["mass_kg"].get<double>());
}

TEST(ExploreTest, UnionOfShardsEqualsTheUnshardedSweepRowForRow) {
  for (const char* sampling : {"grid", "lhs", "sobol"}) {
    Json body = CorkSweep();
    body["parameters"].push_back(
        {{"path", "ball.speed_mps"}, {"min", 20}, {"max", 40}, {"count", 3}});
    body["sampling"] = sampling;
    if (std::string(sampling) != "grid") {
      body["samples"] = 40;
      body["seed"] = 11;
    }
    const Response whole = Explore(body);
    ASSERT_EQ(whole.status, 200) << whole.body.dump();
    std::map<int, Json> merged;
    for (int index = 0; index < 3; ++index) {
      body["shard"] = {{"index", index}, {"count", 3}};
      const Response part = Explore(body);
      ASSERT_EQ(part.status, 200);
      for (const auto& row : part.body["rows"]) {
        EXPECT_TRUE(merged.emplace(row["index"].get<int>(), row).second) << "duplicate row";
      }
    }
    ASSERT_EQ(merged.size(), whole.body["rows"].size()) << sampling;
    for (const auto& row : whole.body["rows"]) {
      EXPECT_EQ(merged.at(row["index"].get<int>()), row) << sampling;
    }
  }
}

TEST(ExploreTest, SameSeedSameDesignsOtherSeedOthers) {
  Json body = CorkSweep();
  body["sampling"] = "lhs";
  body["samples"] = 8;
  body["seed"] = 5;
  const Response a = Explore(body);
  const Response b = Explore(body);
  ASSERT_EQ(a.status, 200);
  EXPECT_EQ(a.body["rows"], b.body["rows"]);
  EXPECT_EQ(a.body["summary"]["provenance"]["seed"], 5);
  body["seed"] = 6;
  EXPECT_NE(Explore(body).body["rows"], a.body["rows"]);
}

TEST(ExploreTest, FailedDesignsAreRowsNotFailures) {
  Json body = CorkSweep();
  // Bores wider than the 0.07 m barrel are refused by the bat's rules.
  body["parameters"] = {{{"path", "fill.diameter_m"}, {"min", 0.02}, {"max", 0.08}, {"count", 4}}};
  const Response r = Explore(body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["summary"]["failed"], 1);
  const Json& bad = r.body["rows"][3];
  EXPECT_FALSE(bad["feasible"].get<bool>());
  EXPECT_EQ(bad["error"]["field"], "bat.fill.diameter_m");
  EXPECT_TRUE(r.body["rows"][0]["feasible"].get<bool>());
}

TEST(ExploreTest, AnOutputNamedTwiceIsOneOutput) {
  // Found by the explore fuzzer: a name given twice rendered the second copy from a moved-from
  // block (null) and the answer-size estimate threw (a 500). /v1/sweet-spot takes it once.
  Json once = CorkSweep();
  once["outputs"] = {"max_exit_speed", "properties"};
  Json twice = CorkSweep();
  twice["outputs"] = {"max_exit_speed", "properties", "max_exit_speed"};
  const Response a = Explore(once);
  const Response b = Explore(twice);
  ASSERT_EQ(a.status, 200) << a.body.dump();
  ASSERT_EQ(b.status, 200) << b.body.dump();
  EXPECT_EQ(b.body["rows"], a.body["rows"]);
  EXPECT_TRUE(b.body["rows"][0]["max_exit_speed"].is_object());
}

TEST(ExploreTest, PropertiesOnlyRowsAreFeasible) {
  // Found by the hard-case suite: a sweep asking only for properties marked
  // every design infeasible ("outputs: empty").
  const Json body = Json::parse(R"({"bat": {"preset": "paper-wood"},
      "parameters": [{"path": "ball.speed_mps", "min": 10, "max": 20, "count": 2}],
      "outputs": ["properties"]})");
  const Response r = Explore(body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["summary"]["failed"], 0);
  for (const Json& row : r.body["rows"]) {
    EXPECT_TRUE(row["feasible"].get<bool>()) << row.dump();
    EXPECT_NEAR(row["properties"]["mass_kg"].get<double>(), 1.0078, 1e-4);  // paper-wood
    EXPECT_FALSE(row.contains("max_exit_speed"));
  }
}

TEST(ExploreTest, RowsWithoutAnImpactNeedNoCor) {
  // A custom material has no default COR; these rows run no impact, so they need none.
  Json body = Json::parse(R"({"bat": {"preset": "paper-wood",
      "material": {"density_kg_m3": 649, "youngs_modulus_pa": 1.814e10}},
      "parameters": [{"path": "material.density_kg_m3", "min": 600, "max": 700, "count": 2}],
      "outputs": ["properties"]})");
  for (const Json& outputs :
       {Json::array({"properties"}), Json::array({"properties", "center_of_percussion"})}) {
    body["outputs"] = outputs;
    const Response r = Explore(body);
    ASSERT_EQ(r.status, 200) << r.body.dump();
    EXPECT_EQ(r.body["summary"]["failed"], 0) << r.body.dump();
    ASSERT_EQ(r.body["rows"].size(), 2u);
    // The mass scales with the density (no fill, solid): 1.0078 kg at 649 kg/m3 (paper-wood),
    // so 1.0078 * 600 / 649 and 1.0078 * 700 / 649, to the 1e-4 of the preset's rounding.
    EXPECT_NEAR(r.body["rows"][0]["properties"]["mass_kg"].get<double>(), 1.0078 * 600 / 649, 1e-4);
    EXPECT_NEAR(r.body["rows"][1]["properties"]["mass_kg"].get<double>(), 1.0078 * 700 / 649, 1e-4);
    EXPECT_EQ(r.body["rows"][0].contains("center_of_percussion"), outputs.size() == 2);
  }
  // An exit-speed row still needs one: a failed row with the same refusal.
  body["outputs"] = {"properties", "max_exit_speed"};
  const Response r = Explore(body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["summary"]["failed"], 2);
  EXPECT_EQ(r.body["rows"][0]["error"]["message"],
            "cor: not given, and material 'custom' has no default COR");
}

TEST(ExploreTest, AModelThatCannotFinishIsAModelFailedRow) {
  // The same code /v1/sweet-spot answers (422 ModelFailed), not InvalidValue.
  const Json body = Json::parse(R"({"bat": {"preset": "paper-wood"},
      "parameters": [{"path": "cor", "min": 0.4, "max": 0.5, "count": 2}],
      "outputs": ["max_exit_speed"],
      "options": {"model": "hertz", "hertz": {"max_steps": 10}}})");
  const Response r = Explore(body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["summary"]["failed"], 2);
  const Json& row = r.body["rows"][0];
  EXPECT_FALSE(row["feasible"].get<bool>());
  EXPECT_EQ(row["error"]["code"], "ModelFailed") << row.dump();
  Json single = Json::parse(R"({"bat": {"preset": "paper-wood"}, "cor": 0.4,
      "outputs": ["max_exit_speed"], "options": {"model": "hertz", "hertz": {"max_steps": 10}}})");
  const Response s = Dispatch({"POST", "/v1/sweet-spot", single.dump()}, Context{});
  EXPECT_EQ(s.status, 422);
  EXPECT_EQ(s.body["code"], row["error"]["code"]);
}

TEST(ExploreTest, ParetoFrontOverTwoObjectives) {
  Json body = CorkSweep();
  body["parameters"] = {{{"path", "fill.depth_m"}, {"min", 0.0}, {"max", 0.3}, {"count", 7}},
                        {{"path", "ball.speed_mps"}, {"min", 20}, {"max", 30}, {"count", 3}}};
  body["pareto"] = {{"objectives",
                     {{{"output", "max_exit_speed.exit_speed_mps"}, {"sense", "max"}},
                      {{"output", "properties.mass_kg"}, {"sense", "min"}}}}};
  const Response r = Explore(body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  // Independent check: a row is on the front iff no row is at least as fast and as light,
  // and strictly better in one.
  std::set<int> expected;
  const Json& rows = r.body["rows"];
  for (const auto& a : rows) {
    bool dominated = false;
    for (const auto& b : rows) {
      const double va = a["max_exit_speed"]["exit_speed_mps"],
                   vb = b["max_exit_speed"]["exit_speed_mps"];
      const double ma = a["properties"]["mass_kg"], mb = b["properties"]["mass_kg"];
      dominated = dominated || (vb >= va && mb <= ma && (vb > va || mb < ma));
    }
    if (!dominated) expected.insert(a["index"].get<int>());
  }
  std::set<int> front;
  for (const auto& i : r.body["summary"]["pareto_front"]) front.insert(i.get<int>());
  EXPECT_EQ(front, expected);
  EXPECT_FALSE(front.empty());
}

// An objective names a number a row has, as a column must: a typo used to give every design
// NaN and an empty front with a 200.
TEST(ExploreTest, AParetoObjectiveARowDoesNotHaveIsRefusedBeforeTheFirstDesign) {
  Json body = CorkSweep();
  body["pareto"] = {{"objectives",
                     {{{"output", "max_exit_speed.exit_speed_mps"}, {"sense", "max"}},
                      {{"output", "properties.mass_kgg"}, {"sense", "min"}}}}};
  Response r = Explore(body);
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "pareto.objectives[1].output");
  EXPECT_NE(r.body["message"].get<std::string>().find("has no field \"mass_kgg\""),
            std::string::npos)
      << r.body["message"];
  for (const char* not_a_number : {"feasible", "max_exit_speed"}) {
    body["pareto"]["objectives"][1]["output"] = not_a_number;
    r = Explore(body);
    EXPECT_EQ(r.status, 400) << not_a_number;
    EXPECT_NE(r.body["message"].get<std::string>().find("must name a number"), std::string::npos)
        << r.body["message"];
  }
  // A trade unit: only in rows that carry it.
  body["pareto"]["objectives"][1]["output"] = "properties.mass_oz";
  r = Explore(body);
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(r.body["message"].get<std::string>().find("report_units"), std::string::npos);
  body["report_units"] = "imperial";
  r = Explore(body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_FALSE(r.body["summary"]["pareto_front"].empty());
}

TEST(ExploreTest, NdjsonHasOneLinePerRowAndASummary) {
  Json body = CorkSweep();
  body["format"] = "ndjson";
  const Response r = Explore(body);
  ASSERT_EQ(r.status, 200);
  EXPECT_EQ(r.content_type, "application/x-ndjson");
  std::size_t lines = 0;
  std::string last;
  for (std::size_t pos = 0, next; (next = r.text.find('\n', pos)) != std::string::npos;
       pos = next + 1) {
    last = r.text.substr(pos, next - pos);
    ASSERT_FALSE(Json::parse(last, nullptr, false).is_discarded());
    ++lines;
  }
  EXPECT_EQ(lines, 32u);
  EXPECT_TRUE(Json::parse(last).contains("summary"));
}

TEST(ExploreTest, LimitsAndBadPathsAreNamed) {
  Context context;
  context.limits.max_samples = 100;
  Json body = CorkSweep();
  body["parameters"][0]["count"] = 101;
  Response r = Explore(body, context);
  EXPECT_EQ(r.status, 413);
  EXPECT_EQ(r.body["code"], "TooBig");
  EXPECT_EQ(r.body["field"], "parameters");

  body = CorkSweep();
  body["parameters"][0]["path"] = "three_segment.taper_start_m";
  r = Explore(body);
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "parameters[0].path");
  EXPECT_EQ(r.body["message"],
            "parameters[0].path = \"three_segment.taper_start_m\": the request has no field "
            "bat.three_segment (give it in the request)");

  body = CorkSweep();
  body["sampling"] = "sobol";
  r = Explore(body);
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["code"], "MissingField");
  EXPECT_EQ(r.body["field"], "samples");

  body = CorkSweep();
  body["shard"] = {{"index", 2}, {"count", 2}};
  r = Explore(body);
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["message"], "shard.index = 2: must be below shard.count = 2");
}

TEST(ExploreTest, AnUnknownLastKeyIsRefusedBeforeTheFirstDesign) {
  // Every design would fail alike (it was a 200 with every row failed): a 400 naming the
  // parameter, the path as written and the parser's rule.
  struct Case {
    Json bat;
    const char* path;
    const char* message;
  };
  const Json profile = Json::parse(R"({"profile": {"knots": [{"x_m": 0, "radius_m": 0.015},
      {"x_m": 0.2, "radius_m": 0.013}, {"x_m": 0.5, "radius_m": 0.03},
      {"x_m": 0.84, "radius_m": 0.033}]}})");
  const Case cases[] = {
      {profile, "profile.knots[3].radius",
       "parameters[0].path = \"profile.knots[3].radius\": bat.profile.knots[3].radius is not a "
       "known field; did you mean radius_m? (known: radius_m, wall_thickness_m, x_m)"},
      {CorkSweep()["bat"], "fill.depht_m",
       "parameters[0].path = \"fill.depht_m\": bat.fill.depht_m is not a known field; did you "
       "mean depth_m? (known: depth_m, diameter_m, material)"},
      {CorkSweep()["bat"], "ball.speed",
       "parameters[0].path = \"ball.speed\": ball.speed is not a known field (known: "
       "descent_angle_deg, mass_kg, preset, radius_m, speed_mps, spin_rpm, stiffness_exponent, "
       "stiffness_n_m_p)"},
  };
  for (const Case& c : cases) {
    Json body = CorkSweep();
    body["bat"] = c.bat;
    body["parameters"] = {{{"path", c.path}, {"min", 0.03}, {"max", 0.04}, {"count", 2}}};
    const Response r = Explore(body);
    EXPECT_EQ(r.status, 400) << c.path << ": " << r.body.dump();
    EXPECT_EQ(r.body["code"], "InvalidValue") << c.path;
    EXPECT_EQ(r.body["field"], "parameters[0].path") << c.path;
    EXPECT_EQ(r.body["message"], c.message) << c.path;
  }
  // The known field beside it is swept (both designs feasible).
  Json body = CorkSweep();
  body["bat"] = profile;
  body["parameters"] = {
      {{"path", "profile.knots[3].radius_m"}, {"min", 0.03}, {"max", 0.04}, {"count", 2}}};
  const Response r = Explore(body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["summary"]["failed"], 0) << r.body.dump();
}

TEST(ExploreTest, ARowComputesTheMassPropertiesOnce) {
  // A row with collision_efficiency ran ParseBat's guard (twice), the scene and the collision:
  // four computations. Now the scene's one is shared with the collision.
  const Json design = Json::parse(R"({"bat": {"preset": "paper-wood"}, "cor": 0.45})");
  RowOutputs outputs;
  outputs.properties = true;
  outputs.collision_efficiency = true;
  outputs.scene = {core::SceneOutput::kMaxExitSpeed};
  const DesignRow d = EvaluateDesign(design, outputs, core::SceneOptions{}, ApiLimits{});
  ASSERT_TRUE(d.row["feasible"].get<bool>()) << d.row.dump();
  int mass_properties_calls = 0, rigid_pivot_calls = 0;
  for (const auto& t : d.timings) {
    if (t.model == "mass_properties") mass_properties_calls += t.calls;
    if (t.model == "rigid_pivot") rigid_pivot_calls += t.calls;
  }
  EXPECT_EQ(mass_properties_calls, 1);
  EXPECT_EQ(rigid_pivot_calls, 2);  // the closed-form maximum, then the impact at it
  // q at the sweet spot, as /v1/collision answers it there (same inputs, same arithmetic).
  const Json collision{{"bat", {{"preset", "paper-wood"}}},
                       {"cor", 0.45},
                       {"model", "rigid_pivot"},
                       {"impact_from_knob_m", d.row["max_exit_speed"]["position_from_knob_m"]}};
  const Response hit = Dispatch({"POST", "/v1/collision", collision.dump()}, Context{});
  ASSERT_EQ(hit.status, 200) << hit.body.dump();
  EXPECT_EQ(d.row["collision_efficiency"], hit.body["rigid_pivot"]["collision_efficiency"]);
  // A row of properties only: one computation too.
  outputs = RowOutputs{};
  outputs.properties = true;
  const DesignRow p = EvaluateDesign(design, outputs, core::SceneOptions{}, ApiLimits{});
  ASSERT_TRUE(p.row["feasible"].get<bool>()) << p.row.dump();
  ASSERT_EQ(p.timings.size(), 1u);
  EXPECT_EQ(p.timings[0].model, "mass_properties");
  EXPECT_EQ(p.timings[0].calls, 1);
  EXPECT_NEAR(p.row["properties"]["mass_kg"].get<double>(), 1.0078, 1e-4);  // paper-wood
}

// A preset's profile points can be swept, as /v1/optimize's variables take them (issue 35: "no
// field bat.profile" before): every knot path the optimiser accepts, SI and trade forms, on
// "wood-34-ash"; each row's bat is the preset with that knot moved (the same mass as the
// explicit profile through /v1/sweet-spot, bit for bit: the same parser and code).
TEST(ExploreTest, APresetsProfileKnotsAreSweptAsTheOptimiserTakesThem) {
  const std::vector<core::ProfileKnot> knots = core::FindPreset("wood-34-ash")->bat.knots;
  ASSERT_GT(knots.size(), 3u);
  std::size_t checked = 0;
  for (const std::string& name : FieldNames(FieldScope::kVariable)) {
    if (name.rfind("profile.knots[i]", 0) != 0) continue;
    SCOPED_TRACE(name);
    const std::string path = "profile.knots[2]" + name.substr(16);
    const auto use = ResolveField(path, FieldScope::kVariable);
    ASSERT_TRUE(use.has_value());
    // The knot's own value and 1 % more, in the written unit (x between its neighbours).
    const bool is_x = use->si.find(".x_m") != std::string::npos;
    // The knot's SI field in the written unit (a diameter in inches: the radius / 0.0127 m).
    const double lo = (is_x ? knots[2].x_m : knots[2].radius_m) / use->to_si;
    Json body = Json::parse(R"({"bat": {"preset": "wood-34-ash"}, "outputs": ["properties"]})");
    body["parameters"] = {{{"path", path}, {"min", lo}, {"max", lo * 1.01}, {"count", 2}}};
    const Response r = Explore(body);
    ASSERT_EQ(r.status, 200) << r.body.dump();
    for (const Json& row : r.body["rows"]) {
      ASSERT_TRUE(row["feasible"].get<bool>()) << row.dump();
      const double written = row["parameters"][path].get<double>();
      Json profile = Json::array();
      for (std::size_t k = 0; k < knots.size(); ++k) {
        Json knot{{"x_m", knots[k].x_m}, {"radius_m", knots[k].radius_m}};
        if (k == 2) knot[is_x ? "x_m" : "radius_m"] = use->to_si * written;
        profile.push_back(knot);
      }
      Json single{{"bat", {{"preset", "wood-34-ash"}, {"profile", {{"knots", profile}}}}}};
      const Response s = Dispatch({"POST", "/v1/bat/properties", single.dump()}, Context{});
      ASSERT_EQ(s.status, 200) << s.body.dump();
      EXPECT_EQ(row["properties"]["mass_kg"], s.body["mass_kg"]) << single.dump();
    }
    // The sweep moved the bat: its two designs differ.
    EXPECT_NE(r.body["rows"][0]["properties"]["moi_knob_kg_m2"],
              r.body["rows"][1]["properties"]["moi_knob_kg_m2"]);
    ++checked;
  }
  EXPECT_GE(checked, 3u);  // x_m, radius_m and at least one trade form (diameter_in)
  // Linked knots (one barrel diameter) too, and the template's preset is untouched elsewhere.
  Json linked = Json::parse(R"({"bat": {"preset": "wood-34-ash"}, "outputs": ["properties"],
      "parameters": [{"paths": ["profile.knots[2].radius_m", "profile.knots[3].radius_m"],
                      "min": 0.03, "max": 0.032, "count": 2}]})");
  const Response l = Explore(linked);
  ASSERT_EQ(l.status, 200) << l.body.dump();
  EXPECT_EQ(l.body["summary"]["failed"], 0);
}

TEST(ExploreTest, CancelledSweepStops) {
  core::Progress progress;
  progress.Cancel();
  Context context;
  context.progress = &progress;
  const Response r = Explore(CorkSweep(), context);
  EXPECT_EQ(r.status, 409);
  EXPECT_EQ(r.body["code"], "Cancelled");
}

TEST(JsonPathTest, ParsesSetsAndRefuses) {
  std::string why;
  const auto steps = ParseJsonPath("profile.knots[3].radius_m", &why);
  ASSERT_TRUE(steps.has_value()) << why;
  ASSERT_EQ(steps->size(), 4u);
  EXPECT_EQ(std::get<std::size_t>((*steps)[2]), 3u);
  Json doc = {
      {"profile",
       {{"knots",
         Json::array(
             {{{"radius_m", 1}}, {{"radius_m", 2}}, {{"radius_m", 3}}, {{"radius_m", 4}}})}}}};
  EXPECT_TRUE(SetNumberAtPath(&doc, *steps, 0.5, &why)) << why;
  EXPECT_EQ(doc["profile"]["knots"][3]["radius_m"], 0.5);
  EXPECT_EQ(NumberAtPath(doc, *steps, &why), 0.5);
  EXPECT_FALSE(ParseJsonPath("a..b", &why).has_value());
  EXPECT_FALSE(ParseJsonPath("a[x]", &why).has_value());
  EXPECT_FALSE(SetNumberAtPath(&doc, *ParseJsonPath("profile.knots[9].radius_m", &why), 1, &why));
  EXPECT_EQ(why, "the request has no element profile.knots[9]");
}

}  // namespace
}  // namespace explore_test
}  // namespace sweetspot::api
