// The answers to a fixed set of requests (every endpoint the api answers without a server,
// explore in every format, refusals among them) against the answers kept in tests/golden/:
// the guard of every refactoring that must not change behaviour (issue "One home for each
// output and each field": "the answers ... are byte-identical before and after").
//
// What is compared: each answer as its JSON text (sorted keys, shortest round-trip numbers;
// CSV and NDJSON line by line), its status and content type, with the values that measure
// time replaced by "<time>" (timing_s, solve_time_s, time_s and the like differ run to run).
// Strings, integers, keys and structure must be equal. Numbers must be equal too, to within
// 1e-9 relative, or exactly with SWEETSPOT_GOLDEN_EXACT=1: the kept answers were computed on
// one machine, and another CPU may take another path through glibc's libm (its FMA variants)
// and round a last bit differently, which a converged iterative solve can carry to ~1e-10;
// a refactoring on one machine is held to the bytes with SWEETSPOT_GOLDEN_EXACT=1. The
// compiler's version is not compared (the sanitizer passes are Clang's builds).
//
// SWEETSPOT_GOLDEN_UPDATE=1 writes the answers of this build for the requests that have no
// kept answer yet (a kept answer is replaced only by deleting its file first, on purpose), and
// compares the others.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "api/json_text.hpp"
#include "api/router.hpp"
#include "tests/sanitizers.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace golden_answers_test {
namespace {

using Json = nlohmann::json;

struct GoldenRequest {
  const char* name;  // the file tests/golden/<name>.txt
  const char* method;
  const char* path;
  const char* body;
};

// The fixed set. Every endpoint but the server's own (jobs, metrics: tests/server) and the
// two documents served verbatim from docs/ (openapi.json, speed-vs-error).
const std::vector<GoldenRequest>& Requests() {
  static const std::vector<GoldenRequest> requests = {
      {"health", "GET", "/health", ""},
      {"version", "GET", "/v1/version", ""},
      {"materials", "GET", "/v1/materials", ""},
      {"presets", "GET", "/v1/presets", ""},
      {"balls", "GET", "/v1/balls", ""},
      {"unknown_path", "GET", "/v1/nowhere", ""},
      {"wrong_method", "GET", "/v1/sweet-spot", ""},
      {"properties_preset", "POST", "/v1/bat/properties",
       R"({"bat": {"preset": "paper-wood"}, "inertia_model": "slender_rod"})"},
      {"properties_three_segment", "POST", "/v1/bat/properties",
       R"({"bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
           "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
           "material": "ash"}, "pivot_from_knob_m": 0.1524})"},
      {"properties_imperial_hollow_fill", "POST", "/v1/bat/properties",
       R"({"bat": {"three_segment": {"length_in": 33, "handle_diameter_in": 0.95,
           "barrel_diameter_in": 2.625, "taper_start_in": 11, "taper_end_in": 21},
           "material": "aluminium-7046", "wall_thickness_in": 0.11,
           "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.1}},
           "report_units": "imperial"})"},
      {"properties_profile", "POST", "/v1/bat/properties",
       R"({"bat": {"profile": {"knots": [{"x_m": 0, "radius_m": 0.012},
           {"x_m": 0.3, "radius_m": 0.013}, {"x_m": 0.6, "radius_m": 0.033},
           {"x_m": 0.84, "radius_m": 0.033}]}, "material": "maple"}})"},
      {"properties_typo", "POST", "/v1/bat/properties",
       R"({"bat": {"three_segment": {"lenght_in": 33, "handle_radius_m": 0.0125,
           "barrel_radius_m": 0.033, "taper_start_m": 0.3, "taper_end_m": 0.55},
           "material": "ash"}})"},
      {"properties_out_of_range", "POST", "/v1/bat/properties",
       R"({"bat": {"preset": "paper-wood"}, "pivot_from_knob_m": 1e301})"},
      {"modes", "POST", "/v1/bat/modes", R"({"bat": {"preset": "wood-34-ash"}})"},
      {"fit_taper", "POST", "/v1/bat/fit",
       R"({"bat": {"preset": "paper-wood"}, "targets": {"mass_kg": 0.95, "balance_point_m": 0.60}})"},
      {"fit_infeasible", "POST", "/v1/bat/fit",
       R"({"bat": {"preset": "paper-wood"}, "targets": {"mass_kg": 0.885, "balance_point_m": 0.564}})"},
      {"fit_density", "POST", "/v1/bat/fit",
       R"({"bat": {"preset": "wood-34-ash"}, "unknowns": [{"path": "material.density_kg_m3",
           "min": 400, "max": 900}], "targets": {"mass_oz": 30}})"},
      {"sweet_spot_default", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "wood-34-ash"}, "ball": {"preset": "mlb", "speed_mph": 90},
           "swing": {"bat_speed_mph": 70}})"},
      {"sweet_spot_closed_forms", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "paper-wood"}, "outputs": ["max_exit_speed",
           "center_of_percussion", "sweet_zone", "exit_speed_curve"],
           "options": {"curve_samples": 5}})"},
      {"sweet_spot_imperial", "POST", "/v1/sweet-spot",
       R"({"bat": {"three_segment": {"length_in": 33, "handle_diameter_in": 0.95,
           "barrel_diameter_in": 2.5, "taper_start_in": 11, "taper_end_in": 21},
           "material": "hard-maple"}, "ball": {"speed_mph": 90},
           "swing": {"angular_speed_rad_s": 40}, "report_units": "imperial"})"},
      {"sweet_spot_nlopt", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "wood-34-ash"}, "options": {"method": "nlopt"}})"},
      {"sweet_spot_hertz", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "wood-34-ash"}, "options": {"model": "hertz"}})"},
      {"sweet_spot_vibration_node", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "paper-wood"}, "outputs": ["vibration_node"]})"},
      {"sweet_spot_flexible", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "wood-34-ash"}, "options": {"model": "flexible"}})"},
      {"sweet_spot_least_sting", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "wood-34-ash"}, "outputs": ["least_sting_zone"]})"},
      {"sweet_spot_barrel_bbcor", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "bbcor-33-aluminium"}, "ball": {"preset": "ncaa-nfhs"},
           "outputs": ["barrel", "bbcor"]})"},
      {"sweet_spot_bbcor_scan", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "bbcor-33-aluminium"}, "outputs": ["bbcor", "bbcor_scan"]})"},
      {"sweet_spot_unknown_output", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "paper-wood"}, "outputs": ["carry_distance"]})"},
      {"collision_rigid", "POST", "/v1/collision",
       R"({"bat": {"preset": "wood-34-ash"}, "impact_from_knob_m": 0.70, "model": "rigid_pivot"})"},
      {"collision_free_bat", "POST", "/v1/collision",
       R"({"bat": {"preset": "bbcor-33-aluminium"}, "impact_from_knob_m": 0.70, "model": "free_bat"})"},
      {"collision_hertz", "POST", "/v1/collision",
       R"({"bat": {"preset": "wood-34-ash"}, "impact_from_knob_m": 0.70, "model": "hertz"})"},
      {"collision_flexible", "POST", "/v1/collision",
       R"({"bat": {"preset": "wood-34-ash"}, "impact_from_knob_m": 0.70, "model": "flexible"})"},
      {"flight", "POST", "/v1/flight",
       R"({"launch": {"exit_speed_mph": 103, "launch_angle_deg": 27.5, "backspin_rpm": 2500,
           "sidespin_rpm": 0}, "environment": {"temperature_f": 70, "elevation_ft": 15,
           "pressure_inhg": 29.92, "wind": {"speed_mph": 5, "direction_deg": 30}},
           "report_units": "imperial"})"},
      {"flight_launches_trajectory", "POST", "/v1/flight",
       R"({"launches": [{"exit_speed_mps": 45, "launch_angle_deg": 30, "spray_angle_deg": -15,
           "batter_hand": "left"}, {"exit_speed_mps": 35, "launch_angle_deg": 80}],
           "aero": {"model": "sawicki-2003"}, "outputs": ["trajectory"],
           "options": {"trajectory_interval_s": 0.5, "max_flight_time_s": 8}})"},
      {"flight_time_limit", "POST", "/v1/flight",
       R"({"launch": {"exit_speed_mps": 40, "launch_angle_deg": 60},
           "options": {"max_flight_time_s": 1}})"},
      {"flight_refused", "POST", "/v1/flight",
       R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 120}})"},
      {"compare", "POST", "/v1/compare",
       R"({"baseline": {"preset": "paper-wood"}, "variants": [{"name": "cork-320",
           "bat": {"preset": "paper-wood", "fill": {"material": {"density_kg_m3": 320,
           "youngs_modulus_pa": 2e7}, "diameter_m": 0.0254, "depth_m": 0.254}}}]})"},
      {"compare_swing_weight", "POST", "/v1/compare",
       R"({"baseline": {"preset": "wood-34-ash"}, "variants": [{"name": "alloy",
           "bat": {"preset": "bbcor-33-aluminium"}}], "ball": {"preset": "mlb", "speed_mph": 90},
           "swing": {"bat_speed_mph": 70, "speed_model": "swing_weight",
           "bat_speed_from_tip_m": "sweet_spot"}, "outputs": ["max_exit_speed"],
           "report_units": "imperial"})"},
      {"explore_json", "POST", "/v1/explore",
       R"({"bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
           "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
           "material": "ash"}, "outputs": ["max_exit_speed", "properties"],
           "pareto": {"objectives": [{"output": "max_exit_speed.exit_speed_mps", "sense": "max"},
                                     {"output": "properties.moi_six_inch_kg_m2", "sense": "min"}]},
           "parameters": [{"path": "cor", "min": 0.4, "max": 0.6, "count": 3},
                          {"path": "three_segment.barrel_radius_m", "min": 0.03,
                           "max": 0.035, "count": 2}]})"},
      {"explore_ndjson_hertz", "POST", "/v1/explore",
       R"({"bat": {"preset": "wood-34-ash"}, "outputs": ["max_exit_speed"],
           "options": {"model": "hertz"}, "format": "ndjson",
           "parameters": [{"path": "ball.speed_mps", "min": 30, "max": 40, "count": 3}]})"},
      {"explore_csv_columns", "POST", "/v1/explore",
       R"({"bat": {"preset": "paper-wood", "fill": {"material": "cork",
           "diameter_m": 0.0254, "depth_m": 0.254}}, "outputs": ["max_exit_speed",
           "properties"], "format": "csv",
           "columns": ["parameters.fill.depth_m", "max_exit_speed.position_from_knob_m",
                       "properties.mass_kg"],
           "parameters": [{"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": 4}]})"},
      {"explore_random_imperial", "POST", "/v1/explore",
       R"({"bat": {"preset": "wood-34-ash"}, "outputs": ["max_exit_speed"],
           "report_units": "imperial", "sampling": "lhs", "samples": 4, "seed": 7,
           "parameters": [{"path": "ball.speed_mph", "min": 80, "max": 95},
                          {"path": "swing.bat_speed_mph", "min": 60, "max": 75}]})"},
      {"optimize_ipopt", "POST", "/v1/optimize",
       R"({"bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
           "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
           "material": "ash"},
           "variables": [{"path": "three_segment.taper_start_m", "min": 0.1, "max": 0.5},
                         {"path": "three_segment.barrel_radius_m", "min": 0.028, "max": 0.0331}],
           "constraints": {"mass_kg": 0.88, "balance_point_m": {"min": 0.56, "max": 0.60},
                           "moi_six_inch_kg_m2": {"max": 0.20}, "rules": "mlb-wood"},
           "objective": "max_exit_speed", "cor": 0.5})"},
      {"optimize_slsqp", "POST", "/v1/optimize",
       R"({"bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
           "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
           "material": "ash"},
           "variables": [{"path": "three_segment.taper_start_m", "min": 0.1, "max": 0.5}],
           "constraints": {"mass_kg": {"max": 0.95}},
           "objective": "max_exit_speed", "cor": 0.5, "options": {"backend": "nlopt_slsqp"}})"},
      {"optimize_bad_variable", "POST", "/v1/optimize",
       R"({"bat": {"preset": "wood-34-ash"},
           "variables": [{"path": "wall_thickness_in", "min": 0.05, "max": 0.2}],
           "objective": "max_exit_speed"})"},
      // Issue 33, item 2: variables and unknowns in the trade's units, and their errors.
      {"optimize_trade_variables", "POST", "/v1/optimize",
       R"({"bat": {"three_segment": {"length_in": 34, "handle_diameter_in": 0.95,
           "barrel_diameter_in": 2.6, "taper_start_in": 12, "taper_end_in": 22},
           "material": "ash"},
           "variables": [{"path": "three_segment.taper_start_in", "min": 4, "max": 20},
                         {"path": "three_segment.barrel_diameter_in", "min": 2.2, "max": 2.6}],
           "constraints": {"mass_oz": {"max": 33}},
           "objective": "max_exit_speed", "cor": 0.5, "options": {"backend": "nlopt_slsqp"}})"},
      {"optimize_trade_variable_typo", "POST", "/v1/optimize",
       R"({"bat": {"preset": "wood-34-ash"},
           "variables": [{"path": "profile.knots[3].diamter_in", "min": 2, "max": 2.6}],
           "objective": "max_exit_speed"})"},
      {"optimize_trade_bounds_refused", "POST", "/v1/optimize",
       R"({"bat": {"preset": "wood-34-ash"},
           "variables": [{"path": "profile.knots[3].diameter_in", "min": 2.6, "max": 2}],
           "objective": "max_exit_speed"})"},
      {"fit_trade_unknowns", "POST", "/v1/bat/fit",
       R"({"bat": {"preset": "paper-wood"}, "targets": {"mass_oz": 31, "balance_point_in": 23},
           "unknowns": [{"name": "taper_start_in", "min": 4, "max": 20},
                        {"name": "barrel_diameter_in", "min": 2, "max": 3}]})"},
      {"fit_trade_unknown_typo", "POST", "/v1/bat/fit",
       R"({"bat": {"preset": "paper-wood"}, "targets": {"mass_kg": 0.9},
           "unknowns": [{"name": "barel_diameter_in", "min": 2, "max": 3}]})"},
      // Issue 33, item 2: the material's, the wall's, the knots' and the swing's numbers read
      // from the table of fields, in the trade's units, and their refusals.
      {"properties_profile_trade", "POST", "/v1/bat/properties",
       R"({"bat": {"profile": {"knots": [{"x_in": 0, "diameter_in": 1.0},
           {"x_in": 12, "diameter_in": 1.0}, {"x_in": 24, "diameter_in": 2.6},
           {"x_in": 33, "diameter_in": 2.6}]},
           "material": {"base": "aluminium-7046", "density_kg_m3": 2800, "cor": 0.55},
           "wall_thickness_in": 0.1, "fill": {"material": "cork", "diameter_in": 1,
           "depth_in": 6}}, "report_units": "imperial"})"},
      {"properties_material_missing", "POST", "/v1/bat/properties",
       R"({"bat": {"preset": "paper-wood", "material": {"youngs_modulus_pa": 1e10}}})"},
      {"sweet_spot_swing_trade", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "wood-34-ash"}, "ball": {"preset": "mlb", "speed_mph": 85},
           "swing": {"bat_speed_mph": 72, "bat_speed_from_tip_in": 5,
                     "pivot_from_knob_in": -2, "hands_from_knob_in": 4},
           "outputs": ["max_exit_speed", "center_of_percussion"]})"},
      {"sweet_spot_batted_ball", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "wood-34-ash"}, "ball": {"preset": "mlb", "speed_mph": 90,
           "descent_angle_deg": 6, "spin_rpm": 2200},
           "swing": {"bat_speed_mph": 70, "attack_angle_deg": 10},
           "contact": {"undercut_in": 0.5}, "options": {"model": "free_bat"},
           "outputs": ["max_exit_speed", "batted_ball"], "report_units": "imperial"})"},
      {"sweet_spot_distance_sweet_spot", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "wood-34-ash"}, "ball": {"preset": "mlb", "speed_mph": 90,
           "descent_angle_deg": 6, "spin_rpm": 2200},
           "swing": {"bat_speed_mph": 70, "attack_angle_deg": 10},
           "environment": {"temperature_f": 85, "elevation_ft": 1000},
           "options": {"model": "free_bat"},
           "outputs": ["distance_sweet_spot"], "report_units": "imperial"})"},
      {"sweet_spot_carry_map", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "wood-34-ash"}, "ball": {"preset": "mlb", "speed_mph": 90,
           "descent_angle_deg": 6},
           "swing": {"bat_speed_mph": 70, "attack_angle_deg": 10},
           "options": {"model": "free_bat", "distance": {"map_positions": 4,
                       "map_undercuts": 3, "undercut_min_m": 0, "undercut_max_m": 0.03}},
           "outputs": ["carry_map"]})"},
      {"collision_batted_ball", "POST", "/v1/collision",
       R"({"bat": {"preset": "wood-34-ash"}, "ball": {"preset": "mlb", "speed_mph": 90,
           "descent_angle_deg": 6}, "swing": {"bat_speed_mph": 70, "attack_angle_deg": 10},
           "contact": {"undercut_in": 0.75}, "aero": {"model": "vacuum"},
           "model": "free_bat", "impact_from_knob_in": 28, "outputs": ["batted_ball"]})"},
      {"sweet_spot_swing_both_speeds", "POST", "/v1/sweet-spot",
       R"({"bat": {"preset": "wood-34-ash"},
           "swing": {"angular_speed_rad_s": 30, "bat_speed_mph": 72}})"},
      {"explore_swing_trade_columns", "POST", "/v1/explore",
       R"({"bat": {"preset": "wood-34-ash"}, "outputs": ["max_exit_speed"], "format": "csv",
           "columns": ["parameters.swing.hands_from_knob_in", "parameters.ball.speed_mph",
                       "max_exit_speed.exit_speed_mph"],
           "parameters": [{"path": "swing.hands_from_knob_in", "min": 4, "max": 8, "count": 2},
                          {"path": "ball.speed_mph", "min": 80, "max": 90, "count": 2}]})"},
      // Issue 33, item 2: report_units imperial everywhere: a mode's nodes (arrays) from the
      // knob and the tip, optimize's objective_value_mph, a preset's design in diameters.
      {"modes_imperial", "POST", "/v1/bat/modes",
       R"({"bat": {"preset": "wood-34-ash"}, "modes": 2, "shape_samples": 3,
           "report_units": "imperial"})"},
      {"optimize_preset_diameters_imperial", "POST", "/v1/optimize",
       R"({"bat": {"preset": "wood-34-ash"},
           "variables": [{"path": "profile.knots[9].diameter_in", "min": 1.0, "max": 2.65}],
           "constraints": {"mass_oz": {"max": 32}}, "objective": "max_exit_speed", "cor": 0.5,
           "options": {"backend": "nlopt_slsqp"}, "report_units": "imperial"})"},
  };
  return requests;
}

// True for the keys whose values measure time (they differ from run to run).
bool IsTimeKey(const std::string& key) {
  return key == "timing_s" || key == "solve_time_s" || key == "time_s" ||
         key == "cpu_time_s" || key == "wall_time_s" || key == "elapsed_s";
}

// `value` with every time value replaced by "<time>", and the compiler's version (GCC in
// the Release pass, Clang in the sanitizer passes) by "<compiler>".
Json WithoutTimes(Json value) {
  if (value.is_object()) {
    for (auto it = value.begin(); it != value.end(); ++it) {
      it.value() = IsTimeKey(it.key())      ? Json("<time>")
                   : it.key() == "compiler" ? Json("<compiler>")
                                            : WithoutTimes(it.value());
    }
  } else if (value.is_array()) {
    for (Json& element : value) element = WithoutTimes(element);
  }
  return value;
}

// One line of text per JSON value or CSV row: status, content type, then the body.
std::string Render(const Response& response) {
  std::ostringstream out;
  out << "status " << response.status << "\ncontent_type "
      << (response.content_type.empty() ? "application/json" : response.content_type) << "\n";
  if (response.content_type.empty()) {
    out << WithoutTimes(response.body).dump(1, ' ', false, Json::error_handler_t::replace)
        << "\n";
    return out.str();
  }
  std::istringstream lines(response.text);
  for (std::string line; std::getline(lines, line);) {
    const Json parsed = Json::parse(line, nullptr, false);
    out << (parsed.is_discarded() ? line : WithoutTimes(parsed).dump()) << "\n";
  }
  return out.str();
}

std::filesystem::path GoldenFile(const std::string& name) {
  return std::filesystem::path(SWEETSPOT_SOURCE_DIR) / "tests" / "golden" / (name + ".txt");
}

// Compares two JSON values: structure, keys, strings and integers exactly, numbers to within
// `relative` (0: exactly). Appends the first difference's path to *where.
bool Same(const Json& expected, const Json& actual, double relative, const std::string& at,
          std::string* where) {
  if (expected.is_number_float() || actual.is_number_float()) {
    if (!expected.is_number() || !actual.is_number()) {
      *where = at;
      return false;
    }
    const double e = expected.get<double>(), a = actual.get<double>();
    if (e == a || std::abs(e - a) <= relative * std::max(std::abs(e), std::abs(a))) return true;
    *where = at + ": " + expected.dump() + " != " + actual.dump();
    return false;
  }
  if (expected.type() != actual.type()) {
    *where = at + ": " + expected.dump().substr(0, 80) + " != " + actual.dump().substr(0, 80);
    return false;
  }
  if (expected.is_object()) {
    if (expected.size() != actual.size()) {
      *where = at + ": keys differ";
      return false;
    }
    for (auto it = expected.begin(); it != expected.end(); ++it) {
      if (!actual.contains(it.key())) {
        *where = at + "/" + it.key() + ": missing";
        return false;
      }
      if (!Same(it.value(), actual.at(it.key()), relative, at + "/" + it.key(), where)) {
        return false;
      }
    }
    return true;
  }
  if (expected.is_array()) {
    if (expected.size() != actual.size()) {
      *where = at + ": " + std::to_string(expected.size()) + " != " +
               std::to_string(actual.size()) + " elements";
      return false;
    }
    for (std::size_t i = 0; i < expected.size(); ++i) {
      if (!Same(expected[i], actual[i], relative, at + "/" + std::to_string(i), where)) {
        return false;
      }
    }
    return true;
  }
  if (expected != actual) {
    *where = at + ": " + expected.dump().substr(0, 120) + " != " + actual.dump().substr(0, 120);
    return false;
  }
  return true;
}

// The kept text and the new one, line by line: a line that is JSON on both sides is compared
// with Same, any other line exactly.
bool SameText(const std::string& expected, const std::string& actual, double relative,
              std::string* where) {
  if (relative == 0) {
    if (expected == actual) return true;
    *where = "the bytes differ";
    return false;
  }
  std::istringstream e_lines(expected), a_lines(actual);
  std::string e_line, a_line;
  // The JSON body of a json answer spans many lines: gather everything after the two
  // header lines and compare it as one value when it parses.
  std::vector<std::string> e_all, a_all;
  while (std::getline(e_lines, e_line)) e_all.push_back(e_line);
  while (std::getline(a_lines, a_line)) a_all.push_back(a_line);
  if (e_all.size() < 2 || a_all.size() < 2 || e_all[0] != a_all[0] || e_all[1] != a_all[1]) {
    *where = "status or content type";
    return false;
  }
  const auto join = [](const std::vector<std::string>& lines) {
    std::string out;
    for (std::size_t i = 2; i < lines.size(); ++i) out += lines[i] + "\n";
    return out;
  };
  const Json e_json = Json::parse(join(e_all), nullptr, false);
  const Json a_json = Json::parse(join(a_all), nullptr, false);
  if (!e_json.is_discarded() && !a_json.is_discarded()) {
    return Same(e_json, a_json, relative, "", where);
  }
  if (e_all.size() != a_all.size()) {
    *where = "line count";
    return false;
  }
  for (std::size_t i = 2; i < e_all.size(); ++i) {
    const Json e = Json::parse(e_all[i], nullptr, false);
    const Json a = Json::parse(a_all[i], nullptr, false);
    const bool ok = !e.is_discarded() && !a.is_discarded()
                        ? Same(e, a, relative, "line " + std::to_string(i), where)
                        : e_all[i] == a_all[i];
    if (!ok) {
      if (where->empty()) *where = "line " + std::to_string(i) + ": " + e_all[i];
      return false;
    }
  }
  return true;
}

TEST(GoldenAnswersTest, EveryAnswerIsTheKeptOne) {
  const bool update = std::getenv("SWEETSPOT_GOLDEN_UPDATE") != nullptr;
  const bool exact = std::getenv("SWEETSPOT_GOLDEN_EXACT") != nullptr;
  // 1e-9 relative: see the file's head (a last bit of libm, carried by a converged solve).
  // The sanitizer passes are Clang's builds at -O2 (the kept answers GCC's at -O3): another
  // compiler may order a sum otherwise; 1e-6 still fails any change of model or formula.
  const double relative = exact ? 0.0 : (SWEETSPOT_UNDER_ASAN || SWEETSPOT_UNDER_TSAN) ? 1e-6 : 1e-9;
  Context context;
  context.explore_threads = 1;
  int compared = 0;
  for (const GoldenRequest& r : Requests()) {
    const std::string text = Render(Dispatch({r.method, r.path, r.body}, context));
    const std::filesystem::path file = GoldenFile(r.name);
    if (update && !std::filesystem::exists(file)) {
      // A new request's answer only: a kept answer changes by deleting it first, on purpose.
      std::filesystem::create_directories(file.parent_path());
      std::ofstream(file) << text;
      continue;
    }
    std::ifstream in(file);
    ASSERT_TRUE(in) << "no kept answer " << file << " (SWEETSPOT_GOLDEN_UPDATE=1 writes it)";
    std::stringstream kept;
    kept << in.rdbuf();
    std::string where;
    EXPECT_TRUE(SameText(kept.str(), text, relative, &where))
        << r.name << " (" << r.method << " " << r.path << ") differs at " << where
        << "\nnow:\n"
        << text.substr(0, 2000);
    ++compared;
  }
  if (!update) {
    EXPECT_EQ(compared, static_cast<int>(Requests().size()));
  }
}

// The answers written as text (Context::answer_text, the server's) are the bytes of the trees
// the same requests give without it (the CLI's, the jobs'), for every request of the fixed set
// that has a text writer, the time values aside: JsonWriter's sorting, numbers and strings
// against nlohmann's.
TEST(GoldenAnswersTest, AnswersWrittenAsTextAreTheTreesBytes) {
  // The time values measured twice differ: each is replaced by 0 in both texts.
  const std::regex times(
      "\"(timing_s|solve_time_s|time_s|cpu_time_s|wall_time_s|elapsed_s)\":[-+.0-9eE]+");
  auto without_times = [&](const std::string& text) {
    return std::regex_replace(text, times, "\"$1\":0");
  };
  Context tree_context;
  tree_context.explore_threads = 1;
  Context text_context = tree_context;
  text_context.answer_text = true;
  int written = 0;
  for (const GoldenRequest& r : Requests()) {
    const Response tree = Dispatch({r.method, r.path, r.body}, tree_context);
    const Response text = Dispatch({r.method, r.path, r.body}, text_context);
    EXPECT_EQ(tree.status, text.status) << r.name;
    if (text.json_text.empty()) {  // no text writer (or a refusal): the same tree
      EXPECT_EQ(WithoutTimes(tree.body), WithoutTimes(text.body)) << r.name;
      continue;
    }
    EXPECT_TRUE(text.body.is_null()) << r.name;
    EXPECT_TRUE(tree.json_text.empty()) << r.name;
    std::string tree_text;
    AppendJson(tree.body, &tree_text);
    EXPECT_EQ(without_times(tree_text), without_times(text.json_text)) << r.name;
    ++written;
  }
  // The answers in SI with a usable result of the endpoints with a text writer (the fixed set
  // has 11 of /v1/sweet-spot and 3 of /v1/bat/properties): a test that compared nothing would
  // pass.
  EXPECT_GE(written, 14);
}

}  // namespace
}  // namespace golden_answers_test
}  // namespace sweetspot::api
