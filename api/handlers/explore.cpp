// POST /v1/explore: design sweeps for pipelines. Parameters are numeric fields
// of the request's bat or scene, addressed by path; designs come from a grid,
// a Latin hypercube or a Sobol sequence; each design is one row (failed
// designs are rows with an error, never fatal to the sweep); shards split a
// sweep deterministically (design i belongs to shard i mod count).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>

#include "api/bat_json.hpp"
#include "api/explore/columns.hpp"
#include "api/explore/design.hpp"
#include "api/explore/engine.hpp"
#include "api/explore/estimate.hpp"
#include "api/explore/flight_sweep.hpp"
#include "api/explore/shards.hpp"
#include "api/explore/streams.hpp"
#include "api/fields.hpp"
#include "api/handlers/endpoint.hpp"
#include "api/handlers/handlers.hpp"
#include "api/json_path.hpp"
#include "api/memory_reserve.hpp"
#include "api/scene_json.hpp"
#include "api/trade_units.hpp"
#include "core/bat/presets.hpp"
#include "core/explore/sampling.hpp"
#include "core/scene/output_registry.hpp"

namespace sweetspot::api {
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

// "columns": 1 to kMaxColumns distinct dotted paths, each naming a part of `shape` (what a
// row of this sweep can have, its numbers also in the trade's units). Returns false with the
// error naming columns[i] and, from `si_shape` (the row in SI), the fields known there.
constexpr std::size_t kMaxColumns = 1024;
bool ParseColumns(const Json& list, const Json& shape, const Json& si_shape,
                  std::vector<ExploreColumn>* columns, ApiError* error) {
  if (!list.is_array() || list.empty() || list.size() > kMaxColumns) {
    SetError(error, ErrorCode::kInvalidValue, "columns", &list,
             "must be an array of 1 to " + std::to_string(kMaxColumns) +
                 " dotted paths into a row, e.g. \"max_exit_speed.exit_speed_mps\"");
    return false;
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where = "columns[" + std::to_string(i) + "]";
    const Json& item = list[i];
    if (!item.is_string() || item.get_ref<const std::string&>().empty()) {
      SetError(error, ErrorCode::kInvalidValue, where, &item,
               "must be a non-empty string: a dotted path into a row");
      return false;
    }
    ExploreColumn column = MakeColumn(item.get<std::string>());
    for (std::size_t j = 0; j < columns->size(); ++j) {
      if ((*columns)[j].path == column.path) {
        SetError(error, ErrorCode::kInvalidValue, where, &item,
                 "repeats columns[" + std::to_string(j) + "]: each column once");
        return false;
      }
    }
    if (std::string why; !CheckColumn(column, shape, &why)) {
      CheckColumn(column, si_shape, &why);  // the known fields without their trade forms
      SetError(error, ErrorCode::kInvalidValue, where, &item, why);
      return false;
    }
    columns->push_back(std::move(column));
  }
  return true;
}

// Each Pareto objective names a number a row has, as a column must: a typo, or an output not
// asked for, is a 400 on pareto.objectives[i].output before the first design (it used to give
// every design NaN and an empty front). A field in a trade unit ("…exit_speed_mph") is in the
// rows only when they carry those units: report_units "imperial", or columns.
bool CheckObjectives(const std::vector<ParetoObjective>& objectives, const Json& shape,
                     const Json& si_shape, bool rows_carry_trade_units, ApiError* error) {
  for (std::size_t i = 0; i < objectives.size(); ++i) {
    const std::string where = "pareto.objectives[" + std::to_string(i) + "].output";
    const Json output = objectives[i].output;
    const ExploreColumn column = MakeColumn(objectives[i].output);
    std::string why;
    if (!CheckColumn(column, si_shape, &why)) {
      if (std::string unused; !CheckColumn(column, shape, &unused)) {
        SetError(error, ErrorCode::kInvalidValue, where, &output, why);
        return false;
      }
      if (!rows_carry_trade_units) {
        SetError(error, ErrorCode::kInvalidValue, where, &output,
                 "names a field in a trade unit, which the rows carry only with "
                 "report_units \"imperial\" or with columns; or name its SI field");
        return false;
      }
      continue;
    }
    // The leaf, an array's elements read through its first (as CheckColumn reads them).
    const Json* leaf = &si_shape;
    for (const std::string& token : column.tokens) {
      if (leaf->is_array()) {
        leaf = leaf->empty() ? nullptr : &leaf->front();
      } else {
        leaf = &(*leaf)[token];  // CheckColumn found it
      }
      if (leaf == nullptr) break;
    }
    if (leaf != nullptr && !leaf->is_number() && !leaf->is_null()) {
      SetError(error, ErrorCode::kInvalidValue, where, &output,
               "must name a number of a row (this is " + std::string(leaf->type_name()) + ")");
      return false;
    }
  }
  return true;
}

}  // namespace

std::optional<ExploreRequest> ParseExploreRequest(const Json& body, const Context& context,
                                                  ApiError* error) {
  ObjectReader reader(body, "", error);
  // "report_units", read as every endpoint reads it (TakeReportUnits).
  ReportUnits units = ReportUnits::kSi;
  if (reader.Has("report_units")) {
    Json only{{"report_units", body["report_units"]}};
    if (!TakeReportUnits(&only, &units, error)) return std::nullopt;
  }

  // The design template: the bat and the scene fields, as written.
  Json base = Json::object();
  for (const char* key : {"bat", "ball", "swing", "cor", "inertia_model", "contact"}) {
    if (const Json* value = reader.Get(key)) base[key] = *value;
  }
  if (!base.contains("bat")) {
    reader.Missing("bat");
    return std::nullopt;
  }
  bool paper_bat = false;  // the template's bat is one of the paper's (model auto: rigid_pivot)
  // The template bat's mass properties, computed once by its check (ParseBat).
  std::optional<core::MassPropertiesOfBothModels> template_properties;
  {  // The template itself must be a valid bat and scene.
    core::Scene scene;
    ObjectReader check(base, "", error);
    const auto spec = ParseBat(base["bat"], "bat", context.limits, error);
    if (!spec || !ReadSceneCommon(check, &scene)) return std::nullopt;
    // The ranges (ball, swing, cor) are core's: checked as a design's row checks them.
    scene.bat = spec->bat;
    scene.paper_bat = spec->paper;
    paper_bat = spec->paper;
    template_properties = spec->properties;
    scene.outputs = {core::SceneOutput::kMaxExitSpeed};
    if (core::Refusal refusal; !scene.Validate(&refusal)) {
      CoreRefusal(refusal, "", error);
      return std::nullopt;
    }
  }

  // A batch (a job, the CLI) writes its rows to a result or a file, not to a waiting
  // client: it has its own, larger limit.
  const std::size_t limit =
      context.batch ? context.limits.max_batch_samples : context.limits.max_samples;
  const char* limit_name = context.batch ? "max_batch_samples" : "max_samples";
  const char* limit_flag = context.batch ? "max-batch-samples" : "max-samples";
  core::SweepPlan plan;
  std::string sampling = "grid";
  reader.OptionalString("sampling", &sampling, {"grid", "lhs", "sobol"});
  plan.method = *core::ParseSamplingMethod(sampling);
  long long samples = 0, seed = 0;
  reader.OptionalInteger(
      "samples", 1, static_cast<long long>(std::min<std::size_t>(limit, 1ULL << 53)), &samples);
  reader.OptionalInteger("seed", 0, 1LL << 53, &seed);
  plan.samples = static_cast<std::uint64_t>(samples);
  plan.seed = static_cast<std::uint64_t>(seed);
  if (reader.ok() && plan.method != core::SamplingMethod::kGrid && samples == 0) {
    reader.Missing("samples");
  }

  std::vector<SweepParameter> parameters;
  const Json* params = reader.Get("parameters");
  if (reader.ok() && params == nullptr) reader.Missing("parameters");
  if (!reader.ok()) return std::nullopt;
  if (!params->is_array() || params->empty() || params->size() > 32) {
    reader.Fail("parameters", "must be an array of 1 to 32 {\"path\", \"min\", \"max\"}");
    return std::nullopt;
  }
  for (std::size_t i = 0; i < params->size(); ++i) {
    const std::string where = "parameters[" + std::to_string(i) + "]";
    ObjectReader p((*params)[i], where, error);
    SweepParameter parameter;
    core::SweepDimension dimension;
    // One field ("path"), or several linked ones: "paths" (all set to the value) or
    // "scale_paths" (each the template's value times it).
    if (!(*params)[i].is_object()) {
      SetError(error, ErrorCode::kInvalidValue, where, &(*params)[i],
               "must be an object {\"path\" (or \"paths\", \"scale_paths\"), \"min\", "
               "\"max\"}");
      return std::nullopt;
    }
    const int forms = int{p.Has("path")} + int{p.Has("paths")} + int{p.Has("scale_paths")};
    if (!p.ok()) return std::nullopt;
    if (forms != 1) {
      p.Fail(forms == 0 ? "path" : "paths",
             "give exactly one of path, paths (several fields set to one value) and "
             "scale_paths (several fields scaled by one value)",
             forms == 0 ? ErrorCode::kMissingField : ErrorCode::kInvalidValue);
      return std::nullopt;
    }
    std::string form = "path";
    std::vector<std::pair<std::string, const Json*>> written;  // each path and its JSON value
    if (p.Has("path")) {
      p.String("path", &parameter.path);
      if (p.ok()) written.emplace_back(parameter.path, p.Get("path"));
    } else {
      form = p.Has("paths") ? "paths" : "scale_paths";
      parameter.scale = form == "scale_paths";
      const Json* list = p.Get(form);
      if (!list->is_array() || list->empty() || list->size() > 32) {
        p.Fail(form, "must be an array of 1 to 32 paths");
        return std::nullopt;
      }
      std::string joined;
      for (std::size_t j = 0; j < list->size(); ++j) {
        if (!(*list)[j].is_string()) {
          SetError(error, ErrorCode::kInvalidValue,
                   where + "." + form + "[" + std::to_string(j) + "]", &(*list)[j],
                   "must be a path (a string)");
          return std::nullopt;
        }
        written.emplace_back((*list)[j].get<std::string>(), &(*list)[j]);
        joined += (j == 0 ? "" : "+") + written.back().first;
      }
      parameter.path = joined;
      p.OptionalString("name", &parameter.path);
    }
    p.Number("min", Between(-1e12, 1e12), &dimension.min);
    p.Number("max", Between(-1e12, 1e12), &dimension.max);
    long long count = plan.method == core::SamplingMethod::kGrid ? 2 : 1;
    p.OptionalInteger("count", 1, 1000000000, &count);  // the total is checked against max_samples
    dimension.count = static_cast<int>(count);
    if (!p.Finish()) return std::nullopt;
    if (dimension.max < dimension.min) {
      p.Fail("max", "must be >= min = " + Show(Json(dimension.min)));
      return std::nullopt;
    }
    for (std::size_t j = 0; j < written.size(); ++j) {
      const std::string field =
          where + "." + form + (form == "path" ? "" : "[" + std::to_string(j) + "]");
      const Json* path_json = written[j].second;
      std::string path = written[j].first;
      const std::string head = path.substr(0, path.find_first_of(".["));
      if (head != "bat" && head != "ball" && head != "swing" && head != "cor" &&
          head != "contact") path = "bat." + path;
      // A scene object the request left to its defaults can still be swept.
      if ((head == "ball" || head == "swing" || head == "contact") && !base.contains(head)) {
        base[head] = Json::object();
      }
      // A preset's profile points, as /v1/optimize's variables take them: the template's bat
      // gets the preset's knots written out (the preset with a "profile" is the same bat), so
      // a knot path, in SI or a trade form, names a number of the template.
      if (path.rfind("bat.profile.", 0) == 0) WritePresetProfile(&base["bat"]);
      std::string why;
      // A preset (bat.preset, ball.preset) is a catalogue name: every design would fail alike.
      if (path.size() >= 7 && path.compare(path.size() - 7, 7, ".preset") == 0) {
        SetError(error, ErrorCode::kInvalidValue, field, path_json,
                 path +
                     " names a catalogue entry, not a number: sweep the preset's numeric "
                     "fields (they override it) instead");
        return std::nullopt;
      }
      auto steps = ParseJsonPath(path, &why);
      double to_si = 1.0;
      if (steps) {
        SweptPathToSi(base, dimension.min, context.limits, &*steps, &to_si);
        TradeFormToSi(&base, *steps);
      }
      std::optional<double> scale_base;
      if (steps && parameter.scale) {
        // A scaled field multiplies the template's own value: it must be there.
        scale_base = NumberAtPath(base, *steps, &why);
        if (!scale_base) why = "scale_paths multiplies the template's value, and " + why;
      }
      Json probe = base;
      if (!steps || (parameter.scale && !scale_base) ||
          !SetNumberAtPath(&probe, *steps, dimension.min * (parameter.scale ? 1.0 : to_si), &why)) {
        SetError(error, ErrorCode::kInvalidValue, field, path_json, why);
        return std::nullopt;
      }
      if (head == "swing") {
        // The swept swing as a design sees it: e.g. swing.angular_speed_rad_s swept beside a
        // bat_speed_mps would be overridden by it in every design (exactly one may be given).
        ApiError swing_error;
        ObjectReader swing_reader(probe, "", &swing_error);
        core::Scene swing_scene;
        if (!ReadSceneCommon(swing_reader, &swing_scene)) {
          SetError(error, ErrorCode::kInvalidValue, field, path_json, swing_error.message);
          return std::nullopt;
        }
      }
      if (ApiError unknown; !IsKnownField(probe, context.limits, &unknown)) {
        SetError(error, ErrorCode::kInvalidValue, field, path_json, unknown.message);
        return std::nullopt;
      }
      if (j == 0) parameter.steps = *steps;
      parameter.targets.push_back(std::move(*steps));
      parameter.to_si.push_back(to_si);
      if (scale_base) parameter.scale_bases.push_back(*scale_base);
    }
    parameters.push_back(std::move(parameter));
    plan.dimensions.push_back(dimension);
  }

  RowOutputs outputs;
  outputs.properties = true;
  outputs.scene = {core::SceneOutput::kMaxExitSpeed};
  if (const Json* list = reader.Get("outputs")) {
    if (!list->is_array() || list->empty()) {
      reader.Fail("outputs", "must be a non-empty array of output names");
      return std::nullopt;
    }
    outputs = RowOutputs{};
    for (std::size_t i = 0; i < list->size(); ++i) {
      const Json& item = (*list)[i];
      const std::string name = item.is_string() ? item.get<std::string>() : "";
      if (name == "properties") {
        outputs.properties = true;
      } else if (name == "collision_efficiency") {
        outputs.collision_efficiency = true;
      } else if (const auto output = core::ParseSceneOutput(name)) {
        outputs.scene.push_back(*output);
      } else {
        reader.Fail("outputs", "outputs[" + std::to_string(i) + "] = " + Show(item) +
                                   " is not one of properties, " + core::SceneOutputNameList() +
                                   ", collision_efficiency");
        return std::nullopt;
      }
    }
    if (outputs.collision_efficiency &&
        std::find(outputs.scene.begin(), outputs.scene.end(), core::SceneOutput::kMaxExitSpeed) ==
            outputs.scene.end()) {
      outputs.scene.push_back(core::SceneOutput::kMaxExitSpeed);
    }
  }
  // A bat speed, in the template or swept, gives each design its own swing, which its row
  // reports (RenderDesignRow): the row's shape says so for the columns and the estimate.
  if (const auto swing = base.find("swing"); swing != base.end() && swing->is_object()) {
    for (const auto& item : swing->items()) {
      if (item.key().rfind("bat_speed_m", 0) == 0) outputs.swing = true;
    }
  }
  for (const SweepParameter& parameter : parameters) {
    for (const auto& target : parameter.targets) {
      const auto* head = target.size() >= 2 ? std::get_if<std::string>(&target[0]) : nullptr;
      const auto* field = head != nullptr ? std::get_if<std::string>(&target[1]) : nullptr;
      if (field != nullptr && *head == "swing" && field->rfind("bat_speed_m", 0) == 0) {
        outputs.swing = true;
      }
    }
  }
  core::SceneOptions options;
  if (!ReadSceneOptions(reader, context.limits, &options)) return std::nullopt;
  options.time_models = false;  // a row reports no timings

  std::vector<ParetoObjective> objectives;
  if (const Json* pareto = reader.Get("pareto")) {
    ObjectReader p(*pareto, "pareto", error);
    const Json* list = p.Get("objectives");
    if (p.ok() && (list == nullptr || !list->is_array() || list->size() < 2 || list->size() > 8)) {
      p.Fail("objectives", "must be an array of 2 to 8 {\"output\", \"sense\"}");
    }
    if (!p.Finish()) return std::nullopt;
    for (std::size_t i = 0; i < list->size(); ++i) {
      ObjectReader o((*list)[i], "pareto.objectives[" + std::to_string(i) + "]", error);
      ParetoObjective objective;
      std::string sense;
      o.String("output", &objective.output);
      o.String("sense", &sense, {"max", "min"});
      if (!o.Finish()) return std::nullopt;
      objective.sense = sense == "max" ? core::Sense::kMaximize : core::Sense::kMinimize;
      // "parameters.<path>" names a swept parameter (its path may hold dots);
      // anything else is a dotted path into the row, e.g. "max_exit_speed.exit_speed_mps".
      objective.tokens = ObjectiveTokens(objective.output);
      objectives.push_back(std::move(objective));
    }
  }
  core::Shard shard;
  if (const Json* s = reader.Get("shard")) {
    ObjectReader sr(*s, "shard", error);
    long long index = 0, count = 1;
    sr.OptionalInteger("index", 0, (1LL << 40) - 1, &index);  // below count (<= 2^40)
    sr.OptionalInteger("count", 1, 1LL << 40, &count);
    if (!sr.Finish()) return std::nullopt;
    shard = {static_cast<std::uint64_t>(index), static_cast<std::uint64_t>(count)};
    if (core::Refusal refusal; !shard.Validate(&refusal)) {
      CoreRefusal(refusal, "", error);
      return std::nullopt;
    }
  }
  std::string format = "json";
  reader.OptionalString("format", &format, {"json", "ndjson", "csv"});
  const Json* column_list = reader.Get("columns");
  if (!reader.Finish()) return std::nullopt;
  // The columns are checked against what a row of this sweep can have, before any design.
  std::vector<std::string> parameter_paths;
  for (const SweepParameter& parameter : parameters) parameter_paths.push_back(parameter.path);
  std::vector<ExploreColumn> columns;
  const Json si_shape = RowShape(parameter_paths, outputs);
  Json shape = si_shape;
  AddImperialToRow(&shape, 0.0);
  if (!CheckObjectives(objectives, shape, si_shape,
                       units == ReportUnits::kImperial || column_list != nullptr, error)) {
    return std::nullopt;
  }
  if (column_list != nullptr || format == "csv") {
    // A column may name a field in a trade unit ("max_exit_speed.exit_speed_mph",
    // "max_exit_speed.position_from_tip_in"), whatever report_units says; the default CSV
    // columns are those of the rows report_units gives.
    if (column_list == nullptr) {
      columns =
          DefaultCsvColumns(parameter_paths, units == ReportUnits::kImperial ? shape : si_shape);
    } else if (!ParseColumns(*column_list, shape, si_shape, &columns, error)) {
      return std::nullopt;
    }
  }
  if (core::Refusal refusal; !plan.Validate(&refusal)) {
    CoreRefusal(refusal, "", error);
    return std::nullopt;
  }
  const std::uint64_t total = plan.DesignCount();
  if (total > limit) {
    SetError(error, ErrorCode::kTooBig, "parameters", nullptr,
             "describe " + std::to_string(total) + " designs, over the limit " + limit_name +
                 " = " + std::to_string(limit) + " (--" + limit_flag + ")");
    return std::nullopt;
  }

  auto sweep = std::make_shared<Sweep>();
  sweep->base = std::move(base);
  sweep->parameters = std::move(parameters);
  sweep->plan = std::move(plan);
  sweep->outputs = std::move(outputs);
  sweep->options = std::move(options);
  {
    // Which exit-speed model the rows' max_exit_speed comes from, and why (as a single
    // request's model_reason): the same for every design of the sweep.
    core::Scene resolved;
    resolved.paper_bat = paper_bat;
    sweep->exit_speed_model = core::CollisionModelName(
        core::ResolveExitModel(sweep->options.model, resolved, &sweep->model_reason));
  }
  sweep->limits = context.limits;
  sweep->objectives = std::move(objectives);
  sweep->shard = shard;
  sweep->total = total;
  // The sweep's identity: the request without its shard, format, columns and report_units,
  // so that every shard of one sweep carries the same provenance (explore-merge checks
  // it), whatever form its rows take.
  Json identity = body;
  identity.erase("shard");
  identity.erase("format");
  identity.erase("columns");
  identity.erase("report_units");
  sweep->provenance = Provenance(identity, Json::object(), sweep->plan.seed);
  sweep->threads = std::max(1, context.explore_threads);
  sweep->imperial = units == ReportUnits::kImperial;
  {
    // What the answer and the work will be, before the first design: a synchronous JSON
    // answer is built in memory (rows, then their text), so its size is bounded; a job's
    // CPU time and result are bounded at submit (ndjson and csv answers are streamed).
    const SweepEstimate estimate = EstimateSweep(*sweep, format, columns);
    std::optional<ApiError> over;
    if (!context.batch && format == "json") {
      over = CheckResponseSize(estimate, *sweep, context.limits);
    }
    if (!over && context.job) {
      over = CheckJobEstimate(estimate, *sweep, sweep->threads, context.limits);
    }
    if (over) {
      *error = std::move(*over);
      return std::nullopt;
    }
  }
  // Designs by index: grids enumerated, Sobol by a jump of its generator, LHS from the table
  // drawn here (every shard draws the same table and takes its designs from it).
  sweep->designs.emplace(sweep->plan);
  // The sweep engine: the template resolved once, the swept values bound without JSON.
  sweep->binder =
      DesignBinder::Compile(sweep->base, sweep->parameters, sweep->outputs, sweep->limits,
                            template_properties ? &*template_properties : nullptr);
  sweep->budget = context.thread_budget;

  return ExploreRequest{std::move(sweep), std::move(format), std::move(columns)};
}

Response HandleExplore(const Request& request, const Context& context) {
  const auto start = std::chrono::steady_clock::now();
  Response failure;
  // Not ParseRequest: "report_units" is this endpoint's own field (ParseExploreRequest).
  const std::optional<Json> body = ParseObjectBody(request, context, &failure);
  if (!body) return failure;
  // A sweep of batted-ball launches ("flight" instead of a bat): api/explore/flight_sweep.hpp.
  if (IsFlightSweep(*body)) return HandleFlightSweep(*body, context);
  ApiError error;
  const auto parsed = ParseExploreRequest(*body, context, &error);
  if (!parsed) return ToResponse(error);
  if (context.validate_only) return ValidRequest();
  // The sweep's timing_s, in its summary, counts from the request's arrival.
  const std::shared_ptr<Sweep>& sweep = parsed->sweep;
  sweep->start = start;
  const std::vector<ExploreColumn> columns = parsed->columns;
  // csv and ndjson are streamed (the sweep runs while the server writes), and so is json for
  // a job's result (api/explore/streams.hpp).
  if (parsed->format == "csv") return StreamedCsvAnswer(sweep, columns, context.progress);
  if (parsed->format == "ndjson") return StreamedNdjsonAnswer(sweep, columns, context.progress);
  if (context.stream_json) return StreamedJsonAnswer(sweep, columns, context.progress);
  Json rows = Json::array();
  const SweepOutcome outcome =
      RunSweep(*sweep, RowFormat::kJson, columns, context.progress, [&](BlockRows& block) {
        for (Json& row : block.rows) rows.push_back(std::move(row));
        return true;
      });
  if (outcome.failed) {
    rows = Json();  // the memory back before the answer is made
    RestoreMemoryReserve();
    return ErrorResponse(503, ErrorCode::kUnavailable,
                         outcome.message +
                             "; retry later, or ask for \"format\": \"ndjson\" or \"csv\" "
                             "(streamed)");
  }
  if (outcome.cancelled) return ErrorResponse(409, ErrorCode::kCancelled, outcome.message);
  return {200, {{"rows", std::move(rows)}, {"summary", outcome.summary}}};
}

}  // namespace sweetspot::api
