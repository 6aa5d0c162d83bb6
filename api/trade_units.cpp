#include "api/trade_units.hpp"

#include <optional>
#include <utility>

#include "api/json_path.hpp"
#include "api/json_reader.hpp"
#include "api/response.hpp"
#include "core/geometry_format.hpp"
#include "core/units.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

constexpr double kMetresPerSecondPerMph = 0.44704;  // exact: 1609.344 m / 3600 s
constexpr double kKgM2PerOzIn2 =
    core::kKilogramsPerOunce * core::kMetresPerInch * core::kMetresPerInch;

bool EndsWith(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

// A unit suffix of an SI name and its trade form.
struct UnitRule {
  std::string_view si;     // "_kg_m2"
  std::string_view trade;  // "_oz_in2"
  double to_si;            // trade value * to_si = SI value
};

// Longest suffixes first: "_kg_m2" before "_m2"-like endings, "_mps" before "_s".
constexpr UnitRule kRules[] = {
    {"_kg_m2", "_oz_in2", kKgM2PerOzIn2},
    {"_mps", "_mph", kMetresPerSecondPerMph},
    {"_kg", "_oz", core::kKilogramsPerOunce},
    {"_m", "_in", core::kMetresPerInch},
};

// The rule of `key`'s SI unit, or nullptr.
const UnitRule* RuleOf(std::string_view key) {
  // Stiffness (N/m) and damping (N·s/m) end in "_m" but are not lengths.
  if (EndsWith(key, "_n_m") || EndsWith(key, "_s_m")) return nullptr;
  // A mode shape's scale per square root of a mass (1/sqrt(kg)) is no mass.
  if (EndsWith(key, "_sqrt_kg")) return nullptr;
  for (const UnitRule& rule : kRules) {
    if (EndsWith(key, rule.si) && key.size() > rule.si.size()) return &rule;
  }
  return nullptr;
}

// The bat length an object states: its own "length_m", or its "properties.length_m".
std::optional<double> LengthOf(const Json& object) {
  if (const auto it = object.find("length_m"); it != object.end() && it->is_number()) {
    return it->get<double>();
  }
  if (const auto p = object.find("properties"); p != object.end() && p->is_object()) {
    if (const auto it = p->find("length_m"); it != p->end() && it->is_number()) {
      return it->get<double>();
    }
  }
  return std::nullopt;
}

// A flight's lengths are read in feet too (/v1/flight: "distance_m" -> "distance_ft", and every
// length of its "landing" and "trajectory"); nothing else in an answer has these keys.
bool IsFlightLength(std::string_view base) { return base == "distance" || base == "apex"; }

// A number, or an array of numbers (and nulls, and such arrays: a mode's nodes, a carry map's
// rows), each element passed through `f`; null stays null. Nullopt for anything else.
template <class F>
std::optional<Json> MapNumbers(const Json& value, const F& f) {
  if (value.is_number()) return Json(f(value.get<double>()));
  if (!value.is_array()) return std::nullopt;
  Json out = Json::array();
  for (const Json& item : value) {
    if (item.is_null()) {
      out.push_back(nullptr);
    } else if (auto mapped = MapNumbers(item, f)) {
      out.push_back(std::move(*mapped));
    } else {
      return std::nullopt;  // an array of objects: walked as a structure instead
    }
  }
  return out;
}

// The rule of a number whose unit is its sibling's string rather than its name's suffix
// ("objective_value" beside "objective_unit": "mps"), or nullptr.
const UnitRule* SiblingUnitRule(const Json& node, std::string_view key) {
  constexpr std::string_view kValue = "_value";
  if (!EndsWith(key, kValue) || key.size() <= kValue.size()) return nullptr;
  const std::string unit_key = std::string(key.substr(0, key.size() - kValue.size())) + "_unit";
  const auto it = node.find(unit_key);
  if (it == node.end() || !it->is_string()) return nullptr;
  // The unit as a name's suffix: "mps" -> "x_mps", whose rule is "_mps" -> "_mph".
  return RuleOf("x_" + it->get<std::string>());
}

// The unit an enclosing object gives its objective's numbers: an answer's "objective_unit"
// holds for "objective_value" beside it and for the objective's values anywhere under it (the
// spread's "objective_min", a run's "objective", a material's "objective_value"); `carry`: the
// objective is max_distance's carry (the answer has a "distance_sweet_spot"), in feet too.
struct ObjectiveUnit {
  const UnitRule* rule = nullptr;
  bool carry = false;
};

bool IsObjectiveKey(std::string_view key) {
  return key == "objective" || key == "objective_value" || key == "objective_min" ||
         key == "objective_max" || key == "objective_median";
}

// The rule of a number whose unit a sibling "unit" string names (an active constraint's
// "value", "bound" and "tolerance" beside "unit": "kg"; an error row's "error" and
// "reference"), or nullptr. Its multiplier (the
// objective's unit per the constraint's) is not converted.
const UnitRule* UnitSiblingRule(const Json& node, std::string_view key) {
  if (key != "value" && key != "bound" && key != "tolerance" && key != "error" &&
      key != "reference") {
    return nullptr;
  }
  const auto it = node.find("unit");
  if (it == node.end() || !it->is_string()) return nullptr;
  return RuleOf("x_" + it->get<std::string>());
}

// The twins AddImperial adds beside `key` (its `value`) in `node`, in order: the trade unit's
// ("_in", "_oz", "_mph", "_oz_in2"), a flight length's or carry's "_ft", and a position's
// "_from_tip_in" where the bat's length is known. Empty for a key without an SI unit.
std::vector<std::pair<std::string, Json>> TwinsOf(const Json& node, const std::string& key,
                                                  const Json& value,
                                                  std::optional<double> length_m, bool feet,
                                                  ObjectiveUnit objective) {
  std::vector<std::pair<std::string, Json>> added;
  const UnitRule* rule = RuleOf(key);
  std::string base;
  bool carry = IsFlightLength(key.substr(0, key.size() - (rule ? rule->si.size() : 0)));
  if (rule != nullptr) {
    base = key.substr(0, key.size() - rule->si.size());
  } else if ((rule = SiblingUnitRule(node, key)) != nullptr) {
    // "objective_value" in "objective_unit" -> "objective_value_mph"; max_distance's
    // objective (the answer carries its distance_sweet_spot) is a carry: in feet too.
    base = key;
    carry = node.contains("distance_sweet_spot");
  } else if ((rule = UnitSiblingRule(node, key)) != nullptr) {
    base = key;  // an active constraint's "bound" in "unit": "kg" -> "bound_oz"
  } else if (objective.rule != nullptr && IsObjectiveKey(key)) {
    rule = objective.rule;  // the spread's "objective_max" -> "objective_max_mph"
    base = key;
    carry = objective.carry;
  } else {
    return added;
  }
  const double to_si = rule->to_si;
  const auto twin = MapNumbers(value, [to_si](double si) { return si / to_si; });
  if (!twin) return added;
  added.emplace_back(base + std::string(rule->trade), *twin);
  if (rule->trade == "_in" && (feet || carry)) {
    const auto in_feet = [](double si) { return si / (12.0 * core::kMetresPerInch); };
    added.emplace_back(base + "_ft", *MapNumbers(value, in_feet));
  }
  if (rule->trade != "_in" || !length_m) return added;
  const auto from_tip = [length = *length_m](double si) {
    return (length - si) / core::kMetresPerInch;
  };
  if (EndsWith(base, "_from_knob")) {
    const std::string stem = base.substr(0, base.size() - std::string_view("_from_knob").size());
    added.emplace_back(stem + "_from_tip_in", *MapNumbers(value, from_tip));
  } else if (EndsWith(base, "_knob")) {
    // A zone's ends ("from_knob_m", "to_knob_m" of sweet_zone): each end from the tip too.
    added.emplace_back(base + "_from_tip_in", *MapNumbers(value, from_tip));
  }
  return added;
}

void AddImperialTo(Json* node, std::optional<double> length_m, bool feet = false,
                   ObjectiveUnit objective = {}) {
  if (node->is_array()) {
    for (Json& item : *node) AddImperialTo(&item, length_m, feet, objective);
    return;
  }
  if (!node->is_object()) return;
  if (const auto own = LengthOf(*node)) length_m = own;
  const ObjectiveUnit here = objective;  // this object's own objective_value: SiblingUnitRule
  if (const auto unit = node->find("objective_unit"); unit != node->end() && unit->is_string()) {
    objective = {RuleOf("x_" + unit->get<std::string>()), node->contains("distance_sweet_spot")};
  }
  std::vector<std::pair<std::string, Json>> added;
  for (auto& [key, value] : node->items()) {
    if (value.is_structured() && !MapNumbers(value, [](double x) { return x; })) {
      // A "bat" is the request's own form (optimize, fit): a request again as it stands, so
      // one form per quantity, as the request gave it.
      if (key != "bat") {
        AddImperialTo(&value, length_m, key == "landing" || key == "trajectory", objective);
      }
      continue;
    }
    for (auto& twin : TwinsOf(*node, key, value, length_m, feet, here)) {
      added.push_back(std::move(twin));
    }
  }
  for (auto& [key, value] : added) {
    if (!node->contains(key)) (*node)[key] = value;
  }
}

// The object holding the last step of `steps` in *root (the field's parent), or nullptr
// when the path does not lead to one.
Json* TradeFieldParent(Json* root, const std::vector<PathStep>& steps) {
  Json* node = root;
  for (std::size_t k = 0; k + 1 < steps.size(); ++k) {
    if (const auto* key = std::get_if<std::string>(&steps[k])) {
      if (!node->is_object() || !node->contains(*key)) return nullptr;
      node = &(*node)[*key];
    } else {
      const std::size_t index = std::get<std::size_t>(steps[k]);
      if (!node->is_array() || index >= node->size()) return nullptr;
      node = &(*node)[index];
    }
  }
  return node->is_object() ? node : nullptr;
}

// Where an object gives the SI field at `steps` in a trade form instead: its parent, the form
// and its number (value null when the path leads to no object, the object has the SI field,
// or it has none of its trade forms as a number).
struct TradeFieldAt {
  Json* parent = nullptr;
  TradeForm form;
  Json* value = nullptr;
};
TradeFieldAt FindTradeField(Json* root, const std::vector<PathStep>& steps) {
  TradeFieldAt at;
  const auto* leaf = steps.empty() ? nullptr : std::get_if<std::string>(&steps.back());
  at.parent = leaf != nullptr ? TradeFieldParent(root, steps) : nullptr;
  if (at.parent == nullptr || at.parent->contains(*leaf)) return at;
  for (const TradeForm& form : TradeForms(*leaf)) {
    const auto it = at.parent->find(form.key);
    if (it == at.parent->end() || !it->is_number()) continue;
    at.form = form;
    at.value = &*it;
    return at;
  }
  return at;
}

}  // namespace

bool SetNumberInRequestForm(nlohmann::json* root, const std::vector<PathStep>& steps,
                            double value_si, std::string* why) {
  const TradeFieldAt at = FindTradeField(root, steps);
  if (at.value != nullptr) {
    *at.value = value_si / at.form.to_si;  // the form the request gave, e.g. "taper_start_in"
    return true;
  }
  return SetNumberAtPath(root, steps, value_si, why);
}

void TradeFormToSi(nlohmann::json* root, const std::vector<PathStep>& steps) {
  const TradeFieldAt at = FindTradeField(root, steps);
  if (at.value == nullptr) return;
  const double si = at.value->get<double>() * at.form.to_si;
  at.parent->erase(at.form.key);  // the object was checked: at most one form of the quantity
  (*at.parent)[*std::get_if<std::string>(&steps.back())] = si;
}

std::vector<TradeForm> TradeForms(std::string_view si_key) {
  std::vector<TradeForm> out;
  const UnitRule* rule = RuleOf(si_key);
  if (rule == nullptr) return out;
  const std::string_view base = si_key.substr(0, si_key.size() - rule->si.size());
  out.push_back({std::string(base) + std::string(rule->trade), rule->to_si});
  if (rule->si == "_m" && EndsWith(base, "radius")) {
    // A radius may be given as a diameter, in metres or inches.
    const std::string stem =
        std::string(base.substr(0, base.size() - std::string_view("radius").size())) + "diameter";
    out.push_back({stem + "_m", 0.5});
    out.push_back({stem + "_in", 0.5 * core::kMetresPerInch});
  }
  return out;
}

std::vector<TradeForm> SiFormsOf(std::string_view key) {
  std::vector<std::string> candidates;
  for (const std::string_view suffix :
       {std::string_view("diameter_m"), std::string_view("diameter_in")}) {
    if (EndsWith(key, suffix)) {
      candidates.push_back(std::string(key.substr(0, key.size() - suffix.size())) + "radius_m");
    }
  }
  for (const UnitRule& rule : kRules) {
    if (EndsWith(key, rule.trade) && key.size() > rule.trade.size()) {
      candidates.push_back(std::string(key.substr(0, key.size() - rule.trade.size())) +
                           std::string(rule.si));
    }
  }
  std::vector<TradeForm> out;
  for (const std::string& si : candidates) {
    for (const TradeForm& form : TradeForms(si)) {
      if (form.key == key) out.push_back({si, form.to_si});
    }
  }
  return out;
}

void AddImperial(Json* answer) { AddImperialTo(answer, std::nullopt); }

std::vector<std::string> ImperialTwinKeys(const Json& object, const std::string& key) {
  std::vector<std::string> keys;
  const auto it = object.find(key);
  if (it == object.end()) return keys;
  // Any length gives the names; the values are not kept.
  for (auto& twin : TwinsOf(object, key, *it, 0.0, false, {})) keys.push_back(twin.first);
  return keys;
}

void AddImperial(Json* answer, std::optional<double> length_m) { AddImperialTo(answer, length_m); }

void ToTradeForm(Json* block) {
  if (block->is_array()) {
    for (Json& item : *block) ToTradeForm(&item);
    return;
  }
  if (!block->is_object()) return;
  Json out = Json::object();
  for (auto& [key, value] : block->items()) {
    const std::vector<TradeForm> forms = TradeForms(key);
    if (!value.is_number() || forms.empty()) {
      ToTradeForm(&value);
      out[key] = std::move(value);
      continue;
    }
    const TradeForm& form = forms.back();  // a radius: "diameter_in"; else the one form
    out[form.key] = value.get<double>() / form.to_si;
  }
  *block = std::move(out);
}

void ToFormOf(Json* block, const Json& request_block) {
  if (!block->is_object() || !request_block.is_object()) return;
  Json out = Json::object();
  for (auto& [key, value] : block->items()) {
    if (value.is_number() && !request_block.contains(key)) {
      bool written = false;
      for (const TradeForm& form : TradeForms(key)) {
        if (!request_block.contains(form.key)) continue;
        out[form.key] = value.get<double>() / form.to_si;
        written = true;
        break;
      }
      if (written) continue;
    }
    out[key] = std::move(value);
  }
  *block = std::move(out);
}

std::vector<ImperialSource> ImperialSources(std::string_view key) {
  std::vector<ImperialSource> out;
  constexpr std::string_view kFromTip = "_from_tip_in";
  if (EndsWith(key, kFromTip) && key.size() > kFromTip.size()) {
    const std::string stem(key.substr(0, key.size() - kFromTip.size()));
    if (EndsWith(stem, "_knob") && !EndsWith(stem, "_from_knob")) {
      out.push_back({stem + "_m", true, core::kMetresPerInch});  // a zone's end: "to_knob_m"
    } else {
      out.push_back({stem + "_from_knob_m", true, core::kMetresPerInch});
    }
  }
  for (const UnitRule& rule : kRules) {
    if (!EndsWith(key, rule.trade) || key.size() <= rule.trade.size()) continue;
    std::string si =
        std::string(key.substr(0, key.size() - rule.trade.size())) + std::string(rule.si);
    if (RuleOf(si) == &rule) out.push_back({std::move(si), false, rule.to_si});
  }
  return out;
}

bool TakeReportUnits(Json* body, ReportUnits* units, ApiError* error) {
  *units = ReportUnits::kSi;
  if (!body->is_object()) return true;
  const auto it = body->find("report_units");
  if (it == body->end()) return true;
  if (it->is_string() && (*it == "si" || *it == "imperial")) {
    *units = *it == "imperial" ? ReportUnits::kImperial : ReportUnits::kSi;
    body->erase(it);
    return true;
  }
  return SetError(error, ErrorCode::kInvalidValue, "report_units", &*it,
                  "must be \"si\" or \"imperial\"");
}

void AppendWarnings(const std::vector<std::string>& warnings, Json* answer) {
  if (warnings.empty()) return;
  Json& list = (*answer)["warnings"];
  if (!list.is_array()) list = Json::array();
  for (const std::string& w : warnings) list.push_back(w);
}

void ErrorAsWritten(const Json& request_body, Response* response) {
  if (response->status < 400 || response->status >= 500 || !response->body.is_object()) return;
  const auto field = response->body.find("field");
  const auto message = response->body.find("message");
  if (field == response->body.end() || !field->is_string() || message == response->body.end() ||
      !message->is_string()) {
    return;
  }
  const std::string si_field = field->get<std::string>();
  std::string why;
  const auto steps = ParseJsonPath(si_field, &why);
  if (!steps || steps->empty() || !std::holds_alternative<std::string>(steps->back())) return;
  if (NumberAtPath(request_body, *steps, &why)) return;  // written in SI
  std::vector<PathStep> written = *steps;
  for (const TradeForm& form : TradeForms(std::get<std::string>(steps->back()))) {
    written.back() = form.key;
    const auto value = NumberAtPath(request_body, written, &why);
    if (!value) continue;
    const std::string written_field = FormatJsonPath(written);
    std::string text = message->get<std::string>();
    const std::string head = si_field + " = ";
    if (text.rfind(head, 0) == 0) {
      // "field = shown: rule" -> "written = value: rule (in SI: field = shown)".
      const std::size_t colon = text.find(": ", head.size());
      if (colon == std::string::npos) return;
      const std::string si_value = text.substr(head.size(), colon - head.size());
      text = written_field + " = " + core::FormatNumber(*value) + text.substr(colon) + " (in SI: " +
             si_field + " = " + si_value + ")";
    } else {
      // A rule about the field that quotes no value ("... give exactly one of
      // swing.bat_speed_mps and ..."): the field as written wherever it is named.
      for (std::size_t at = text.find(si_field); at != std::string::npos;
           at = text.find(si_field, at + written_field.size())) {
        text.replace(at, si_field.size(), written_field);
      }
    }
    *message = text;
    *field = written_field;
    return;
  }
}

}  // namespace sweetspot::api
