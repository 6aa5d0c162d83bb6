// Issue 33, item 2, "A field is declared once": every row of the table of settable fields
// (api/fields.hpp) round-trips through the request's parser, the sweep's binder and the
// optimiser's variables, in SI and in every trade form; /v1/optimize variables and /v1/bat/fit
// unknowns take the trade forms (the same optimum as the SI request), answer under the name as
// written, in its unit, and their errors name the field as written with the value in its unit.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "api/bat_json.hpp"
#include "api/explore/binder.hpp"
#include "api/fields.hpp"
#include "api/json_path.hpp"
#include "api/json_reader.hpp"
#include "api/router.hpp"
#include "api/scene_json.hpp"
#include "api/trade_units.hpp"
#include "core/optimize/design_problem.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace fields_test {
namespace {

using Json = nlohmann::json;

Response Post(const std::string& path, const Json& body) {
  return Dispatch({"POST", path, body.dump()}, Context{});
}

// A request with every part a field can sit in: the three-segment form, or a profile; the
// swing by its bat speed for a field of the bat speed (the parser takes one of it and the
// angular speed).
Json Template(bool profile, bool bat_speed = false) {
  Json bat = profile ? Json::parse(R"({"profile": {"knots": [{"x_m": 0, "radius_m": 0.012},
                         {"x_m": 0.3, "radius_m": 0.013, "wall_thickness_m": 0.0028},
                         {"x_m": 0.6, "radius_m": 0.033},
                         {"x_m": 0.84, "radius_m": 0.033}]}})")
                     : Json::parse(R"({"three_segment": {"length_m": 0.8636,
                         "handle_radius_m": 0.0125, "barrel_radius_m": 0.033,
                         "taper_start_m": 0.30, "taper_end_m": 0.55}})");
  bat["material"] = Json::parse(R"({"density_kg_m3": 2800, "youngs_modulus_pa": 7e10,
      "shear_modulus_pa": 2.6e10, "poissons_ratio": 0.33, "cor": 0.5})");
  bat["wall_thickness_m"] = 0.003;
  bat["fill"] = Json::parse(R"({"material": {"density_kg_m3": 200, "youngs_modulus_pa": 2e7},
      "diameter_m": 0.02, "depth_m": 0.1})");
  bat["end_cap"] = Json::parse(R"({"mass_kg": 0.03, "length_m": 0.01, "material": "rubber"})");
  bat["knob"] = Json::parse(R"({"mass_kg": 0.02, "length_m": 0.015})");
  bat["handle"] = Json::parse(R"({"material": "ash", "joint_from_knob_m": 0.25,
      "wall_thickness_m": 0.002})");
  Json swing = {{"angular_speed_rad_s", 40.0}, {"pivot_from_knob_m", 0.01},
                {"hands_from_knob_m", 0.15}, {"attack_angle_deg", 8.0}};
  if (bat_speed) {
    swing.erase("angular_speed_rad_s");
    swing["bat_speed_mps"] = 31.0;
    swing["bat_speed_from_tip_m"] = 0.16;
  }
  return Json{{"bat", bat},
              {"ball", {{"mass_kg", 0.145}, {"radius_m", 0.0366}, {"speed_mps", 30.0},
                        {"stiffness_n_m_p", 1e7}, {"stiffness_exponent", 1.5},
                        {"descent_angle_deg", 6.0}, {"spin_rpm", 1500.0}}},
              {"swing", swing},
              {"cor", 0.5},
              {"contact", {{"undercut_m", 0.01}}}};
}

// The request parsed as a sweep's template is (ParseBatGeometry, ReadSceneCommon).
struct Parsed {
  core::Scene scene;
  std::optional<core::ThreeSegmentShape> shape;
};
std::optional<Parsed> Parse(const Json& request, std::string* why) {
  ApiError error;
  const auto spec = ParseBatGeometry(request["bat"], "bat", ApiLimits{}, &error);
  if (!spec) {
    *why = error.message;
    return std::nullopt;
  }
  Parsed parsed;
  parsed.scene.bat = spec->bat;
  parsed.shape = spec->three_segment;
  ObjectReader reader(request, "", &error);
  if (!ReadSceneCommon(reader, &parsed.scene)) {
    *why = error.message;
    return std::nullopt;
  }
  return parsed;
}

double Get(const Field& field, Parsed* parsed) {
  FieldHost host = FieldHost::Of(&parsed->scene, parsed->shape ? &*parsed->shape : nullptr);
  host.knot = 1;
  return field.get(host);
}

// The field's path in the request with a knot's index 1.
std::string Concrete(std::string_view pattern) {
  std::string path(pattern);
  if (const std::size_t at = path.find("[]"); at != std::string::npos) path.replace(at, 2, "[1]");
  return path;
}

bool IsProfileField(const Field& field) { return field.group == FieldGroup::kKnot; }
bool IsBatSpeedField(const Field& field) {
  return field.path.rfind("swing.bat_speed", 0) == 0;
}

// Every field: set in SI and in each trade form through the parser, read back through its
// accessor; bound by the sweep's binder to the same scene the parser gives; and, when a
// variable, named by core's variable path in every form.
TEST(FieldsTest, EveryFieldRoundTripsThroughParserBinderAndOptimizeVariable) {
  ASSERT_EQ(Fields().size(), 40u);
  for (const Field& field : Fields()) {
    SCOPED_TRACE(std::string(field.path));
    const Json base = Template(IsProfileField(field), IsBatSpeedField(field));
    std::string why;
    auto parsed_base = Parse(base, &why);
    ASSERT_TRUE(parsed_base) << why;
    const double old_value = Get(field, &*parsed_base);
    const double value = old_value * 1.01;  // valid for every row of the template
    ASSERT_GE(value, field.min);
    ASSERT_LE(value, field.max);
    const std::string path = Concrete(field.path);
    const auto steps = ParseJsonPath(path, &why);
    ASSERT_TRUE(steps) << why;

    // The parser, SI.
    Json request = base;
    ASSERT_TRUE(SetNumberAtPath(&request, *steps, value, &why)) << why;
    auto parsed = Parse(request, &why);
    ASSERT_TRUE(parsed) << why;
    EXPECT_EQ(Get(field, &*parsed), value);

    // The parser, each trade form: the value in its unit, read back in SI.
    const std::string leaf = std::get<std::string>(steps->back());
    const std::string parent = path.substr(0, path.size() - leaf.size());
    for (const TradeForm& form : TradeForms(leaf)) {
      const auto use = ResolveField(parent + form.key, FieldScope::kRequest);
      if (field.swept) {
        // Every trade form of a swept field names it (a fill's diameter has no radius forms).
        if (!use) continue;
        EXPECT_EQ(use->field, &field) << form.key;
        EXPECT_EQ(use->to_si, form.to_si);
        EXPECT_EQ(use->si, path);
      }
      Json traded = base;
      Json* parent_object = &traded;
      for (std::size_t k = 0; k + 1 < steps->size(); ++k) {
        if (const auto* key = std::get_if<std::string>(&(*steps)[k])) {
          parent_object = &(*parent_object)[*key];
        } else {
          parent_object = &(*parent_object)[std::get<std::size_t>((*steps)[k])];
        }
      }
      parent_object->erase(leaf);
      (*parent_object)[form.key] = value / form.to_si;
      auto traded_parsed = Parse(traded, &why);
      ASSERT_TRUE(traded_parsed) << form.key << ": " << why;
      EXPECT_NEAR(Get(field, &*traded_parsed), value, 1e-12 * std::abs(value)) << form.key;
    }

    // The binder: the swept value bound on the template's scene is the parser's scene.
    if (field.swept) {
      SweepParameter parameter;
      parameter.path = path;
      parameter.steps = *steps;
      parameter.targets = {*steps};
      parameter.to_si = {1.0};
      RowOutputs outputs;
      outputs.scene = {core::SceneOutput::kMaxExitSpeed};
      const auto binder = DesignBinder::Compile(base, {parameter}, outputs, ApiLimits{});
      ASSERT_TRUE(binder.has_value());
      core::Scene bound = binder->base_scene();
      EXPECT_TRUE(binder->Bind({value}, &bound));
      const core::Bat& a = *bound.bat;
      const core::Bat& b = *parsed->scene.bat;
      ASSERT_EQ(a.knots.size(), b.knots.size());
      for (std::size_t k = 0; k < a.knots.size(); ++k) {
        EXPECT_EQ(a.knots[k].x_m, b.knots[k].x_m);
        EXPECT_EQ(a.knots[k].radius_m, b.knots[k].radius_m);
      }
      EXPECT_EQ(a.material.density_kg_m3, b.material.density_kg_m3);
      EXPECT_EQ(a.material.youngs_modulus_pa, b.material.youngs_modulus_pa);
      EXPECT_EQ(a.material.shear_modulus_pa, b.material.shear_modulus_pa);
      EXPECT_EQ(a.material.poissons_ratio, b.material.poissons_ratio);
      EXPECT_EQ(a.material.cor, b.material.cor);
      EXPECT_EQ(a.wall_thickness_m, b.wall_thickness_m);
      EXPECT_EQ(a.fill->diameter_m, b.fill->diameter_m);
      EXPECT_EQ(a.fill->depth_m, b.fill->depth_m);
      EXPECT_EQ(bound.ball.mass_kg, parsed->scene.ball.mass_kg);
      EXPECT_EQ(bound.ball.radius_m, parsed->scene.ball.radius_m);
      EXPECT_EQ(bound.ball.speed_mps, parsed->scene.ball.speed_mps);
      EXPECT_EQ(bound.ball.stiffness, parsed->scene.ball.stiffness);
      EXPECT_EQ(bound.ball.stiffness_exponent, parsed->scene.ball.stiffness_exponent);
      EXPECT_EQ(bound.swing.angular_speed_rad_s, parsed->scene.swing.angular_speed_rad_s);
      EXPECT_EQ(bound.swing.pivot_from_knob_m, parsed->scene.swing.pivot_from_knob_m);
      EXPECT_EQ(bound.swing.hands_from_knob_m, parsed->scene.swing.hands_from_knob_m);
      EXPECT_EQ(bound.swing.bat_speed_mps, parsed->scene.swing.bat_speed_mps);
      EXPECT_EQ(bound.swing.bat_speed_from_tip_m, parsed->scene.swing.bat_speed_from_tip_m);
      EXPECT_EQ(bound.swing.reference_moi_kg_m2, parsed->scene.swing.reference_moi_kg_m2);
      EXPECT_EQ(bound.swing.swing_weight_exponent, parsed->scene.swing.swing_weight_exponent);
      EXPECT_EQ(bound.cor, parsed->scene.cor);
    }

    // The optimiser's variable: core's path, in SI and each trade form.
    if (field.variable) {
      const std::string variable = path.substr(4);  // without "bat."
      const auto ref = core::ParseDesignVariablePath(variable);
      ASSERT_TRUE(ref.has_value()) << variable;
      EXPECT_EQ(core::DesignVariablePath(*ref), variable);
      const std::string variable_parent = variable.substr(0, variable.size() - leaf.size());
      for (const TradeForm& form : TradeForms(leaf)) {
        const auto use = ResolveField(variable_parent + form.key, FieldScope::kVariable);
        if (!use) continue;  // a fill's diameter has no radius forms
        EXPECT_EQ(use->field, &field);
        EXPECT_EQ(use->si, variable);
        EXPECT_EQ(use->to_si, form.to_si);
      }
    }
    if (!field.fit_name.empty()) {
      const auto use = ResolveField(field.fit_name, FieldScope::kFitName);
      ASSERT_TRUE(use.has_value());
      EXPECT_EQ(use->field, &field);
    }
  }
}

TEST(FieldsTest, TradeFormsResolveToTheirField) {
  const auto wall = ResolveField("wall_thickness_in", FieldScope::kVariable);
  ASSERT_TRUE(wall);
  EXPECT_EQ(wall->si, "wall_thickness_m");
  EXPECT_EQ(wall->to_si, 0.0254);
  const auto knot = ResolveField("profile.knots[3].diameter_in", FieldScope::kVariable);
  ASSERT_TRUE(knot);
  EXPECT_EQ(knot->si, "profile.knots[3].radius_m");
  EXPECT_EQ(knot->to_si, 0.0127);
  const auto fill = ResolveField("fill.diameter_in", FieldScope::kVariable);
  ASSERT_TRUE(fill);
  EXPECT_EQ(fill->si, "fill.diameter_m");
  EXPECT_EQ(fill->to_si, 0.0254);
  const auto barrel = ResolveField("barrel_diameter_in", FieldScope::kFitName);
  ASSERT_TRUE(barrel);
  EXPECT_EQ(barrel->si, "barrel_radius_m");
  const auto speed = ResolveField("ball.speed_mph", FieldScope::kRequest);
  ASSERT_TRUE(speed);
  EXPECT_EQ(speed->si, "ball.speed_mps");
  const auto bat_speed = ResolveField("swing.bat_speed_mph", FieldScope::kRequest);
  ASSERT_TRUE(bat_speed);  // bound by the sweep's binder since it is a row
  EXPECT_EQ(bat_speed->si, "swing.bat_speed_mps");
  EXPECT_TRUE(bat_speed->field->swept);
  // A knot's index as the JSON path reads it: the variable is core's, named as written.
  const auto padded = ResolveField("profile.knots[02].radius_m", FieldScope::kVariable);
  ASSERT_TRUE(padded);
  EXPECT_EQ(padded->si, "profile.knots[2].radius_m");
  EXPECT_FALSE(ResolveField("wall_thickness_oz", FieldScope::kVariable));
  EXPECT_FALSE(ResolveField("ball.speed_mps", FieldScope::kVariable));
  EXPECT_EQ(DidYouMeanField("three_segment.taper_strat_in", FieldScope::kVariable),
            " (did you mean \"three_segment.taper_start_in\"?)");
  EXPECT_EQ(DidYouMeanField("profile.knots[4].radus_m", FieldScope::kVariable),
            " (did you mean \"profile.knots[4].radius_m\"?)");
}

// Every variable core's optimiser knows is a variable row of the table (and the reverse is
// the round trip's): /v1/optimize takes its variables from the table only.
TEST(FieldsTest, EveryCoreDesignVariableIsAVariableRow) {
  for (int kind = 0; kind <= static_cast<int>(core::DesignVariableKind::kFillDensity); ++kind) {
    core::DesignVariableRef ref;
    ref.kind = static_cast<core::DesignVariableKind>(kind);
    const bool knot = ref.kind == core::DesignVariableKind::kKnotRadius ||
                      ref.kind == core::DesignVariableKind::kKnotPosition;
    ref.knot = knot ? 2 : -1;
    const std::string path = core::DesignVariablePath(ref);
    SCOPED_TRACE(path);
    const auto use = ResolveField(path, FieldScope::kVariable);
    ASSERT_TRUE(use.has_value());
    EXPECT_EQ(use->si, path);
    EXPECT_TRUE(use->field->variable);
  }
}

// The swing's numbers come from the table: each in its trade form, and exactly one of the
// angular speed and the bat speed, refused as before.
TEST(FieldsTest, SwingFromTheTableInTradeForms) {
  Json request = Template(false);
  request["swing"] = {{"bat_speed_mph", 70.0}, {"bat_speed_from_tip_in", 6.0},
                      {"pivot_from_knob_in", -1.0}, {"hands_from_knob_in", 5.0}};
  std::string why;
  const auto parsed = Parse(request, &why);
  ASSERT_TRUE(parsed) << why;
  const core::Swing& swing = parsed->scene.swing;
  ASSERT_TRUE(swing.bat_speed_mps.has_value());
  EXPECT_DOUBLE_EQ(*swing.bat_speed_mps, 70.0 * 0.44704);
  EXPECT_DOUBLE_EQ(swing.bat_speed_from_tip_m, 6.0 * 0.0254);
  EXPECT_DOUBLE_EQ(swing.pivot_from_knob_m, -0.0254);
  EXPECT_DOUBLE_EQ(swing.hands_from_knob_m, 5.0 * 0.0254);
  request["swing"] = {{"angular_speed_rad_s", 30.0}, {"bat_speed_mps", 31.0}};
  EXPECT_FALSE(Parse(request, &why));
  EXPECT_EQ(why,
            "swing.bat_speed_mps = 31.0: give exactly one of swing.bat_speed_mps and "
            "swing.angular_speed_rad_s (both are given; the bat speed sets the angular speed)");
}

// A material object's numbers come from the table: density and Young's modulus required
// without a base (the first missing one named), any of them over a base; G or nu given means
// nu is not assumed.
TEST(FieldsTest, MaterialFromTheTable) {
  Json request = Template(false);
  request["bat"]["material"] = {{"youngs_modulus_pa", 1e10}};
  std::string why;
  EXPECT_FALSE(Parse(request, &why));
  EXPECT_EQ(why, "bat.material.density_kg_m3 is required");
  request["bat"]["material"] = {{"density_kg_m3", 700.0}};
  EXPECT_FALSE(Parse(request, &why));
  EXPECT_EQ(why, "bat.material.youngs_modulus_pa is required");
  request["bat"]["material"] = {{"density_kg_m3", 700.0}, {"youngs_modulus_pa", 1e10}};
  auto parsed = Parse(request, &why);
  ASSERT_TRUE(parsed) << why;
  EXPECT_TRUE(parsed->scene.bat->material.poissons_ratio_assumed);
  EXPECT_FALSE(parsed->scene.bat->material.cor.has_value());
  request["bat"]["material"]["poissons_ratio"] = 0.3;
  parsed = Parse(request, &why);
  ASSERT_TRUE(parsed) << why;
  EXPECT_FALSE(parsed->scene.bat->material.poissons_ratio_assumed);
  request["bat"]["material"] = {{"base", "ash"}, {"cor", 0.55}};
  parsed = Parse(request, &why);
  ASSERT_TRUE(parsed) << why;
  EXPECT_EQ(parsed->scene.bat->material.cor, 0.55);
  EXPECT_FALSE(parsed->scene.bat->material.poissons_ratio_assumed);
}

// An explore column of a parameter named in a trade form ("parameters.swing.hands_from_knob_in")
// holds the swept value as written; the design is the SI sweep's (the table's row, bound by
// the binder: the same exit speeds as the sweep written in SI).
TEST(FieldsTest, ExploreColumnsOfTradeFormParameters) {
  const auto use = ResolveField("swing.hands_from_knob_in", FieldScope::kRequest);
  ASSERT_TRUE(use);
  EXPECT_EQ(use->field, FindField("swing.hands_from_knob_m"));
  const auto sweep = [](const std::string& path, double min, double max) {
    Json body = Json::parse(R"({"bat": {"preset": "wood-34-ash"}, "outputs": ["max_exit_speed"],
        "format": "csv"})");
    body["columns"] = {"parameters." + path, "max_exit_speed.exit_speed_mps"};
    body["parameters"] = Json::array({{{"path", path}, {"min", min}, {"max", max}, {"count", 2}}});
    return Post("/v1/explore", body);
  };
  const Response in = sweep("swing.hands_from_knob_in", 4.0, 8.0);
  const Response si = sweep("swing.hands_from_knob_m", 4.0 * 0.0254, 8.0 * 0.0254);
  ASSERT_EQ(in.status, 200) << in.text << in.body.dump();
  ASSERT_EQ(si.status, 200) << si.text << si.body.dump();
  std::istringstream a(in.text), b(si.text);
  std::string line_in, line_si;
  std::getline(a, line_in);
  std::getline(b, line_si);
  EXPECT_EQ(line_in, "parameters.swing.hands_from_knob_in,max_exit_speed.exit_speed_mps");
  for (double hands_in : {4.0, 8.0}) {
    ASSERT_TRUE(std::getline(a, line_in));
    ASSERT_TRUE(std::getline(b, line_si));
    EXPECT_EQ(std::stod(line_in.substr(0, line_in.find(','))), hands_in);
    EXPECT_EQ(line_in.substr(line_in.find(',')), line_si.substr(line_si.find(',')));
  }
}

Json Optimize(const Json& variable) {
  Json body = Json::parse(R"({"bat": {"three_segment": {"length_m": 0.8636,
      "handle_radius_m": 0.0125, "barrel_radius_m": 0.033, "taper_start_m": 0.30,
      "taper_end_m": 0.55}, "material": "ash"}, "constraints": {"mass_kg": {"max": 0.95}},
      "objective": "max_exit_speed", "cor": 0.5, "options": {"backend": "nlopt_slsqp"}})");
  body["variables"] = Json::array({variable});
  return body;
}

void ExpectSameOptimum(const Response& si, const Response& trade, const std::string& si_name,
                       const std::string& trade_name, double to_si) {
  ASSERT_EQ(si.status, 200) << si.body.dump();
  ASSERT_EQ(trade.status, 200) << trade.body.dump();
  const double a = si.body["objective_value"].get<double>();
  const double b = trade.body["objective_value"].get<double>();
  EXPECT_NEAR(b, a, 1e-9 * std::abs(a));
  ASSERT_TRUE(trade.body["variables"].contains(trade_name)) << trade.body["variables"].dump();
  EXPECT_FALSE(trade.body["variables"].contains(si_name));
  const double x_si = si.body["variables"][si_name].get<double>();
  const double x_trade = trade.body["variables"][trade_name].get<double>() * to_si;
  EXPECT_NEAR(x_trade, x_si, 1e-9 * std::abs(x_si));
  EXPECT_NEAR(trade.body["properties"]["mass_kg"].get<double>(),
              si.body["properties"]["mass_kg"].get<double>(), 1e-9);
}

TEST(FieldsTest, OptimizeVariableInInchesHasTheSIOptimum) {
  const Response si = Post("/v1/optimize", Optimize({{"path", "three_segment.taper_start_m"},
                                                     {"min", 4 * 0.0254},
                                                     {"max", 20 * 0.0254}}));
  const Response in = Post("/v1/optimize", Optimize({{"path", "three_segment.taper_start_in"},
                                                     {"min", 4},
                                                     {"max", 20}}));
  ExpectSameOptimum(si, in, "three_segment.taper_start_m", "three_segment.taper_start_in", 0.0254);
}

TEST(FieldsTest, OptimizeVariableAsADiameterInInchesHasTheSIOptimum) {
  const Response si = Post("/v1/optimize", Optimize({{"path", "three_segment.barrel_radius_m"},
                                                     {"min", 2.2 * 0.0127},
                                                     {"max", 2.6 * 0.0127}}));
  const Response in = Post("/v1/optimize", Optimize({{"path", "three_segment.barrel_diameter_in"},
                                                     {"min", 2.2},
                                                     {"max", 2.6}}));
  ExpectSameOptimum(si, in, "three_segment.barrel_radius_m", "three_segment.barrel_diameter_in",
                    0.0127);
}

Json Fit(const Json& unknown) {
  Json body = Json::parse(R"({"bat": {"preset": "paper-wood"},
      "targets": {"mass_kg": 0.86, "balance_point_m": 0.57}})");
  body["unknowns"] = Json::array({{{"name", "taper_start_m"}, {"min", 0.1}, {"max", 0.5}},
                                  unknown});
  return body;
}

TEST(FieldsTest, FitUnknownAsADiameterInInchesHasTheSIFit) {
  const Response si = Post("/v1/bat/fit", Fit({{"name", "barrel_radius_m"},
                                               {"min", 2.0 * 0.0127},
                                               {"max", 3.0 * 0.0127}}));
  const Response in = Post("/v1/bat/fit", Fit({{"name", "barrel_diameter_in"},
                                               {"min", 2.0},
                                               {"max", 3.0}}));
  ASSERT_EQ(si.status, in.status) << si.body.dump() << in.body.dump();
  const Json a = si.status == 200 ? si.body : si.body["closest"];
  const Json b = in.status == 200 ? in.body : in.body["closest"];
  ASSERT_TRUE(b["unknowns"].contains("barrel_diameter_in")) << b.dump();
  EXPECT_FALSE(b["unknowns"].contains("barrel_radius_m"));
  const double r_si = a["unknowns"]["barrel_radius_m"].get<double>();
  const double r_in = b["unknowns"]["barrel_diameter_in"].get<double>() * 0.0127;
  EXPECT_NEAR(r_in, r_si, 1e-9 * r_si);
  EXPECT_NEAR(b["unknowns"]["taper_start_m"].get<double>(),
              a["unknowns"]["taper_start_m"].get<double>(), 1e-9);
  EXPECT_NEAR(b["properties"]["mass_kg"].get<double>(), a["properties"]["mass_kg"].get<double>(),
              1e-9);
}

TEST(FieldsTest, DesignFitUnknownInInchesIsAccepted) {
  // The general fit (unknowns by path) goes through /v1/optimize's variables.
  const Json body = Json::parse(R"({"bat": {"preset": "bbcor-33-aluminium"},
      "targets": {"mass_oz": 30},
      "unknowns": [{"path": "wall_thickness_in", "min": 0.05, "max": 0.2}]})");
  const Response r = Post("/v1/bat/fit", body);
  ASSERT_TRUE(r.status == 200 || r.status == 422) << r.body.dump();
  const Json& answer = r.status == 200 ? r.body : r.body["closest"];
  ASSERT_TRUE(answer["unknowns"].contains("wall_thickness_in")) << answer.dump();
  const double wall_in = answer["unknowns"]["wall_thickness_in"].get<double>();
  EXPECT_GE(wall_in, 0.05);
  EXPECT_LE(wall_in, 0.2);
}

TEST(FieldsTest, ErrorsNameTheFieldAsWrittenWithTheValueInItsUnit) {
  // A bound core refuses, in the request's unit.
  Response r = Post("/v1/optimize", Optimize({{"path", "three_segment.taper_start_in"},
                                              {"min", 20},
                                              {"max", 4}}));
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "variables[0].max");
  EXPECT_EQ(r.body["message"],
            "variables[0].max = 4: must be greater than variables[0].min = 20 (in SI: 0.1016)");
  // A typo: the nearest name, as the user would write it.
  r = Post("/v1/optimize", Optimize({{"path", "three_segment.taper_strat_in"},
                                     {"min", 4},
                                     {"max", 20}}));
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "variables[0].path");
  EXPECT_NE(r.body["message"].get<std::string>().find(
                "(did you mean \"three_segment.taper_start_in\"?)"),
            std::string::npos)
      << r.body.dump();
  // A fit's unknown: its bound over the cap, in inches, named as written.
  r = Post("/v1/bat/fit", Fit({{"name", "barrel_diameter_in"}, {"min", 2}, {"max", 1e7}}));
  EXPECT_EQ(r.status, 400) << r.body.dump();
  EXPECT_EQ(r.body["field"], "unknowns[1].max");
  EXPECT_EQ(r.body["message"], "unknowns[1].max = 1e+07: must be in [0, 1e+05] (in SI: 127000)");
  r = Post("/v1/bat/fit", Fit({{"name", "barel_diameter_in"}, {"min", 2}, {"max", 3}}));
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(r.body["message"].get<std::string>().find("(did you mean \"barrel_diameter_in\"?)"),
            std::string::npos)
      << r.body.dump();
}

}  // namespace
}  // namespace fields_test
}  // namespace sweetspot::api
