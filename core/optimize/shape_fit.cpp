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

// A feasible point of the scan: the parameters t and the unknowns' values there.
struct ScanPoint {
  double phi = 0.0;
  std::vector<double> t;
  std::vector<double> x;
};

// The parameters at the point s in [0, 1]^n of the unknowns' bounds (x_j = lo (1 - s) + hi s).
std::vector<double> ParametersAtS(const ShapeFitProblem& problem, const std::vector<double>& start,
                                  const std::vector<double>& s) {
  const DesignParameterLayout lay{4};
  std::vector<double> t = start;
  for (std::size_t j = 0; j < problem.unknowns.size(); ++j) {
    const FitUnknown& u = problem.unknowns[j];
    const double x = u.min * (1.0 - s[j]) + u.max * s[j];
    for (int p : design_detail::DesignParametersOf(fit_detail::DesignVariableOf(u.variable), lay)) {
      t[static_cast<std::size_t>(p)] = x;
    }
  }
  return t;
}

// 1. Scan: the start and a Halton set of the bounds; the points where every validity rule
// that an unknown can break holds (the others were checked by Validate), in scan order.
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
  const std::vector<double> start = fit_detail::StartParameters(problem);
  const std::size_t n = problem.unknowns.size();
  std::vector<double> s(n);
  for (std::size_t j = 0; j < n; ++j) {
    const FitUnknown& u = problem.unknowns[j];
    s[j] = (fit_detail::FitValue(start, u.variable) - u.min) / (u.max - u.min);
  }
  std::vector<ScanPoint> points;
  for (int k = 0; k <= options.scan_points; ++k) {
    if (k > 0) {
      for (std::size_t j = 0; j < n; ++j) s[j] = RadicalInverse(k, kPrimes[j]);
    }
    ScanPoint point;
    point.t = ParametersAtS(problem, start, s);
    const bool feasible = std::all_of(constraints.begin(), constraints.end(), [&](FitConstraint c) {
      return fit_detail::ConstraintValue(c, point.t, hollow) <= 0.0;
    });
    if (!feasible) continue;
    point.x = fit_detail::UnknownValues(problem, point.t);
    points.push_back(std::move(point));
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
  for (int i = 1; i < o.starts; ++i)
    o.start_points.push_back(ranked[static_cast<std::size_t>(i)].x);
  // SLSQP runs at most 20 evaluations per "iteration" (nlopt_design.cpp): the budget left,
  // shared by the starts.
  const int left = std::max(1, options.max_evaluations - evaluations);
  o.max_iterations = std::clamp(left / (20 * o.starts), 1, 100000);
  o.max_time_s = std::max(time_left_s, 1e-6);
  o.explain_infeasibility = false;  // no property constraints: the metric says how far
  return o;
}

// 3. The design optimiser from the best scan points (the best is the base design) with its
// polish to round-off, within what is left of the budgets: the unknowns' values it ends at, or
// the best scan point's when the budget is spent or the solve gives no usable design. Sets the
// summary's counts, raw status, constraint violation and warnings.
std::vector<double> SolveFromScan(const ShapeFitProblem& problem, const ShapeFitOptions& options,
                                  const std::vector<ScanPoint>& ranked, int scan_evaluations,
                                  double time_left_s, Summary* summary) {
  summary->evaluations = scan_evaluations;
  summary->iterations = 0;
  summary->constraint_violation = 0.0;
  if (scan_evaluations >= options.max_evaluations || !(time_left_s > 0.0)) return ranked.front().x;
  const DesignResult design =
      OptimizeDesign(fit_detail::FitDesignProblem(problem, options, ranked.front().t),
                     SolveOptions(options, ranked, scan_evaluations, time_left_s));
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
    return ranked.front().x;
  }
  if (failed) {
    summary->warnings.push_back("the local solve stopped with " + design.summary.message +
                                "; its best point is kept");
  }
  summary->constraint_violation = std::max(0.0, design.summary.constraint_violation);
  std::vector<double> x;
  for (const DesignValue& v : design.variables) x.push_back(v.value);
  return x;
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
    // The fit's design model (its base the first valid point) ranks the scan.
    DesignModel model;
    Refusal model_why;
    if (!DesignModel::Build(fit_detail::FitDesignProblem(problem, options, ranked.front().t),
                            DesignOptions{}, &model, &model_why)) {
      summary.termination = Termination::kFailure;
      summary.message = "the fit's design problem is refused: " + model_why.Message();
      BuildBat(problem, ranked.front().t, &result);
      summary.solve_time_s = elapsed_s();
      return result;
    }
    int evaluations = 0;
    RankScan(model, options, &ranked, &evaluations);
    if (ranked.empty()) throw std::runtime_error("the metric is not finite at any scan point");

    const std::vector<double> x = SolveFromScan(problem, options, ranked, evaluations,
                                                options.max_time_s - elapsed_s(), &summary);

    // The result: repair the ordering round-off, build the bat, classify.
    std::vector<double> t = ranked.front().t;
    const DesignParameterLayout lay{4};
    for (std::size_t j = 0; j < x.size(); ++j) {
      for (int p : design_detail::DesignParametersOf(
               fit_detail::DesignVariableOf(problem.unknowns[j].variable), lay)) {
        t[static_cast<std::size_t>(p)] = x[j];
      }
    }
    const ThreeSegmentShape repaired = design_detail::ThreeSegmentShapeAt(t, problem.shape);
    t[static_cast<std::size_t>(lay.KnotPosition(1))] = repaired.taper_start_m;
    t[static_cast<std::size_t>(lay.KnotPosition(2))] = repaired.taper_end_m;
    BuildBat(problem, t, &result);
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
