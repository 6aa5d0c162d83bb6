// The NLopt backends over ScaledDesignNlp: LD_SLSQP (the same functions and gradients Ipopt
// sees), for cross-checks, and LN_COBYLA (values only), for the derivative-free min_sting. One
// nlopt::opt per solve; every NLopt exception is caught; the best point is kept on round-off
// (NLopt 2.7.1 leaves it in x) and, for COBYLA, on any early stop (tracked in the callbacks).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlopt.hpp>

#include "core/nlopt_search.hpp"
#include "core/optimize/design_backends.hpp"

namespace sweetspot::core {
namespace {

struct NloptContext {
  ScaledDesignNlp* nlp = nullptr;
  const LocalSolveSettings* settings = nullptr;
  bool failed = false;     // an evaluation was not finite
  bool cancelled = false;  // Progress::Cancel()
  bool deadline = false;   // wall-clock budget
};

struct NloptConstraint {
  NloptContext* context = nullptr;
  int index = 0;       // constraint k
  double bound = 0.0;  // scaled bound
  double sign = 1.0;   // +1: g - upper <= 0; -1: lower - g <= 0
};

double Objective(unsigned n, const double* s, double* grad, void* data) {
  auto* c = static_cast<NloptContext*>(data);
  if (IsCancelled(c->settings->progress)) {
    c->cancelled = true;
    throw nlopt::forced_stop();
  }
  if (std::chrono::steady_clock::now() >= c->settings->deadline) {
    c->deadline = true;
    throw nlopt::forced_stop();
  }
  if (!c->nlp->Evaluate(s, grad != nullptr)) {
    c->failed = true;
    if (grad != nullptr) {
      for (unsigned j = 0; j < n; ++j) grad[j] = 0.0;
    }
    return std::numeric_limits<double>::max();  // SLSQP backs off from a huge value
  }
  if (grad != nullptr) {
    for (unsigned j = 0; j < n; ++j) grad[j] = c->nlp->grad_f()(static_cast<Eigen::Index>(j));
  }
  return c->nlp->f();
}

double Constraint(unsigned n, const double* s, double* grad, void* data) {
  auto* k = static_cast<NloptConstraint*>(data);
  ScaledDesignNlp& nlp = *k->context->nlp;
  if (!nlp.Evaluate(s, grad != nullptr)) {
    k->context->failed = true;
    if (grad != nullptr) {
      for (unsigned j = 0; j < n; ++j) grad[j] = 0.0;
    }
    return 1.0;  // violated
  }
  if (grad != nullptr) {
    for (unsigned j = 0; j < n; ++j) {
      grad[j] = k->sign * nlp.jacobian()(k->index, static_cast<Eigen::Index>(j));
    }
  }
  return k->sign * (nlp.g()[static_cast<std::size_t>(k->index)] - k->bound);
}

// ---------------------------------------------------------------------------------------------
// COBYLA.

// A scaled objective COBYLA gets where the model has no value (the flexible model refused the
// design): far above any design's (the objective is scaled by the start's value), so COBYLA
// steps back from such designs, and finite, so its linear models stay defined.
constexpr double kCobylaBarrier = 1e6;

struct CobylaContext {
  ScaledDesignNlp* nlp = nullptr;
  const LocalSolveSettings* settings = nullptr;
  int failures = 0;        // evaluations where the objective had no value
  bool cancelled = false;  // Progress::Cancel()
  bool deadline = false;   // wall-clock budget
  // The point where the objective last failed: its constraints come straight from the model.
  std::vector<double> failed_s;
  // The best point evaluated: least violation beyond the feasibility tolerance, then least f.
  std::vector<double> best_s;
  double best_excess = std::numeric_limits<double>::infinity();
  double best_f = std::numeric_limits<double>::infinity();
};

struct CobylaConstraint {
  CobylaContext* context = nullptr;
  int index = 0;       // constraint k
  double bound = 0.0;  // scaled bound
  double sign = 1.0;   // +1: g - upper <= 0; -1: lower - g <= 0
};

bool SamePoint(const std::vector<double>& a, const double* s) {
  return !a.empty() && std::equal(a.begin(), a.end(), s);
}

// Evaluates values at s; false (and s remembered) when the objective has no value there.
bool CobylaEvaluate(CobylaContext* c, const double* s) {
  if (SamePoint(c->failed_s, s)) return false;
  if (c->nlp->Evaluate(s, false) && std::isfinite(c->nlp->f())) return true;
  c->failed_s.assign(s, s + c->nlp->n());
  return false;
}

double CobylaObjective(unsigned n, const double* s, double* /*grad*/, void* data) {
  auto* c = static_cast<CobylaContext*>(data);
  if (IsCancelled(c->settings->progress)) {
    c->cancelled = true;
    throw nlopt::forced_stop();
  }
  if (std::chrono::steady_clock::now() >= c->settings->deadline) {
    c->deadline = true;
    throw nlopt::forced_stop();
  }
  if (!CobylaEvaluate(c, s)) {
    ++c->failures;
    return kCobylaBarrier;
  }
  const double f = c->nlp->f();
  const double excess = std::max(0.0, c->nlp->Violation() - c->settings->feasibility_tolerance);
  if (excess < c->best_excess || (excess == c->best_excess && f < c->best_f)) {
    c->best_s.assign(s, s + n);
    c->best_excess = excess;
    c->best_f = f;
  }
  return f;
}

double CobylaConstraintValue(unsigned /*n*/, const double* s, double* /*grad*/, void* data) {
  auto* k = static_cast<CobylaConstraint*>(data);
  ScaledDesignNlp& nlp = *k->context->nlp;
  const auto kk = static_cast<std::size_t>(k->index);
  double g = 0.0;
  if (CobylaEvaluate(k->context, s)) {
    g = nlp.g()[kk];
  } else {
    // The objective failed here, the constraints (closed forms) need not have.
    const DesignConstraintSpec& spec = nlp.model().constraints()[kk];
    const std::vector<double> x = nlp.ToUser(s);
    g = nlp.model().Value(spec.f, x.data()) / spec.scale;
    if (!std::isfinite(g)) return 1.0;  // violated
  }
  return k->sign * (g - k->bound);
}

// ---------------------------------------------------------------------------------------------
// Projection onto the constraints (after COBYLA).

struct ProjectionContext {
  std::vector<double> centre;  // the point projected
};

double ProjectionObjective(unsigned n, const double* s, double* grad, void* data) {
  auto* c = static_cast<ProjectionContext*>(data);
  double f = 0.0;
  for (unsigned j = 0; j < n; ++j) {
    const double d = s[j] - c->centre[j];
    f += 0.5 * d * d;
    if (grad != nullptr) grad[j] = d;
  }
  return f;
}

// COBYLA meets the constraints only as its trust radius shrinks, and may stop on the objective's
// tolerance with a violation of ~1e-8 relative. The constraints are smooth closed forms with
// exact gradients: move *s to the nearest point (Euclidean, scaled variables) that meets them, by
// SLSQP on the constraints alone (microseconds per evaluation, no sting). Kept only when it
// lowers the violation. Never throws.
void ProjectOntoConstraints(const ScaledDesignNlp& nlp, const LocalSolveSettings& settings,
                            std::vector<double>* s) {
  try {
    DesignFunctionSpec zero;  // kLinear, no terms: the constraints alone
    const DesignModel model = nlp.model().WithObjective(zero, false, 1.0, "");
    ScaledDesignNlp constraints_only(model);
    if (!constraints_only.Evaluate(s->data(), false)) return;
    const double before = constraints_only.Violation();
    if (!(before > settings.constraint_tolerance)) return;
    NloptContext context{&constraints_only, &settings};
    ProjectionContext projection{*s};
    const auto n = static_cast<unsigned>(nlp.n());
    nlopt::opt opt(nlopt::LD_SLSQP, n);
    opt.set_lower_bounds(std::vector<double>(n, 0.0));
    opt.set_upper_bounds(std::vector<double>(n, 1.0));
    opt.set_min_objective(ProjectionObjective, &projection);
    std::vector<double> lower, upper;
    constraints_only.ConstraintBounds(&lower, &upper);
    std::vector<NloptConstraint> constraints;
    constraints.reserve(2 * static_cast<std::size_t>(nlp.m()));
    const double tol = settings.constraint_tolerance;
    for (int k = 0; k < nlp.m(); ++k) {
      const auto kk = static_cast<std::size_t>(k);
      if (lower[kk] == upper[kk]) {
        constraints.push_back({&context, k, upper[kk], 1.0});
        opt.add_equality_constraint(Constraint, &constraints.back(), tol);
        continue;
      }
      if (std::isfinite(upper[kk])) {
        constraints.push_back({&context, k, upper[kk], 1.0});
        opt.add_inequality_constraint(Constraint, &constraints.back(), tol);
      }
      if (std::isfinite(lower[kk])) {
        constraints.push_back({&context, k, lower[kk], -1.0});
        opt.add_inequality_constraint(Constraint, &constraints.back(), tol);
      }
    }
    opt.set_xtol_rel(1e-14);
    opt.set_maxeval(100);
    std::vector<double> p = *s;
    double f = 0.0;
    try {
      opt.optimize(p, f);
    } catch (const nlopt::roundoff_limited&) {
      // p holds the best point: judged below like any other
    }
    for (double& v : p) v = std::clamp(v, 0.0, 1.0);
    if (!constraints_only.Evaluate(p.data(), false)) return;
    if (constraints_only.Violation() < before) *s = p;
  } catch (const std::exception&) {
    // keep *s
  }
}

// Adds every constraint of `nlp` to `opt` as NLopt constraints on the scaled problem:
// equalities as one equality, ranges as one or two inequalities (g - upper <= 0,
// lower - g <= 0). `constraints` keeps their callback data alive (reserved up front so the
// pointers stay valid). Constraint is NloptConstraint or CobylaConstraint.
template <typename Context, typename Constraint>
void AddConstraints(nlopt::opt& opt, ScaledDesignNlp& nlp, Context* context, double tol,
                    nlopt::func value, std::vector<Constraint>* constraints) {
  std::vector<double> lower, upper;
  nlp.ConstraintBounds(&lower, &upper);
  constraints->reserve(2 * static_cast<std::size_t>(nlp.m()));
  for (int k = 0; k < nlp.m(); ++k) {
    const auto kk = static_cast<std::size_t>(k);
    if (lower[kk] == upper[kk]) {
      constraints->push_back({context, k, upper[kk], 1.0});
      opt.add_equality_constraint(value, &constraints->back(), tol);
      continue;
    }
    if (std::isfinite(upper[kk])) {
      constraints->push_back({context, k, upper[kk], 1.0});
      opt.add_inequality_constraint(value, &constraints->back(), tol);
    }
    if (std::isfinite(lower[kk])) {
      constraints->push_back({context, k, lower[kk], -1.0});
      opt.add_inequality_constraint(value, &constraints->back(), tol);
    }
  }
}

// Runs opt.optimize from s (left at the point NLopt returns) and maps every NLopt exception
// to its result code, with the exception's text in *message where it has one.
int RunOptimize(nlopt::opt& opt, std::vector<double>& s, std::string* message) {
  double f = 0.0;
  try {
    return opt.optimize(s, f);
  } catch (const nlopt::roundoff_limited&) {
    return nlopt::ROUNDOFF_LIMITED;  // s holds the best point: keep it
  } catch (const nlopt::forced_stop&) {
    return nlopt::FORCED_STOP;
  } catch (const std::invalid_argument& e) {
    *message = e.what();
    return nlopt::INVALID_ARGS;
  } catch (const std::bad_alloc&) {
    return nlopt::OUT_OF_MEMORY;
  } catch (const std::runtime_error& e) {
    *message = e.what();
    return nlopt::FAILURE;
  }
}

// NLopt's time budget: what is left until the deadline (at least 1 ms), s.
double SecondsLeft(const LocalSolveSettings& settings) {
  const double left_s =
      std::chrono::duration<double>(settings.deadline - std::chrono::steady_clock::now()).count();
  return std::max(left_s, 1e-3);
}

}  // namespace

LocalSolveOutcome SolveWithCobyla(ScaledDesignNlp& nlp, const std::vector<double>& s0,
                                  const LocalSolveSettings& settings) {
  LocalSolveOutcome out;
  const int evaluations_before = nlp.evaluations();
  CobylaContext context;
  context.nlp = &nlp;
  context.settings = &settings;
  std::vector<double> s = s0;
  for (double& v : s) v = std::clamp(v, 0.0, 1.0);
  int status = nlopt::FAILURE;
  try {
    const auto n = static_cast<unsigned>(nlp.n());
    nlopt::opt opt(nlopt::LN_COBYLA, n);
    opt.set_lower_bounds(std::vector<double>(n, 0.0));
    opt.set_upper_bounds(std::vector<double>(n, 1.0));
    opt.set_min_objective(CobylaObjective, &context);
    std::vector<CobylaConstraint> constraints;
    AddConstraints(opt, nlp, &context, settings.constraint_tolerance, CobylaConstraintValue,
                   &constraints);
    const double rel = std::max(settings.tolerance, kDerivativeFreeTolerance);
    opt.set_ftol_rel(rel);
    opt.set_xtol_rel(rel);
    opt.set_maxeval(settings.max_iterations);  // one evaluation per COBYLA iteration
    opt.set_maxtime(SecondsLeft(settings));
    status = RunOptimize(opt, s, &out.message);
    out.iterations = opt.get_numevals();
  } catch (const std::exception& e) {
    status = nlopt::FAILURE;
    out.message = std::string("exception: ") + e.what();
  }
  // A normal end is COBYLA's own answer; after any other stop, the best point evaluated.
  const bool normal_end = status == nlopt::SUCCESS || status == nlopt::FTOL_REACHED ||
                          status == nlopt::XTOL_REACHED || status == nlopt::STOPVAL_REACHED;
  if (!normal_end && !context.best_s.empty()) s = context.best_s;
  for (double& v : s) v = std::clamp(v, 0.0, 1.0);
  ProjectOntoConstraints(nlp, settings, &s);
  out.s = s;
  out.has_point = true;
  out.raw_status = status;
  out.status_name = NloptResultName(status);
  out.cancelled = context.cancelled;
  // NLopt's maxtime is the budget left: reaching it is the deadline too.
  out.deadline_reached = context.deadline || status == nlopt::MAXTIME_REACHED;
  out.termination = TerminationFromNloptResult(status);
  if (status == nlopt::ROUNDOFF_LIMITED || context.cancelled || context.deadline) {
    out.termination = Termination::kNoConvergence;  // the best point so far is kept
  }
  if (context.failures > 0) {
    const std::string note = std::to_string(context.failures) +
                             " evaluation(s) had no objective value (the model refused the "
                             "design) and were given a barrier value";
    out.message = out.message.empty() ? note : out.message + "; " + note;
  }
  out.evaluations = nlp.evaluations() - evaluations_before;
  return out;
}

LocalSolveOutcome SolveWithNlopt(ScaledDesignNlp& nlp, const std::vector<double>& s0,
                                 const LocalSolveSettings& settings) {
  LocalSolveOutcome out;
  const int evaluations_before = nlp.evaluations();
  NloptContext context{&nlp, &settings};
  std::vector<double> s = s0;
  for (double& v : s) v = std::clamp(v, 0.0, 1.0);
  int status = nlopt::FAILURE;
  try {
    const auto n = static_cast<unsigned>(nlp.n());
    nlopt::opt opt(nlopt::LD_SLSQP, n);
    opt.set_lower_bounds(std::vector<double>(n, 0.0));
    opt.set_upper_bounds(std::vector<double>(n, 1.0));
    opt.set_min_objective(Objective, &context);
    std::vector<NloptConstraint> constraints;
    AddConstraints(opt, nlp, &context, settings.constraint_tolerance, Constraint, &constraints);
    opt.set_ftol_rel(settings.tolerance);
    opt.set_xtol_rel(settings.tolerance);
    // SLSQP counts evaluations, not iterations: allow a few per iteration.
    opt.set_maxeval(20 * settings.max_iterations);
    opt.set_maxtime(SecondsLeft(settings));
    status = RunOptimize(opt, s, &out.message);
    out.iterations = opt.get_numevals();
  } catch (const std::exception& e) {
    status = nlopt::FAILURE;
    out.message = std::string("exception: ") + e.what();
  }
  for (double& v : s) v = std::clamp(v, 0.0, 1.0);
  out.s = s;
  out.has_point = true;
  out.raw_status = status;
  out.status_name = NloptResultName(status);
  out.cancelled = context.cancelled;
  // NLopt's maxtime is the budget left: reaching it is the deadline too.
  out.deadline_reached = context.deadline || status == nlopt::MAXTIME_REACHED;
  out.termination = TerminationFromNloptResult(status);
  if (status == nlopt::ROUNDOFF_LIMITED || context.cancelled || context.deadline) {
    out.termination = Termination::kNoConvergence;  // the best point so far is kept
  }
  out.evaluations = nlp.evaluations() - evaluations_before;
  return out;
}

}  // namespace sweetspot::core
