// The trade's units at the API boundary (issue 19): every SI input field may be written in
// inches, ounces, mph or oz·in² with the unit in its name, and radii as diameters; and
// "report_units": "imperial" adds those units beside every SI number of an answer. Core stays
// SI: these conversions happen only here.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "api/json_path.hpp"

namespace sweetspot::api {

/// Another spelling of an SI field: its name and the factor that turns its value into the SI
/// field's (SI = value * to_si).
struct TradeForm {
  std::string key;     ///< e.g. "length_in", "barrel_diameter_in".
  double to_si = 1.0;  ///< e.g. 0.0254 (in -> m), 0.0127 (diameter in -> radius m).
};

/// The trade spellings of SI field `si_key`: "*_m" -> "*_in" (a length; not "*_n_m" or
/// "*_s_m", which are stiffness and damping); "*radius_m" also -> "*diameter_m", "*diameter_in";
/// "*_kg" -> "*_oz"; "*_mps" -> "*_mph"; "*_kg_m2" -> "*_oz_in2". Empty for any other name.
std::vector<TradeForm> TradeForms(std::string_view si_key);

/// The inverse of TradeForms: the SI fields that `key` is a trade spelling of, each with the
/// factor to it (its TradeForm's), a radius from a diameter first: "barrel_diameter_in" ->
/// {"barrel_radius_m", 0.0127}, {"barrel_diameter_m", 0.0254}; "speed_mph" -> {"speed_mps",
/// 0.44704}. Empty for a key that is no trade spelling ("length_m", "cor"). Which of several
/// is the field a given object has (a fill has "diameter_m" of its own, a knot "radius_m") is
/// the caller's to decide.
std::vector<TradeForm> SiFormsOf(std::string_view key);

/// Where `steps` leads to an SI field that its object (in *root) gives in a trade form instead
/// ("taper_start_in" for "three_segment.taper_start_m", "barrel_diameter_in" for
/// ".barrel_radius_m", "speed_mph" for "ball.speed_mps"), replaces that form by the SI field,
/// its value converted as a request's reader converts it; otherwise leaves *root as it is.
/// Used where a path is then set in SI (a swept field of /v1/explore's template, a design
/// variable written back into /v1/optimize's bat), so the object never holds two forms of one
/// quantity, which a request's reader refuses.
void TradeFormToSi(nlohmann::json* root, const std::vector<PathStep>& steps);

/// Sets the SI field at `steps` in *root to `value_si`, in the form the object gives it: where
/// the object has a trade form of it instead ("taper_start_in" for ".taper_start_m",
/// "barrel_diameter_in" for ".barrel_radius_m"), that form gets the value converted
/// (value_si / its to_si); otherwise SetNumberAtPath. So a bat written back into the request's
/// own form (/v1/optimize's answer) stays in the request's units, one form per quantity.
bool SetNumberInRequestForm(nlohmann::json* root, const std::vector<PathStep>& steps,
                            double value_si, std::string* why);

/// `block` (a shape, the fill; arrays and nested objects too) in the trade's form, as a request
/// in inches writes a bat: each length in inches, a radius as a diameter in inches, a mass in
/// ounces (TradeForms' factors); numbers with no trade form (a density, a modulus) stay.
void ToTradeForm(nlohmann::json* block);

/// Each SI number of `block` (an SI object the answer writes: a fitted three_segment) in the
/// form `request_block` (the request's object in its place) gave it: "taper_start_m" as
/// "taper_start_in" when the request wrote that, "barrel_radius_m" as "barrel_diameter_in";
/// the rest as it is. One level (the object's own numbers).
void ToFormOf(nlohmann::json* block, const nlohmann::json& request_block);

/// How an answer reports its numbers ("report_units").
enum class ReportUnits {
  kSi,        ///< SI only (the default).
  kImperial,  ///< SI, and beside each SI number its inches / ounces / mph / oz·in² form.
};

/// Adds, beside every number of `answer` whose key has an SI unit (as TradeForms reads it; not
/// "*_diameter_*"), the same quantity in the trade's unit ("length_m" -> "length_in",
/// "mass_kg" -> "mass_oz", "exit_speed_mps" -> "exit_speed_mph", "*_kg_m2" -> "*_oz_in2"), and
/// beside every position "*_from_knob_m" its distance from the barrel end in inches
/// ("*_from_tip_in"; a zone's ends "from_knob_m", "to_knob_m": "*_knob_from_tip_in") where the
/// bat's length is known (the object's own "length_m", its
/// "properties.length_m", or the nearest enclosing one's). An array of numbers (and nulls, and
/// of such arrays) gets its twin element by element, null staying null ("nodes_from_knob_m"
/// -> "nodes_from_knob_in", "nodes_from_tip_in"); a number whose unit a sibling string names
/// ("objective_value" beside "objective_unit": "mps") gets it named after itself
/// ("objective_value_mph"; a length in inches, and in feet too where the object carries a
/// "distance_sweet_spot": max_distance's carry). Lengths "distance_m", "apex_m" and those under
/// "landing" and "trajectory" (a flight's) get "_ft" twins too. An answer's "objective_unit"
/// holds for its objective's numbers anywhere under it too (the spread's "objective_min",
/// "objective_max", "objective_median", a run's "objective", a material's "objective_value"),
/// and an object's "unit" for its "value", "bound", "tolerance", "error" and "reference" (an
/// active constraint's "bound_oz"; its "multiplier", a unit per unit, is left). Keys already
/// present are kept. An
/// object under the key "bat" is left as it is: it is a request's form (optimize's, fit's
/// answer), in the units the request gave, and can be sent again as it stands.
void AddImperial(nlohmann::json* answer);
/// AddImperial, with the bat's length `length_m` where `answer` states none (a /v1/explore
/// row's output block: the row need not carry the bat's properties).
void AddImperial(nlohmann::json* answer, std::optional<double> length_m);

/// The keys AddImperial adds beside `key` of `object` (a trade unit's first, then "_ft",
/// "_from_tip_in"), as a table of rows names its columns (/v1/optimize's frontier in CSV):
/// "objective_value" beside "objective_unit": "mps" -> {"objective_value_mph"}; "mass_kg" ->
/// {"mass_oz"}; "position_from_knob_m" -> {"position_from_knob_in", "position_from_tip_in"}
/// (the last only where the bat's length is known: a caller keeps the keys its row has).
/// Empty when `object` has no `key` or `key` has no SI unit.
std::vector<std::string> ImperialTwinKeys(const nlohmann::json& object, const std::string& key);

/// Where AddImperial takes a field it adds: `key` is `si_key`'s value divided by `to_si`
/// ("exit_speed_mph" = "exit_speed_mps" / 0.44704), or, `from_tip`, the bat's length less
/// `si_key`'s value, in inches ("position_from_tip_in" = (length_m - "position_from_knob_m") /
/// 0.0254). So a reader of one number (a /v1/explore column) computes it as AddImperial does.
struct ImperialSource {
  std::string si_key;     ///< e.g. "exit_speed_mps", "position_from_knob_m".
  bool from_tip = false;  ///< The distance from the barrel end, in inches.
  double to_si = 1.0;     ///< The divisor when not from_tip.
};

/// The SI fields AddImperial could add `key` from, in the order it prefers them (a position
/// "*_from_tip_in" from "*_from_knob_m" before a "*_from_tip_m" length); the first one an
/// object has is the one. Empty when `key` is no name AddImperial adds.
std::vector<ImperialSource> ImperialSources(std::string_view key);

struct ApiError;
struct Response;

/// An error answer (a 4xx with "field" and "message") about an SI field the request gave in a
/// trade form instead, rewritten to name the field as written, with the value as written and
/// the SI value after it: core checks the ball's speed in SI ("ball.speed_mps =
/// -4.4703999999999997: must be in [0, 1000]" for "ball": {"speed_mph": -10}), the answer says
/// "ball.speed_mph = -10: must be in [0, 1000] (in SI: ball.speed_mps = -4.4703999999999997)".
/// A message that quotes no value names the field as written wherever it names it. Any other
/// answer is left as it is.
void ErrorAsWritten(const nlohmann::json& request_body, Response* response);

/// Reads and removes "report_units" ("si", the default, or "imperial") from a request body
/// (an object), so the endpoint's own reader never sees it. False with the error (field
/// report_units, the value, the rule) when it is not one of those.
bool TakeReportUnits(nlohmann::json* body, ReportUnits* units, ApiError* error);

/// Appends `warnings` to the answer's top-level "warnings" array (created when absent).
void AppendWarnings(const std::vector<std::string>& warnings, nlohmann::json* answer);

}  // namespace sweetspot::api
