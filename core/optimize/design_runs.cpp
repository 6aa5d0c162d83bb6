// OptimizeDesign's local solves: the end of a solve, the choice among the starts, the
// backends, the multipliers and the active constraints. See design_runs.hpp.
#include "core/optimize/design_runs.hpp"

#include "core/numerics/limits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace sweetspot::core::design_detail {
namespace {

// A constraint is reported active when within this of a limit, relative to its scale; a
// variable when within this fraction of its range of a bound.
constexpr double kActiveRelative = 1e-6;

// Above this many variables the KKT residual sums J^T lambda over the Jacobian's nonzero
// entries (rounding differs from the dense product's in the last bits); at most this many it
// keeps the dense product (the certificate's threshold, CertificateTolerances).
constexpr int kDenseMaxVariables = 32;

bool Better(const DesignModel& model, double a, double b) {
  return model.maximize() ? a > b : a < b;
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
  if (nlp.n() > kDenseMaxVariables && nlp.m() > 0 &&
      o.lambda.size() == static_cast<std::size_t>(nlp.m()) &&
      o.z_lower.size() == static_cast<std::size_t>(nlp.n()) &&
      o.z_upper.size() == static_cast<std::size_t>(nlp.n())) {
    // J^T lambda over the rows' nonzero entries: O(m + n), not O(m n).
    if (!nlp.EvaluateRows(o.s.data())) return kNaN;
    Eigen::VectorXd r = nlp.grad_f();
    for (Eigen::Index j = 0; j < r.size(); ++j) {
      r(j) -= o.z_lower[static_cast<std::size_t>(j)];
      r(j) += o.z_upper[static_cast<std::size_t>(j)];
    }
    for (int k = 0; k < nlp.m(); ++k) {
      const double lk = o.lambda[static_cast<std::size_t>(k)];
      for (const auto& [j, v] : nlp.jacobian_rows()[static_cast<std::size_t>(k)]) r(j) += v * lk;
    }
    return r.lpNorm<Eigen::Infinity>() / std::max(1.0, nlp.grad_f().lpNorm<Eigen::Infinity>());
  }
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

}  // namespace

// Evaluates the end of a local solve.
Run Finish(const DesignModel& model, LocalSolveOutcome outcome, double feasibility_tolerance) {
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
    run.feasible = run.violation <= feasibility_tolerance;
  }
  run.outcome = std::move(outcome);
  return run;
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
  return problem.objective == DesignObjective::kMinSting ||
                 problem.objective == DesignObjective::kMaxDistance
             ? DesignBackend::kNloptCobyla
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
  s.feasibility_tolerance = options.feasibility_tolerance;
  s.lift = options.lift;
  s.taper_steps = options.taper_steps;
  return s;
}

double Violation(const DesignConstraintSpec& c, double v) {
  if (!std::isfinite(v)) return kInf;
  return std::max({0.0, c.lower - v, v - c.upper});
}

void ReportActiveConstraints(const DesignModel& model, const std::vector<double>& x,
                             const LocalSolveOutcome& o, DesignResult* result,
                             double feasibility_tolerance) {
  ScaledDesignNlp nlp(model);
  std::vector<double> s = nlp.ToScaled(x);
  LocalSolveOutcome mult = o;
  double kkt = kNaN;
  if (model.derivative_free()) {
    // No gradient of the sting: neither multipliers nor a KKT residual.
    mult.lambda.assign(static_cast<std::size_t>(model.m()), kNaN);
    mult.z_lower.assign(static_cast<std::size_t>(model.n()), kNaN);
    mult.z_upper.assign(static_cast<std::size_t>(model.n()), kNaN);
    result->summary.warnings.push_back(
        std::string("objective = ") + model.objective_name() +
        ": the objective has no derivative, so the active constraints have no multipliers "
        "(NaN) and error_estimate (the KKT residual) is not computed");
  } else if (o.has_multipliers && o.lambda.size() == static_cast<std::size_t>(model.m())) {
    mult.s = s;
    kkt = KktResidual(nlp, mult);
  } else {
    kkt = EstimateMultipliers(nlp, s, &mult.lambda, &mult.z_lower, &mult.z_upper);
  }
  result->summary.error_estimate = kkt;
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
      // The verdict: met to the stated tolerance of the constraint's scale.
      a.tolerance = feasibility_tolerance * std::abs(c.scale);
      a.satisfied = Violation(c, a.value) <= a.tolerance;
      result->active_constraints.push_back(a);
    }
    for (int j = 0; j < model.n(); ++j) {
      const auto jj = static_cast<std::size_t>(j);
      const DesignVariableSpec& v = model.variables()[jj];
      const double width = v.upper - v.lower;
      DesignActiveConstraint a;
      a.unit = v.scale ? "" : v.path.ends_with("kg_m3") ? "kg_m3" : "m";  // a scale: a factor
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
      // A bound holds to the stated tolerance of the variable's range (the solution is clamped
      // into it: always satisfied).
      a.tolerance = feasibility_tolerance * width;
      a.satisfied = a.value >= v.lower - a.tolerance && a.value <= v.upper + a.tolerance;
      result->active_constraints.push_back(a);
    }
  }
}
// The spread of the starts' answers.
void FillSpread(const std::vector<Run>& runs, DesignSpread* spread_out) {
  DesignSpread& spread = *spread_out;
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
}

}  // namespace sweetspot::core::design_detail
