#include "core/sweet_spot/numeric.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <vector>

#include <boost/math/tools/minima.hpp>
#include <boost/math/tools/roots.hpp>

#include "core/geometry_format.hpp"
#include "core/numerics/timing_book.hpp"
#include "core/refusal.hpp"

namespace sweetspot::core {

MaxExitSpeedResult SearchMaxExitSpeed(ExitSpeedFunction* model, double length_m,
                                      const ScalarSearchOptions& options) {
  MaxExitSpeedResult out;
  out.model = model->name();
  double model_err = 0.0;
  std::string model_error;
  auto f = [&](double s, double* grad) {
    double v = 0.0, e = 0.0;
    if (!model->Eval(s, &v, grad, &e, &model_error)) {
      return std::numeric_limits<double>::quiet_NaN();  // reported by the search as a failure
    }
    model_err = std::max(model_err, e);
    return v;
  };
  const ScalarSearchResult r = MaximizeScalar(f, model->has_gradient(), 0.0, length_m, options);
  out.summary = r.summary;
  out.method = r.summary.backend;
  if (!model_error.empty()) out.summary.message += " (" + model_error + ")";
  out.position_from_knob_m = r.x;
  out.unconstrained_position_from_knob_m = r.x;
  out.exit_speed_mps = r.value;
  out.placement = r.at_upper_bound && !r.at_lower_bound   ? Placement::kBeyondTip
                  : r.at_lower_bound && !r.at_upper_bound ? Placement::kBeforeKnob
                                                          : Placement::kOnBat;
  out.error_estimate_m = r.error_estimate_x;
  out.error_estimate_mps = r.error_estimate_value + model_err;
  return out;
}

bool BracketSearchOptions::Validate(Refusal* why) const {
  if (samples < 3 || samples > 1001)
    return Refuse(why, IntegerRefusal("samples", samples, "must be in [3, 1001]"));
  if (!(std::isfinite(x_tolerance_m) && x_tolerance_m >= 1e-9 && x_tolerance_m <= 0.01))
    return Refuse(why, Number17Refusal("x_tolerance_m", x_tolerance_m, "must be in [1e-9, 0.01]"));
  if (max_iterations < 5 || max_iterations > 1000)
    return Refuse(why, IntegerRefusal("max_iterations", max_iterations, "must be in [5, 1000]"));
  return true;
}

MaxExitSpeedResult BracketMaxExitSpeed(ExitSpeedFunction* model, double length_m,
                                       const BracketSearchOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  MaxExitSpeedResult out;
  out.model = model->name();
  out.method = "bracket_brent";
  Summary& sm = out.summary;
  sm.backend = out.method;
  sm.termination = Termination::kInvalidInput;
  sm.evaluations = 0;
  sm.iterations = 0;
  CatchInternalError(&sm, [&] {
    if (Refusal why; !options.Validate(&why)) {
      sm.SetRefusal(std::move(why));
      return;
    }
    if (!(std::isfinite(length_m) && length_m > 0.0)) {
      sm.SetRefusal(Number17Refusal("length_m", length_m, "must be finite and > 0"));
      return;
    }
    std::string error;
    double noise = 0.0;
    bool failed = false;
    auto fast = [&](double s) {
      double v = 0.0, e = 0.0;
      ++sm.evaluations;
      if (failed || !model->EvalFast(s, &v, &e, &error)) {
        failed = true;
        return -std::numeric_limits<double>::infinity();
      }
      noise = std::max(noise, e);
      return v;
    };
    auto fail = [&] {
      sm.termination = Termination::kFailure;
      sm.message = error.empty() ? std::string("the exit-speed model failed") : error;
    };
    // 1. The samples: the best one and its neighbours bracket the maximum of a smooth curve.
    const int n = options.samples;
    std::vector<double> xs(static_cast<std::size_t>(n)), fs(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      const std::size_t is = static_cast<std::size_t>(i);
      xs[is] = i + 1 == n ? length_m : length_m * i / (n - 1);
      fs[is] = fast(xs[is]);
      if (failed) return fail();
    }
    const std::size_t best =
        static_cast<std::size_t>(std::max_element(fs.begin(), fs.end()) - fs.begin());
    const std::size_t lo_i = best == 0 ? 0 : best - 1;
    const std::size_t hi_i = std::min(best + 1, fs.size() - 1);
    // 2. Brent between the neighbours (boost's tolerance is relative to |x|: 2 tol (|x| + 1/4)
    // bounds the final bracket's half-width, so tol = x_tolerance / (2 (L + 1/4))).
    const double rel = options.x_tolerance_m / (2.0 * (length_m + 0.25));
    const int bits = static_cast<int>(std::floor(1.0 - std::log2(rel)));
    boost::uintmax_t iters = static_cast<boost::uintmax_t>(options.max_iterations);
    const auto m = boost::math::tools::brent_find_minima([&](double s) { return -fast(s); },
                                                         xs[lo_i], xs[hi_i], bits, iters);
    if (failed) return fail();
    sm.iterations = static_cast<int>(iters);
    double x = m.first, f = -m.second;
    if (fs[best] >= f) {  // an end of the bat (or a sample) that the interior does not beat
      x = xs[best];
      f = fs[best];
    }
    const bool at_knob = x == 0.0, at_tip = x == length_m;
    // 3. The error: the tolerance, plus how far noise moves a maximum of curvature f''
    // (the samples' second difference around the best one; a flat or convex triple: half the
    // bracket).
    const std::size_t c = std::clamp<std::size_t>(best, 1, fs.size() - 2);
    const double h = xs[c + 1] - xs[c];
    const double curv = (fs[c + 1] + fs[c - 1] - 2.0 * fs[c]) / (h * h);
    double err_x = options.x_tolerance_m +
                   (curv < 0.0 ? std::sqrt(4.0 * noise / -curv) : 0.5 * (xs[hi_i] - xs[lo_i]));
    if ((at_knob || at_tip) && curv < 0.0) {
      // An end: the converged answer is that end too unless noise hides the slope there.
      const std::size_t in = at_knob ? 1 : fs.size() - 2;
      const double slope = std::abs(fs[best] - fs[in]) / std::abs(xs[best] - xs[in]);
      if (slope * options.x_tolerance_m > 2.0 * noise) err_x = 0.0;
    }
    // 4. One full evaluation at the answer: the value and the model's own error estimate.
    double v = 0.0, model_err = 0.0;
    ++sm.evaluations;
    if (!model->Eval(x, &v, nullptr, &model_err, &error)) return fail();
    out.position_from_knob_m = x;
    out.unconstrained_position_from_knob_m = x;
    out.exit_speed_mps = v;
    out.placement = at_tip    ? Placement::kBeyondTip
                    : at_knob ? Placement::kBeforeKnob
                              : Placement::kOnBat;
    out.error_estimate_m = err_x;
    out.error_estimate_mps = model_err + (curv < 0.0 ? 0.5 * -curv * err_x * err_x : noise);
    const bool converged = iters < static_cast<boost::uintmax_t>(options.max_iterations);
    sm.termination = converged ? Termination::kConverged : Termination::kNoConvergence;
    sm.message = std::string(converged ? "converged" : "Brent's iteration budget reached") + ": " +
                 std::to_string(n) + " samples, Brent between " + FormatNumber17(xs[lo_i]) +
                 " and " + FormatNumber17(xs[hi_i]) + " m";
    sm.objective = v;
    sm.error_estimate = err_x;
  });
  sm.solve_time_s = SecondsSince(t0);
  return out;
}

SweetZoneResult RootFindSweetZone(ExitSpeedFunction* model, double length_m,
                                  const MaxExitSpeedResult& max, double tolerance_mps,
                                  std::string* error) {
  SweetZoneResult out;
  out.method = "root_finding";
  out.tolerance_mps = tolerance_mps;
  out.threshold_mps = max.exit_speed_mps - tolerance_mps;
  const double s0 = max.position_from_knob_m;
  double worst_err = 0.0;
  bool failed = false;
  auto g = [&](double s) {
    double v = 0.0, e = 0.0;
    if (!model->Eval(s, &v, nullptr, &e, error)) {
      failed = true;
      return 0.0;
    }
    worst_err = std::max(worst_err, e);
    return v - out.threshold_mps;
  };
  auto edge = [&](double end, bool* clipped) -> double {
    if (tolerance_mps == 0.0 || end == s0) return s0;
    const double g_end = g(end);
    if (failed) return s0;
    if (g_end >= 0.0) {
      *clipped = true;
      return end;
    }
    const double g0 = tolerance_mps;
    const double a = std::min(s0, end), b = std::max(s0, end);
    const double ga = a == s0 ? g0 : g_end, gb = b == s0 ? g0 : g_end;
    boost::uintmax_t iters = 200;
    try {
      const auto r = boost::math::tools::toms748_solve(
          g, a, b, ga, gb, boost::math::tools::eps_tolerance<double>(48), iters);
      const double root = 0.5 * (r.first + r.second);
      // The root moves by (model error) / |slope|; the slope from the bracket.
      const double slope = std::abs(tolerance_mps / (root - s0));
      const double e = (r.second - r.first) + (slope > 0.0 ? 2.0 * worst_err / slope : 0.0);
      out.error_estimate_m = std::max(out.error_estimate_m, e);
      return root;
    } catch (const std::exception& ex) {
      failed = true;
      *error = std::string("sweet-zone root finding failed: ") + ex.what();
      return s0;
    }
  };
  bool clip_lo = false, clip_hi = false;
  out.from_knob_m = edge(0.0, &clip_lo);
  out.to_knob_m = edge(length_m, &clip_hi);
  out.clipped_at_knob = clip_lo;
  out.clipped_at_tip = clip_hi;
  if (failed && error->empty()) *error = "sweet-zone root finding failed";
  return out;
}

}  // namespace sweetspot::core
