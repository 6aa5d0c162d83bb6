// The NLopt backends over ScaledDesignNlp: LD_SLSQP (the same functions and gradients Ipopt
// sees), for cross-checks, and LN_COBYLA (values only), for the derivative-free min_sting. Each
// solve is one run of the NLopt trampoline (nlopt_run.hpp: callbacks, deadline, cancellation,
// exception ladder); the best point is kept on round-off (NLopt 2.7.1 leaves it in x) and, for
// COBYLA, on any early stop (tracked in the objective).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <string>
#include <vector>

#include "core/numerics/nlopt_run.hpp"
#include "core/numerics/termination.hpp"
#include "core/optimize/design_backends.hpp"

namespace sweetspot::core {
namespace {

// The SLSQP objective: f and its gradient on the scaled problem.
double SlsqpObjective(ScaledDesignNlp& nlp, const double* s, double* grad) {
  const auto n = static_cast<unsigned>(nlp.n());
  if (!nlp.Evaluate(s, grad != nullptr)) {
    if (grad != nullptr) {
      for (unsigned j = 0; j < n; ++j) grad[j] = 0.0;
    }
    return std::numeric_limits<double>::max();  // SLSQP backs off from a huge value
  }
  if (grad != nullptr) {
    for (unsigned j = 0; j < n; ++j) grad[j] = nlp.grad_f()(static_cast<Eigen::Index>(j));
  }
  return nlp.f();
}

// One side of constraint k: sign (g_k - bound) <= 0 (sign +1: upper, -1: lower), with its
// gradient; a failed evaluation counts as violated.
double SlsqpConstraint(ScaledDesignNlp& nlp, int k, double bound, double sign, const double* s,
                       double* grad) {
  const auto n = static_cast<unsigned>(nlp.n());
  if (!nlp.Evaluate(s, grad != nullptr)) {
    if (grad != nullptr) {
      for (unsigned j = 0; j < n; ++j) grad[j] = 0.0;
    }
    return 1.0;  // violated
  }
  if (grad != nullptr) {
    for (unsigned j = 0; j < n; ++j) {
      grad[j] = sign * nlp.jacobian()(k, static_cast<Eigen::Index>(j));
    }
  }
  return sign * (nlp.g()[static_cast<std::size_t>(k)] - bound);
}

// Every constraint of `nlp` as NLopt constraints on the scaled problem: equalities as one
// equality, ranges as one or two inequalities (g - upper <= 0, lower - g <= 0). `side(k, bound,
// sign)` gives the function of one side.
template <typename Side>
std::vector<NloptConstraintFunction> ConstraintsOf(const ScaledDesignNlp& nlp, double tol,
                                                   const Side& side) {
  std::vector<double> lower, upper;
  nlp.ConstraintBounds(&lower, &upper);
  std::vector<NloptConstraintFunction> out;
  for (int k = 0; k < nlp.m(); ++k) {
    const auto kk = static_cast<std::size_t>(k);
    if (lower[kk] == upper[kk]) {
      out.push_back({side(k, upper[kk], 1.0), true, tol});
      continue;
    }
    if (std::isfinite(upper[kk])) out.push_back({side(k, upper[kk], 1.0), false, tol});
    if (std::isfinite(lower[kk])) out.push_back({side(k, lower[kk], -1.0), false, tol});
  }
  return out;
}

// The box [0, 1]^n of the scaled variables.
void SetUnitBox(int n, NloptRunSettings* settings) {
  settings->lower.assign(static_cast<std::size_t>(n), 0.0);
  settings->upper.assign(static_cast<std::size_t>(n), 1.0);
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
  int failures = 0;  // evaluations where the objective had no value
  // The point where the objective last failed: its constraints come straight from the model.
  std::vector<double> failed_s;
  // The best point evaluated: least violation beyond the feasibility tolerance, then least f.
  std::vector<double> best_s;
  double best_excess = std::numeric_limits<double>::infinity();
  double best_f = std::numeric_limits<double>::infinity();
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

double CobylaObjective(CobylaContext* c, const double* s) {
  const auto n = static_cast<std::size_t>(c->nlp->n());
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

// One side of constraint k for COBYLA: sign (g_k - bound) <= 0.
double CobylaConstraintValue(CobylaContext* c, int k, double bound, double sign, const double* s) {
  ScaledDesignNlp& nlp = *c->nlp;
  const auto kk = static_cast<std::size_t>(k);
  double g = 0.0;
  if (CobylaEvaluate(c, s)) {
    g = nlp.g()[kk];
  } else {
    // The objective failed here, the constraints (closed forms) need not have.
    const DesignConstraintSpec& spec = nlp.model().constraints()[kk];
    const std::vector<double> x = nlp.ToUser(s);
    g = nlp.model().Value(spec.f, x.data()) / spec.scale;
    if (!std::isfinite(g)) return 1.0;  // violated
  }
  return sign * (g - bound);
}

// ---------------------------------------------------------------------------------------------
// Projection onto the constraints (after COBYLA).

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
    const std::vector<double> centre = *s;
    const NloptFunction distance = [&centre](const double* p, double* grad) {
      double f = 0.0;
      for (std::size_t j = 0; j < centre.size(); ++j) {
        const double d = p[j] - centre[j];
        f += 0.5 * d * d;
        if (grad != nullptr) grad[j] = d;
      }
      return f;
    };
    const auto constraints = ConstraintsOf(
        constraints_only, settings.constraint_tolerance, [&](int k, double bound, double sign) {
          return NloptFunction([&constraints_only, k, bound, sign](const double* p, double* g) {
            return SlsqpConstraint(constraints_only, k, bound, sign, p, g);
          });
        });
    NloptRunSettings run;
    run.algorithm = NloptAlgorithm::kLdSlsqp;
    SetUnitBox(nlp.n(), &run);
    run.x_tolerance_rel = 1e-14;
    run.max_evaluations = 100;
    std::vector<double> p = *s;
    const NloptRunOutcome outcome = RunNlopt(distance, constraints, run, &p);
    // A normal end or round-off (p holds the best point) is judged below; other stops keep *s.
    if (outcome.raw_status < 0 && outcome.raw_status != kNloptRoundoffLimited) return;
    for (double& v : p) v = std::clamp(v, 0.0, 1.0);
    if (!constraints_only.Evaluate(p.data(), false)) return;
    if (constraints_only.Violation() < before) *s = p;
  } catch (const std::exception&) {
    // keep *s
  }
}

// NLopt's time budget: what is left until the deadline (at least 1 ms), s.
double SecondsLeft(const LocalSolveSettings& settings) {
  const double left_s =
      std::chrono::duration<double>(settings.deadline - std::chrono::steady_clock::now()).count();
  return std::max(left_s, 1e-3);
}

// The trampoline's settings shared by both backends: the unit box, the deadline, the progress
// and NLopt's time budget.
NloptRunSettings RunSettings(NloptAlgorithm algorithm, const ScaledDesignNlp& nlp,
                             const LocalSolveSettings& settings) {
  NloptRunSettings run;
  run.algorithm = algorithm;
  SetUnitBox(nlp.n(), &run);
  run.deadline = settings.deadline;
  run.progress = settings.progress;
  run.max_time_s = SecondsLeft(settings);
  return run;
}

// The outcome fields both backends fill the same way from a run.
void FillOutcome(const NloptRunOutcome& run, std::vector<double> s, LocalSolveOutcome* out) {
  for (double& v : s) v = std::clamp(v, 0.0, 1.0);
  out->s = std::move(s);
  out->has_point = true;
  out->raw_status = run.raw_status;
  out->status_name = NloptResultName(run.raw_status);
  out->iterations = run.evaluations;
  out->message = run.message;
  out->cancelled = run.cancelled;
  // NLopt's maxtime is the budget left: reaching it is the deadline too.
  out->deadline_reached = run.deadline_reached || run.raw_status == kNloptMaxtimeReached;
  out->termination = TerminationFromNloptResult(run.raw_status);
  if (run.raw_status == kNloptRoundoffLimited || run.cancelled || run.deadline_reached) {
    out->termination = Termination::kNoConvergence;  // the best point so far is kept
  }
}

}  // namespace

LocalSolveOutcome SolveWithCobyla(ScaledDesignNlp& nlp, const std::vector<double>& s0,
                                  const LocalSolveSettings& settings) {
  LocalSolveOutcome out;
  const int evaluations_before = nlp.evaluations();
  CobylaContext context;
  context.nlp = &nlp;
  context.settings = &settings;
  NloptRunSettings run = RunSettings(NloptAlgorithm::kLnCobyla, nlp, settings);
  const double rel = std::max(settings.tolerance, kDerivativeFreeTolerance);
  run.f_tolerance_rel = rel;
  run.x_tolerance_rel = rel;
  run.max_evaluations = settings.max_iterations;  // one evaluation per COBYLA iteration
  const NloptFunction objective = [&context](const double* s, double* /*grad*/) {
    return CobylaObjective(&context, s);
  };
  const auto constraints = ConstraintsOf(
      nlp, settings.constraint_tolerance, [&context](int k, double bound, double sign) {
        return NloptFunction([&context, k, bound, sign](const double* s, double* /*grad*/) {
          return CobylaConstraintValue(&context, k, bound, sign, s);
        });
      });
  std::vector<double> s = s0;
  const NloptRunOutcome result = RunNlopt(objective, constraints, run, &s);
  // A normal end is COBYLA's own answer; after any other stop, the best point evaluated.
  const int status = result.raw_status;
  const bool normal_end = status == kNloptSuccess || status == kNloptFtolReached ||
                          status == kNloptXtolReached || status == kNloptStopvalReached;
  if (!normal_end && !context.best_s.empty()) s = context.best_s;
  for (double& v : s) v = std::clamp(v, 0.0, 1.0);
  ProjectOntoConstraints(nlp, settings, &s);
  FillOutcome(result, std::move(s), &out);
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
  NloptRunSettings run = RunSettings(NloptAlgorithm::kLdSlsqp, nlp, settings);
  run.f_tolerance_rel = settings.tolerance;
  run.x_tolerance_rel = settings.tolerance;
  // SLSQP counts evaluations, not iterations: allow a few per iteration.
  run.max_evaluations = 20 * settings.max_iterations;
  const NloptFunction objective = [&nlp](const double* s, double* grad) {
    return SlsqpObjective(nlp, s, grad);
  };
  const auto constraints =
      ConstraintsOf(nlp, settings.constraint_tolerance, [&nlp](int k, double bound, double sign) {
        return NloptFunction([&nlp, k, bound, sign](const double* s, double* grad) {
          return SlsqpConstraint(nlp, k, bound, sign, s, grad);
        });
      });
  std::vector<double> s = s0;
  for (double& v : s) v = std::clamp(v, 0.0, 1.0);
  const NloptRunOutcome result = RunNlopt(objective, constraints, run, &s);
  FillOutcome(result, std::move(s), &out);
  out.evaluations = nlp.evaluations() - evaluations_before;
  return out;
}

}  // namespace sweetspot::core
