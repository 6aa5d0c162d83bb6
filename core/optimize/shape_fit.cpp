// The shape fit: its checks, and the scan, SLSQP and Gauss-Newton stages over the least-squares
// design problem of core/optimize/shape_fit_model.hpp (the design code's parametrisation and AD,
// the one NLopt trampoline). See shape_fit.hpp.
#include "core/optimize/shape_fit.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/numerics/nlopt_run.hpp"
#include "core/numerics/termination.hpp"
#include "core/optimize/design_integrals.hpp"
#include "core/optimize/shape_fit_model.hpp"

namespace sweetspot::core {
namespace {

using fit_detail::FitConstraint;
using fit_detail::kNumFitVariables;
using fit_detail::ShapeFitModel;

constexpr const char* kVariableName[kNumFitVariables] = {
    "taper_start_m",   "taper_end_m",       "length_m",         "handle_radius_m",
    "barrel_radius_m", "density_kg_m3",     "wall_thickness_m", "fill.diameter_m",
    "fill.depth_m",    "fill.density_kg_m3"};

// Builds the bat of the family at parameters t (DesignParameterLayout{4}).
void BuildBat(const ShapeFitProblem& problem, const std::vector<double>& t, ShapeFitResult* out) {
  const auto value = [&t](DesignVariableKind v) { return fit_detail::FitValue(t, v); };
  out->shape.taper_start_m = value(DesignVariableKind::kTaperStart);
  out->shape.taper_end_m = value(DesignVariableKind::kTaperEnd);
  out->shape.length_m = value(DesignVariableKind::kLength);
  out->shape.handle_radius_m = value(DesignVariableKind::kHandleRadius);
  out->shape.barrel_radius_m = value(DesignVariableKind::kBarrelRadius);
  out->material = problem.material;
  out->material.density_kg_m3 = value(DesignVariableKind::kDensity);
  out->wall_thickness_m = value(DesignVariableKind::kWallThickness);
  out->fill = problem.fill;
  if (out->fill.has_value()) {
    out->fill->diameter_m = value(DesignVariableKind::kFillDiameter);
    out->fill->depth_m = value(DesignVariableKind::kFillDepth);
    out->fill->material.density_kg_m3 = value(DesignVariableKind::kFillDensity);
  }
  out->bat = MakeThreeSegmentBat(out->shape, out->material);
  out->bat.wall_thickness_m = out->wall_thickness_m;
  out->bat.fill = out->fill;
  out->properties = ComputeMassProperties(out->bat, InertiaModel::kRigidBody);
  out->values.clear();
  for (const FitUnknown& u : problem.unknowns) out->values.push_back(value(u.variable));
}

// Radical-inverse (Halton) point `index` in [0, 1)^n: a deterministic scan.
double RadicalInverse(int index, int base) {
  double result = 0.0;
  double f = 1.0 / base;
  while (index > 0) {
    result += f * (index % base);
    index /= base;
    f /= base;
  }
  return result;
}

std::string DescribeTargets(const ShapeFitProblem& problem) {
  std::string out;
  if (problem.targets.mass_kg.has_value()) {
    out += "mass_kg = " + FormatNumber(*problem.targets.mass_kg);
  }
  if (problem.targets.balance_point_m.has_value()) {
    if (!out.empty()) out += " and ";
    out += "balance_point_m = " + FormatNumber(*problem.targets.balance_point_m);
  }
  return out;
}

std::string DescribeUnknowns(const ShapeFitProblem& problem) {
  std::string out;
  for (const FitUnknown& u : problem.unknowns) {
    if (!out.empty()) out += ", ";
    out += std::string(FitUnknownName(u.variable)) + " in [" + FormatNumber(u.min) + ", " +
           FormatNumber(u.max) + "]";
  }
  return out;
}

// Smallest target or scale of the fit's metric, kg or m: residuals divided by
// less than this can overflow to inf.
constexpr double kMinMetricScale = 1e-6;

}  // namespace

int FitUnknownIndex(DesignVariableKind kind) {
  for (int i = 0; i < kNumFitUnknowns; ++i) {
    if (kFitUnknownKinds[i] == kind) return i;
  }
  return -1;
}

const char* FitUnknownName(DesignVariableKind kind) {
  const int i = FitUnknownIndex(kind);
  return i >= 0 ? kVariableName[i] : "unknown";
}

std::optional<DesignVariableKind> FitUnknownFromName(std::string_view name) {
  for (int i = 0; i < kNumFitUnknowns; ++i) {
    if (name == kVariableName[i]) return kFitUnknownKinds[i];
  }
  return std::nullopt;
}

bool ShapeFitOptions::Validate(Refusal* why) const {
  if (!std::isfinite(mass_scale_kg) || mass_scale_kg < 0.0) {
    return Refuse(why, "mass_scale_kg", mass_scale_kg,
                  "must be finite and non-negative (0 = the target)");
  }
  if (!std::isfinite(balance_point_scale_m) || balance_point_scale_m < 0.0) {
    return Refuse(why, "balance_point_scale_m", balance_point_scale_m,
                  "must be finite and non-negative (0 = the target)");
  }
  if (mass_scale_kg > kMaxFitMassKg) {
    return Refuse(why, "mass_scale_kg", mass_scale_kg,
                  RangeRule(0.0, kMaxFitMassKg) + " (0 = the target)");
  }
  if (balance_point_scale_m > kMaxBatLengthM) {
    return Refuse(why, "balance_point_scale_m", balance_point_scale_m,
                  RangeRule(0.0, kMaxBatLengthM) + " (0 = the target)");
  }
  // Smaller scales overflow the scaled residuals to inf (found by fuzzing).
  if (mass_scale_kg > 0.0 && mass_scale_kg < kMinMetricScale) {
    return Refuse(why, "mass_scale_kg", mass_scale_kg, "must be 0 (the target) or at least 1e-06");
  }
  if (balance_point_scale_m > 0.0 && balance_point_scale_m < kMinMetricScale) {
    return Refuse(why, "balance_point_scale_m", balance_point_scale_m,
                  "must be 0 (the target) or at least 1e-06");
  }
  if (!CheckInRange(why, "tolerance", tolerance, kMinFitTolerance, kMaxFitTolerance)) return false;
  if (!std::isfinite(kkt_tolerance) || !(kkt_tolerance > 0.0)) {
    return Refuse(why, "kkt_tolerance", kkt_tolerance, "must be finite and positive");
  }
  if (scan_points < 1) return Refuse(why, "scan_points", scan_points, "must be at least 1");
  if (local_starts < 1) return Refuse(why, "local_starts", local_starts, "must be at least 1");
  if (max_evaluations < 1) {
    return Refuse(why, "max_evaluations", max_evaluations, "must be at least 1");
  }
  if (!std::isfinite(max_time_s) || !(max_time_s > 0.0)) {
    return Refuse(why, "max_time_s", max_time_s, "must be finite and positive");
  }
  return true;
}

bool ShapeFitProblem::Validate(Refusal* why) const {
  if (!targets.mass_kg.has_value() && !targets.balance_point_m.has_value()) {
    return Refuse(why, TextRefusal("targets", "must give mass_kg, balance_point_m or both"));
  }
  if (targets.mass_kg.has_value() && !(std::isfinite(*targets.mass_kg) && *targets.mass_kg > 0.0)) {
    return Refuse(why, "targets.mass_kg", *targets.mass_kg, "must be finite and positive");
  }
  if (targets.balance_point_m.has_value() &&
      !(std::isfinite(*targets.balance_point_m) && *targets.balance_point_m > 0.0)) {
    return Refuse(why, "targets.balance_point_m", *targets.balance_point_m,
                  "must be finite and positive");
  }
  // A target is the metric's default scale: a smaller one overflows it (found by fuzzing).
  if (targets.mass_kg.has_value() && *targets.mass_kg < kMinMetricScale) {
    return Refuse(why, "targets.mass_kg", *targets.mass_kg, "must be at least 1e-06");
  }
  if (targets.balance_point_m.has_value() && *targets.balance_point_m < kMinMetricScale) {
    return Refuse(why, "targets.balance_point_m", *targets.balance_point_m,
                  "must be at least 1e-06");
  }
  if (targets.mass_kg.has_value() && *targets.mass_kg > kMaxFitMassKg) {
    return Refuse(why, "targets.mass_kg", *targets.mass_kg,
                  RangeRule(kMinMetricScale, kMaxFitMassKg));
  }
  if (targets.balance_point_m.has_value() && *targets.balance_point_m > kMaxBatLengthM) {
    return Refuse(why, "targets.balance_point_m", *targets.balance_point_m,
                  RangeRule(kMinMetricScale, kMaxBatLengthM));
  }
  if (unknowns.empty() || unknowns.size() > static_cast<std::size_t>(kNumFitVariables)) {
    return Refuse(why, "unknowns.size()", static_cast<double>(unknowns.size()),
                  "must be between 1 and 10");
  }
  std::vector<bool> unknown(static_cast<std::size_t>(kNumFitVariables), false);
  for (std::size_t i = 0; i < unknowns.size(); ++i) {
    const FitUnknown& u = unknowns[i];
    const int idx = FitUnknownIndex(u.variable);
    if (idx < 0) {
      return Refuse(why, IndexedField("unknowns", i, "variable"), static_cast<int>(u.variable),
                    "is not a fit unknown (a profile knot's kind)");
    }
    const char* name = kVariableName[idx];
    if (unknown[static_cast<std::size_t>(idx)]) {
      return Refuse(why, QuotedRefusal(IndexedField("unknowns", i, "variable"), name,
                                       "appears more than once"));
    }
    unknown[static_cast<std::size_t>(idx)] = true;
    if (fit_detail::IsFillVariable(u.variable) && !fill.has_value()) {
      return Refuse(
          why, QuotedRefusal(IndexedField("unknowns", i, "variable"), name, "the bat has no fill"));
    }
    if (!std::isfinite(u.min)) {
      return why == nullptr
                 ? false
                 : Refuse(why, IndexedField("unknowns", i, "min"), u.min, "must be finite");
    }
    if (!std::isfinite(u.max)) {
      return why == nullptr
                 ? false
                 : Refuse(why, IndexedField("unknowns", i, "max"), u.max, "must be finite");
    }
    if (!(u.max > u.min)) {
      return why == nullptr ? false
                            : Refuse(why, IndexedField("unknowns", i, "max"), u.max,
                                     "must be greater than " + IndexedField("unknowns", i, "min") +
                                         " = " + FormatNumber(u.min));
    }
    const DesignVariableKind v = u.variable;
    const bool must_be_positive =
        v == DesignVariableKind::kLength || v == DesignVariableKind::kHandleRadius ||
        v == DesignVariableKind::kBarrelRadius || v == DesignVariableKind::kDensity ||
        v == DesignVariableKind::kWallThickness;
    if (must_be_positive && !(u.min > 0.0)) {
      return why == nullptr
                 ? false
                 : Refuse(why, IndexedField("unknowns", i, "min"), u.min,
                          std::string("must be positive for ") + name +
                              (v == DesignVariableKind::kWallThickness ? " (the bat stays hollow)"
                                                                       : ""));
    }
    if (!must_be_positive && u.min < 0.0) {
      return why == nullptr ? false
                            : Refuse(why, IndexedField("unknowns", i, "min"), u.min,
                                     std::string("must be non-negative for ") + name);
    }
  }
  // The fixed values.
  const std::vector<double> t = fit_detail::StartParameters(*this);
  for (int i = 0; i < kNumFitVariables; ++i) {
    const DesignVariableKind v = kFitUnknownKinds[i];
    if (unknown[static_cast<std::size_t>(i)] ||
        (fit_detail::IsFillVariable(v) && !fill.has_value()))
      continue;
    const double value = fit_detail::FitValue(t, v);
    const char* field = fit_detail::FitUnknownField(v);
    if (!std::isfinite(value)) return Refuse(why, field, value, "must be finite");
    const bool must_be_positive =
        v == DesignVariableKind::kLength || v == DesignVariableKind::kHandleRadius ||
        v == DesignVariableKind::kBarrelRadius || v == DesignVariableKind::kDensity;
    if (must_be_positive && !(value > 0.0)) return Refuse(why, field, value, "must be positive");
    if (value < 0.0) return Refuse(why, field, value, "must be non-negative");
  }
  Material m = material;
  m.density_kg_m3 = fit_detail::FitValue(t, DesignVariableKind::kDensity);
  Refusal inner;
  if (!m.Validate(why != nullptr ? &inner : nullptr))
    return Refuse(why, Prefixed("material.", inner));
  if (fill.has_value()) {
    Material f = fill->material;
    if (unknown[static_cast<std::size_t>(FitUnknownIndex(DesignVariableKind::kFillDensity))]) {
      // check the other fields
      f.density_kg_m3 = std::max(fit_detail::FitValue(t, DesignVariableKind::kFillDensity), 1.0);
    }
    if (f.density_kg_m3 != 0.0 && !f.Validate(why != nullptr ? &inner : nullptr)) {
      return Refuse(why, Prefixed("fill.material.", inner));
    }
  }
  const bool hollow = fit_detail::HollowOf(*this);
  for (FitConstraint kind : fit_detail::ApplicableConstraints(hollow, fill.has_value())) {
    if (!fit_detail::ConstraintInvolves(kind, unknown) &&
        fit_detail::ConstraintValue(kind, t, hollow) > 0.0) {
      return Refuse(why, fit_detail::ConstraintRefusal(kind, t, hollow));
    }
  }
  return true;
}

bool ShapeFitProblem::ValidateSize(Refusal* why) const {
  if (!Validate(why)) return false;
  for (std::size_t i = 0; i < unknowns.size(); ++i) {
    const FitUnknown& u = unknowns[i];
    if (u.min > kMaxFitBound || u.max > kMaxFitBound) {
      const bool min = u.min > kMaxFitBound;
      return why == nullptr ? false
                            : Refuse(why, IndexedField("unknowns", i, min ? "min" : "max"),
                                     min ? u.min : u.max, RangeRule(0.0, kMaxFitBound));
    }
  }
  return true;
}

namespace {

// The fit's running state: the best feasible point in s, its metric, the stages' counts.
struct FitSearch {
  std::vector<double> best;
  double best_phi = 0.0;
  int local_runs = 0;
  int raw_status = 0;  // of the SLSQP run that produced best (of the last one if none did)
  int gauss_newton_steps = 0;
};

// 1. Scan: the start and a Halton set; the feasible points, best first.
std::vector<std::pair<double, std::vector<double>>> ScanBounds(ShapeFitModel& model,
                                                               const ShapeFitOptions& options) {
  constexpr int kPrimes[kNumFitVariables] = {2, 3, 5, 7, 11, 13, 17, 19, 23, 29};
  const int n = model.n();
  std::vector<std::pair<double, std::vector<double>>> candidates;
  std::vector<double> s = model.StartS();
  for (int k = 0; k <= options.scan_points && options.max_evaluations - model.evaluations() > 0;
       ++k) {
    if (k > 0) {
      for (int j = 0; j < n; ++j) s[static_cast<std::size_t>(j)] = RadicalInverse(k, kPrimes[j]);
    }
    if (!model.Feasible(s.data())) continue;
    candidates.emplace_back(model.Objective(s.data(), nullptr), s);
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  return candidates;
}

// 2. SLSQP from the best scan points; keeps a feasible improvement in *search.
template <typename Elapsed>
void RunLocalStarts(ShapeFitModel& model, const ShapeFitOptions& options,
                    const std::vector<std::pair<double, std::vector<double>>>& candidates,
                    const Elapsed& elapsed_s, FitSearch* search, Summary* summary) {
  const int n = model.n();
  const auto budget_left = [&] { return options.max_evaluations - model.evaluations(); };
  bool improved = false;
  const std::vector<double> lower(static_cast<std::size_t>(n), 0.0);
  const std::vector<double> upper(static_cast<std::size_t>(n), 1.0);
  const NloptFunction objective = [&model](const double* x, double* grad) {
    return model.Objective(x, grad);
  };
  std::vector<NloptConstraintFunction> constraints;
  for (FitConstraint kind : model.constraints()) {
    constraints.push_back(
        {[&model, kind](const double* x, double* grad) { return model.Constraint(kind, x, grad); },
         false, 0.0});
  }
  for (std::size_t c = 0; c < candidates.size() && search->local_runs < options.local_starts; ++c) {
    const double time_left = options.max_time_s - elapsed_s();
    if (budget_left() <= 0 || time_left <= 0.0) break;
    ++search->local_runs;
    NloptRunSettings run;
    run.algorithm = NloptAlgorithm::kLdSlsqp;
    run.lower = lower;
    run.upper = upper;
    run.x_tolerance_rel = 1e-14;
    run.f_tolerance_abs = 1e-30;
    run.max_evaluations = budget_left();
    run.max_time_s = time_left;
    std::vector<double> x = candidates[c].second;
    const int status = RunNlopt(objective, constraints, run, &x).raw_status;
    for (double& xj : x) xj = std::clamp(xj, 0.0, 1.0);
    if (status > 0 || status == kNloptRoundoffLimited) {  // x holds the best point: keep it
      const double phi = model.Objective(x.data(), nullptr);
      if (model.Feasible(x.data()) && phi < search->best_phi) {
        search->best_phi = phi;
        search->best = x;
        search->raw_status = status;
        improved = true;
      }
    }
    if (!improved) search->raw_status = status;
  }
  summary->raw_status = search->raw_status;
  if (search->raw_status == kNloptRoundoffLimited) {
    summary->warnings.push_back("NLopt SLSQP stopped round-off limited; its best point is kept");
  } else if (search->raw_status == kNloptMaxevalReached ||
             search->raw_status == kNloptMaxtimeReached) {
    summary->warnings.push_back("NLopt SLSQP stopped at the evaluation or time budget");
  }
}

// 3. Gauss-Newton on the residuals (keeps only feasible decreases).
void PolishGaussNewton(ShapeFitModel& model, const ShapeFitOptions& options, FitSearch* search) {
  const int n = model.n();
  std::vector<double>& best = search->best;
  for (int iter = 0; iter < 50 && options.max_evaluations - model.evaluations() > 0; ++iter) {
    Eigen::VectorXd r;
    Eigen::MatrixXd jac;
    model.Residuals(best.data(), &r, &jac);
    if (r.lpNorm<Eigen::Infinity>() <= 1e-3 * options.tolerance) break;
    const Eigen::VectorXd step = jac.completeOrthogonalDecomposition().solve(-r);
    bool accepted = false;
    double alpha = 1.0;
    for (int halving = 0; halving < 30; ++halving, alpha *= 0.5) {
      std::vector<double> trial = best;
      for (int j = 0; j < n; ++j) {
        trial[static_cast<std::size_t>(j)] =
            std::clamp(best[static_cast<std::size_t>(j)] + alpha * step[j], 0.0, 1.0);
      }
      if (!model.Feasible(trial.data())) continue;
      const double phi = model.Objective(trial.data(), nullptr);
      if (phi < search->best_phi) {
        search->best_phi = phi;
        best = trial;
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
    ++search->gauss_newton_steps;
  }
}

// 4. The metric of the built bat and the termination: targets met, the certified closest bat,
// or the best found.
void Classify(const ShapeFitProblem& problem, const ShapeFitOptions& options, ShapeFitModel& model,
              const std::vector<double>& best, ShapeFitResult* result) {
  Summary& summary = result->summary;
  double max_scaled = 0.0;
  result->metric = 0.0;
  if (problem.targets.mass_kg.has_value()) {
    result->mass_residual_kg = result->properties.mass_kg - *problem.targets.mass_kg;
    const double scaled =
        result->mass_residual_kg /
        (options.mass_scale_kg > 0.0 ? options.mass_scale_kg : *problem.targets.mass_kg);
    max_scaled = std::max(max_scaled, std::abs(scaled));
    result->metric += scaled * scaled;
  }
  if (problem.targets.balance_point_m.has_value()) {
    result->balance_point_residual_m =
        result->properties.balance_point_m - *problem.targets.balance_point_m;
    const double scaled = result->balance_point_residual_m /
                          (options.balance_point_scale_m > 0.0 ? options.balance_point_scale_m
                                                               : *problem.targets.balance_point_m);
    max_scaled = std::max(max_scaled, std::abs(scaled));
    result->metric += scaled * scaled;
  }
  summary.objective = result->metric;
  const std::string achieved =
      "mass_kg = " + FormatNumber(result->properties.mass_kg) +
      ", balance_point_m = " + FormatNumber(result->properties.balance_point_m);
  if (max_scaled <= options.tolerance) {
    result->targets_met = true;
    summary.termination = Termination::kConverged;
    summary.error_estimate = max_scaled;
    summary.message = "targets met (" + DescribeTargets(problem) + "): " + achieved;
    return;
  }
  result->kkt_error = fit_detail::KktError(model, best);
  summary.error_estimate = result->kkt_error;
  const std::string metric =
      "metric ((M - M*)/s_M)^2 + ((C - C*)/s_C)^2 = " + FormatNumber(result->metric) + ": " +
      achieved;
  if (result->kkt_error <= options.kkt_tolerance) {
    summary.termination = Termination::kInfeasible;
    summary.message = "no bat with " + DescribeUnknowns(problem) + " meets " +
                      DescribeTargets(problem) + "; closest bat in the " + metric;
  } else {
    summary.termination = Termination::kNoConvergence;
    summary.message = "targets " + DescribeTargets(problem) + " not met with " +
                      DescribeUnknowns(problem) +
                      "; best bat found (not certified as closest: first-order residual " +
                      FormatNumber(result->kkt_error) + ") in the " + metric;
    summary.warnings.push_back("the closest point failed the first-order (KKT) check");
  }
}

}  // namespace

ShapeFitResult FitShape(const ShapeFitProblem& problem, const ShapeFitOptions& options) {
  const auto start_time = std::chrono::steady_clock::now();
  const auto elapsed_s = [&start_time] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  };
  ShapeFitResult result;
  Summary& summary = result.summary;
  summary.models_used = {"mass_properties"};
  summary.backend = "nlopt:slsqp+gauss_newton";
  Refusal why;
  bool invalid = false;
  if (!options.Validate(&why)) {
    invalid = true;
    why = Prefixed("options.", std::move(why));
  } else if (!problem.Validate(&why)) {
    invalid = true;
  }
  if (invalid) {
    summary.SetRefusal(std::move(why));
    BuildBat(problem, fit_detail::BaseParameters(problem), &result);
    result.metric = result.mass_residual_kg = result.balance_point_residual_m = kNaN;
    summary.objective = kNaN;
    summary.solve_time_s = elapsed_s();
    return result;
  }

  try {
    ShapeFitModel model(problem, options);
    const auto candidates = ScanBounds(model, options);
    if (candidates.empty()) {
      // About the unknowns' bounds together, not one field.
      summary.SetRefusal(TextRefusal("", "the unknowns' bounds (" + DescribeUnknowns(problem) +
                                             ") admit no valid bat: every one of " +
                                             std::to_string(options.scan_points + 1) +
                                             " points tried is invalid"));
      BuildBat(problem, fit_detail::BaseParameters(problem), &result);
      summary.evaluations = model.evaluations();
      summary.solve_time_s = elapsed_s();
      return result;
    }
    FitSearch search;
    search.best = candidates.front().second;
    search.best_phi = candidates.front().first;
    RunLocalStarts(model, options, candidates, elapsed_s, &search, &summary);
    PolishGaussNewton(model, options, &search);

    // The result: repair the ordering round-off, build the bat, classify.
    std::vector<double> t = model.ToParameters(search.best.data());
    const ThreeSegmentShape repaired = design_detail::ThreeSegmentShapeAt(t, problem.shape);
    const DesignParameterLayout lay{4};
    t[static_cast<std::size_t>(lay.KnotPosition(1))] = repaired.taper_start_m;
    t[static_cast<std::size_t>(lay.KnotPosition(2))] = repaired.taper_end_m;
    BuildBat(problem, t, &result);
    summary.iterations = search.local_runs + search.gauss_newton_steps;
    summary.evaluations = model.evaluations();
    summary.constraint_violation = std::max(0.0, model.MaxViolationM(search.best.data()));
    if (Refusal bat_why; !result.bat.Validate(&bat_why)) {
      summary.termination = Termination::kFailure;
      summary.message = "the fitted bat is invalid: " + bat_why.Message();
      summary.objective = search.best_phi;
      summary.solve_time_s = elapsed_s();
      return result;
    }
    Classify(problem, options, model, search.best, &result);
  } catch (const std::bad_alloc&) {
    summary.termination = Termination::kFailure;
    summary.message = "out of memory";
  } catch (const std::exception& e) {
    summary.termination = Termination::kFailure;
    summary.message = std::string("solver failure: ") + e.what();
  }
  summary.solve_time_s = elapsed_s();
  return result;
}

}  // namespace sweetspot::core
