// POST /v1/explore's request (ParseExploreRequest): the design template, the swept parameters
// (numeric fields of the request's bat or scene, addressed by path), the sampling plan, the
// rows' outputs and columns, the Pareto objectives and the shard, all checked before the first
// design; the sweep it describes is run by api/explore/engine.hpp (HandleExplore, explore.cpp).
#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>

#include "api/bat_json.hpp"
#include "api/explore/columns.hpp"
#include "api/explore/design.hpp"
#include "api/explore/engine.hpp"
#include "api/explore/estimate.hpp"
#include "api/explore/shards.hpp"
#include "api/fields.hpp"
#include "api/handlers/endpoint.hpp"
#include "api/handlers/explore_parameters.hpp"
#include "api/handlers/handlers.hpp"
#include "api/json_path.hpp"
#include "api/scene_json.hpp"
#include "api/trade_units.hpp"
#include "core/bat/presets.hpp"
#include "core/explore/sampling.hpp"
#include "core/scene/output_registry.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

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

// The design template: the bat and the scene fields of `reader`'s body, as written, into *base;
// the template itself must be a valid bat and scene (core's ranges of ball, swing and cor,
// checked as a design's row checks them). *paper_bat: the template's bat is one of the paper's
// (model auto: rigid_pivot); *properties: its mass properties, computed once by its check
// (ParseBat). False with *error set.
bool ReadExploreTemplate(ObjectReader& reader, const Context& context, Json* base, bool* paper_bat,
                         std::optional<core::MassPropertiesOfBothModels>* properties,
                         ApiError* error) {
  for (const char* key : {"bat", "ball", "swing", "cor", "inertia_model", "contact"}) {
    if (const Json* value = reader.Get(key)) (*base)[key] = *value;
  }
  if (!base->contains("bat")) {
    reader.Missing("bat");
    return false;
  }
  core::Scene scene;
  ObjectReader check(*base, "", error);
  const auto spec = ParseBat((*base)["bat"], "bat", context.limits, error);
  if (!spec || !ReadSceneCommon(check, &scene)) return false;
  scene.bat = spec->bat;
  scene.paper_bat = spec->paper;
  *paper_bat = spec->paper;
  *properties = spec->properties;
  scene.outputs = {core::SceneOutput::kMaxExitSpeed};
  if (core::Refusal refusal; !scene.Validate(&refusal)) {
    CoreRefusal(refusal, "", error);
    return false;
  }
  return true;
}

// The most designs a sweep may have: a batch (a job, the CLI) writes its rows to a result or a
// file, not to a waiting client, so it has its own, larger limit.
std::size_t DesignLimit(const Context& context) {
  return context.batch ? context.limits.max_batch_samples : context.limits.max_samples;
}

// The plan valid (core's rules) and its design count (*total) within DesignLimit, the refusal
// naming the limit and its command-line flag. False with *error set.
bool CheckDesignCount(const core::SweepPlan& plan, const Context& context, std::uint64_t* total,
                      ApiError* error) {
  if (core::Refusal refusal; !plan.Validate(&refusal)) {
    CoreRefusal(refusal, "", error);
    return false;
  }
  const std::size_t limit = DesignLimit(context);
  const char* limit_name = context.batch ? "max_batch_samples" : "max_samples";
  const char* limit_flag = context.batch ? "max-batch-samples" : "max-samples";
  *total = plan.DesignCount();
  if (*total > limit) {
    SetError(error, ErrorCode::kTooBig, "parameters", nullptr,
             "describe " + std::to_string(*total) + " designs, over the limit " + limit_name +
                 " = " + std::to_string(limit) + " (--" + limit_flag + ")");
    return false;
  }
  return true;
}

// "sampling", "samples" (1 to `limit` designs) and "seed" into *plan; "samples" is required
// but for a grid. Errors are recorded by `reader`.
void ReadSweepPlan(ObjectReader& reader, std::size_t limit, core::SweepPlan* plan) {
  std::string sampling = "grid";
  reader.OptionalString("sampling", &sampling, {"grid", "lhs", "sobol"});
  plan->method = *core::ParseSamplingMethod(sampling);
  long long samples = 0, seed = 0;
  reader.OptionalInteger(
      "samples", 1, static_cast<long long>(std::min<std::size_t>(limit, 1ULL << 53)), &samples);
  reader.OptionalInteger("seed", 0, 1LL << 53, &seed);
  plan->samples = static_cast<std::uint64_t>(samples);
  plan->seed = static_cast<std::uint64_t>(seed);
  if (reader.ok() && plan->method != core::SamplingMethod::kGrid && samples == 0) {
    reader.Missing("samples");
  }
}

// "outputs" (default: the properties and max_exit_speed) into *outputs: each "properties", a
// scene output's name (a name given twice counts once) or "collision_efficiency" (which adds
// max_exit_speed). Errors are
// recorded by `reader`; false on one.
bool ReadRowOutputs(ObjectReader& reader, RowOutputs* outputs) {
  outputs->properties = true;
  outputs->scene = {core::SceneOutput::kMaxExitSpeed};
  const Json* list = reader.Get("outputs");
  if (list == nullptr) return true;
  if (!list->is_array() || list->empty()) {
    reader.Fail("outputs", "must be a non-empty array of output names");
    return false;
  }
  *outputs = RowOutputs{};
  for (std::size_t i = 0; i < list->size(); ++i) {
    const Json& item = (*list)[i];
    const std::string name = item.is_string() ? item.get<std::string>() : "";
    if (name == "properties") {
      outputs->properties = true;
    } else if (name == "collision_efficiency") {
      outputs->collision_efficiency = true;
    } else if (const auto output = core::ParseSceneOutput(name)) {
      // A name given twice is one output, as /v1/sweet-spot's ReadOutputs takes it (a row
      // renders each output once).
      if (std::find(outputs->scene.begin(), outputs->scene.end(), *output) ==
          outputs->scene.end()) {
        outputs->scene.push_back(*output);
      }
    } else {
      reader.Fail("outputs", "outputs[" + std::to_string(i) + "] = " + Show(item) +
                                 " is not one of properties, " + core::SceneOutputNameList() +
                                 ", collision_efficiency");
      return false;
    }
  }
  if (outputs->collision_efficiency &&
      std::find(outputs->scene.begin(), outputs->scene.end(), core::SceneOutput::kMaxExitSpeed) ==
          outputs->scene.end()) {
    outputs->scene.push_back(core::SceneOutput::kMaxExitSpeed);
  }
  return true;
}

// True when the designs have their own swing, which their rows report (RenderDesignRow): a bat
// speed ("swing.bat_speed_m…") in the template `base` or among the swept `parameters`.
bool DesignsHaveOwnSwing(const Json& base, const std::vector<SweepParameter>& parameters) {
  bool own = false;
  if (const auto swing = base.find("swing"); swing != base.end() && swing->is_object()) {
    for (const auto& item : swing->items()) {
      if (item.key().rfind("bat_speed_m", 0) == 0) own = true;
    }
  }
  for (const SweepParameter& parameter : parameters) {
    for (const auto& target : parameter.targets) {
      const auto* head = target.size() >= 2 ? std::get_if<std::string>(&target[0]) : nullptr;
      const auto* field = head != nullptr ? std::get_if<std::string>(&target[1]) : nullptr;
      if (field != nullptr && *head == "swing" && field->rfind("bat_speed_m", 0) == 0) {
        own = true;
      }
    }
  }
  return own;
}

// "pareto": 2 to 8 objectives {"output", "sense"} into *objectives ("parameters.<path>" names a
// swept parameter, its path may hold dots; anything else is a dotted path into the row, e.g.
// "max_exit_speed.exit_speed_mps"). False with *error set.
bool ReadParetoObjectives(ObjectReader& reader, ApiError* error,
                          std::vector<ParetoObjective>* objectives) {
  const Json* pareto = reader.Get("pareto");
  if (pareto == nullptr) return true;
  ObjectReader p(*pareto, "pareto", error);
  const Json* list = p.Get("objectives");
  if (p.ok() && (list == nullptr || !list->is_array() || list->size() < 2 || list->size() > 8)) {
    p.Fail("objectives", "must be an array of 2 to 8 {\"output\", \"sense\"}");
  }
  if (!p.Finish()) return false;
  for (std::size_t i = 0; i < list->size(); ++i) {
    ObjectReader o((*list)[i], "pareto.objectives[" + std::to_string(i) + "]", error);
    ParetoObjective objective;
    std::string sense;
    o.String("output", &objective.output);
    o.String("sense", &sense, {"max", "min"});
    if (!o.Finish()) return false;
    objective.sense = sense == "max" ? core::Sense::kMaximize : core::Sense::kMinimize;
    objective.tokens = ObjectiveTokens(objective.output);
    objectives->push_back(std::move(objective));
  }
  return true;
}

// "shard": {"index", "count"} (index below count <= 2^40) into *shard; default the whole
// sweep. False with *error set.
bool ReadShard(ObjectReader& reader, ApiError* error, core::Shard* shard) {
  const Json* s = reader.Get("shard");
  if (s == nullptr) return true;
  ObjectReader sr(*s, "shard", error);
  long long index = 0, count = 1;
  sr.OptionalInteger("index", 0, (1LL << 40) - 1, &index);  // below count (<= 2^40)
  sr.OptionalInteger("count", 1, 1LL << 40, &count);
  if (!sr.Finish()) return false;
  *shard = {static_cast<std::uint64_t>(index), static_cast<std::uint64_t>(count)};
  if (core::Refusal refusal; !shard->Validate(&refusal)) {
    CoreRefusal(refusal, "", error);
    return false;
  }
  return true;
}

// The objectives and the columns (`column_list`, or CSV's defaults) checked against what a row
// of this sweep can have, before any design: a column may name a field in a trade unit
// ("max_exit_speed.exit_speed_mph", "max_exit_speed.position_from_tip_in"), whatever
// report_units says; the default CSV columns are those of the rows `imperial` gives. False
// with *error set.
bool CheckRowShape(const std::vector<SweepParameter>& parameters, const RowOutputs& outputs,
                   const std::vector<ParetoObjective>& objectives, const Json* column_list,
                   const std::string& format, bool imperial, std::vector<ExploreColumn>* columns,
                   ApiError* error) {
  std::vector<std::string> parameter_paths;
  for (const SweepParameter& parameter : parameters) parameter_paths.push_back(parameter.path);
  const Json si_shape = RowShape(parameter_paths, outputs);
  Json shape = si_shape;
  AddImperialToRow(&shape, 0.0);
  if (!CheckObjectives(objectives, shape, si_shape, imperial || column_list != nullptr, error)) {
    return false;
  }
  if (column_list == nullptr && format != "csv") return true;
  if (column_list == nullptr) {
    *columns = DefaultCsvColumns(parameter_paths, imperial ? shape : si_shape);
    return true;
  }
  return ParseColumns(*column_list, shape, si_shape, columns, error);
}

// What the answer and the work of `sweep` will be, before the first design: a synchronous JSON
// answer is built in memory (rows, then their text), so its size is bounded; a job's CPU time
// and result are bounded at submit (ndjson and csv answers are streamed). False with *error.
bool CheckSweepEstimate(const Sweep& sweep, const std::string& format,
                        const std::vector<ExploreColumn>& columns, const Context& context,
                        ApiError* error) {
  const SweepEstimate estimate = EstimateSweep(sweep, format, columns);
  std::optional<ApiError> over;
  if (!context.batch && format == "json") {
    over = CheckResponseSize(estimate, sweep, context.limits);
  }
  if (!over && context.job) {
    over = CheckJobEstimate(estimate, sweep, sweep.threads, context.limits);
  }
  if (over) {
    *error = std::move(*over);
    return false;
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
  bool paper_bat = false;  // the template's bat is one of the paper's (model auto: rigid_pivot)
  // The template bat's mass properties, computed once by its check (ParseBat).
  std::optional<core::MassPropertiesOfBothModels> template_properties;
  if (!ReadExploreTemplate(reader, context, &base, &paper_bat, &template_properties, error)) {
    return std::nullopt;
  }

  core::SweepPlan plan;
  ReadSweepPlan(reader, DesignLimit(context), &plan);

  std::vector<SweepParameter> parameters;
  const Json* params = reader.Get("parameters");
  if (reader.ok() && params == nullptr) reader.Missing("parameters");
  if (!reader.ok()) return std::nullopt;
  if (!params->is_array() || params->empty() || params->size() > 32) {
    reader.Fail("parameters", "must be an array of 1 to 32 {\"path\", \"min\", \"max\"}");
    return std::nullopt;
  }
  for (std::size_t i = 0; i < params->size(); ++i) {
    SweepParameter parameter;
    core::SweepDimension dimension;
    if (!explore_detail::ParseSweepParameter((*params)[i], i, plan.method, context, &base,
                                             &parameter, &dimension, error)) {
      return std::nullopt;
    }
    parameters.push_back(std::move(parameter));
    plan.dimensions.push_back(dimension);
  }

  RowOutputs outputs;
  if (!ReadRowOutputs(reader, &outputs)) return std::nullopt;
  // A bat speed, in the template or swept, gives each design its own swing, which its row
  // reports (RenderDesignRow): the row's shape says so for the columns and the estimate.
  if (DesignsHaveOwnSwing(base, parameters)) outputs.swing = true;
  core::SceneOptions options;
  if (!ReadSceneOptions(reader, context.limits, &options)) return std::nullopt;
  options.time_models = false;  // a row reports no timings

  std::vector<ParetoObjective> objectives;
  if (!ReadParetoObjectives(reader, error, &objectives)) return std::nullopt;
  core::Shard shard;
  if (!ReadShard(reader, error, &shard)) return std::nullopt;
  std::string format = "json";
  reader.OptionalString("format", &format, {"json", "ndjson", "csv"});
  const Json* column_list = reader.Get("columns");
  if (!reader.Finish()) return std::nullopt;
  // The columns are checked against what a row of this sweep can have, before any design.
  std::vector<ExploreColumn> columns;
  if (!CheckRowShape(parameters, outputs, objectives, column_list, format,
                     units == ReportUnits::kImperial, &columns, error)) {
    return std::nullopt;
  }
  std::uint64_t total = 0;
  if (!CheckDesignCount(plan, context, &total, error)) return std::nullopt;

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
  if (!CheckSweepEstimate(*sweep, format, columns, context, error)) return std::nullopt;
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

}  // namespace sweetspot::api
