// The NLopt trampoline (see nlopt_run.hpp).
#include "core/numerics/nlopt_run.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>

#include <nlopt.hpp>

#include "core/numerics/termination.hpp"

namespace sweetspot::core {
namespace {

nlopt::algorithm NloptId(NloptAlgorithm a) {
  switch (a) {
    case NloptAlgorithm::kLdSlsqp:
      return nlopt::LD_SLSQP;
    case NloptAlgorithm::kLdLbfgs:
      return nlopt::LD_LBFGS;
    case NloptAlgorithm::kLdTnewton:
      return nlopt::LD_TNEWTON_PRECOND_RESTART;
    case NloptAlgorithm::kLdMma:
      return nlopt::LD_MMA;
    case NloptAlgorithm::kLdCcsaq:
      return nlopt::LD_CCSAQ;
    case NloptAlgorithm::kLnBobyqa:
      return nlopt::LN_BOBYQA;
    case NloptAlgorithm::kLnCobyla:
      return nlopt::LN_COBYLA;
    case NloptAlgorithm::kLnSbplx:
      return nlopt::LN_SBPLX;
    case NloptAlgorithm::kLnNelderMead:
      return nlopt::LN_NELDERMEAD;
    case NloptAlgorithm::kGnDirectL:
      return nlopt::GN_DIRECT_L;
    case NloptAlgorithm::kGnAgs:
      return nlopt::GN_AGS;
    case NloptAlgorithm::kGnCrs2Lm:
      return nlopt::GN_CRS2_LM;
  }
  return nlopt::LD_SLSQP;
}

// What the C callbacks share: the run's settings, the opt to stop, and what stopped it.
struct RunState {
  const NloptRunSettings* settings = nullptr;
  nlopt::opt* opt = nullptr;
  NloptRunOutcome* outcome = nullptr;
  bool has_deadline = false;  // settings->deadline is not time_point::max()
};

// One function NLopt calls, with the run it belongs to.
struct Callback {
  RunState* run = nullptr;
  const NloptFunction* function = nullptr;
  bool is_objective = false;
};

// Stops the run from inside a callback: NLopt ends with FORCED_STOP after this call returns.
double Stop(const Callback& c, unsigned n, double* gradient) {
  if (gradient != nullptr) std::fill(gradient, gradient + n, 0.0);
  c.run->opt->force_stop();
  return HUGE_VAL;
}

// The C callback of every function: checks cancellation and the deadline (objective only),
// calls the function, and turns a throw or a non-finite value into a stop. Nothing escapes.
double Trampoline(unsigned n, const double* x, double* gradient, void* data) {
  const auto& c = *static_cast<const Callback*>(data);
  NloptRunOutcome& outcome = *c.run->outcome;
  if (c.is_objective) {
    if (IsCancelled(c.run->settings->progress)) {
      outcome.cancelled = true;
      return Stop(c, n, gradient);
    }
    // No clock read without a deadline (the scalar search's evaluations take ~50 ns).
    if (c.run->has_deadline && std::chrono::steady_clock::now() >= c.run->settings->deadline) {
      outcome.deadline_reached = true;
      return Stop(c, n, gradient);
    }
  }
  try {
    const double value = (*c.function)(x, gradient);
    if (std::isfinite(value)) return value;
    outcome.message = "a function NLopt called returned a non-finite value";
  } catch (const std::exception& e) {
    outcome.message = std::string("a function NLopt called threw: ") + e.what();
  } catch (...) {
    outcome.message = "a function NLopt called threw an unknown exception";
  }
  outcome.callback_failed = true;
  return Stop(c, n, gradient);
}

// Builds the opt from the settings and runs it; throws what NLopt throws.
nlopt::result Optimize(const NloptFunction& objective,
                       const std::vector<NloptConstraintFunction>& constraints,
                       const NloptRunSettings& settings, std::vector<double>* x,
                       NloptRunOutcome* outcome) {
  nlopt::opt opt(NloptId(settings.algorithm), static_cast<unsigned>(x->size()));
  RunState run{&settings, &opt, outcome,
               settings.deadline != std::chrono::steady_clock::time_point::max()};
  Callback objective_callback{&run, &objective, true};
  opt.set_min_objective(Trampoline, &objective_callback);
  std::vector<Callback> callbacks;        // no allocation without constraints (the scalar search)
  callbacks.reserve(constraints.size());  // stable addresses for NLopt's data pointers
  for (const NloptConstraintFunction& c : constraints) {
    callbacks.push_back({&run, &c.value, false});
    if (c.equality) {
      opt.add_equality_constraint(Trampoline, &callbacks.back(), c.tolerance);
    } else {
      opt.add_inequality_constraint(Trampoline, &callbacks.back(), c.tolerance);
    }
  }
  if (!settings.lower.empty()) opt.set_lower_bounds(settings.lower);
  if (!settings.upper.empty()) opt.set_upper_bounds(settings.upper);
  for (std::size_t j = 0; j < x->size(); ++j) {
    if (j < settings.lower.size()) (*x)[j] = std::max((*x)[j], settings.lower[j]);
    if (j < settings.upper.size()) (*x)[j] = std::min((*x)[j], settings.upper[j]);
  }
  if (settings.x_tolerance_rel > 0.0) opt.set_xtol_rel(settings.x_tolerance_rel);
  if (settings.x_tolerance_abs > 0.0) opt.set_xtol_abs(settings.x_tolerance_abs);
  if (settings.f_tolerance_rel > 0.0) opt.set_ftol_rel(settings.f_tolerance_rel);
  if (settings.f_tolerance_abs > 0.0) opt.set_ftol_abs(settings.f_tolerance_abs);
  if (settings.max_evaluations > 0) opt.set_maxeval(settings.max_evaluations);
  if (settings.max_time_s > 0.0) opt.set_maxtime(settings.max_time_s);
  if (settings.initial_step > 0.0) opt.set_initial_step(settings.initial_step);
  if (settings.seed.has_value()) nlopt::srand(*settings.seed);
  double minimum = HUGE_VAL;
  nlopt::result result = nlopt::FAILURE;
  try {
    result = opt.optimize(*x, minimum);
  } catch (...) {
    outcome->evaluations = opt.get_numevals();
    outcome->minimum = minimum;
    throw;
  }
  outcome->evaluations = opt.get_numevals();
  outcome->minimum = minimum;
  return result;
}

}  // namespace

NloptRunOutcome RunNlopt(const NloptFunction& objective,
                         const std::vector<NloptConstraintFunction>& constraints,
                         const NloptRunSettings& settings, std::vector<double>* x) {
  NloptRunOutcome outcome;
  try {
    outcome.raw_status = static_cast<int>(Optimize(objective, constraints, settings, x, &outcome));
  } catch (...) {
    // The ladder: on ROUNDOFF_LIMITED *x holds NLopt's best point and is kept as it is.
    std::string message;
    outcome.raw_status = NloptResultFromException(std::current_exception(), &message);
    if (outcome.message.empty()) outcome.message = message;
  }
  return outcome;
}

}  // namespace sweetspot::core
