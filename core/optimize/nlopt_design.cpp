// The NLopt backend: LD_SLSQP over ScaledDesignNlp (the same functions and gradients Ipopt
// sees), for cross-checks. One nlopt::opt per solve; every NLopt exception is caught; the best
// point is kept on round-off (NLopt 2.7.1 leaves it in x).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <new>
#include <stdexcept>

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

}  // namespace

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
    std::vector<double> lower, upper;
    nlp.ConstraintBounds(&lower, &upper);
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
    opt.set_ftol_rel(settings.tolerance);
    opt.set_xtol_rel(settings.tolerance);
    // SLSQP counts evaluations, not iterations: allow a few per iteration.
    opt.set_maxeval(20 * settings.max_iterations);
    const double left_s =
        std::chrono::duration<double>(settings.deadline - std::chrono::steady_clock::now()).count();
    opt.set_maxtime(std::max(left_s, 1e-3));
    double f = 0.0;
    try {
      status = opt.optimize(s, f);
    } catch (const nlopt::roundoff_limited&) {
      status = nlopt::ROUNDOFF_LIMITED;  // s holds the best point: keep it
    } catch (const nlopt::forced_stop&) {
      status = nlopt::FORCED_STOP;
    } catch (const std::invalid_argument& e) {
      status = nlopt::INVALID_ARGS;
      out.message = e.what();
    } catch (const std::bad_alloc&) {
      status = nlopt::OUT_OF_MEMORY;
    } catch (const std::runtime_error& e) {
      status = nlopt::FAILURE;
      out.message = e.what();
    }
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
  out.deadline_reached = context.deadline;
  out.termination = TerminationFromNloptResult(status);
  if (status == nlopt::ROUNDOFF_LIMITED || context.cancelled || context.deadline) {
    out.termination = Termination::kNoConvergence;  // the best point so far is kept
  }
  out.evaluations = nlp.evaluations() - evaluations_before;
  return out;
}

}  // namespace sweetspot::core
