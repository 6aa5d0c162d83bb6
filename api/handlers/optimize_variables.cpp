// /v1/optimize's "variables": paths through the table of fields, trade forms converted at this
// boundary (api/handlers/optimize_variables.hpp).
#include "api/handlers/optimize_variables.hpp"

#include <cmath>
#include <cstdlib>
#include <set>
#include <utility>

#include "api/bat_json.hpp"
#include "api/fields.hpp"
#include "core/geometry_format.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

// Every occurrence of the path `from` in *text replaced by `to`, but where the text quotes the
// field's value ("gives profile.knots[2].radius_m = 0.0125": an SI value keeps its SI name).
void ReplaceAll(std::string* text, const std::string& from, const std::string& to) {
  if (from.empty()) return;
  for (std::size_t at = text->find(from); at != std::string::npos;) {
    if (text->compare(at + from.size(), 3, " = ") == 0) {
      at = text->find(from, at + from.size());
      continue;
    }
    text->replace(at, from.size(), to);
    at = text->find(from, at + to.size());
  }
}

// The variable path `item` as core takes it: a variable row of the table of fields
// (api/fields.hpp), SI as written, or a trade form converted ("three_segment.barrel_diameter_in"
// -> "three_segment.barrel_radius_m", 0.0127). Nullopt when it names no design variable.
std::optional<WrittenVariable> VariablePath(const std::string& item) {
  const auto use = ResolveField(item, FieldScope::kVariable);
  if (!use || !core::ParseDesignVariablePath(use->si)) return std::nullopt;
  return WrittenVariable{use->si, item, use->to_si};
}

// Refuses `field` = `value`, a path that names no variable, suggesting the nearest name.
bool NotAVariable(ApiError* error, const std::string& field, const Json& value,
                  const std::string& rule) {
  const std::string hint =
      value.is_string() ? DidYouMeanField(value.get<std::string>(), FieldScope::kVariable) : "";
  return SetError(error, ErrorCode::kInvalidValue, field, &value, rule + hint);
}

// Reads "paths" or "scale_paths" of variable `where` into *variable.
bool ReadPathList(ObjectReader& v, const std::string& where, const std::string& form,
                  std::set<std::string>* scale_names, core::DesignVariable* variable,
                  double* bound_to_si, VariableNames* names) {
  ApiError* error = v.error();
  const Json* paths = v.Get(form);
  if (!paths->is_array() || paths->empty() || paths->size() > 32) {
    return v.Fail(form, "must be an array of 1 to 32 variable paths");
  }
  std::string joined;
  for (std::size_t k = 0; k < paths->size(); ++k) {
    const Json& item = (*paths)[k];
    const std::string field = where + "." + form + "[" + std::to_string(k) + "]";
    const auto path = item.is_string() ? VariablePath(item.get<std::string>()) : std::nullopt;
    if (!path) {
      return NotAVariable(error, field, item,
                          "is not a design variable path (profile.knots[i].radius_m, ...; "
                          "material choices cannot be linked or scaled)");
    }
    if (path->written != path->si) names->paths.push_back(*path);
    if (form == "scale_paths") {
      variable->scale_paths.push_back(path->si);
      joined += (k == 0 ? "" : "+") + path->written;
    } else if (k == 0) {
      variable->path = path->si;
      *bound_to_si = path->to_si;  // the bounds are in the first path's unit
    } else if (path->to_si != *bound_to_si) {
      return SetError(error, ErrorCode::kInvalidValue, field, &item,
                      "is in another unit than " + where + ".paths[0] (linked fields take one "
                      "value: write them in one unit)");
    } else {
      variable->linked_paths.push_back(path->si);
    }
  }
  if (form != "scale_paths") return true;
  variable->path = "scale:" + joined;
  v.OptionalString("name", &variable->path);
  if (!v.ok()) return false;
  if (variable->path.empty() || variable->path == "material" ||
      core::ParseDesignVariablePath(variable->path) || VariablePath(variable->path)) {
    return v.Fail("name",
                  "must be a non-empty name that is not a design variable path "
                  "(the answer's variables list the scale under it beside its "
                  "fields)");
  }
  if (!scale_names->insert(variable->path).second) {
    return v.Fail(v.Has("name") ? "name" : "scale_paths",
                  "names a scale variable \"" + variable->path +
                      "\" already given: each needs its own name");
  }
  return true;
}

// Reads a "material" variable's choices.
bool ReadMaterialChoices(ObjectReader& v, const std::string& where,
                         std::vector<core::Material>* material_choices) {
  const Json* choices = v.Get("choices");
  if (choices == nullptr || !choices->is_array() || choices->empty() || choices->size() > 16) {
    return v.Fail("choices", "must be an array of 1 to 16 material names");
  }
  for (std::size_t k = 0; k < choices->size(); ++k) {
    auto m = ParseMaterial((*choices)[k], where + ".choices[" + std::to_string(k) + "]", false,
                           v.error());
    if (!m) return false;
    material_choices->push_back(*m);
  }
  return v.Finish();
}

// Reads variable i.
bool ReadVariable(const Json& item, std::size_t i, std::set<std::string>* scale_names,
                  core::DesignProblem* problem, std::vector<core::Material>* material_choices,
                  VariableNames* names, ApiError* error) {
  const std::string where = "variables[" + std::to_string(i) + "]";
  ObjectReader v(item, where, error);
  core::DesignVariable variable;
  double bound_to_si = 1.0;
  if (!v.ok()) return false;  // not an object
  // One field ("path"), several set to the value ("paths"), or several each the base
  // design's value times it ("scale_paths"): exactly one form, as /v1/explore's parameters.
  const char* const kForms[] = {"path", "paths", "scale_paths"};
  std::vector<const char*> given;
  for (const char* form : kForms) {
    if (v.Has(form)) given.push_back(form);
  }
  if (!v.ok()) return false;
  if (given.size() != 1) {
    return v.Fail(given.empty() ? "path" : given[1],
                  "give exactly one of path, paths (several fields set to one value) and "
                  "scale_paths (several fields scaled by one value)",
                  given.empty() ? ErrorCode::kMissingField : ErrorCode::kInvalidValue);
  }
  const std::string form = given.front();
  if (v.Has("name") && form != "scale_paths") {
    return v.Fail("name",
                  "names a scale variable: give it with scale_paths only (a path is "
                  "its own name)");
  }
  if (form != "path") {
    // paths: the first is the variable's path, the rest linked. scale_paths: the fields of a
    // scale variable named by "name" (default "scale:" and the paths joined with "+").
    if (!ReadPathList(v, where, form, scale_names, &variable, &bound_to_si, names)) return false;
  } else {
    v.String("path", &variable.path);
  }
  if (v.ok() && variable.path == "material") {  // a discrete choice among materials
    return ReadMaterialChoices(v, where, material_choices);
  }
  v.Number("min", AnyNumber(), &variable.min);  // the bounds' ranges: core's
  v.Number("max", AnyNumber(), &variable.max);
  if (!v.Finish()) return false;
  if (form == "path") {
    const auto path = VariablePath(variable.path);
    if (!path) {
      return NotAVariable(
          error, where + ".path", item["path"],
          "is not a design variable (profile.knots[i].radius_m, profile.knots[i].x_m, "
          "three_segment.<field>, material.density_kg_m3, wall_thickness_m, "
          "fill.diameter_m, fill.depth_m, fill.material.density_kg_m3, or material "
          "with choices)");
    }
    if (path->written != path->si) names->paths.push_back(*path);
    variable.path = path->si;
    bound_to_si = path->to_si;
  }
  variable.min *= bound_to_si;  // core is SI
  variable.max *= bound_to_si;
  problem->variables.push_back(variable);
  names->bound_to_si.push_back(bound_to_si);
  return true;
}

}  // namespace

const WrittenVariable* VariableNames::Find(const std::string& si) const {
  for (const WrittenVariable& p : paths) {
    if (p.si == si) return &p;
  }
  return nullptr;
}

core::Refusal VariableNames::AsWritten(core::Refusal refusal) const {
  // "variables[i].min" / ".max": the bound in the request's unit.
  const std::string_view field = refusal.field;
  if (field.rfind("variables[", 0) == 0) {
    const std::size_t i = std::strtoul(refusal.field.c_str() + 10, nullptr, 10);
    const bool bound = field.size() > 4 && (field.substr(field.size() - 4) == ".min" ||
                                            field.substr(field.size() - 4) == ".max");
    if (i < bound_to_si.size() && bound_to_si[i] != 1.0) {
      const double f = bound_to_si[i];
      if (bound && std::isfinite(refusal.value) && refusal.QuotesValue()) {
        refusal.value /= f;
        refusal.shown = core::FormatNumber(refusal.value);
        refusal.rule += " (in SI: " + core::FormatNumber(refusal.value * f) + ")";
      }
      // "must be greater than variables[0].min = 0.00254": the other bound too.
      const std::string other = "variables[" + std::to_string(i) + "].min = ";
      if (const std::size_t at = refusal.rule.find(other); at != std::string::npos) {
        const std::size_t from = at + other.size();
        char* end = nullptr;
        const double si = std::strtod(refusal.rule.c_str() + from, &end);
        const std::size_t to = static_cast<std::size_t>(end - refusal.rule.c_str());
        if (to > from) refusal.rule.replace(from, to - from, core::FormatNumber(si / f));
      }
    }
  }
  for (const WrittenVariable& p : paths) {
    ReplaceAll(&refusal.rule, p.si, p.written);
    if (refusal.shown == p.si) refusal.shown = p.written;
  }
  return refusal;
}

Json VariableNames::ValuesAsWritten(const std::vector<core::DesignValue>& values) const {
  Json out = Json::object();
  for (const core::DesignValue& v : values) {
    const WrittenVariable* written = v.scale_factor ? nullptr : Find(v.path);
    if (written != nullptr) {
      out[written->written] = v.value / written->to_si;
    } else {
      out[v.path] = v.value;
    }
  }
  return out;
}

bool ReadVariables(ObjectReader& reader, const ApiLimits& limits, core::DesignProblem* problem,
                   std::vector<core::Material>* material_choices, VariableNames* names) {
  const Json* variables = reader.Get("variables");
  if (reader.ok() && variables == nullptr) reader.Missing("variables");
  if (!reader.ok()) return false;
  const std::size_t max_variables = limits.max_design_variables;
  if (!variables->is_array() || variables->empty() || variables->size() > max_variables) {
    return reader.Fail("variables", "must be an array of 1 to " + std::to_string(max_variables) +
                                        " {\"path\", \"min\", \"max\"}");
  }
  std::set<std::string> scale_names;  // the scale variables' names, each once
  for (std::size_t i = 0; i < variables->size(); ++i) {
    if (!ReadVariable((*variables)[i], i, &scale_names, problem, material_choices, names,
                      reader.error())) {
      return false;
    }
  }
  return true;
}

}  // namespace sweetspot::api
