// OptimizeDesign and OptimizeOverMaterials: validation, seeded multi-start, the independent
// re-check of the answer through the public mass properties and closed-form sweet spot, the
// active constraints and their multipliers, and the explanation of infeasible requests.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <new>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/collision/rigid_pivot.hpp"
#include "core/geometry_format.hpp"
#include "core/optimize/design_backends.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
// A point is feasible when every constraint is met to this, relative to its scale.
constexpr double kFeasibleRelative = 1e-6;
// A constraint is reported active when within this of a limit, relative to its scale; a
// variable when within this fraction of its range of a bound.
constexpr double kActiveRelative = 1e-6;

std::string Num(double v) { return FormatNumber(v); }

std::string WithUnit(double v, const std::string& unit) {
  return Num(v) + (unit.empty() ? "" : " " + unit);
}

// A uniform double in [0, 1) from the generator's top 53 bits (the same on every platform,
// unlike std::uniform_real_distribution).
double Uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// A random start: every variable uniform in its bounds, then knot positions pushed apart so
// the profile's knots stay in order where the bounds allow (the model is finite everywhere;
// this only helps the solver start from a sensible bat).
std::vector<double> RandomStart(const DesignModel& model, std::mt19937_64& rng, double gap) {
  const auto& vars = model.variables();
  std::vector<double> x(vars.size());
  for (std::size_t j = 0; j < vars.size(); ++j) {
    x[j] = vars[j].lower + Uniform(rng) * (vars[j].upper - vars[j].lower);
  }
  // Profile positions in knot order; three-segment x1 <= x2 <= L.
  std::vector<std::pair<int, std::size_t>> positions;  // (knot, variable)
  int taper_start = -1, taper_end = -1, length = -1;
  for (std::size_t j = 0; j < vars.size(); ++j) {
    if (vars[j].ref.kind == DesignVariableKind::kKnotPosition)
      positions.push_back({vars[j].ref.knot, j});
    if (vars[j].ref.kind == DesignVariableKind::kTaperStart) taper_start = static_cast<int>(j);
    if (vars[j].ref.kind == DesignVariableKind::kTaperEnd) taper_end = static_cast<int>(j);
    if (vars[j].ref.kind == DesignVariableKind::kLength) length = static_cast<int>(j);
  }
  std::sort(positions.begin(), positions.end());
  for (std::size_t q = 1; q < positions.size(); ++q) {
    if (positions[q].first != positions[q - 1].first + 1) continue;
    const std::size_t a = positions[q - 1].second, b = positions[q].second;
    if (x[b] < x[a] + gap) x[b] = std::min(x[a] + gap, vars[b].upper);
  }
  if (taper_start >= 0 && taper_end >= 0 &&
      x[static_cast<std::size_t>(taper_start)] > x[static_cast<std::size_t>(taper_end)]) {
    std::swap(x[static_cast<std::size_t>(taper_start)], x[static_cast<std::size_t>(taper_end)]);
    for (int j : {taper_start, taper_end}) {
      const auto jj = static_cast<std::size_t>(j);
      x[jj] = std::clamp(x[jj], vars[jj].lower, vars[jj].upper);
    }
  }
  if (taper_end >= 0 && length >= 0) {
    const auto e = static_cast<std::size_t>(taper_end), l = static_cast<std::size_t>(length);
    if (x[l] < x[e]) x[l] = std::clamp(x[e], vars[l].lower, vars[l].upper);
  }
  return x;
}

// The public re-evaluation of a design (ComputeMassProperties + the closed-form sweet spot;
// min_sting: + Collide(kFlexible) there, with the error checks).
struct PublicEvaluation {
  MassProperties properties;
  double objective = kNaN;
  double sweet_spot_m = kNaN;
  double max_exit_speed_mps = kNaN;
  double omega_rad_s = kNaN;
  std::optional<StingEvaluation> sting;  // min_sting
};

PublicEvaluation EvaluatePublic(const DesignProblem& problem, const DesignModel& model,
                                const Bat& bat, bool cor_known) {
  PublicEvaluation out;
  out.properties = ComputeMassProperties(bat, problem.inertia_model);
  const MassProperties& p = out.properties;
  const double length = bat.LengthM();
  out.omega_rad_s = model.AngularSpeedFor(p.MoiSixInchKgM2());
  double zone_width = kNaN;
  if (cor_known) {
    Swing swing = problem.swing;
    swing.angular_speed_rad_s = out.omega_rad_s;  // the design's own (from its swing weight)
    const ExitSpeedProfile profile =
        RigidPivotProfile(RigidPivotInputsFor(p, problem.ball, swing, model.cor()));
    const MaxExitSpeedResult max = ClosedFormMaxExitSpeed(profile, length);
    out.sweet_spot_m = max.position_from_knob_m;
    out.max_exit_speed_mps = max.exit_speed_mps;
    const SweetZoneResult zone =
        ClosedFormSweetZone(profile, length, max, problem.sweet_zone_tolerance_mps);
    zone_width = zone.to_knob_m - zone.from_knob_m;
  }
  switch (problem.objective) {
    case DesignObjective::kMaxExitSpeed:
    case DesignObjective::kMaxExitSpeedSwingWeight:
      out.objective = out.max_exit_speed_mps;
      break;
    case DesignObjective::kWidestSweetZone:
      out.objective = zone_width;
      break;
    case DesignObjective::kMinMoi:
      out.objective = p.MoiSixInchKgM2();
      break;
    case DesignObjective::kMinSting:
      out.sting = model.StingOf(bat, true);
      out.objective = out.sting->sting_j;
      break;
  }
  return out;
}

// Value of constraint c for a design, through the public path for the properties.
double PublicConstraintValue(const DesignModel& model, const DesignConstraintSpec& c,
                             const PublicEvaluation& e, const Bat& bat, const double* x) {
  switch (c.f.function) {
    case DesignFunction::kMass:
      return e.properties.mass_kg;
    case DesignFunction::kBalancePoint:
      return e.properties.balance_point_m;
    case DesignFunction::kMoiSixInch:
      return e.properties.MoiSixInchKgM2();
    case DesignFunction::kDrop:
      return ToImperial(e.properties, bat.LengthM()).drop;
    case DesignFunction::kLinear:
    case DesignFunction::kObjective:
      break;
  }
  return model.Value(c.f, x);
}

double Violation(const DesignConstraintSpec& c, double v) {
  if (!std::isfinite(v)) return kInf;
  return std::max({0.0, c.lower - v, v - c.upper});
}

// One finished local solve.
struct Run {
  LocalSolveOutcome outcome;
  std::vector<double> x;    // user units, clamped into the bounds
  double objective = kNaN;  // model objective at x
  double violation = kInf;  // largest scaled violation at x
  bool feasible = false;
};

// Evaluates the end of a local solve.
Run Finish(const DesignModel& model, LocalSolveOutcome outcome) {
  Run run;
  ScaledDesignNlp nlp(model);
  std::vector<double> s = outcome.s;
  for (double& v : s) v = std::clamp(v, 0.0, 1.0);
  run.x = nlp.ToUser(s.data());
  for (std::size_t j = 0; j < run.x.size(); ++j) {
    run.x[j] = std::clamp(run.x[j], model.variables()[j].lower, model.variables()[j].upper);
  }
  const std::vector<double> s2 = nlp.ToScaled(run.x);
  if (nlp.Evaluate(s2.data(), false)) {
    // The sting is not recomputed (an impact per call): the NLP's value at the same point.
    run.objective =
        model.derivative_free() ? nlp.objective() : model.Value(model.objective(), run.x.data());
    run.violation = nlp.Violation();
    run.feasible = run.violation <= kFeasibleRelative;
  }
  run.outcome = std::move(outcome);
  return run;
}

bool Better(const DesignModel& model, double a, double b) {
  return model.maximize() ? a > b : a < b;
}

// Index of the run to answer with: feasible and converged by objective, then feasible by
// objective, then the least violation.
int ChooseRun(const DesignModel& model, const std::vector<Run>& runs) {
  int best = -1;
  auto rank = [](const Run& r) {
    if (r.feasible && r.outcome.termination == Termination::kConverged) return 0;
    if (r.feasible) return 1;
    return 2;
  };
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const Run& r = runs[i];
    if (!std::isfinite(r.violation)) continue;
    if (best < 0) {
      best = static_cast<int>(i);
      continue;
    }
    const Run& b = runs[static_cast<std::size_t>(best)];
    const int ra = rank(r), rb = rank(b);
    if (ra != rb) {
      if (ra < rb) best = static_cast<int>(i);
      continue;
    }
    if (ra == 2 ? r.violation < b.violation : Better(model, r.objective, b.objective)) {
      best = static_cast<int>(i);
    }
  }
  return best;
}

LocalSolveOutcome Solve(DesignBackend backend, ScaledDesignNlp& nlp, const std::vector<double>& s0,
                        const LocalSolveSettings& settings) {
  switch (backend) {
    case DesignBackend::kIpopt:
      return SolveWithIpopt(nlp, s0, settings);
    case DesignBackend::kNloptSlsqp:
      return SolveWithNlopt(nlp, s0, settings);
    case DesignBackend::kNloptCobyla:
      return SolveWithCobyla(nlp, s0, settings);
  }
  return SolveWithIpopt(nlp, s0, settings);
}

// The backend of the design's local solves: min_sting has no derivative, so COBYLA whatever
// was asked.
DesignBackend MainBackend(const DesignProblem& problem, const DesignOptions& options) {
  return problem.objective == DesignObjective::kMinSting ? DesignBackend::kNloptCobyla
                                                         : options.backend;
}

// The backend of the infeasibility analysis, whose sub-problems are smooth (the objective is
// a property, never the sting): the requested gradient solver, Ipopt when COBYLA was asked.
DesignBackend SmoothBackend(const DesignOptions& options) {
  return options.backend == DesignBackend::kNloptCobyla ? DesignBackend::kIpopt : options.backend;
}

const char* BackendName(DesignBackend backend) {
  switch (backend) {
    case DesignBackend::kIpopt:
      return "ipopt";
    case DesignBackend::kNloptSlsqp:
      return "nlopt:LD_SLSQP";
    case DesignBackend::kNloptCobyla:
      return "nlopt:LN_COBYLA";
  }
  return "ipopt";
}

LocalSolveSettings SettingsFrom(const DesignOptions& options, Clock::time_point deadline,
                                Progress* progress) {
  LocalSolveSettings s;
  s.max_iterations = options.max_iterations;
  s.tolerance = options.tolerance;
  s.constraint_tolerance = options.constraint_tolerance;
  s.hessian = options.hessian;
  s.max_cpu_time_s = options.max_cpu_time_s;
  s.deadline = deadline;
  s.progress = progress;
  s.feasibility_tolerance = kFeasibleRelative;
  return s;
}

// Words for the ends of a property's range in the conflict messages.
struct RangeWords {
  const char* least;
  const char* most;
};

RangeWords WordsFor(const DesignConstraintSpec& c) {
  switch (c.f.function) {
    case DesignFunction::kMass:
      return {"the lightest bat", "the heaviest bat"};
    case DesignFunction::kBalancePoint:
      return {"the balance point nearest the knob", "the balance point farthest from the knob"};
    case DesignFunction::kMoiSixInch:
      return {"the least MOI about the 6-in point", "the largest MOI about the 6-in point"};
    case DesignFunction::kDrop:
      return {"the least length_in - weight_oz", "the largest length_in - weight_oz"};
    default:
      if (c.name.rfind("length_m", 0) == 0 || c.name.find(".length") != std::string::npos) {
        return {"the shortest bat", "the longest bat"};
      }
      return {"the least value", "the largest value"};
  }
}

// "mass_kg = 0.5", "balance_point_m in [0.56, 0.6]", "rules.bbcor.drop <= 3".
std::string Requested(const DesignConstraintSpec& c) {
  if (c.lower == c.upper) return c.name + " = " + WithUnit(c.lower, c.unit);
  if (!std::isfinite(c.lower)) return c.max_name + " = " + WithUnit(c.upper, c.unit);
  if (!std::isfinite(c.upper)) return c.min_name + " = " + WithUnit(c.lower, c.unit);
  return c.name + " in [" + Num(c.lower) + ", " + WithUnit(c.upper, c.unit) + "]";
}

// Least and largest value of constraint k's function under the constraints `keep`.
struct Reach {
  bool known = false;
  double least = kNaN;
  double most = kNaN;
};

Reach ReachOf(const DesignModel& model, int k, const std::vector<int>& keep,
              const DesignOptions& options, Clock::time_point deadline, Progress* progress,
              int* evaluations, int* iterations) {
  Reach out;
  const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
  const DesignModel restricted = model.WithConstraints(keep);
  double ends[2] = {kNaN, kNaN};
  for (int side = 0; side < 2; ++side) {
    if (Clock::now() >= deadline || IsCancelled(progress)) return out;
    const DesignModel m = restricted.WithObjective(c.f, side == 1, c.scale, c.unit);
    ScaledDesignNlp nlp(m);
    LocalSolveSettings settings = SettingsFrom(options, deadline, progress);
    const LocalSolveOutcome o =
        Solve(SmoothBackend(options), nlp, nlp.ToScaled(m.BaseX()), settings);
    *evaluations += o.evaluations;
    *iterations += o.iterations;
    const Run run = Finish(m, o);
    if (o.termination != Termination::kConverged || !run.feasible) return out;
    ends[side] = run.objective;
  }
  out.known = true;
  out.least = ends[0];
  out.most = ends[1];
  return out;
}

// Why no design meets the constraints: single constraints that cannot be met within the
// variable bounds and the geometric constraints, then pairs of property constraints.
std::vector<DesignConflict> Explain(const DesignModel& model, const DesignOptions& options,
                                    Clock::time_point deadline, Progress* progress,
                                    const Run& least_violating, bool solver_says_infeasible,
                                    int* evaluations, int* iterations) {
  std::vector<DesignConflict> out;
  std::vector<int> property, structural;
  for (int k = 0; k < model.m(); ++k) {
    (model.constraints()[static_cast<std::size_t>(k)].property ? property : structural)
        .push_back(k);
  }
  const bool has_structural = !structural.empty();
  const std::string within = has_structural
                                 ? "within the variable bounds and the geometric constraints"
                                 : "within the variable bounds";
  auto conflict = [&](const std::vector<int>& names, int k, const Reach& r,
                      const std::string& context) {
    const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
    DesignConflict d;
    for (int q : names)
      d.constraints.push_back(model.constraints()[static_cast<std::size_t>(q)].name);
    d.unit = c.unit;
    d.requested_min = c.lower;
    d.requested_max = c.upper;
    d.achievable_min = r.least;
    d.achievable_max = r.most;
    const RangeWords words = WordsFor(c);
    if (c.lower > r.most) {
      d.shortfall = c.lower - r.most;
      d.message = Requested(c) + " is above " + words.most + " " + context + ": " +
                  WithUnit(r.most, c.unit) + " (short by " + WithUnit(d.shortfall, c.unit) + ")";
    } else {
      d.shortfall = r.least - c.upper;
      d.message = Requested(c) + " is below " + words.least + " " + context + ": " +
                  WithUnit(r.least, c.unit) + " (over by " + WithUnit(d.shortfall, c.unit) + ")";
    }
    out.push_back(std::move(d));
  };
  auto excluded = [](const DesignConstraintSpec& c, const Reach& r) {
    const double tol = kFeasibleRelative * c.scale;
    return r.known && (c.lower > r.most + tol || c.upper < r.least - tol);
  };

  // 1. The geometric constraints alone.
  if (has_structural && !(Clock::now() >= deadline)) {
    DesignFunctionSpec zero;  // kLinear, no terms: a constant objective
    const DesignModel m = model.WithConstraints(structural).WithObjective(zero, false, 1.0, "");
    ScaledDesignNlp nlp(m);
    const LocalSolveOutcome o = Solve(SmoothBackend(options), nlp, nlp.ToScaled(m.BaseX()),
                                      SettingsFrom(options, deadline, progress));
    *evaluations += o.evaluations;
    *iterations += o.iterations;
    const Run run = Finish(m, o);
    if (!run.feasible && o.termination == Termination::kInfeasible) {
      DesignConflict d;
      std::string names;
      for (int k : structural) {
        const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
        const double v = model.Value(c.f, run.x.data());
        const double viol = Violation(c, v);
        if (viol > kFeasibleRelative * c.scale) {
          d.constraints.push_back(c.name);
          if (!names.empty()) names += ", ";
          names += c.name + " (off by " + WithUnit(viol, c.unit) + ")";
        }
      }
      d.achievable_min = d.achievable_max = d.requested_min = d.requested_max = kNaN;
      d.shortfall = run.violation;
      d.message =
          "the variable bounds and the geometric constraints admit no design; at the "
          "least-violating design found: " +
          names;
      out.push_back(std::move(d));
      return out;
    }
  }
  // 2. Each property constraint against the bounds and the geometric constraints.
  for (int k : property) {
    const Reach r =
        ReachOf(model, k, structural, options, deadline, progress, evaluations, iterations);
    if (excluded(model.constraints()[static_cast<std::size_t>(k)], r)) conflict({k}, k, r, within);
  }
  if (!out.empty()) return out;
  // 3. Pairs of property constraints.
  for (std::size_t a = 0; a < property.size(); ++a) {
    for (std::size_t b = a + 1; b < property.size(); ++b) {
      const int k = property[a], l = property[b];
      std::vector<int> keep = structural;
      keep.push_back(l);
      const Reach r = ReachOf(model, k, keep, options, deadline, progress, evaluations, iterations);
      if (excluded(model.constraints()[static_cast<std::size_t>(k)], r)) {
        conflict(
            {k, l}, k, r,
            "with " + Requested(model.constraints()[static_cast<std::size_t>(l)]) + " " + within);
      }
    }
  }
  if (!out.empty() || !solver_says_infeasible) return out;
  // 4. The solver found no feasible point and nothing smaller explains it: name what the
  // least-violating design breaks.
  DesignConflict d;
  std::string names;
  for (int k = 0; k < model.m(); ++k) {
    const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
    const double viol = Violation(c, model.Value(c.f, least_violating.x.data()));
    if (viol > kFeasibleRelative * c.scale) {
      d.constraints.push_back(c.name);
      if (!names.empty()) names += ", ";
      names += c.name + " (off by " + WithUnit(viol, c.unit) + ")";
    }
  }
  d.achievable_min = d.achievable_max = d.requested_min = d.requested_max = kNaN;
  d.shortfall = least_violating.violation;
  d.message = names.empty() ? "no conflict could be isolated"
                            : "no smaller conflict could be isolated; the least-violating design "
                              "found misses: " +
                                  names;
  out.push_back(std::move(d));
  return out;
}

// Multipliers for a point without solver multipliers (NLopt): least squares on the
// stationarity conditions over the active set. Returns the KKT residual (scaled problem).
double EstimateMultipliers(ScaledDesignNlp& nlp, const std::vector<double>& s,
                           std::vector<double>* lambda, std::vector<double>* z_lower,
                           std::vector<double>* z_upper) {
  const int n = nlp.n(), m = nlp.m();
  lambda->assign(static_cast<std::size_t>(m), 0.0);
  z_lower->assign(static_cast<std::size_t>(n), 0.0);
  z_upper->assign(static_cast<std::size_t>(n), 0.0);
  if (!nlp.Evaluate(s.data(), true)) return kNaN;
  std::vector<double> lower, upper;
  nlp.ConstraintBounds(&lower, &upper);
  std::vector<Eigen::VectorXd> columns;
  std::vector<std::pair<int, int>>
      what;  // (kind 0 = constraint, 1 = lower bound, 2 = upper), index
  for (int k = 0; k < m; ++k) {
    const double g = nlp.g()[static_cast<std::size_t>(k)];
    const auto kk = static_cast<std::size_t>(k);
    if (std::abs(g - lower[kk]) <= kActiveRelative || std::abs(g - upper[kk]) <= kActiveRelative) {
      columns.push_back(nlp.jacobian().row(k).transpose());
      what.push_back({0, k});
    }
  }
  for (int j = 0; j < n; ++j) {
    if (s[static_cast<std::size_t>(j)] <= kActiveRelative) {
      columns.push_back(-Eigen::VectorXd::Unit(n, j));
      what.push_back({1, j});
    } else if (s[static_cast<std::size_t>(j)] >= 1.0 - kActiveRelative) {
      columns.push_back(Eigen::VectorXd::Unit(n, j));
      what.push_back({2, j});
    }
  }
  const Eigen::VectorXd grad = nlp.grad_f();
  if (columns.empty())
    return grad.lpNorm<Eigen::Infinity>() / std::max(1.0, grad.lpNorm<Eigen::Infinity>());
  Eigen::MatrixXd a(n, static_cast<Eigen::Index>(columns.size()));
  for (std::size_t c = 0; c < columns.size(); ++c) a.col(static_cast<Eigen::Index>(c)) = columns[c];
  const Eigen::VectorXd mult = a.completeOrthogonalDecomposition().solve(-grad);
  for (std::size_t c = 0; c < what.size(); ++c) {
    const double v = mult(static_cast<Eigen::Index>(c));
    const auto idx = static_cast<std::size_t>(what[c].second);
    if (what[c].first == 0) (*lambda)[idx] = v;
    if (what[c].first == 1) (*z_lower)[idx] = v;
    if (what[c].first == 2) (*z_upper)[idx] = v;
  }
  const Eigen::VectorXd r = grad + a * mult;
  return r.lpNorm<Eigen::Infinity>() / std::max(1.0, grad.lpNorm<Eigen::Infinity>());
}

// KKT residual of a point with solver multipliers: |grad f + J^T lambda - z_L + z_U|_inf,
// relative to max(1, |grad f|_inf).
double KktResidual(ScaledDesignNlp& nlp, const LocalSolveOutcome& o) {
  if (!nlp.Evaluate(o.s.data(), true)) return kNaN;
  const Eigen::Map<const Eigen::VectorXd> lambda(o.lambda.data(),
                                                 static_cast<Eigen::Index>(o.lambda.size()));
  const Eigen::Map<const Eigen::VectorXd> zl(o.z_lower.data(),
                                             static_cast<Eigen::Index>(o.z_lower.size()));
  const Eigen::Map<const Eigen::VectorXd> zu(o.z_upper.data(),
                                             static_cast<Eigen::Index>(o.z_upper.size()));
  Eigen::VectorXd r = nlp.grad_f() - zl + zu;
  if (nlp.m() > 0) r += nlp.jacobian().transpose() * lambda;
  return r.lpNorm<Eigen::Infinity>() / std::max(1.0, nlp.grad_f().lpNorm<Eigen::Infinity>());
}

void FillBase(const DesignProblem& problem, DesignResult* result) {
  result->bat = problem.bat;
  if (problem.three_segment.has_value()) {
    result->three_segment = problem.three_segment;
    if (problem.three_segment->IsValid(nullptr)) result->bat.knots = problem.three_segment->Knots();
  }
  result->properties = ComputeMassProperties(result->bat, problem.inertia_model);
  result->objective_value = kNaN;
  result->sweet_spot_from_knob_m = kNaN;
  result->max_exit_speed_mps = kNaN;
  result->angular_speed_rad_s = problem.swing.angular_speed_rad_s;
  for (const DesignVariable& v : problem.variables) result->variables.push_back({v.path, kNaN});
  result->spread.objective_min = result->spread.objective_max = result->spread.objective_median =
      kNaN;
}

const char* ObjectiveUnit(DesignObjective objective) {
  switch (objective) {
    case DesignObjective::kMinMoi:
      return "kg_m2";
    case DesignObjective::kWidestSweetZone:
      return "m";
    case DesignObjective::kMinSting:
      return "j";
    default:
      return "mps";
  }
}

// The optimisation, with the progress it reports mapped into [progress_from, progress_to]
// and an overall deadline (OptimizeOverMaterials shares one budget between materials).
DesignResult Optimize(const DesignProblem& problem, const DesignOptions& options,
                      Progress* progress, double progress_from, double progress_to,
                      std::optional<Clock::time_point> shared_deadline) {
  const Clock::time_point start = Clock::now();
  const auto elapsed_s = [&start] {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  DesignResult result;
  Summary& summary = result.summary;
  const DesignBackend backend = MainBackend(problem, options);
  summary.backend = BackendName(backend);
  summary.models_used = {"mass_properties"};
  if (problem.objective != DesignObjective::kMinMoi) summary.models_used.push_back("rigid_pivot");
  const bool sting = problem.objective == DesignObjective::kMinSting;
  if (sting) {
    summary.models_used.push_back(kFlexibleBeamModel);
    summary.models_used.push_back("flexible");
  }
  summary.iterations = 0;
  summary.evaluations = 0;
  result.objective_unit = ObjectiveUnit(problem.objective);

  std::string why;
  DesignModel model;
  bool invalid = false;
  if (!options.IsValid(&why)) {
    invalid = true;
    why = "options." + why;
  } else if (sting && options.derivative_check != DerivativeCheck::kNone) {
    invalid = true;
    why =
        "options.derivative_check: objective = min_sting has no derivatives to check (it is "
        "solved derivative-free by COBYLA)";
  } else if (!DesignModel::Build(problem, options, &model, &why)) {
    invalid = true;
  }
  if (invalid) {
    FillBase(problem, &result);
    summary.termination = Termination::kInvalidInput;
    summary.message = why;
    summary.objective = kNaN;
    summary.constraint_violation = kNaN;
    summary.error_estimate = kNaN;
    summary.solve_time_s = elapsed_s();
    return result;
  }
  const bool cor_known = problem.cor.has_value() || problem.bat.material.cor.has_value();
  result.cor = cor_known ? model.cor() : kNaN;
  if (sting && options.backend != DesignBackend::kNloptCobyla) {
    summary.warnings.push_back(
        std::string("objective = min_sting: solved by NLopt LN_COBYLA, not ") +
        BackendName(options.backend) +
        ": the sting comes from an adaptive FE mesh and an adaptive ODE integration (piecewise "
        "smooth, no derivative), so a derivative-free solver is used");
  }

  try {
    const Clock::time_point deadline =
        shared_deadline.value_or(start + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(options.max_time_s)));
    std::vector<Run> runs;
    if (model.fixed_violations().empty()) {
      std::mt19937_64 rng(options.seed);
      const std::vector<double> x0 = model.BaseX();
      for (int i = 0; i < options.starts; ++i) {
        // Draw every start's point whether or not it runs, so start i is the same design for
        // any budget (reproducible).
        const std::vector<double> x = i == 0 ? x0 : RandomStart(model, rng, options.min_knot_gap_m);
        if (i > 0 && (Clock::now() >= deadline || IsCancelled(progress))) {
          summary.warnings.push_back(
              std::string(IsCancelled(progress) ? "cancelled" : "time budget reached") + " after " +
              std::to_string(i) + " of " + std::to_string(options.starts) + " starts");
          break;
        }
        ScaledDesignNlp nlp(model);
        LocalSolveSettings settings = SettingsFrom(options, deadline, progress);
        if (i == 0) settings.derivative_check = options.derivative_check;
        LocalSolveOutcome o = Solve(backend, nlp, nlp.ToScaled(x), settings);
        summary.iterations += o.iterations;
        summary.evaluations += o.evaluations;
        if (i == 0) {
          result.derivative_check_errors = o.derivative_check_errors;
          result.derivative_check_report = o.derivative_check_report;
        }
        runs.push_back(Finish(model, std::move(o)));
        if (progress != nullptr) {
          progress->Report(progress_from +
                           (progress_to - progress_from) * (i + 1.0) / options.starts);
        }
        if (runs.back().outcome.cancelled || runs.back().outcome.deadline_reached) break;
      }
    }

    // Spread.
    DesignSpread& spread = result.spread;
    spread.starts = static_cast<int>(runs.size());
    std::vector<double> feasible_objectives;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const Run& r = runs[i];
      DesignStart d;
      d.index = static_cast<int>(i);
      d.termination = r.outcome.termination;
      d.raw_status = r.outcome.raw_status;
      d.iterations = r.outcome.iterations;
      d.objective = r.objective;
      d.constraint_violation = r.violation;
      spread.runs.push_back(d);
      if (r.outcome.termination == Termination::kConverged) ++spread.converged;
      if (r.feasible) {
        ++spread.feasible;
        feasible_objectives.push_back(r.objective);
      }
    }
    spread.objective_min = spread.objective_max = spread.objective_median = kNaN;
    if (!feasible_objectives.empty()) {
      std::sort(feasible_objectives.begin(), feasible_objectives.end());
      const std::size_t q = feasible_objectives.size();
      spread.objective_min = feasible_objectives.front();
      spread.objective_max = feasible_objectives.back();
      spread.objective_median =
          q % 2 == 1 ? feasible_objectives[q / 2]
                     : 0.5 * (feasible_objectives[q / 2 - 1] + feasible_objectives[q / 2]);
    }

    // The answer.
    const int best = ChooseRun(model, runs);
    spread.best_start = best;
    std::vector<double> x = best >= 0 ? runs[static_cast<std::size_t>(best)].x : model.BaseX();
    result.bat = model.BatAt(x.data());
    result.three_segment = model.ShapeAt(x.data());
    for (std::size_t j = 0; j < x.size(); ++j)
      result.variables.push_back({model.variables()[j].path, x[j]});
    const PublicEvaluation pub = EvaluatePublic(problem, model, result.bat, cor_known);
    result.properties = pub.properties;
    result.objective_value = pub.objective;
    result.sweet_spot_from_knob_m = pub.sweet_spot_m;
    result.max_exit_speed_mps = pub.max_exit_speed_mps;
    result.angular_speed_rad_s = pub.omega_rad_s;
    summary.objective = pub.objective;

    // Independent re-check of every constraint (public mass properties).
    double worst = 0.0, worst_relative = 0.0;
    for (const DesignConstraintSpec& c : model.constraints()) {
      const double v = PublicConstraintValue(model, c, pub, result.bat, x.data());
      const double viol = Violation(c, v);
      worst = std::max(worst, viol);
      worst_relative = std::max(worst_relative, viol / c.scale);
    }
    summary.constraint_violation = worst;
    std::string bat_why;
    const bool bat_valid = result.bat.IsValid(&bat_why);

    if (!model.fixed_violations().empty()) {
      summary.termination = Termination::kInfeasible;
      std::string text;
      for (const std::string& v : model.fixed_violations()) {
        DesignConflict d;
        d.constraints.push_back(v.substr(0, v.find(' ')));
        d.requested_min = d.requested_max = d.achievable_min = d.achievable_max = kNaN;
        d.shortfall = kNaN;
        d.message = v;
        result.conflicts.push_back(d);
        text += (text.empty() ? "" : "; ") + v;
      }
      summary.message = "infeasible: " + text;
      summary.raw_status = 0;
      summary.error_estimate = kNaN;
      summary.solve_time_s = elapsed_s();
      return result;
    }
    if (best < 0) {
      summary.termination = Termination::kFailure;
      summary.message = "no local solve returned a design";
      if (!runs.empty()) {
        const LocalSolveOutcome& o = runs.front().outcome;
        summary.raw_status = o.raw_status;
        summary.message += " (" + o.status_name + (o.message.empty() ? "" : ": " + o.message) + ")";
      }
      summary.error_estimate = kNaN;
      summary.solve_time_s = elapsed_s();
      return result;
    }
    const Run& chosen = runs[static_cast<std::size_t>(best)];
    const LocalSolveOutcome& o = chosen.outcome;
    summary.raw_status = o.raw_status;
    summary.termination = o.termination;
    summary.message = o.status_name;
    if (!o.message.empty()) summary.message += ": " + o.message;
    if (o.cancelled)
      summary.message = "cancelled (" + summary.message + "); the best design so far is kept";
    if (o.deadline_reached) {
      summary.message = "time budget max_time_s = " + Num(options.max_time_s) + " s reached (" +
                        summary.message + "); the best design so far is kept";
    }
    if (o.raw_status == 1 && backend == DesignBackend::kIpopt) {
      summary.warnings.push_back("Ipopt converged to its acceptable (looser) tolerance");
    }
    if (!bat_valid) {
      summary.termination = Termination::kFailure;
      summary.message = "the optimised bat is invalid: " + bat_why;
    }
    if (pub.sting.has_value()) {
      const StingEvaluation& st = *pub.sting;
      for (const std::string& w : st.impact.summary.warnings)
        summary.warnings.push_back("sting: " + w);
      if (st.ok) {
        DesignSting d;
        d.impact_from_knob_m = st.sweet_spot_from_knob_m;
        d.hands_vibration_energy_j = st.sting_j;
        d.error_estimate_j = st.impact.error_estimate_hands_energy_j;
        d.impact = st.impact;
        result.sting = std::move(d);
      } else if (summary.termination != Termination::kFailure) {
        summary.termination = Termination::kFailure;
        summary.message = "the sting of the optimised bat cannot be computed: " + st.message;
      }
    }
    const bool feasible = worst_relative <= kFeasibleRelative;
    if (summary.termination == Termination::kConverged && !feasible) {
      summary.termination = Termination::kNoConvergence;
      summary.warnings.push_back(
          "the solver reported convergence but the re-checked design "
          "violates a constraint by " +
          Num(worst));
    }
    if (!feasible && summary.termination != Termination::kFailure &&
        summary.termination != Termination::kInvalidInput) {
      // No start reached a feasible design: say why.
      const bool solver_says_infeasible = summary.termination == Termination::kInfeasible;
      if (options.explain_infeasibility && !o.cancelled) {
        int evals = 0, iters = 0;
        result.conflicts = Explain(model, options, deadline, progress, chosen,
                                   solver_says_infeasible, &evals, &iters);
        summary.evaluations += evals;
        summary.iterations += iters;
        const bool isolated =
            !result.conflicts.empty() && std::isfinite(result.conflicts.front().achievable_min);
        const bool geometric = !result.conflicts.empty() && result.conflicts.front().message.rfind(
                                                                "the variable bounds", 0) == 0;
        if (isolated || geometric || solver_says_infeasible) {
          summary.termination = Termination::kInfeasible;
        }
      } else if (solver_says_infeasible) {
        summary.termination = Termination::kInfeasible;
      }
      if (summary.termination == Termination::kInfeasible) {
        std::string text;
        for (const DesignConflict& d : result.conflicts)
          text += (text.empty() ? "" : "; ") + d.message;
        summary.message = "infeasible: " + (text.empty() ? o.status_name : text) +
                          "; the least-violating design found is returned";
      }
    } else if (summary.termination == Termination::kConverged) {
      summary.message = "converged (" + o.status_name + ")";
    }

    // Active constraints and their multipliers (sensitivities of the objective).
    {
      ScaledDesignNlp nlp(model);
      std::vector<double> s = nlp.ToScaled(x);
      LocalSolveOutcome mult = o;
      double kkt = kNaN;
      if (model.derivative_free()) {
        // No gradient of the sting: neither multipliers nor a KKT residual.
        mult.lambda.assign(static_cast<std::size_t>(model.m()), kNaN);
        mult.z_lower.assign(static_cast<std::size_t>(model.n()), kNaN);
        mult.z_upper.assign(static_cast<std::size_t>(model.n()), kNaN);
        summary.warnings.push_back(
            "objective = min_sting: the sting has no derivative, so the active constraints have "
            "no multipliers (NaN) and error_estimate (the KKT residual) is not computed");
      } else if (o.has_multipliers && o.lambda.size() == static_cast<std::size_t>(model.m())) {
        mult.s = s;
        kkt = KktResidual(nlp, mult);
      } else {
        kkt = EstimateMultipliers(nlp, s, &mult.lambda, &mult.z_lower, &mult.z_upper);
      }
      summary.error_estimate = kkt;
      const double sense = model.maximize() ? -1.0 : 1.0;
      const double fs = model.objective_scale();
      if (nlp.Evaluate(s.data(), false)) {
        std::vector<double> lower, upper;
        nlp.ConstraintBounds(&lower, &upper);
        for (int k = 0; k < model.m(); ++k) {
          const auto kk = static_cast<std::size_t>(k);
          const DesignConstraintSpec& c = model.constraints()[kk];
          const double g = nlp.g()[kk];
          const bool at_lower = std::abs(g - lower[kk]) <= kActiveRelative;
          const bool at_upper = std::abs(g - upper[kk]) <= kActiveRelative;
          if (!at_lower && !at_upper) continue;
          DesignActiveConstraint a;
          a.name = c.lower == c.upper ? c.name : (at_upper ? c.max_name : c.min_name);
          a.unit = c.unit;
          a.value = g * c.scale;
          a.bound = at_upper ? c.upper : c.lower;
          a.multiplier = -sense * fs * mult.lambda[kk] / c.scale;
          result.active_constraints.push_back(a);
        }
        for (int j = 0; j < model.n(); ++j) {
          const auto jj = static_cast<std::size_t>(j);
          const DesignVariableSpec& v = model.variables()[jj];
          const double width = v.upper - v.lower;
          DesignActiveConstraint a;
          a.unit = v.path.ends_with("kg_m3") ? "kg_m3" : "m";
          a.value = x[jj];
          if (s[jj] <= kActiveRelative) {
            a.name = v.path + ".min";
            a.bound = v.lower;
            a.multiplier = sense * fs * mult.z_lower[jj] / width;
          } else if (s[jj] >= 1.0 - kActiveRelative) {
            a.name = v.path + ".max";
            a.bound = v.upper;
            a.multiplier = -sense * fs * mult.z_upper[jj] / width;
          } else {
            continue;
          }
          result.active_constraints.push_back(a);
        }
      }
    }
  } catch (const std::bad_alloc&) {
    summary.termination = Termination::kFailure;
    summary.message = "out of memory";
  } catch (const std::exception& e) {
    summary.termination = Termination::kFailure;
    summary.message = std::string("failure: ") + e.what();
  }
  summary.solve_time_s = elapsed_s();
  return result;
}

}  // namespace

DesignResult OptimizeDesign(const DesignProblem& problem, const DesignOptions& options,
                            Progress* progress) {
  return Optimize(problem, options, progress, 0.0, 1.0, std::nullopt);
}

MaterialChoiceResult OptimizeOverMaterials(const DesignProblem& problem,
                                           const std::vector<Material>& materials,
                                           const DesignOptions& options, Progress* progress) {
  const Clock::time_point start = Clock::now();
  const Clock::time_point deadline =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                  std::isfinite(options.max_time_s) && options.max_time_s > 0.0 ? options.max_time_s
                                                                                : 0.0));
  MaterialChoiceResult out;
  out.summary.backend = BackendName(MainBackend(problem, options));
  out.summary.iterations = 0;
  out.summary.evaluations = 0;
  out.summary.objective = kNaN;
  if (materials.empty()) {
    out.summary.termination = Termination::kInvalidInput;
    out.summary.message = "materials: give at least one material";
    out.summary.solve_time_s = 0.0;
    return out;
  }
  const bool maximize = problem.objective != DesignObjective::kMinMoi &&
                        problem.objective != DesignObjective::kMinSting;
  for (std::size_t i = 0; i < materials.size(); ++i) {
    if (IsCancelled(progress)) {
      out.summary.warnings.push_back("cancelled after " + std::to_string(i) + " materials");
      break;
    }
    DesignProblem p = problem;
    p.bat.material = materials[i];
    MaterialDesignResult r;
    r.material = materials[i].name;
    const double n = static_cast<double>(materials.size());
    r.result = Optimize(p, options, progress, i / n, (i + 1.0) / n, deadline);
    out.summary.iterations += std::max(r.result.summary.iterations, 0);
    out.summary.evaluations += std::max(r.result.summary.evaluations, 0);
    out.per_material.push_back(std::move(r));
  }
  auto rank = [](const DesignResult& r) {
    if (r.summary.termination == Termination::kConverged) return 0;
    if (r.summary.termination == Termination::kNoConvergence) return 1;
    return 2;
  };
  for (std::size_t i = 0; i < out.per_material.size(); ++i) {
    const DesignResult& r = out.per_material[i].result;
    if (rank(r) == 2 || !std::isfinite(r.objective_value)) continue;
    if (out.best < 0) {
      out.best = static_cast<int>(i);
      continue;
    }
    const DesignResult& b = out.per_material[static_cast<std::size_t>(out.best)].result;
    if (rank(r) < rank(b) ||
        (rank(r) == rank(b) && (maximize ? r.objective_value > b.objective_value
                                         : r.objective_value < b.objective_value))) {
      out.best = static_cast<int>(i);
    }
  }
  if (out.best >= 0) {
    const MaterialDesignResult& b = out.per_material[static_cast<std::size_t>(out.best)];
    out.summary.termination = b.result.summary.termination;
    out.summary.raw_status = b.result.summary.raw_status;
    out.summary.objective = b.result.objective_value;
    out.summary.constraint_violation = b.result.summary.constraint_violation;
    out.summary.error_estimate = b.result.summary.error_estimate;
    out.summary.models_used = b.result.summary.models_used;
    out.summary.message = "best material: " + b.material + " (" + b.result.summary.message + ")";
  } else {
    bool all_infeasible = !out.per_material.empty();
    bool all_invalid = !out.per_material.empty();
    for (const auto& r : out.per_material) {
      all_infeasible = all_infeasible && r.result.summary.termination == Termination::kInfeasible;
      all_invalid = all_invalid && r.result.summary.termination == Termination::kInvalidInput;
    }
    out.summary.termination = all_infeasible ? Termination::kInfeasible
                              : all_invalid  ? Termination::kInvalidInput
                                             : Termination::kFailure;
    std::string text;
    for (const auto& r : out.per_material) {
      text += (text.empty() ? "" : "; ") + r.material + ": " + r.result.summary.message;
    }
    out.summary.message = "no material gives a usable design: " + text;
  }
  out.summary.solve_time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

}  // namespace sweetspot::core
