// POST /v1/optimize: Ipopt design of a bat's profile and material under
// length, mass, balance-point, MOI, diameter, taper and league-rule
// constraints (min_sting: NLopt COBYLA over the flexible beam's sting). The
// answer's bat is in the request's own form, so it can be sent straight back
// to /v1/bat/properties.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "api/bat_json.hpp"
#include "api/handlers/endpoint.hpp"
#include "api/handlers/handlers.hpp"
#include "api/handlers/optimize_request.hpp"
#include "api/handlers/optimize_variables.hpp"
#include "api/json_path.hpp"
#include "api/scene_json.hpp"
#include "api/trade_units.hpp"
#include "core/optimize/design_cor.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/scene/sanity.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

Json Finite(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

// A constraint: a number (equality) or {"min", "max"} (either optional). The limits' ranges
// are core's (DesignProblem::Validate).
bool ReadRange(ObjectReader& reader, const char* key, std::optional<core::DesignRange>* out) {
  const NumberRule rule = AnyNumber();
  // The SI key or a trade spelling ("mass_oz": {"min": 30, "max": 31}), converted to SI.
  std::string_view given_as;
  double to_si = 1.0;
  const Json* value = reader.GetInUnits(key, &given_as, &to_si);
  if (value == nullptr || !reader.ok()) return reader.ok();
  if (value->is_number()) {
    double v = 0;
    if (!reader.OptionalNumber(key, rule, &v)) return false;
    *out = core::DesignRange::Equal(v);
    return true;
  }
  ObjectReader range(*value, reader.PathOf(given_as), reader.error());
  core::DesignRange r;
  r.min = range.MaybeNumber("min", rule);
  r.max = range.MaybeNumber("max", rule);
  if (r.min) *r.min *= to_si;
  if (r.max) *r.max *= to_si;
  if (!range.Finish()) return false;
  if (!r.min && !r.max) return range.Fail("min", "give min, max or both", ErrorCode::kMissingField);
  if (r.min && r.max && *r.min > *r.max) {
    return range.Fail("max", "must be >= min = " + Show(Json(*r.min)));
  }
  *out = r;
  return true;
}

bool ReadConstraints(ObjectReader& top, core::DesignConstraints* c) {
  const Json* value = top.Get("constraints");
  if (value == nullptr || !top.ok()) return top.ok();
  ObjectReader reader(*value, "constraints", top.error());
  // Presence and types here; the ranges are core's (DesignProblem::Validate).
  ReadRange(reader, "length_m", &c->length_m);
  ReadRange(reader, "mass_kg", &c->mass_kg);
  ReadRange(reader, "balance_point_m", &c->balance_point_m);
  ReadRange(reader, "moi_six_inch_kg_m2", &c->moi_six_inch_kg_m2);
  c->max_barrel_diameter_m = reader.MaybeNumber("max_barrel_diameter_m", AnyNumber());
  c->min_handle_diameter_m = reader.MaybeNumber("min_handle_diameter_m", AnyNumber());
  if (const Json* region = reader.Get("handle_region_from_knob_m")) {
    // [from, to], m from the knob; the numbers' ranges and order are core's.
    if (!region->is_array() || region->size() != 2 || !(*region)[0].is_number() ||
        !(*region)[1].is_number()) {
      return reader.Fail("handle_region_from_knob_m",
                         "must be [from, to]: two numbers, m from the knob");
    }
    c->handle_region_from_knob_m =
        std::pair{(*region)[0].get<double>(), (*region)[1].get<double>()};
  }
  c->min_frequency_hz = reader.MaybeNumber("min_frequency_hz", AnyNumber());
  c->bbcor_max = reader.MaybeNumber("bbcor_max", AnyNumber());
  if (const Json* taper = reader.Get("taper")) {
    if (taper->is_string() && taper->get<std::string>() == "non_decreasing") {
      c->taper = core::TaperRule::kNonDecreasing;
    } else if (taper->is_object()) {
      ObjectReader t(*taper, "constraints.taper", top.error());
      t.Number("max_slope", AnyNumber(), &c->max_taper_slope);
      t.OptionalInt("first_knot", &c->taper_first_knot);
      t.OptionalInt("last_knot", &c->taper_last_knot);
      if (!t.Finish()) return false;
      c->taper = core::TaperRule::kMaxSlope;
    } else {
      return reader.Fail("taper", "must be \"non_decreasing\" or {\"max_slope\": dr/dx}");
    }
  }
  if (const Json* rules = reader.Get("rules")) {
    std::vector<Json> names;
    if (rules->is_string()) {
      names.push_back(*rules);
    } else if (rules->is_array()) {
      names.assign(rules->begin(), rules->end());
    } else {
      return reader.Fail("rules", "must be a rule-set name or an array of names");
    }
    for (const Json& name : names) {
      const auto rule =
          name.is_string() ? core::ParseRuleSet(name.get<std::string>()) : std::nullopt;
      if (!rule) return reader.Fail("rules", "must name rule sets among mlb-wood, bbcor, usssa");
      c->rules.push_back(*rule);
    }
  }
  return reader.Finish();
}

// "options": the solver's settings, and "flexible" (min_sting: the flexible
// beam's settings, as for /v1/sweet-spot). Without "backend", min_sting runs
// nlopt_cobyla (the only solver it can use) and the other objectives ipopt.
bool ReadOptions(ObjectReader& top, const ApiLimits& limits, core::DesignObjective objective,
                 core::DesignOptions* o, core::FlexibleOptions* flexible,
                 core::DistanceOptions* distance, core::CollisionModel* model) {
  // Defaults never exceed the configured limits.
  o->max_iterations = std::min(o->max_iterations, limits.max_iterations);
  o->max_time_s = std::min(o->max_time_s, limits.max_time_s);
  // Core enforces the configured cap on the variables (--max-design-variables).
  o->max_variables = static_cast<int>(std::min<std::size_t>(
      limits.max_design_variables, static_cast<std::size_t>(std::numeric_limits<int>::max())));
  ClampToLimits(limits, flexible);
  // The objectives without a derivative: COBYLA unless another backend is asked for (core
  // then solves them by COBYLA anyway, with a warning).
  const bool sting = objective == core::DesignObjective::kMinSting ||
                     objective == core::DesignObjective::kMaxDistance;
  if (sting) o->backend = core::DesignBackend::kNloptCobyla;
  // Without "backend" the optimiser chooses (DesignOptions::choose_backend): NLopt SLSQP for a
  // small lifted problem when its answer is certified, Ipopt otherwise.
  o->choose_backend = !sting;
  const Json* value = top.Get("options");
  if (value == nullptr || !top.ok()) return top.ok();
  ObjectReader reader(*value, "options", top.error());
  std::string backend = sting ? "nlopt_cobyla" : "ipopt", hessian = "limited_memory",
              check = "none";
  if (reader.Has("backend")) o->choose_backend = false;
  reader.OptionalString("backend", &backend, {"ipopt", "nlopt_slsqp", "nlopt_cobyla"});
  reader.OptionalString("hessian", &hessian, {"limited_memory", "exact"});
  reader.OptionalString("derivative_check", &check, {"none", "first_order", "second_order"});
  // The exit-speed model: the closed forms only (the design's derivatives are exact).
  std::string model_name = "auto";
  reader.OptionalString("model", &model_name, {"auto", "rigid_pivot", "free_bat"});
  *model = *core::ParseCollisionModel(model_name);
  o->backend = backend == "ipopt"         ? core::DesignBackend::kIpopt
               : backend == "nlopt_slsqp" ? core::DesignBackend::kNloptSlsqp
                                          : core::DesignBackend::kNloptCobyla;
  o->hessian = hessian == "exact" ? core::HessianMode::kExact : core::HessianMode::kLimitedMemory;
  o->derivative_check = check == "first_order"    ? core::DerivativeCheck::kFirstOrder
                        : check == "second_order" ? core::DerivativeCheck::kSecondOrder
                                                  : core::DerivativeCheck::kNone;
  // The budgets are the server's configured limits (checked here); the seed is any integer
  // a JSON number holds exactly; the other ranges are core's (DesignOptions::Validate).
  long long iterations = o->max_iterations;
  long long seed = 1;
  reader.OptionalInteger("max_iterations", 1, limits.max_iterations, &iterations);
  reader.OptionalInt("starts", &o->starts);
  reader.OptionalInteger("seed", 0, 1LL << 53, &seed);
  o->max_iterations = static_cast<int>(iterations);
  o->seed = static_cast<std::uint64_t>(seed);
  reader.OptionalNumber("max_time_s", Positive(limits.max_time_s), &o->max_time_s);
  reader.OptionalNumber("max_cpu_time_s", NonNegative(limits.max_time_s), &o->max_cpu_time_s);
  reader.OptionalNumber("tolerance", AnyNumber(), &o->tolerance);
  reader.OptionalNumber("constraint_tolerance", AnyNumber(), &o->constraint_tolerance);
  reader.OptionalNumber("feasibility_tolerance", AnyNumber(), &o->feasibility_tolerance);
  reader.OptionalBool("explain_infeasibility", &o->explain_infeasibility);
  reader.OptionalNumber("stationarity_tolerance", AnyNumber(), &o->stationarity_tolerance);
  reader.OptionalNumber("complementarity_tolerance", AnyNumber(), &o->complementarity_tolerance);
  if (const Json* f = reader.Get("flexible")) {
    if (!ReadFlexibleOptions(*f, reader.PathOf("flexible"), limits, flexible, top.error())) {
      return false;
    }
  }
  // max_distance: the distance sweet spot's region and tolerances, as /v1/sweet-spot reads them.
  if (const Json* d = reader.Get("distance")) {
    if (objective != core::DesignObjective::kMaxDistance) {
      return reader.Fail("distance", "applies to objective max_distance only");
    }
    if (!ReadDistanceOptions(*d, reader.PathOf("distance"), distance, top.error())) return false;
  }
  if (!reader.Finish()) return false;
  if (core::Refusal refusal; !o->Validate(&refusal)) {
    return CoreRefusal(refusal, "options", top.error());
  }
  return true;
}

}  // namespace

namespace optimize_detail {

std::optional<OptimizeRequest> ParseOptimize(const Json& body, const Context& context,
                                             ApiError* error) {
  ObjectReader reader(body, "", error);
  const Json* bat_json = reader.Get("bat");
  if (bat_json == nullptr) {
    reader.Missing("bat");
    return std::nullopt;
  }
  const auto spec = ParseBat(*bat_json, "bat", context.limits, error);
  if (!spec) return std::nullopt;
  // The design model's integrals and fixed-mesh beam (core/optimize) have no end cap, knob,
  // wall per knot or two-piece handle yet: refused rather than optimised without them.
  if (spec->bat.end_cap.has_value() || spec->bat.knob.has_value() || spec->bat.HasKnotWalls() ||
      spec->bat.handle.has_value()) {
    const char* part = spec->bat.end_cap.has_value()  ? "bat.end_cap"
                       : spec->bat.knob.has_value()   ? "bat.knob"
                       : spec->bat.handle.has_value() ? "bat.handle"
                                                      : "bat.profile.knots";
    SetError(error, ErrorCode::kInvalidValue, part, nullptr,
             "is not taken by /v1/optimize yet (its design model has no end cap, knob, wall "
             "per knot or two-piece handle); "
             "/v1/sweet-spot, /v1/compare and /v1/explore take it");
    return std::nullopt;
  }
  OptimizeRequest request;
  request.request_bat = *bat_json;
  core::DesignProblem& problem = request.problem;
  problem.bat = spec->bat;
  problem.three_segment = spec->three_segment;
  core::Scene scene;
  if (!ReadSceneCommon(reader, &scene)) return std::nullopt;
  // A swing by its bat speed (swing.bat_speed_mps or _mph) is core's to resolve: omega per
  // design from the design's length (DesignModel; the answer's sweet_spot.angular_speed_rad_s).
  problem.ball = scene.ball;
  problem.swing = scene.swing;
  problem.cor = scene.cor;
  problem.inertia_model = scene.inertia_model;
  problem.environment = scene.environment;  // max_distance: the flight's air and aero
  problem.aero = scene.aero;
  if (!ReadVariables(reader, context.limits, &problem, &request.material_choices,
                     &request.variable_names) ||
      !ReadConstraints(reader, &problem.constraints)) {
    return std::nullopt;
  }
  request.objective = "max_exit_speed";
  reader.OptionalString("objective", &request.objective,
                        {"max_exit_speed", "max_exit_speed_swing_weight", "widest_sweet_zone",
                         "min_moi", "min_sting", "max_distance"});
  problem.objective = *core::ParseDesignObjective(request.objective);
  request.base_properties = spec->properties->Of(scene.inertia_model);
  problem.base_mass_properties = request.base_properties;  // computed once, by ParseBat
  request.cor_policy = core::ResolveDesignCor(scene, request.base_properties, &problem);
  reader.OptionalNumber("swing_weight_exponent", AnyNumber(), &problem.swing_weight_exponent);
  problem.swing_weight_reference_kg_m2 =
      reader.MaybeNumber("swing_weight_reference_kg_m2", AnyNumber());  // range: core's
  reader.OptionalNumber("sweet_zone_tolerance_mps", AnyNumber(), &problem.sweet_zone_tolerance_mps);
  core::CollisionModel model = core::CollisionModel::kAuto;
  if (!ReadOptions(reader, context.limits, problem.objective, &request.options, &problem.flexible,
                   &problem.distance, &model) ||
      !reader.Finish()) {
    return std::nullopt;
  }
  // "auto" as the scenes resolve it: the free bat, or the paper's rigid_pivot for its bats.
  scene.paper_bat = spec->paper;
  problem.model = core::ResolveExitModel(model, scene, &request.model_reason);
  if (problem.variables.empty()) {
    reader.Fail("variables", "needs at least one continuous variable besides a material choice");
    return std::nullopt;
  }
  if (core::Refusal refusal; !problem.Validate(&refusal)) {
    CoreRefusal(request.variable_names.AsWritten(refusal), "", error);
    return std::nullopt;
  }
  return request;
}

}  // namespace optimize_detail

namespace {

using optimize_detail::OptimizeRequest;
using optimize_detail::ParseOptimize;
using optimize_detail::ResultToJson;

// What the optimiser returned: one design, or one per material and the best of them.
struct OptimizeResult {
  bool by_material = false;
  core::MaterialChoiceResult choice;  // by_material
  core::DesignResult single;          // otherwise

  // The design answered with; null when no material gives a usable design.
  const core::DesignResult* Chosen() const {
    if (!by_material) return &single;
    if (choice.best < 0) return nullptr;
    return &choice.per_material[static_cast<std::size_t>(choice.best)].result;
  }
};

OptimizeResult RunOptimize(const OptimizeRequest& request, const Context& context) {
  OptimizeResult result;
  result.by_material = !request.material_choices.empty();
  if (result.by_material) {
    result.choice = core::OptimizeOverMaterials(request.problem, request.material_choices,
                                                request.options, context.progress);
  } else {
    result.single = core::OptimizeDesign(request.problem, request.options, context.progress);
  }
  return result;
}

// No usable material (422), or a problem the optimiser refused (400).
std::optional<Response> OptimizeFailure(const OptimizeRequest& request,
                                        const OptimizeResult& result) {
  const core::DesignResult* chosen = result.Chosen();
  if (chosen == nullptr) {
    return ErrorResponse(422, ErrorCode::kInfeasible,
                         "no material gives a usable design: " + result.choice.summary.message,
                         "variables");
  }
  if (chosen->summary.termination == core::Termination::kInvalidInput) {
    ApiError error;
    if (chosen->summary.refusal) {
      CoreRefusal(request.variable_names.AsWritten(*chosen->summary.refusal), "", &error);
    } else {
      CoreRefusal(chosen->summary, "", &error);
    }
    return ToResponse(error);
  }
  return std::nullopt;
}

Json RenderOptimize(const OptimizeRequest& request, const OptimizeResult& result) {
  Json out = ResultToJson(*result.Chosen(), request.request_bat, request.variable_names);
  // The verdicts' tolerance (each active constraint's "satisfied"), relative to a constraint's
  // scale.
  out["summary"]["feasibility_tolerance"] = request.options.feasibility_tolerance;
  if (result.by_material) {
    Json per_material = Json::array();
    for (const auto& m : result.choice.per_material) {
      per_material.push_back({{"material", m.material},
                              {"termination", core::TerminationName(m.result.summary.termination)},
                              {"message", m.result.summary.message},
                              {"objective_value", Finite(m.result.objective_value)}});
    }
    out["materials"] = std::move(per_material);
    // The bat comes back in the chosen material: by name, or written out whole when a
    // material field is also a variable (the request's own material object would be stale).
    const core::DesignResult& chosen = *result.Chosen();
    const bool material_field_varies =
        std::any_of(chosen.variables.begin(), chosen.variables.end(),
                    [](const core::DesignValue& v) { return v.path.rfind("material.", 0) == 0; });
    if (material_field_varies) {
      out["bat"]["material"] = optimize_detail::MaterialInRequestForm(chosen.bat.material);
    } else {
      out["bat"]["material"] =
          result.choice.per_material[static_cast<std::size_t>(result.choice.best)].material;
    }
  }
  // Where the COR came from: the request, the ball's law, or the chosen design's material.
  out["cor_source"] = request.cor_policy.Describe(result.Chosen()->bat.material.name);
  out["objective"] = request.objective;
  if (request.problem.objective != core::DesignObjective::kMinMoi) {
    out["sweet_spot"]["model"] = core::CollisionModelName(request.problem.model);
    out["sweet_spot"]["model_reason"] = request.model_reason;
  }
  return out;
}

// Infeasible: 422 with the closest design. Converged, no_convergence and failure are 200s
// whose summary says which.
std::optional<Unmet> OptimizeUnmet(const OptimizeRequest&, const OptimizeResult& result) {
  const core::DesignResult& chosen = *result.Chosen();
  if (chosen.summary.termination != core::Termination::kInfeasible) return std::nullopt;
  std::string message = "no design meets the constraints";
  if (!chosen.conflicts.empty()) message += ": " + chosen.conflicts.front().message;
  return Unmet{ErrorCode::kInfeasible, std::move(message), "constraints"};
}

const Endpoint<OptimizeRequest, OptimizeResult>& OptimizeEndpoint() {
  static const auto endpoint = [] {
    Endpoint<OptimizeRequest, OptimizeResult> e;
    e.parse = ParseOptimize;
    e.run = RunOptimize;
    e.failure = OptimizeFailure;
    e.render = RenderOptimize;
    e.warnings = [](const OptimizeRequest& request, const OptimizeResult&) {
      // The base design's (the designs the solver finds are bounded by the variables).
      const core::DesignProblem& p = request.problem;
      return core::SanityWarnings(&p.bat, &request.base_properties, &p.ball, &p.swing);
    };
    e.provenance = [](const OptimizeRequest& request, const Json& body) {
      return BodyOptions(body, request.options.seed);
    };
    e.unmet = OptimizeUnmet;
    return e;
  }();
  return endpoint;
}

}  // namespace

Response HandleOptimize(const Request& request, const Context& context) {
  const auto start = std::chrono::steady_clock::now();
  Response refused;
  std::optional<Json> body = ParseObjectBody(request, context, &refused);
  if (!body) return refused;
  if (body->contains("frontier")) {
    return optimize_detail::HandleFrontier(std::move(*body), context, start);
  }
  Request parsed = request;  // the body parsed once: ServeEndpoint takes it from here
  parsed.parsed_body = std::make_shared<Json>(std::move(*body));
  return ServeEndpoint(OptimizeEndpoint(), parsed, context);
}

}  // namespace sweetspot::api
