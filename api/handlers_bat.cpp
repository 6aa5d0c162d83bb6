// POST /v1/bat/properties and POST /v1/bat/fit.
#include <algorithm>
#include <chrono>

#include "api/bat_json.hpp"
#include "api/handlers.hpp"
#include "core/presets.hpp"
#include "core/shape_fit.hpp"

namespace sweetspot::api {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

Response HandleBatProperties(const Request& request, const Context& context) {
  const auto start = std::chrono::steady_clock::now();
  Response failure;
  const auto body = ParseObjectBody(request, context, &failure);
  if (!body) return failure;
  ApiError error;
  ObjectReader reader(*body, "", &error);
  const nlohmann::json* bat_json = reader.Get("bat");
  if (bat_json == nullptr) {
    reader.Missing("bat");
    return ToResponse(error);
  }
  const auto spec = ParseBat(*bat_json, "bat", context.limits, &error);
  if (!spec) return ToResponse(error);
  std::optional<double> pivot = reader.MaybeNumber("pivot_from_knob_m", Between(-100.0, 100.0));
  std::string inertia_model = "rigid_body";
  reader.OptionalString("inertia_model", &inertia_model, {"rigid_body", "slender_rod"});
  if (!reader.Finish()) return ToResponse(error);

  const core::InertiaModel model = inertia_model == "slender_rod"
                                       ? core::InertiaModel::kSlenderRod
                                       : core::InertiaModel::kRigidBody;
  const core::MassProperties properties = core::ComputeMassProperties(spec->bat, model);
  nlohmann::json out = PropertiesToJson(properties, spec->bat.LengthM(), pivot);
  out["models_used"] = {"mass_properties"};
  out["method"] = "closed_form";
  out["timing_s"] = SecondsSince(start);
  return {200, std::move(out)};
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
    const bool fill_density_fitted = spec.bat.fill && fit.fill->material.density_kg_m3 !=
                                                          spec.bat.fill->material.density_kg_m3;
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

}  // namespace

Response HandleBatFit(const Request& request, const Context& context) {
  const auto start = std::chrono::steady_clock::now();
  Response failure;
  const auto body = ParseObjectBody(request, context, &failure);
  if (!body) return failure;
  ApiError error;
  ObjectReader reader(*body, "", &error);
  const nlohmann::json* bat_json = reader.Get("bat");
  if (bat_json == nullptr) {
    reader.Missing("bat");
    return ToResponse(error);
  }
  const auto spec = ParseBat(*bat_json, "bat", context.limits, &error);
  if (!spec) return ToResponse(error);
  const auto shape = ThreeSegmentOf(*spec);
  if (!shape) {
    reader.Fail("bat",
                "must be a three-segment bat (three_segment, or the paper-wood presets): the fit "
                "solves three-segment dimensions");
    return ToResponse(error);
  }
  core::ShapeFitProblem problem;
  problem.shape = *shape;
  problem.material = spec->bat.material;
  problem.wall_thickness_m = spec->bat.wall_thickness_m;
  problem.fill = spec->bat.fill;

  const nlohmann::json* targets = reader.Get("targets");
  if (reader.ok() && targets == nullptr) reader.Missing("targets");
  if (!reader.ok()) return ToResponse(error);
  {
    ObjectReader t(*targets, "targets", &error);
    problem.targets.mass_kg = t.MaybeNumber("mass_kg", Positive(1e4));
    problem.targets.balance_point_m = t.MaybeNumber("balance_point_m", Positive(100.0));
    if (!t.Finish()) return ToResponse(error);
    if (!problem.targets.mass_kg && !problem.targets.balance_point_m) {
      SetError(&error, ErrorCode::kMissingField, "targets", nullptr,
               "needs mass_kg, balance_point_m or both");
      return ToResponse(error);
    }
  }
  if (const nlohmann::json* unknowns = reader.Get("unknowns")) {
    if (!unknowns->is_array() || unknowns->empty() || unknowns->size() > 10) {
      reader.Fail("unknowns", "must be an array of 1 to 10 {\"name\", \"min\", \"max\"}");
      return ToResponse(error);
    }
    for (std::size_t i = 0; i < unknowns->size(); ++i) {
      ObjectReader u((*unknowns)[i], "unknowns[" + std::to_string(i) + "]", &error);
      std::string name;
      u.String("name", &name,
               {"taper_start_m", "taper_end_m", "length_m", "handle_radius_m", "barrel_radius_m",
                "density_kg_m3", "wall_thickness_m", "fill.diameter_m", "fill.depth_m",
                "fill.density_kg_m3"});
      core::FitUnknown unknown;
      u.Number("min", Between(0.0, 1e5), &unknown.min);
      u.Number("max", Between(0.0, 1e5), &unknown.max);
      if (!u.Finish()) return ToResponse(error);
      unknown.variable = *core::FitVariableFromName(name);
      problem.unknowns.push_back(unknown);
    }
  } else {
    // The paper's question: where do the taper start and end lie?
    problem.unknowns = {{core::FitVariable::kTaperStart, 0.0, shape->length_m},
                        {core::FitVariable::kTaperEnd, 0.0, shape->length_m}};
  }
  core::ShapeFitOptions options;
  // Defaults never exceed the configured limits.
  options.max_time_s = std::min(options.max_time_s, context.limits.max_time_s);
  options.max_evaluations = std::min(options.max_evaluations, context.limits.max_iterations);
  if (const nlohmann::json* o = reader.Get("options")) {
    ObjectReader opt(*o, "options", &error);
    opt.OptionalNumber("mass_scale_kg", NonNegative(1e4), &options.mass_scale_kg);
    opt.OptionalNumber("balance_point_scale_m", NonNegative(100.0), &options.balance_point_scale_m);
    opt.OptionalNumber("tolerance", Between(1e-15, 1e-1), &options.tolerance);
    long long max_evaluations = options.max_evaluations;
    opt.OptionalInteger("max_evaluations", 1, context.limits.max_iterations, &max_evaluations);
    options.max_evaluations = static_cast<int>(max_evaluations);
    opt.OptionalNumber("max_time_s", Positive(context.limits.max_time_s), &options.max_time_s);
    if (!opt.Finish()) return ToResponse(error);
  }
  if (!reader.Finish()) return ToResponse(error);
  if (core::Refusal why; !problem.Validate(&why)) {
    CoreRefusal(why, "", &error);
    return ToResponse(error);
  }

  const core::ShapeFitResult fit = core::FitShape(problem, options);
  if (fit.summary.termination == core::Termination::kInvalidInput) {
    CoreRefusal(fit.summary, "", &error);
    return ToResponse(error);
  }
  if (fit.summary.termination == core::Termination::kFailure) {
    return ErrorResponse(500, ErrorCode::kInternalError, "the fit failed: " + fit.summary.message);
  }
  nlohmann::json unknown_values = nlohmann::json::object();
  for (std::size_t i = 0; i < problem.unknowns.size() && i < fit.values.size(); ++i) {
    unknown_values[core::FitVariableName(problem.unknowns[i].variable)] = fit.values[i];
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
  nlohmann::json options_json{{"tolerance", options.tolerance},
                              {"max_evaluations", options.max_evaluations},
                              {"max_time_s", options.max_time_s},
                              {"scan_points", options.scan_points},
                              {"local_starts", options.local_starts}};
  nlohmann::json result{
      {"bat", FittedBatJson(fit, *spec)},
      {"unknowns", std::move(unknown_values)},
      {"properties", PropertiesToJson(fit.properties, fit.bat.LengthM())},
      {"residuals", std::move(residuals)},
      {"metric",
       "((M - M*) / s_M)^2 + ((C - C*) / s_C)^2 over the targets given; s_M = M*, s_C = C* "
       "unless options set mass_scale_kg, balance_point_scale_m"},
      {"summary", std::move(summary)},
      {"provenance", Provenance(*body, options_json)},
      {"timing_s", SecondsSince(start)}};
  if (fit.summary.termination == core::Termination::kConverged) return {200, std::move(result)};
  // No bat of this family meets the targets (or the budget ran out): 422 with
  // the closest feasible bat and its properties.
  const bool infeasible = fit.summary.termination == core::Termination::kInfeasible;
  nlohmann::json out{
      {"code", ErrorCodeName(infeasible ? ErrorCode::kInfeasible : ErrorCode::kTimeout)},
      {"message", infeasible
                      ? "no bat of this family meets the targets: " + fit.summary.message
                      : "the fit stopped before meeting the targets: " + fit.summary.message},
      {"field", "targets"},
      {"closest", std::move(result)}};
  return {422, std::move(out)};
}

}  // namespace sweetspot::api
