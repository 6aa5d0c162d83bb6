// The shape fit: its checks, a scan of the bounds, then the fit as a design problem solved by the
// one solver layer (OptimizeDesign with the least-squares objective, NLopt SLSQP from the best
// scan points and the layer's Gauss-Newton polish), and its certification. See shape_fit.hpp.
#include "core/optimize/shape_fit.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/optimize/design_integrals.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/least_squares_polish.hpp"
#include "core/optimize/shape_fit_checks.hpp"

namespace sweetspot::core {
namespace {

using fit_detail::FitConstraint;
using fit_detail::kNumFitVariables;

// The fit's backend: NLopt SLSQP through the design optimiser, then its Gauss-Newton polish.
constexpr const char* kFitBackend = "nlopt:slsqp+gauss_newton";
// The design optimiser's tolerance for the fit (SLSQP's ftol_rel and xtol_rel): the fit's
// SLSQP ran to x within 1e-14 relative, so a closest bat on a bound (which the polish cannot
// improve) is placed to round-off.
constexpr double kFitSolverTolerance = 1e-14;

// True when two bats have the same knots, densities, wall and fill (the same mass properties).
bool SameBat(const Bat& a, const Bat& b) {
  const auto same_fill = [](const std::optional<Fill>& f, const std::optional<Fill>& g) {
    return f.has_value() == g.has_value() &&
           (!f.has_value() || (f->diameter_m == g->diameter_m && f->depth_m == g->depth_m &&
                               f->material.density_kg_m3 == g->material.density_kg_m3));
  };
  if (a.knots.size() != b.knots.size()) return false;
  for (std::size_t i = 0; i < a.knots.size(); ++i) {
    if (a.knots[i].x_m != b.knots[i].x_m || a.knots[i].radius_m != b.knots[i].radius_m) {
      return false;
    }
  }
  return a.material.density_kg_m3 == b.material.density_kg_m3 &&
         a.wall_thickness_m == b.wall_thickness_m && same_fill(a.fill, b.fill);
}

// Builds the bat of the family at parameters t (DesignParameterLayout{4}); its mass properties
// are `known`'s when that is the same bat (computed once), else computed.
void BuildBat(const ShapeFitProblem& problem, const std::vector<double>& t, ShapeFitResult* out,
              const std::optional<std::pair<Bat, MassProperties>>& known = std::nullopt) {
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
  out->properties = known.has_value() && SameBat(known->first, out->bat)
                        ? known->second
                        : ComputeMassProperties(out->bat, InertiaModel::kRigidBody);
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

}  // namespace

namespace {

// A valid point of the scan: the unknowns' values there and the metric.
struct ScanPoint {
  double phi = 0.0;
  std::vector<double> x;
  bool start = false;  // the problem's start (its unknowns clamped into their bounds)
};

// The parameters each unknown sets (DesignParameterLayout{4}; two for a radius).
std::vector<std::vector<int>> UnknownParameters(const ShapeFitProblem& problem) {
  std::vector<std::vector<int>> out;
  for (const FitUnknown& u : problem.unknowns) {
    out.push_back(design_detail::DesignParametersOf(fit_detail::DesignVariableOf(u.variable),
                                                    DesignParameterLayout{4}));
  }
  return out;
}

// The parameters t with the unknowns' values x set in the problem's start.
std::vector<double> ParametersAtX(const ShapeFitProblem& problem, const std::vector<double>& x) {
  std::vector<double> t = fit_detail::StartParameters(problem);
  const std::vector<std::vector<int>> parameters = UnknownParameters(problem);
  for (std::size_t j = 0; j < x.size(); ++j) {
    for (int p : parameters[j]) t[static_cast<std::size_t>(p)] = x[j];
  }
  return t;
}

// 1. Scan: the start and a Halton set of the bounds (x_j = lo (1 - s) + hi s); the points where
// every validity rule that an unknown can break holds (the others were checked by Validate),
// in scan order.
std::vector<ScanPoint> ScanBounds(const ShapeFitProblem& problem, const ShapeFitOptions& options) {
  constexpr int kPrimes[kNumFitVariables] = {2, 3, 5, 7, 11, 13, 17, 19, 23, 29};
  const bool hollow = fit_detail::HollowOf(problem);
  std::vector<bool> unknown(static_cast<std::size_t>(kNumFitVariables), false);
  for (const FitUnknown& u : problem.unknowns) {
    unknown[static_cast<std::size_t>(FitUnknownIndex(u.variable))] = true;
  }
  std::vector<FitConstraint> constraints;
  for (FitConstraint kind : fit_detail::ApplicableConstraints(hollow, problem.fill.has_value())) {
    if (fit_detail::ConstraintInvolves(kind, unknown)) constraints.push_back(kind);
  }
  const std::vector<std::vector<int>> parameters = UnknownParameters(problem);
  std::vector<double> t = fit_detail::StartParameters(problem);
  const std::size_t n = problem.unknowns.size();
  std::vector<double> s(n), x(n);
  for (std::size_t j = 0; j < n; ++j) {
    const FitUnknown& u = problem.unknowns[j];
    s[j] = (t[static_cast<std::size_t>(parameters[j].front())] - u.min) / (u.max - u.min);
  }
  std::vector<ScanPoint> points;
  for (int k = 0; k <= options.scan_points; ++k) {
    for (std::size_t j = 0; j < n; ++j) {
      // The start itself, then x_j = lo (1 - s) + hi s.
      if (k > 0) s[j] = RadicalInverse(k, kPrimes[j]);
      x[j] = k == 0 ? t[static_cast<std::size_t>(parameters[j].front())]
                    : problem.unknowns[j].min * (1.0 - s[j]) + problem.unknowns[j].max * s[j];
      for (int p : parameters[j]) t[static_cast<std::size_t>(p)] = x[j];
    }
    const bool valid = std::all_of(constraints.begin(), constraints.end(), [&](FitConstraint c) {
      return fit_detail::ConstraintValue(c, t, hollow) <= 0.0;
    });
    if (valid) points.push_back({0.0, x, k == 0});
  }
  return points;
}

// 2. phi at the scan's points by the fit's design model (within the evaluation budget), best
// first; *evaluations counts them.
void RankScan(const DesignModel& model, const ShapeFitOptions& options,
              std::vector<ScanPoint>* points, int* evaluations) {
  std::vector<ScanPoint> ranked;
  for (ScanPoint& point : *points) {
    if (*evaluations >= options.max_evaluations) break;
    ++*evaluations;
    point.phi = model.Value(model.objective(), point.x.data());
    if (std::isfinite(point.phi)) ranked.push_back(std::move(point));
  }
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const ScanPoint& a, const ScanPoint& b) { return a.phi < b.phi; });
  *points = std::move(ranked);
}

// 4. The metric of the built bat and the termination: targets met, the certified closest bat,
// or the best found.
void Classify(const ShapeFitProblem& problem, const ShapeFitOptions& options,
              const DesignModel& model, const std::vector<double>& x, ShapeFitResult* result) {
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
  result->kkt_error = design_detail::LeastSquaresKktError(model, x);
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

// The design optimiser's options for the fit: NLopt SLSQP from the best scan points, to the
// fit's own tolerances (x to 1e-14 relative), within what is left of its budgets.
DesignOptions SolveOptions(const ShapeFitOptions& options, const std::vector<ScanPoint>& ranked,
                           int evaluations, double time_left_s) {
  DesignOptions o;
  o.backend = DesignBackend::kNloptSlsqp;
  o.tolerance = kFitSolverTolerance;
  o.starts = static_cast<int>(
      std::min<std::size_t>({static_cast<std::size_t>(options.local_starts), ranked.size(), 64}));
  for (int i = 0; i < o.starts; ++i) {
    o.start_points.push_back(ranked[static_cast<std::size_t>(i)].x);
  }
  // SLSQP runs at most 20 evaluations per "iteration" (nlopt_design.cpp): the budget left,
  // shared by the starts.
  const int left = std::max(1, options.max_evaluations - evaluations);
  o.max_iterations = std::clamp(left / (20 * o.starts), 1, 100000);
  o.max_time_s = std::max(time_left_s, 1e-6);
  o.explain_infeasibility = false;  // no property constraints: the metric says how far
  return o;
}

// The design optimiser's answer: the unknowns' values, and its bat with their mass properties.
struct FitSolve {
  std::vector<double> x;
  std::optional<std::pair<Bat, MassProperties>> bat;
};

// 3. OptimizeDesign on the fit's problem from the best scan points with its polish to round-off,
// within what is left of the budgets: the values it ends at, or the best scan point's when the
// budget is spent or the solve gives no usable design. Sets the summary's counts, raw status,
// constraint violation and warnings.
FitSolve SolveFromScan(const ShapeFitProblem& problem, const DesignProblem& fit_problem,
                       const ShapeFitOptions& options, const std::vector<ScanPoint>& ranked,
                       int scan_evaluations, double time_left_s, Summary* summary) {
  summary->evaluations = scan_evaluations;
  summary->iterations = 0;
  summary->constraint_violation = 0.0;
  if (scan_evaluations >= options.max_evaluations || !(time_left_s > 0.0)) {
    return {ranked.front().x, std::nullopt};
  }
  const DesignResult design =
      OptimizeDesign(fit_problem, SolveOptions(options, ranked, scan_evaluations, time_left_s));
  // iterations: the local solves run plus the polish's accepted steps (the iterations the
  // design layer adds beyond its starts' own).
  int solver_iterations = 0;
  for (const DesignStart& run : design.spread.runs) solver_iterations += run.iterations;
  summary->iterations =
      design.spread.starts + std::max(design.summary.iterations - solver_iterations, 0);
  summary->evaluations += std::max(design.summary.evaluations, 0);
  summary->raw_status = design.summary.raw_status;
  summary->warnings = design.summary.warnings;
  // The design's point, unless it has none or is worse than the scan's best (a solver's
  // failure keeps its best point when that is feasible: NLopt SLSQP may stop with "more than
  // iter SQP iterations" at a root).
  const bool failed = design.summary.termination == Termination::kFailure;
  const bool usable = design.summary.termination != Termination::kInvalidInput &&
                      design.message_kind != DesignMessageKind::kNoDesign &&
                      design.variables.size() == problem.unknowns.size() &&
                      std::isfinite(design.objective_value) &&
                      design.objective_value <= ranked.front().phi &&
                      std::isfinite(design.summary.constraint_violation) &&
                      (!failed || design.summary.constraint_violation <= 0.0);
  if (!usable) {
    summary->warnings.push_back("the design optimiser's solve gave no usable design (" +
                                design.summary.message + "); the best scan point is kept");
    return {ranked.front().x, std::nullopt};
  }
  if (failed) {
    summary->warnings.push_back("the local solve stopped with " + design.summary.message +
                                "; its best point is kept");
  }
  summary->constraint_violation = std::max(0.0, design.summary.constraint_violation);
  FitSolve out;
  for (const DesignValue& v : design.variables) out.x.push_back(v.value);
  out.bat.emplace(design.bat, design.properties);
  return out;
}

// The rigid-body mass properties of the fit problem's base design: the caller's when it is
// the problem's bat (its start, nothing clamped), else computed.
MassProperties BaseProperties(const ShapeFitProblem& problem, const ScanPoint& base,
                              const DesignProblem& fit_problem) {
  if (base.start && problem.bat_mass_properties.has_value() &&
      fit_detail::StartParameters(problem) == fit_detail::BaseParameters(problem)) {
    return *problem.bat_mass_properties;
  }
  Bat bat = fit_problem.bat;
  bat.knots = fit_problem.three_segment->Knots();
  return ComputeMassProperties(bat, InertiaModel::kRigidBody);
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
  summary.backend = kFitBackend;
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
    std::vector<ScanPoint> ranked = ScanBounds(problem, options);
    if (ranked.empty()) {
      // About the unknowns' bounds together, not one field.
      summary.SetRefusal(TextRefusal("", "the unknowns' bounds (" + DescribeUnknowns(problem) +
                                             ") admit no valid bat: every one of " +
                                             std::to_string(options.scan_points + 1) +
                                             " points tried is invalid"));
      BuildBat(problem, fit_detail::BaseParameters(problem), &result);
      summary.evaluations = 0;
      summary.solve_time_s = elapsed_s();
      return result;
    }
    // The fit's design problem (its base the first valid point: the start, when valid), whose
    // model ranks the scan.
    DesignProblem fit_problem =
        fit_detail::FitDesignProblem(problem, options, ParametersAtX(problem, ranked.front().x));
    fit_problem.base_mass_properties = BaseProperties(problem, ranked.front(), fit_problem);
    DesignModel model;
    Refusal model_why;
    if (!DesignModel::Build(fit_problem, DesignOptions{}, &model, &model_why)) {
      summary.termination = Termination::kFailure;
      summary.message = "the fit's design problem is refused: " + model_why.Message();
      BuildBat(problem, ParametersAtX(problem, ranked.front().x), &result);
      summary.solve_time_s = elapsed_s();
      return result;
    }
    int evaluations = 0;
    RankScan(model, options, &ranked, &evaluations);
    if (ranked.empty()) throw std::runtime_error("the metric is not finite at any scan point");

    const FitSolve solve = SolveFromScan(problem, fit_problem, options, ranked, evaluations,
                                         options.max_time_s - elapsed_s(), &summary);
    const std::vector<double>& x = solve.x;

    // The result: repair the ordering round-off, build the bat, classify.
    std::vector<double> t = ParametersAtX(problem, x);
    const DesignParameterLayout lay{4};
    const ThreeSegmentShape repaired = design_detail::ThreeSegmentShapeAt(t, problem.shape);
    t[static_cast<std::size_t>(lay.KnotPosition(1))] = repaired.taper_start_m;
    t[static_cast<std::size_t>(lay.KnotPosition(2))] = repaired.taper_end_m;
    BuildBat(problem, t, &result, solve.bat);
    if (Refusal bat_why; !result.bat.Validate(&bat_why)) {
      summary.termination = Termination::kFailure;
      summary.message = "the fitted bat is invalid: " + bat_why.Message();
      summary.objective = kNaN;
      summary.solve_time_s = elapsed_s();
      return result;
    }
    Classify(problem, options, model, x, &result);
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
