#include "core/sweet_spot/numeric.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>

#include <boost/math/tools/roots.hpp>

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
