// POST /v1/bat/properties and POST /v1/bat/fit.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <utility>

#include "api/bat_json.hpp"
#include "api/fields.hpp"
#include "api/handlers/endpoint.hpp"
#include "api/handlers/handlers.hpp"
#include "api/trade_units.hpp"
#include "core/bat/presets.hpp"
#include "core/geometry_format.hpp"
#include "core/optimize/shape_fit.hpp"
#include "core/scene/sanity.hpp"
#include "core/units.hpp"

namespace sweetspot::api {
namespace {

// A parsed /v1/bat/properties request: the bat, the optional pivot and the inertia model.
struct PropertiesRequest {
  BatSpec spec;
  std::optional<double> pivot_from_knob_m;
  core::InertiaModel inertia_model = core::InertiaModel::kRigidBody;
};

std::optional<PropertiesRequest> ParseProperties(const nlohmann::json& body, const Context& context,
                                                 ApiError* error) {
  ObjectReader reader(body, "", error);
  const nlohmann::json* bat_json = reader.Get("bat");
  if (bat_json == nullptr) {
    reader.Missing("bat");
    return std::nullopt;
  }
  auto spec = ParseBat(*bat_json, "bat", context.limits, error);
  if (!spec) return std::nullopt;
  PropertiesRequest request{std::move(*spec), {}, core::InertiaModel::kRigidBody};
  request.pivot_from_knob_m = reader.MaybeNumber("pivot_from_knob_m", AnyNumber());
  std::string inertia_model = "rigid_body";
  reader.OptionalString("inertia_model", &inertia_model, {"rigid_body", "slender_rod"});
  if (!reader.Finish()) return std::nullopt;
  if (core::Refusal refusal; request.pivot_from_knob_m.has_value() &&
                             !core::ValidatePivotFromKnob(*request.pivot_from_knob_m, &refusal)) {
    CoreRefusal(refusal, "", error);
    return std::nullopt;
  }
  if (inertia_model == "slender_rod") request.inertia_model = core::InertiaModel::kSlenderRod;
  return request;
}

// The answer's members: the properties, the model and method, and `warnings` (if any).
template <class Out>
void WriteBatProperties(const PropertiesRequest& request, const core::MassProperties& properties,
                        const std::vector<std::string>& warnings, Out& out) {
  WriteProperties(properties, request.spec.bat.LengthM(), request.pivot_from_knob_m, out);
  out.Set("method", "closed_form");
  out.Set("models_used", std::vector<std::string>{"mass_properties"});
  if (!warnings.empty()) out.Set("warnings", warnings);
}

// A closed form: no summary and no provenance, as documented in docs/api.md.
const Endpoint<PropertiesRequest, core::MassProperties>& PropertiesEndpoint() {
  static const auto endpoint = [] {
    Endpoint<PropertiesRequest, core::MassProperties> e;
    e.parse = ParseProperties;
    e.run = [](const PropertiesRequest& request, const Context&) {
      // Computed once, by ParseBat's check.
      return request.spec.properties->Of(request.inertia_model);
    };
    e.render = [](const PropertiesRequest& request, const core::MassProperties& properties) {
      return TreeOf([&](TreeObject& out) { WriteBatProperties(request, properties, {}, out); });
    };
    e.write = [](const PropertiesRequest& request, const core::MassProperties& properties,
                 const std::vector<std::string>& warnings,
                 TextObject& out) { WriteBatProperties(request, properties, warnings, out); };
    e.warnings = [](const PropertiesRequest& request, const core::MassProperties& properties) {
      return core::SanityWarnings(&request.spec.bat, &properties, nullptr, nullptr);
    };
    return e;
  }();
  return endpoint;
}

}  // namespace

Response HandleBatProperties(const Request& request, const Context& context) {
  return ServeEndpoint(PropertiesEndpoint(), request, context);
}

}  // namespace sweetspot::api

namespace sweetspot::api {
namespace {

// The three-segment shape of a parsed bat: its own for the three_segment
// form, the paper's for the paper presets; nullopt for general profiles.
std::optional<core::ThreeSegmentShape> ThreeSegmentOf(const BatSpec& spec) {
  if (spec.three_segment) return spec.three_segment;
  const core::ThreeSegmentShape paper = core::PaperThreeSegmentShape();
  const auto knots = paper.Knots();
  if (spec.bat.knots.size() != knots.size()) return std::nullopt;
  for (std::size_t i = 0; i < knots.size(); ++i) {
    if (spec.bat.knots[i].x_m != knots[i].x_m || spec.bat.knots[i].radius_m != knots[i].radius_m) {
      return std::nullopt;
    }
  }
  return paper;
}

nlohmann::json ThreeSegmentJson(const core::ThreeSegmentShape& s) {
  return {{"length_m", s.length_m},
          {"handle_radius_m", s.handle_radius_m},
          {"barrel_radius_m", s.barrel_radius_m},
          {"taper_start_m", s.taper_start_m},
          {"taper_end_m", s.taper_end_m}};
}

// The fitted bat as the request wrote its bat: a block the request gave (its three_segment, its
// fill) with each number in the form given ("taper_start_in", "barrel_diameter_in"), the wall
// as given ("wall_thickness_in"); a block the request did not write (a preset's), in inches when
// an unknown was written in a trade form ("taper_start_in"), else SI.
void InRequestUnits(const nlohmann::json& request_bat, bool trade_unknowns,
                    nlohmann::json* bat) {
  for (const char* block : {"three_segment", "fill"}) {
    if (!bat->contains(block)) continue;
    if (const auto given = request_bat.find(block);
        given != request_bat.end() && given->is_object()) {
      ToFormOf(&(*bat)[block], *given);
    } else if (trade_unknowns) {
      ToTradeForm(&(*bat)[block]);
    }
  }
  if (const auto wall = bat->find("wall_thickness_m"); wall != bat->end()) {
    if (request_bat.contains("wall_thickness_in") ||
        (!request_bat.contains("wall_thickness_m") && trade_unknowns)) {
      (*bat)["wall_thickness_in"] = wall->get<double>() / core::kMetresPerInch;
      bat->erase("wall_thickness_m");
    }
  }
}

// The fitted bat in the request's form: three_segment with the fitted
// dimensions, material (object if its density was fitted), wall and fill.
nlohmann::json FittedBatJson(const core::ShapeFitResult& fit, const BatSpec& spec) {
  nlohmann::json bat{{"three_segment", ThreeSegmentJson(fit.shape)}};
  const bool density_fitted = fit.material.density_kg_m3 != spec.bat.material.density_kg_m3;
  if (density_fitted || !core::FindMaterial(fit.material.name)) {
    nlohmann::json material{{"name", fit.material.name},
                            {"density_kg_m3", fit.material.density_kg_m3},
                            {"youngs_modulus_pa", fit.material.youngs_modulus_pa},
                            {"poissons_ratio", fit.material.poissons_ratio}};
    if (fit.material.shear_modulus_pa > 0) {
      material["shear_modulus_pa"] = fit.material.shear_modulus_pa;
    }
    if (fit.material.cor) material["cor"] = *fit.material.cor;
    bat["material"] = std::move(material);
  } else {
    bat["material"] = fit.material.name;
  }
  if (fit.wall_thickness_m > 0) bat["wall_thickness_m"] = fit.wall_thickness_m;
  if (fit.fill) {
    const bool fill_density_fitted =
        spec.bat.fill && fit.fill->material.density_kg_m3 != spec.bat.fill->material.density_kg_m3;
    nlohmann::json fill_material =
        fit.fill->IsEmpty() ? nlohmann::json("empty") : nlohmann::json(fit.fill->material.name);
    if (fill_density_fitted) {
      fill_material = {{"name", fit.fill->material.name},
                       {"density_kg_m3", fit.fill->material.density_kg_m3},
                       {"youngs_modulus_pa", fit.fill->material.youngs_modulus_pa},
                       {"poissons_ratio", fit.fill->material.poissons_ratio}};
    }
    bat["fill"] = {{"material", std::move(fill_material)},
                   {"diameter_m", fit.fill->diameter_m},
                   {"depth_m", fit.fill->depth_m}};
  }
  return bat;
}

// A parsed /v1/bat/fit request: the bat as given, the fit problem and the solver's options.
struct FitRequest {
  BatSpec spec;
  core::ShapeFitProblem problem;
  core::ShapeFitOptions options;
  // Per unknown, its name as the request wrote it ("barrel_diameter_in") and the factor of
  // its value and bounds to core's SI (0.0127); empty for the default unknowns.
  std::vector<std::pair<std::string, double>> written;
  // The request's bat as written, so that the fitted bat is answered in its form and units.
  nlohmann::json request_bat;
  // Whether an unknown was written in a trade form ("taper_start_in"): a preset's shape is
  // then answered in inches.
  bool TradeUnknowns() const {
    return std::any_of(written.begin(), written.end(),
                       [](const auto& w) { return w.second != 1.0; });
  }

  // Core's refusal with an unknown named, and its bound given, as the request wrote them.
  core::Refusal AsWritten(core::Refusal refusal) const {
    const std::string& field = refusal.field;
    if (field.rfind("unknowns[", 0) != 0) return refusal;
    const std::size_t i = std::strtoul(field.c_str() + 9, nullptr, 10);
    if (i >= written.size()) return refusal;
    const auto& [name, to_si] = written[i];
    if (refusal.shown == core::FitUnknownName(problem.unknowns[i].variable)) refusal.shown = name;
    const bool bound = field.size() > 4 && (field.compare(field.size() - 4, 4, ".min") == 0 ||
                                            field.compare(field.size() - 4, 4, ".max") == 0);
    if (bound && to_si != 1.0 && std::isfinite(refusal.value) && refusal.QuotesValue()) {
      refusal.value /= to_si;
      refusal.shown = core::FormatNumber(refusal.value);
      refusal.rule += " (in SI: " + core::FormatNumber(refusal.value * to_si) + ")";
    }
    return refusal;
  }
};

// Reads "unknowns" (default: the paper's question, where the taper starts and ends).
// The three-segment fit's unknowns by name: the table of fields' fit names (api/fields.hpp), in
// core's kFitUnknownKinds order (the order the refusal of an unknown name lists them in).
const std::vector<std::string>& FitUnknownNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::pair<int, std::string>> ordered;
    for (const Field& field : Fields()) {
      if (field.fit_name.empty()) continue;
      const std::string name(field.fit_name);
      ordered.emplace_back(core::FitUnknownIndex(*core::FitUnknownFromName(name)), name);
    }
    std::sort(ordered.begin(), ordered.end());
    std::vector<std::string> out;
    for (auto& [variable, name] : ordered) out.push_back(std::move(name));
    return out;
  }();
  return names;
}

bool ReadFitUnknowns(ObjectReader& reader, const core::ThreeSegmentShape& shape,
                     core::ShapeFitProblem* problem,
                     std::vector<std::pair<std::string, double>>* written) {
  const nlohmann::json* unknowns = reader.Get("unknowns");
  if (unknowns == nullptr) {
    problem->unknowns = {{core::DesignVariableKind::kTaperStart, 0.0, shape.length_m},
                         {core::DesignVariableKind::kTaperEnd, 0.0, shape.length_m}};
    return reader.ok();
  }
  if (!unknowns->is_array() || unknowns->empty() || unknowns->size() > 10) {
    return reader.Fail("unknowns", "must be an array of 1 to 10 {\"name\", \"min\", \"max\"}");
  }
  for (std::size_t i = 0; i < unknowns->size(); ++i) {
    ObjectReader u((*unknowns)[i], "unknowns[" + std::to_string(i) + "]", reader.error());
    // A name of the table of fields (api/fields.hpp), in SI or a trade form
    // ("barrel_diameter_in", "wall_thickness_in"): the bounds are in its unit.
    std::string name;
    u.String("name", &name);
    const auto use = u.ok() ? ResolveField(name, FieldScope::kFitName) : std::nullopt;
    if (u.ok() && !use) {
      std::string refused;
      u.String("name", &refused, FitUnknownNames());  // the refusal that lists the names
      reader.error()->message += DidYouMeanField(name, FieldScope::kFitName);
      return false;
    }
    core::FitUnknown unknown;
    u.Number("min", AnyNumber(), &unknown.min);  // the bounds' ranges: core's problem.Validate
    u.Number("max", AnyNumber(), &unknown.max);
    if (!u.Finish()) return false;
    unknown.variable = *core::FitUnknownFromName(use->si);
    unknown.min *= use->to_si;  // core is SI
    unknown.max *= use->to_si;
    problem->unknowns.push_back(unknown);
    written->emplace_back(name, use->to_si);
  }
  return true;
}

// Reads "options" over defaults that never exceed the configured limits.
bool ReadFitOptions(ObjectReader& reader, const ApiLimits& limits, core::ShapeFitOptions* options) {
  options->max_time_s = std::min(options->max_time_s, limits.max_time_s);
  options->max_evaluations = std::min(options->max_evaluations, limits.max_iterations);
  const nlohmann::json* o = reader.Get("options");
  if (o == nullptr) return reader.ok();
  ObjectReader opt(*o, "options", reader.error());
  // The ranges are core's (ShapeFitOptions::Validate, in ParseFit); the budgets below are
  // the server's configured limits.
  opt.OptionalNumber("mass_scale_kg", AnyNumber(), &options->mass_scale_kg);
  opt.OptionalNumber("balance_point_scale_m", AnyNumber(), &options->balance_point_scale_m);
  opt.OptionalNumber("tolerance", AnyNumber(), &options->tolerance);
  long long max_evaluations = options->max_evaluations;
  opt.OptionalInteger("max_evaluations", 1, limits.max_iterations, &max_evaluations);
  options->max_evaluations = static_cast<int>(max_evaluations);
  opt.OptionalNumber("max_time_s", Positive(limits.max_time_s), &options->max_time_s);
  return opt.Finish();
}

std::optional<FitRequest> ParseFit(const nlohmann::json& body, const Context& context,
                                   ApiError* error) {
  ObjectReader reader(body, "", error);
  const nlohmann::json* bat_json = reader.Get("bat");
  if (bat_json == nullptr) {
    reader.Missing("bat");
    return std::nullopt;
  }
  auto spec = ParseBat(*bat_json, "bat", context.limits, error);
  if (!spec) return std::nullopt;
  const auto shape = ThreeSegmentOf(*spec);
  if (!shape) {
    reader.Fail("bat",
                "is not a three-segment bat (three_segment, or the paper-wood presets), whose "
                "unknowns are named by name: for any bat, name the unknowns by design-variable "
                "path ({\"path\": \"material.density_kg_m3\", \"min\", \"max\"})");
    return std::nullopt;
  }
  FitRequest request{std::move(*spec), {}, {}, {}, *bat_json};
  core::ShapeFitProblem& problem = request.problem;
  problem.shape = *shape;
  problem.material = request.spec.bat.material;
  problem.wall_thickness_m = request.spec.bat.wall_thickness_m;
  problem.fill = request.spec.bat.fill;
  if (request.spec.properties) {  // computed once, by ParseBat
    problem.bat_mass_properties = request.spec.properties->rigid_body;
  }

  const nlohmann::json* targets = reader.Get("targets");
  if (reader.ok() && targets == nullptr) reader.Missing("targets");
  if (!reader.ok()) return std::nullopt;
  ObjectReader t(*targets, "targets", error);
  problem.targets.mass_kg = t.MaybeNumber("mass_kg", AnyNumber());  // ranges: problem.Validate
  problem.targets.balance_point_m = t.MaybeNumber("balance_point_m", AnyNumber());
  if (!t.Finish()) return std::nullopt;
  if (!problem.targets.mass_kg && !problem.targets.balance_point_m) {
    SetError(error, ErrorCode::kMissingField, "targets", nullptr,
             "needs mass_kg, balance_point_m or both");
    return std::nullopt;
  }
  if (!ReadFitUnknowns(reader, *shape, &problem, &request.written) ||
      !ReadFitOptions(reader, context.limits, &request.options) || !reader.Finish()) {
    return std::nullopt;
  }
  if (core::Refusal why; !problem.ValidateSize(&why)) {
    CoreRefusal(request.AsWritten(why), "", error);
    return std::nullopt;
  }
  if (core::Refusal why; !request.options.Validate(&why)) {
    CoreRefusal(why, "options", error);
    return std::nullopt;
  }
  return request;
}

// A refused problem is the client's (400); a failed fit is ours (500).
std::optional<Response> FitFailure(const FitRequest& request, const core::ShapeFitResult& fit) {
  if (fit.summary.termination == core::Termination::kInvalidInput) {
    ApiError error;
    if (fit.summary.refusal) {
      CoreRefusal(request.AsWritten(*fit.summary.refusal), "", &error);
    } else {
      CoreRefusal(fit.summary, "", &error);
    }
    return ToResponse(error);
  }
  if (fit.summary.termination == core::Termination::kFailure) {
    return ErrorResponse(500, ErrorCode::kInternalError, "the fit failed: " + fit.summary.message);
  }
  return std::nullopt;
}

nlohmann::json RenderFit(const FitRequest& request, const core::ShapeFitResult& fit) {
  const core::ShapeFitProblem& problem = request.problem;
  nlohmann::json unknown_values = nlohmann::json::object();
  for (std::size_t i = 0; i < problem.unknowns.size() && i < fit.values.size(); ++i) {
    if (i < request.written.size()) {  // as the request wrote it, in its unit
      unknown_values[request.written[i].first] = fit.values[i] / request.written[i].second;
    } else {
      unknown_values[core::FitUnknownName(problem.unknowns[i].variable)] = fit.values[i];
    }
  }
  nlohmann::json residuals = nlohmann::json::object();
  if (problem.targets.mass_kg) residuals["mass_kg"] = fit.mass_residual_kg;
  if (problem.targets.balance_point_m) residuals["balance_point_m"] = fit.balance_point_residual_m;
  nlohmann::json summary{{"termination", core::TerminationName(fit.summary.termination)},
                         {"message", fit.summary.message},
                         {"backend", fit.summary.backend},
                         {"iterations", fit.summary.iterations},
                         {"evaluations", fit.summary.evaluations},
                         {"solve_time_s", fit.summary.solve_time_s},
                         {"metric", fit.metric},
                         {"kkt_error", fit.kkt_error},
                         {"warnings", fit.summary.warnings}};
  nlohmann::json bat = FittedBatJson(fit, request.spec);
  InRequestUnits(request.request_bat, request.TradeUnknowns(), &bat);
  return {{"bat", std::move(bat)},
          {"unknowns", std::move(unknown_values)},
          {"properties", PropertiesToJson(fit.properties, fit.bat.LengthM())},
          {"residuals", std::move(residuals)},
          {"metric",
           "((M - M*) / s_M)^2 + ((C - C*) / s_C)^2 over the targets given; s_M = M*, s_C = C* "
           "unless options set mass_scale_kg, balance_point_scale_m"},
          {"summary", std::move(summary)}};
}

// The provenance records the options the fit ran with (defaults included), not the body's.
ProvenanceInputs FitProvenance(const FitRequest& request, const nlohmann::json&) {
  const core::ShapeFitOptions& options = request.options;
  ProvenanceInputs inputs;
  inputs.options = {{"tolerance", options.tolerance},
                    {"max_evaluations", options.max_evaluations},
                    {"max_time_s", options.max_time_s},
                    {"scan_points", options.scan_points},
                    {"local_starts", options.local_starts}};
  return inputs;
}

// No bat of this family meets the targets (or the budget ran out): 422 with the closest
// feasible bat and its properties.
std::optional<Unmet> FitUnmet(const FitRequest&, const core::ShapeFitResult& fit) {
  if (fit.summary.termination == core::Termination::kConverged) return std::nullopt;
  const bool infeasible = fit.summary.termination == core::Termination::kInfeasible;
  return Unmet{infeasible ? ErrorCode::kInfeasible : ErrorCode::kTimeout,
               infeasible ? "no bat of this family meets the targets: " + fit.summary.message
                          : "the fit stopped before meeting the targets: " + fit.summary.message,
               "targets"};
}

const Endpoint<FitRequest, core::ShapeFitResult>& FitEndpoint() {
  static const auto endpoint = [] {
    Endpoint<FitRequest, core::ShapeFitResult> e;
    e.parse = ParseFit;
    e.run = [](const FitRequest& request, const Context&) {
      return core::FitShape(request.problem, request.options);
    };
    e.failure = FitFailure;
    e.render = RenderFit;
    e.provenance = FitProvenance;
    e.unmet = FitUnmet;
    return e;
  }();
  return endpoint;
}

// True when the fit's unknowns name design-variable paths ({"path"}, {"paths"} or
// {"scale_paths"}): the general fit, of any bat, by the design optimiser.
bool IsDesignFit(const nlohmann::json& body) {
  const auto unknowns = body.find("unknowns");
  if (unknowns == body.end() || !unknowns->is_array()) return false;
  return std::any_of(unknowns->begin(), unknowns->end(), [](const nlohmann::json& u) {
    return u.is_object() &&
           (u.contains("path") || u.contains("paths") || u.contains("scale_paths"));
  });
}

// The optimiser's names in a refusal, as the fit's request writes them.
std::string FitNames(std::string text) {
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"variables[", "unknowns["},
                                 {"constraints.", "targets."},
                                 {"constraints", "targets"}}) {
    for (std::size_t at = text.find(from); at != std::string::npos;
         at = text.find(from, at + to.size())) {
      text.replace(at, from.size(), to);
    }
  }
  return text;
}

// An optimiser answer (or its "closest") as a fit's: the bat, the unknowns' values, the
// properties, each target's residual (achieved - target, SI) and the summary.
nlohmann::json DesignFitAnswer(const nlohmann::json& design, const nlohmann::json& targets) {
  nlohmann::json residuals = nlohmann::json::object();
  const nlohmann::json& properties = design.value("properties", nlohmann::json::object());
  for (const char* si : {"mass_kg", "balance_point_m", "moi_six_inch_kg_m2", "length_m"}) {
    std::optional<double> target;
    if (targets.contains(si) && targets[si].is_number()) target = targets[si].get<double>();
    for (const TradeForm& form : TradeForms(si)) {
      if (targets.contains(form.key) && targets[form.key].is_number()) {
        target = targets[form.key].get<double>() * form.to_si;
      }
    }
    if (target && properties.contains(si) && properties[si].is_number()) {
      residuals[si] = properties[si].get<double>() - *target;
    }
  }
  nlohmann::json out{{"bat", design.value("bat", nlohmann::json())},
                     {"unknowns", design.value("variables", nlohmann::json::object())},
                     {"properties", properties},
                     {"residuals", std::move(residuals)},
                     {"method",
                      "the design optimiser: every target an equality constraint, the unknowns "
                      "its variables, and among the bats that meet the targets the one with the "
                      "least MOI about the 6-in point (objective min_moi)"}};
  for (const char* key : {"summary", "conflicts", "provenance", "timing_s", "warnings"}) {
    if (design.contains(key)) out[key] = design[key];
  }
  return out;
}

// The general fit: the request rewritten as /v1/optimize's (targets -> constraints, unknowns
// -> variables, objective min_moi) and its answer as a fit's.
Response HandleDesignFit(const nlohmann::json& body, const Request& request,
                         const Context& context) {
  nlohmann::json optimize = nlohmann::json::object();
  for (const auto& [key, value] : body.items()) {
    if (key == "targets") {
      optimize["constraints"] = value;
    } else if (key == "unknowns") {
      optimize["variables"] = value;
    } else if (key == "objective" || key == "variables" || key == "constraints") {
      return ErrorResponse(400, ErrorCode::kUnknownField,
                           key +
                               " is not a field of /v1/bat/fit (targets, unknowns, bat, "
                               "options)",
                           key);
    } else {
      optimize[key] = value;
    }
  }
  if (!optimize.contains("constraints")) {
    return ErrorResponse(400, ErrorCode::kMissingField, "targets: is required", "targets");
  }
  optimize["objective"] = "min_moi";
  Request inner = request;
  inner.path = "/v1/optimize";
  inner.body = optimize.dump();
  Response answer = HandleOptimize(inner, context);
  const nlohmann::json targets = body.value("targets", nlohmann::json::object());
  if (answer.status == 200) {
    answer.body = DesignFitAnswer(answer.body, targets);
  } else if (answer.status == 422 && answer.body.contains("closest")) {
    answer.body["closest"] = DesignFitAnswer(answer.body["closest"], targets);
    answer.body["field"] = "targets";
    answer.body["message"] = FitNames(answer.body.value("message", std::string()));
  } else if (answer.body.is_object()) {
    if (answer.body.contains("field") && answer.body["field"].is_string()) {
      answer.body["field"] = FitNames(answer.body["field"].get<std::string>());
    }
    if (answer.body.contains("message") && answer.body["message"].is_string()) {
      answer.body["message"] = FitNames(answer.body["message"].get<std::string>());
    }
  }
  return answer;
}

}  // namespace

Response HandleBatFit(const Request& request, const Context& context) {
  // A body that names design-variable paths goes to the general fit; any other to the
  // three-segment fit (whose refusal of a profile bat says how to ask the general one).
  ApiError error;
  if (const auto body = ParseBody(request.body, context.limits, &error);
      body && body->is_object() && IsDesignFit(*body)) {
    return HandleDesignFit(*body, request, context);
  }
  return ServeEndpoint(FitEndpoint(), request, context);
}

}  // namespace sweetspot::api
