#include "core/numerics/nlopt_search.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/numerics/nlopt_run.hpp"
#include "core/numerics/termination.hpp"
#include "core/numerics/timing_book.hpp"

namespace sweetspot::core {
namespace {

struct AlgorithmInfo {
  NloptAlgorithm id;
  const char* name;
};

constexpr AlgorithmInfo kAlgorithms[] = {
    {NloptAlgorithm::kLdSlsqp, "LD_SLSQP"},
    {NloptAlgorithm::kLdLbfgs, "LD_LBFGS"},
    {NloptAlgorithm::kLdTnewton, "LD_TNEWTON_PRECOND_RESTART"},
    {NloptAlgorithm::kLdMma, "LD_MMA"},
    {NloptAlgorithm::kLdCcsaq, "LD_CCSAQ"},
    {NloptAlgorithm::kLnBobyqa, "LN_BOBYQA"},
    {NloptAlgorithm::kLnCobyla, "LN_COBYLA"},
    {NloptAlgorithm::kLnSbplx, "LN_SBPLX"},
    {NloptAlgorithm::kLnNelderMead, "LN_NELDERMEAD"},
    {NloptAlgorithm::kGnDirectL, "GN_DIRECT_L"},
    {NloptAlgorithm::kGnAgs, "GN_AGS"},
    {NloptAlgorithm::kGnCrs2Lm, "GN_CRS2_LM"},
};

const AlgorithmInfo& Info(NloptAlgorithm a) {
  for (const auto& info : kAlgorithms) {
    if (info.id == a) return info;
  }
  return kAlgorithms[0];
}

// Evaluation bookkeeping shared with the NLopt callback. The callback never lets an
// exception escape: it records the problem and asks NLopt to stop.
struct Tracker {
  const ScalarObjective* f = nullptr;
  int evaluations = 0;
  bool failed = false;
  std::string error;
  struct Point {
    double x, f, g;
  };
  bool record = false;  // record (x, f, f') of gradient evaluations
  std::vector<Point> points;

  // f(x) (and f'(x) into *grad when grad != nullptr) with bookkeeping; false on failure.
  bool Eval(double x, double* value, double* grad) {
    try {
      double g = 0.0;
      const double v = (*f)(x, grad != nullptr ? &g : nullptr);
      ++evaluations;
      if (!std::isfinite(v) || (grad != nullptr && !std::isfinite(g))) {
        failed = true;
        error = "the objective returned a non-finite value at x = " + FormatNumber17(x);
        return false;
      }
      *value = v;
      if (grad != nullptr) {
        *grad = g;
        if (record) points.push_back({x, v, g});
      }
      return true;
    } catch (const std::exception& e) {
      failed = true;
      error = std::string("the objective threw: ") + e.what();
    } catch (...) {
      failed = true;
      error = "the objective threw an unknown exception";
    }
    return false;
  }
};

// One NLopt run from x0 (the trampoline; f maximised as -f minimised); returns the raw result
// code and updates x0 / fval (maximised f). An objective failure is recorded in the tracker.
int RunStage(NloptAlgorithm alg, double lower, double upper, double x_tol, int max_eval,
             double max_time_s, double initial_step, unsigned seed, Tracker* tracker, double* x0,
             double* fval, std::string* error) {
  NloptRunSettings settings;
  settings.algorithm = alg;
  settings.lower = {lower};
  settings.upper = {upper};
  settings.x_tolerance_abs = x_tol;
  settings.max_evaluations = std::max(1, max_eval);
  settings.max_time_s = std::max(1e-6, max_time_s);
  settings.initial_step = initial_step;
  if (NloptAlgorithmIsStochastic(alg)) settings.seed = seed;
  const NloptFunction objective = [tracker](const double* x, double* grad) {
    double v = 0.0;
    double g = 0.0;
    if (!tracker->Eval(x[0], &v, grad != nullptr ? &g : nullptr))
      return std::numeric_limits<double>::quiet_NaN();
    if (grad != nullptr) grad[0] = -g;
    return -v;  // NLopt minimises
  };
  std::vector<double> x{std::clamp(*x0, lower, upper)};
  const NloptRunOutcome run = RunNlopt(objective, {}, settings, &x);
  if (!run.message.empty() && !run.callback_failed) *error = run.message;
  if (std::isfinite(x[0])) *x0 = x[0];
  if (std::isfinite(run.minimum) && run.minimum != HUGE_VAL) *fval = -run.minimum;
  return run.raw_status;
}

// The state of one MaximizeScalar: the problem, the evaluations and the best point so far;
// its stages are the member functions.
struct ScalarSearch {
  ScalarSearch(const ScalarSearchOptions& o, double lo, double hi, bool gradient,
               std::chrono::steady_clock::time_point start, Summary* summary)
      : options(o),
        lower(lo),
        upper(hi),
        range(hi - lo),
        has_gradient(gradient),
        t0(start),
        s(*summary) {}

  // The search proper: coarse samples then the local method, or the global method then a
  // polish; updates x, fx, raw and the warnings.
  void RunStages(NloptAlgorithm alg, bool global);
  // A posteriori check (first-order conditions) and restarts of the local method from the
  // point with the smallest |f'| among the ties of the best f.
  void Polish(NloptAlgorithm alg, bool global);
  // The answer: x on the interval, the bound flags, the first-order check and the error
  // estimates (curvature by differences); a failed evaluation is a failure in the summary.
  void Certify(ScalarSearchResult* result);

  const ScalarSearchOptions& options;
  const double lower;
  const double upper;
  const double range;
  const bool has_gradient;
  const std::chrono::steady_clock::time_point t0;
  Summary& s;
  Tracker tracker;
  double x = 0.0;   // the best point so far
  double fx = 0.0;  // f there
  int raw = 0;      // NLopt's last result code
  std::string nlopt_error;
};

void ScalarSearch::RunStages(NloptAlgorithm alg, bool global) {
  if (!global) {
    // Coarse samples pick the start, so a local method starts in the right basin.
    const int n = options.start_samples;
    double best = -HUGE_VAL;
    for (int i = 0; i < n; ++i) {
      const double xi = i + 1 == n ? upper : lower + range * i / (n - 1);
      double fi = 0.0;
      if (!tracker.Eval(xi, &fi, nullptr)) break;
      if (fi > best) {
        best = fi;
        x = xi;
      }
    }
    fx = best;
    tracker.record = true;
    if (!tracker.failed) {
      const double remaining_time = options.max_time_s - SecondsSince(t0);
      raw = RunStage(alg, lower, upper, options.x_tolerance_m,
                     options.max_evaluations - tracker.evaluations, remaining_time,
                     NloptAlgorithmNeedsGradient(alg) ? 0.0 : range / (n - 1), options.seed,
                     &tracker, &x, &fx, &nlopt_error);
    }
  } else {
    raw = RunStage(alg, lower, upper, std::max(options.x_tolerance_m, 1e-4 * range),
                   std::min(options.global_max_evaluations, options.max_evaluations),
                   options.max_time_s, 0.0, options.seed, &tracker, &x, &fx, &nlopt_error);
    // A global stage stopping on its budget is expected; the polish decides convergence.
    if (options.polish && !tracker.failed && (raw > 0 || raw == kNloptRoundoffLimited)) {
      const NloptAlgorithm local =
          has_gradient ? NloptAlgorithm::kLdSlsqp : NloptAlgorithm::kLnBobyqa;
      tracker.record = true;
      const double remaining_time = options.max_time_s - SecondsSince(t0);
      raw = RunStage(local, lower, upper, options.x_tolerance_m,
                     options.max_evaluations - tracker.evaluations, remaining_time,
                     has_gradient ? 0.0 : 1e-3 * range, options.seed, &tracker, &x, &fx,
                     &nlopt_error);
      s.warnings.push_back(std::string("polished with ") + NloptAlgorithmName(local));
    }
  }
}

void ScalarSearch::Polish(NloptAlgorithm alg, bool global) {
  // A posteriori check and error estimate (first-order conditions; curvature by differences).
  // Near a smooth maximum f is flat to rounding over ~sqrt(eps |f| / |f''|) (about 1e-8 m
  // here), so "the best f seen", which NLopt returns, cannot resolve the position further.
  // With a derivative, pick among the points NLopt evaluated whose f ties the best (within
  // rounding) the one with the smallest |f'|: the first-order condition resolves the
  // maximiser to ~eps |x| instead of ~sqrt(eps).
  auto select_by_first_order = [&]() {
    if (!has_gradient || tracker.points.empty()) return;
    double best_f = -HUGE_VAL;
    for (const auto& p : tracker.points) best_f = std::max(best_f, p.f);
    // Points within 1e-10 (relative) of the best f are all within ~sqrt(2e-10 |f| / |f''|) of
    // the maximiser, where f is quadratic and |f'| grows with the distance: the smallest |f'|
    // wins. (Rounding in f can exceed eps |f| when f is a difference of larger terms.)
    const double tie = 1e-10 * std::max(1.0, std::abs(best_f));
    double best_g = HUGE_VAL;
    for (const auto& p : tracker.points) {
      if (p.f >= best_f - tie && std::abs(p.g) < best_g && p.x > lower && p.x < upper) {
        best_g = std::abs(p.g);
        x = p.x;
      }
    }
  };
  select_by_first_order();
  // If the selected point's Newton step still exceeds the tolerance, restart the local
  // method there (a fresh quasi-Newton model takes a full step), at most three times.
  const NloptAlgorithm final_alg =
      global ? (has_gradient ? NloptAlgorithm::kLdSlsqp : NloptAlgorithm::kLnBobyqa) : alg;
  for (int restart = 0; has_gradient && NloptAlgorithmNeedsGradient(final_alg) && restart < 3 &&
                        !tracker.failed && raw > 0 && raw < 5;
       ++restart) {
    const double hr = 1e-6 * range;
    if (x - lower <= hr || upper - x <= hr) break;
    tracker.record = false;
    double f0 = 0.0, g0 = 0.0, fa = 0.0, ga = 0.0, fb = 0.0, gb = 0.0;
    if (!(tracker.Eval(x, &f0, &g0) && tracker.Eval(x + hr, &fa, &ga) &&
          tracker.Eval(x - hr, &fb, &gb))) {
      break;
    }
    const double curv = (ga - gb) / (2.0 * hr);
    if (!(curv < 0.0) || std::abs(g0 / curv) <= 10.0 * options.x_tolerance_m) break;
    const double remaining_time = options.max_time_s - SecondsSince(t0);
    const int remaining_evals = options.max_evaluations - tracker.evaluations;
    if (remaining_evals < 5 || remaining_time <= 0.0) break;
    tracker.record = true;
    raw = RunStage(final_alg, lower, upper, options.x_tolerance_m, remaining_evals, remaining_time,
                   0.0, options.seed, &tracker, &x, &fx, &nlopt_error);
    s.raw_status = raw;
    s.termination = TerminationFromNloptResult(raw);
    select_by_first_order();
  }
}

void ScalarSearch::Certify(ScalarSearchResult* result) {
  ScalarSearchResult& out = *result;
  out.x = std::clamp(x, lower, upper);
  const double bound_tol = std::max(options.x_tolerance_m, 4.0 * kEps * std::abs(out.x));
  out.at_lower_bound = out.x - lower <= bound_tol;
  out.at_upper_bound = upper - out.x <= bound_tol;
  double g = 0.0;
  bool ok = tracker.Eval(out.x, &fx, has_gradient ? &g : nullptr);
  out.value = fx;
  const double h = 1e-4 * range;
  const double xp = std::min(upper, out.x + h);
  const double xm = std::max(lower, out.x - h);
  double curvature = 0.0;
  if (ok && has_gradient) {
    double fp = 0.0, fm = 0.0, gp = 0.0, gm = 0.0;
    ok = tracker.Eval(xp, &fp, &gp) && tracker.Eval(xm, &fm, &gm);
    if (ok && xp > xm) curvature = (gp - gm) / (xp - xm);
  } else if (ok) {
    double fp = 0.0, fm = 0.0;
    ok = tracker.Eval(xp, &fp, nullptr) && tracker.Eval(xm, &fm, nullptr);
    if (ok && xp > out.x && out.x > xm) {
      curvature = 2.0 * ((fp - fx) / (xp - out.x) - (fx - fm) / (out.x - xm)) / (xp - xm);
    }
  }
  s.evaluations = tracker.evaluations;
  if (!ok) {
    s.termination = Termination::kFailure;
    s.message = tracker.error;
    return;
  }
  const double value_noise = 8.0 * kEps * std::abs(fx);
  if (out.at_lower_bound || out.at_upper_bound) {
    out.error_estimate_x = options.x_tolerance_m;
    if (has_gradient && ((out.at_lower_bound && g > 0.0 && !out.at_upper_bound) ||
                         (out.at_upper_bound && g < 0.0 && !out.at_lower_bound))) {
      s.termination = Termination::kNoConvergence;
      s.warnings.push_back(
          "stopped at a bound where the derivative points inside (f' = " + FormatNumber17(g) + ")");
    }
  } else if (has_gradient) {
    const double newton = curvature < 0.0 ? std::abs(g / curvature) : range;
    out.error_estimate_x = std::max(options.x_tolerance_m, newton);
    if (newton > 1e-6 * range) {
      s.termination = Termination::kNoConvergence;
      s.warnings.push_back("first-order check failed: f' = " + FormatNumber17(g) +
                           " at the reported point (Newton step " + FormatNumber17(newton) + ")");
    }
  } else {
    // Without derivatives the position is resolvable only to sqrt(noise / |f''|).
    const double resolvable = curvature < 0.0 ? std::sqrt(2.0 * value_noise / -curvature) : 0.0;
    out.error_estimate_x = std::max(options.x_tolerance_m, resolvable);
  }
  out.error_estimate_value =
      0.5 * std::abs(curvature) * out.error_estimate_x * out.error_estimate_x + value_noise;
  s.objective = out.value;
  s.error_estimate = out.error_estimate_x;
}

}  // namespace

const char* NloptAlgorithmName(NloptAlgorithm a) { return Info(a).name; }

std::optional<NloptAlgorithm> ParseNloptAlgorithm(std::string_view name, std::string* why) {
  for (const auto& info : kAlgorithms) {
    if (name == info.name) return info.id;
  }
  if (why != nullptr) {
    if (name == "LN_NEWUOA" || name == "LN_NEWUOA_BOUND") {
      *why = "nlopt.algorithm = " + std::string(name) +
             ": not offered for 1-D searches (NLopt refuses NEWUOA in one dimension)";
    } else {
      std::string list;
      for (const auto& info : kAlgorithms)
        list += (list.empty() ? "" : ", ") + std::string(info.name);
      *why = "nlopt.algorithm = " + std::string(name) + ": must be one of " + list;
    }
  }
  return std::nullopt;
}

const std::vector<NloptAlgorithm>& OfferedNloptAlgorithms() {
  static const std::vector<NloptAlgorithm> kAll = [] {
    std::vector<NloptAlgorithm> v;
    for (const auto& info : kAlgorithms) v.push_back(info.id);
    return v;
  }();
  return kAll;
}

bool NloptAlgorithmNeedsGradient(NloptAlgorithm a) { return Info(a).name[1] == 'D'; }
bool NloptAlgorithmIsGlobal(NloptAlgorithm a) { return Info(a).name[0] == 'G'; }
bool NloptAlgorithmIsStochastic(NloptAlgorithm a) { return a == NloptAlgorithm::kGnCrs2Lm; }

bool ScalarSearchOptions::Validate(Refusal* why) const {
  if (!(std::isfinite(x_tolerance_m) && x_tolerance_m > 0.0))
    return Refuse(why,
                  Number17Refusal("nlopt.x_tolerance_m", x_tolerance_m, "must be finite and > 0"));
  if (max_evaluations < 10)
    return Refuse(why, IntegerRefusal("nlopt.max_evaluations", max_evaluations, "must be >= 10"));
  if (!(std::isfinite(max_time_s) && max_time_s > 0.0))
    return Refuse(why, Number17Refusal("nlopt.max_time_s", max_time_s, "must be finite and > 0"));
  if (start_samples < 2)
    return Refuse(why, IntegerRefusal("nlopt.start_samples", start_samples, "must be >= 2"));
  if (start_samples > max_evaluations)
    return Refuse(why, IntegerRefusal("nlopt.start_samples", start_samples,
                                      "must be <= nlopt.max_evaluations (" +
                                          std::to_string(max_evaluations) + ")"));
  if (global_max_evaluations < 10)
    return Refuse(why, IntegerRefusal("nlopt.global_max_evaluations", global_max_evaluations,
                                      "must be >= 10"));
  return true;
}

ScalarSearchResult MaximizeScalar(const ScalarObjective& f, bool has_gradient, double lower,
                                  double upper, const ScalarSearchOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  ScalarSearchResult out;
  Summary& s = out.summary;
  s.termination = Termination::kInvalidInput;
  s.backend = "nlopt";
  auto finish = [&]() -> ScalarSearchResult& {
    s.solve_time_s = SecondsSince(t0);
    return out;
  };
  if (Refusal why; !options.Validate(&why)) {
    s.message = why.Message();
    return finish();
  }
  const NloptAlgorithm alg = options.algorithm.value_or(has_gradient ? NloptAlgorithm::kLdSlsqp
                                                                     : NloptAlgorithm::kLnBobyqa);
  s.backend = std::string("nlopt:") + NloptAlgorithmName(alg);
  if (!f) {
    s.message = "objective: missing";
    return finish();
  }
  if (!(std::isfinite(lower) && std::isfinite(upper) && lower <= upper)) {
    s.message = "search interval = [" + FormatNumber17(lower) + ", " + FormatNumber17(upper) +
                "]: must be finite with lower <= upper";
    return finish();
  }
  if (NloptAlgorithmNeedsGradient(alg) && !has_gradient) {
    s.message = std::string("nlopt.algorithm = ") + NloptAlgorithmName(alg) +
                ": needs the objective's derivative, which this model does not provide; use an "
                "LN_ or GN_ algorithm";
    return finish();
  }
  ScalarSearch st(options, lower, upper, has_gradient, t0, &s);
  Tracker& tracker = st.tracker;
  tracker.f = &f;
  const double range = upper - lower;
  double& x = st.x;
  double& fx = st.fx;
  x = 0.5 * (lower + upper);
  if (range == 0.0) {
    if (!tracker.Eval(lower, &fx, nullptr)) {
      s.termination = Termination::kFailure;
      s.message = tracker.error;
      s.evaluations = tracker.evaluations;
      return finish();
    }
    out.x = lower;
    out.value = fx;
    out.at_lower_bound = out.at_upper_bound = true;
    s.termination = Termination::kConverged;
    s.message = "the search interval is a single point";
    s.evaluations = tracker.evaluations;
    s.objective = fx;
    return finish();
  }

  const bool global = NloptAlgorithmIsGlobal(alg);
  st.RunStages(alg, global);
  s.raw_status = st.raw;
  s.evaluations = tracker.evaluations;
  if (tracker.failed) {
    s.termination = Termination::kFailure;
    s.message = tracker.error;
    return finish();
  }
  s.termination = TerminationFromNloptResult(st.raw);
  s.message = std::string("NLopt ") + NloptResultName(st.raw);
  if (!st.nlopt_error.empty()) s.message += ": " + st.nlopt_error;
  if (st.raw == kNloptRoundoffLimited) {
    s.warnings.push_back("NLopt stopped on round-off (ROUNDOFF_LIMITED); the best point is kept");
  }
  if (!s.IsSolutionUsable()) {
    s.evaluations = tracker.evaluations;
    return finish();
  }
  st.Polish(alg, global);
  tracker.record = false;
  if (tracker.failed) {
    s.termination = Termination::kFailure;
    s.message = tracker.error;
    s.evaluations = tracker.evaluations;
    return finish();
  }
  st.Certify(&out);
  return finish();
}

}  // namespace sweetspot::core
