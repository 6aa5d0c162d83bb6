// /v1/explore's swept parameters (explore_parameters.hpp): each parameter's paths read and
// bound into the design template, checked before the first design.
#include "api/handlers/explore_parameters.hpp"

#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "api/bat_json.hpp"
#include "api/fields.hpp"
#include "api/json_path.hpp"
#include "api/json_reader.hpp"
#include "api/scene_json.hpp"
#include "api/trade_units.hpp"
#include "core/bat/presets.hpp"

namespace sweetspot::api::explore_detail {
namespace {

using Json = nlohmann::json;

// The error a swept field gives because the design's parser does not know it (a misspelt
// last key, "profile.knots[3].radius"): every design would fail alike, so the sweep is
// refused before its first design. `probe` is the valid template with only that field set;
// returns false (with the parser's UnknownField error in *unknown) when the field is unknown.
bool IsKnownField(const Json& probe, const ApiLimits& limits, ApiError* unknown) {
  ApiError error;
  ObjectReader reader(probe, "", &error);
  core::Scene scene;
  const Json* bat = reader.Get("bat");
  if (bat != nullptr && ParseBatGeometry(*bat, "bat", limits, &error)) {
    ReadSceneCommon(reader, &scene);
  }
  if (error.code != ErrorCode::kUnknownField) return true;
  *unknown = std::move(error);
  return false;
}

// A template bat given as a preset and no shape of its own gets the preset's knots as its
// "profile" (ParseBatGeometry: the preset's material, wall and fill, these knots): the same bat,
// whose knots a sweep can now name. Anything else is left as it is.
void WritePresetProfile(Json* bat) {
  if (!bat->is_object() || bat->contains("profile") || bat->contains("three_segment")) return;
  const auto name = bat->find("preset");
  if (name == bat->end() || !name->is_string()) return;
  const std::optional<core::BatPreset> preset = core::FindPreset(name->get<std::string>());
  if (!preset) return;
  (*bat)["profile"] = BatToJson(preset->bat)["profile"];
}

// A swept path written in a trade unit ("ball.speed_mph", "three_segment.barrel_diameter_in")
// sweeps its SI field: *steps becomes that field's path and *to_si the factor from the swept
// value to it. A path whose last key is no trade spelling, or whose SI field the design's
// parser does not know (a fill's own "diameter_m" is not a "radius_m"), is left as written.
void SweptPathToSi(const Json& base, double min, const ApiLimits& limits,
                   std::vector<PathStep>* steps, double* to_si) {
  *to_si = 1.0;
  if (steps->empty()) return;
  const auto* leaf = std::get_if<std::string>(&steps->back());
  if (leaf == nullptr) return;
  // A field of the table of fields (api/fields.hpp) in a trade form: its row says which SI field.
  if (const auto use = ResolveField(FormatJsonPath(*steps), FieldScope::kRequest);
      use && use->to_si != 1.0) {
    std::string why;
    auto si_steps = ParseJsonPath(use->si, &why);
    if (Json probe = base; si_steps && SetNumberAtPath(&probe, *si_steps, min * use->to_si, &why)) {
      *steps = std::move(*si_steps);
      *to_si = use->to_si;
      return;
    }
  }
  // Any other numeric field the request's parser knows: the first SI spelling it takes.
  for (const TradeForm& si : SiFormsOf(*leaf)) {
    std::vector<PathStep> candidate = *steps;
    candidate.back() = si.key;
    // The template as written with the SI field added: a parser that knows the field reads
    // it (and may refuse two forms of it), one that does not calls it unknown.
    Json probe = base;
    if (!SetNumberAtPath(&probe, candidate, min * si.to_si, nullptr)) continue;
    if (ApiError unknown; !IsKnownField(probe, limits, &unknown)) continue;
    *steps = std::move(candidate);
    *to_si = si.to_si;
    return;
  }
}

// Each swept path as written and its JSON value (for the error's quote).
using WrittenPaths = std::vector<std::pair<std::string, const Json*>>;

// The paths of the parameter `item` at `where` (`p` its reader): one field ("path"), or several
// linked ones: "paths" (all set to the value) or "scale_paths" (each the template's value times
// it). Each path into *written, the form's key into *form; parameter->path is the path, or the
// paths joined by "+" (or the optional "name"), parameter->scale true for scale_paths. False
// with *error set.
bool ReadParameterPaths(const Json& item, const std::string& where, ObjectReader& p,
                        ApiError* error, SweepParameter* parameter, std::string* form,
                        WrittenPaths* written) {
  if (!item.is_object()) {
    SetError(error, ErrorCode::kInvalidValue, where, &item,
             "must be an object {\"path\" (or \"paths\", \"scale_paths\"), \"min\", "
             "\"max\"}");
    return false;
  }
  const int forms = int{p.Has("path")} + int{p.Has("paths")} + int{p.Has("scale_paths")};
  if (!p.ok()) return false;
  if (forms != 1) {
    p.Fail(forms == 0 ? "path" : "paths",
           "give exactly one of path, paths (several fields set to one value) and "
           "scale_paths (several fields scaled by one value)",
           forms == 0 ? ErrorCode::kMissingField : ErrorCode::kInvalidValue);
    return false;
  }
  *form = "path";
  if (p.Has("path")) {
    p.String("path", &parameter->path);
    if (p.ok()) written->emplace_back(parameter->path, p.Get("path"));
    return true;
  }
  *form = p.Has("paths") ? "paths" : "scale_paths";
  parameter->scale = *form == "scale_paths";
  const Json* list = p.Get(*form);
  if (!list->is_array() || list->empty() || list->size() > 32) {
    p.Fail(*form, "must be an array of 1 to 32 paths");
    return false;
  }
  std::string joined;
  for (std::size_t j = 0; j < list->size(); ++j) {
    if (!(*list)[j].is_string()) {
      SetError(error, ErrorCode::kInvalidValue, where + "." + *form + "[" + std::to_string(j) + "]",
               &(*list)[j], "must be a path (a string)");
      return false;
    }
    written->emplace_back((*list)[j].get<std::string>(), &(*list)[j]);
    joined += (j == 0 ? "" : "+") + written->back().first;
  }
  parameter->path = joined;
  p.OptionalString("name", &parameter->path);
  return true;
}

// One swept path `path` as written (at `field`, its JSON `path_json`) bound into *parameter:
// its steps in the template *base (a head other than bat, ball, swing, cor, contact is the
// bat's; a scene object left to its defaults added; a preset's knots written out for a knot
// path; a trade unit swept as its SI field, the factor in parameter->to_si), checked by setting
// the range's `min` in a probe of the template: a number the design's parser knows, a swing
// still valid, a scaled field present (its template value in parameter->scale_bases). `first`:
// the parameter's first path (its steps also parameter->steps). False with *error set.
bool BindSweptPath(const Context& context, const std::string& field, const Json* path_json,
                   std::string path, double min, bool first, Json* base, SweepParameter* parameter,
                   ApiError* error) {
  Json& template_json = *base;
  const std::string head = path.substr(0, path.find_first_of(".["));
  if (head != "bat" && head != "ball" && head != "swing" && head != "cor" && head != "contact")
    path = "bat." + path;
  // A scene object the request left to its defaults can still be swept.
  if ((head == "ball" || head == "swing" || head == "contact") && !template_json.contains(head)) {
    template_json[head] = Json::object();
  }
  // A preset's profile points, as /v1/optimize's variables take them: the template's bat
  // gets the preset's knots written out (the preset with a "profile" is the same bat), so
  // a knot path, in SI or a trade form, names a number of the template.
  if (path.rfind("bat.profile.", 0) == 0) WritePresetProfile(&template_json["bat"]);
  std::string why;
  // A preset (bat.preset, ball.preset) is a catalogue name: every design would fail alike.
  if (path.size() >= 7 && path.compare(path.size() - 7, 7, ".preset") == 0) {
    SetError(error, ErrorCode::kInvalidValue, field, path_json,
             path +
                 " names a catalogue entry, not a number: sweep the preset's numeric "
                 "fields (they override it) instead");
    return false;
  }
  auto steps = ParseJsonPath(path, &why);
  double to_si = 1.0;
  if (steps) {
    SweptPathToSi(template_json, min, context.limits, &*steps, &to_si);
    TradeFormToSi(&template_json, *steps);
  }
  std::optional<double> scale_base;
  if (steps && parameter->scale) {
    // A scaled field multiplies the template's own value: it must be there.
    scale_base = NumberAtPath(template_json, *steps, &why);
    if (!scale_base) why = "scale_paths multiplies the template's value, and " + why;
  }
  Json probe = template_json;
  if (!steps || (parameter->scale && !scale_base) ||
      !SetNumberAtPath(&probe, *steps, min * (parameter->scale ? 1.0 : to_si), &why)) {
    SetError(error, ErrorCode::kInvalidValue, field, path_json, why);
    return false;
  }
  if (head == "swing") {
    // The swept swing as a design sees it: e.g. swing.angular_speed_rad_s swept beside a
    // bat_speed_mps would be overridden by it in every design (exactly one may be given).
    ApiError swing_error;
    ObjectReader swing_reader(probe, "", &swing_error);
    core::Scene swing_scene;
    if (!ReadSceneCommon(swing_reader, &swing_scene)) {
      SetError(error, ErrorCode::kInvalidValue, field, path_json, swing_error.message);
      return false;
    }
  }
  if (ApiError unknown; !IsKnownField(probe, context.limits, &unknown)) {
    SetError(error, ErrorCode::kInvalidValue, field, path_json, unknown.message);
    return false;
  }
  if (first) parameter->steps = *steps;
  parameter->targets.push_back(std::move(*steps));
  parameter->to_si.push_back(to_si);
  if (scale_base) parameter->scale_bases.push_back(*scale_base);
  return true;
}

}  // namespace

// parameters[i] (`item`): its paths bound into *parameter (each checked against the template
// *base, which may gain a scene object or a preset's knots), its range "min", "max" (in the
// paths' units) and grid "count" (default 2 for a grid, else 1) into *dimension. False with
// *error set.
bool ParseSweepParameter(const Json& item, std::size_t i, core::SamplingMethod method,
                         const Context& context, Json* base, SweepParameter* parameter,
                         core::SweepDimension* dimension, ApiError* error) {
  const std::string where = "parameters[" + std::to_string(i) + "]";
  ObjectReader p(item, where, error);
  std::string form;
  WrittenPaths written;
  if (!ReadParameterPaths(item, where, p, error, parameter, &form, &written)) return false;
  p.Number("min", Between(-1e12, 1e12), &dimension->min);
  p.Number("max", Between(-1e12, 1e12), &dimension->max);
  long long count = method == core::SamplingMethod::kGrid ? 2 : 1;
  p.OptionalInteger("count", 1, 1000000000, &count);  // the total is checked against max_samples
  dimension->count = static_cast<int>(count);
  if (!p.Finish()) return false;
  if (dimension->max < dimension->min) {
    p.Fail("max", "must be >= min = " + Show(Json(dimension->min)));
    return false;
  }
  for (std::size_t j = 0; j < written.size(); ++j) {
    const std::string field =
        where + "." + form + (form == "path" ? "" : "[" + std::to_string(j) + "]");
    if (!BindSweptPath(context, field, written[j].second, written[j].first, dimension->min, j == 0,
                       base, parameter, error)) {
      return false;
    }
  }
  return true;
}

}  // namespace sweetspot::api::explore_detail
