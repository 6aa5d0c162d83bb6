#include "core/sweet_spot/least_sting.hpp"

#include <algorithm>
#include <cmath>
#include <exception>

#include <boost/math/tools/minima.hpp>
#include <boost/math/tools/roots.hpp>

#include "core/geometry_format.hpp"

namespace sweetspot::core {

bool LeastStingZone(const StingImpact& solve, double from_knob_m, double to_knob_m, int samples,
                    double fraction, double x_tolerance_m, std::vector<std::string>* warnings,
                    LeastStingZoneResult* out, std::string* error) {
  const double lo = from_knob_m;
  const double hi = to_knob_m;
  bool failed = false;
  auto impact = [&](double s, StingRun run) {
    FlexibleImpactResult fr = solve(s, run);
    for (const auto& w : fr.summary.warnings) {
      if (std::find(warnings->begin(), warnings->end(), w) == warnings->end()) {
        warnings->push_back(w);
      }
    }
    if (!fr.summary.IsSolutionUsable() && !failed) {
      failed = true;
      *error = "flexible at " + FormatNumber17(s) + " m from the knob: " + fr.summary.message;
    }
    return fr;
  };
  const int n = samples;
  std::vector<double> xs, es;
  double err_e = 0.0;
  for (int i = 0; i < n; ++i) {
    const double s = i + 1 == n ? hi : lo + (hi - lo) * i / (n - 1);
    const FlexibleImpactResult fr = impact(s, StingRun::kSample);
    if (failed) return false;
    StingPoint p;
    p.position_from_knob_m = s;
    p.exit_speed_mps = fr.exit_speed_mps;
    p.rigid_exit_speed_mps = fr.rigid_exit_speed_mps;
    p.vibration_energy_j = fr.vibration_energy_j;
    p.hands_vibration_energy_j = fr.hands_vibration_energy_j;
    p.hands_peak_shear_force_n = fr.hands_peak_shear_force_n;
    p.hands_peak_bending_moment_n_m = fr.hands_peak_bending_moment_n_m;
    p.contact_time_s = fr.contact_time_s;
    p.error_estimate_exit_speed_mps = fr.error_estimate_exit_speed_mps;
    p.error_estimate_hands_energy_j = fr.error_estimate_hands_energy_j;
    out->curve.push_back(p);
    out->modes_used = std::max(out->modes_used, fr.modes_used);
    xs.push_back(s);
    es.push_back(fr.hands_vibration_energy_j);
    err_e = std::max(err_e, fr.error_estimate_hands_energy_j);
  }
  out->fraction = fraction;
  const std::size_t i_min =
      static_cast<std::size_t>(std::min_element(es.begin(), es.end()) - es.begin());
  out->max_hands_energy_j = *std::max_element(es.begin(), es.end());
  // Refine the minimum between the neighbouring samples (Brent to x_tolerance_m: boost's
  // tolerance is relative to |x|, and 2 tol (|x| + 1/4) bounds its final half-bracket).
  auto energy = [&](double s) { return impact(s, StingRun::kSearch).hands_vibration_energy_j; };
  const double rel = x_tolerance_m / (2.0 * (std::max(std::abs(lo), std::abs(hi)) + 0.25));
  const int bits = static_cast<int>(std::floor(1.0 - std::log2(rel)));
  const double a = xs[i_min == 0 ? 0 : i_min - 1];
  const double b = xs[std::min(i_min + 1, xs.size() - 1)];
  double x_min = xs[i_min], e_min = es[i_min];
  double err_x = 0.5 * (b - a);
  if (b > a) {
    boost::uintmax_t iters = 60;
    const auto m = boost::math::tools::brent_find_minima(energy, a, b, bits, iters);
    if (failed) return false;
    if (m.second <= e_min) {
      x_min = m.first;
      e_min = m.second;
    }
  }
  // The least-sting impact once more, with the refinement check: the exit speed there and the
  // error of the hands' energy (integration + mode truncation) that the ends' estimates use.
  const FlexibleImpactResult checked = impact(x_min, StingRun::kChecked);
  if (failed) return false;
  err_e = std::max(err_e, checked.error_estimate_hands_energy_j);
  if (b > a) {
    // Brent's bracket, widened by how far the energy's own error moves a flat minimum.
    const double h = 0.5 * (b - a);
    const double curv = (es[std::min(i_min + 1, es.size() - 1)] + es[i_min == 0 ? 0 : i_min - 1] -
                         2.0 * es[i_min]) /
                        (h * h);
    err_x = x_tolerance_m + (curv > 0.0 ? std::sqrt(2.0 * err_e / curv) : 0.5 * (b - a));
  }
  out->min_position_from_knob_m = x_min;
  out->min_hands_energy_j = e_min;
  out->exit_speed_at_min_mps = checked.exit_speed_mps;
  out->threshold_j = e_min + fraction * (out->max_hands_energy_j - e_min);
  auto g = [&](double s) { return energy(s) - out->threshold_j; };
  double err_edges = 0.0;
  auto edge = [&](int dir, bool* clipped) -> double {
    // The first sample beyond the threshold, walking away from the minimum.
    long j = static_cast<long>(i_min);
    while (true) {
      const long next = j + dir;
      if (next < 0 || next >= static_cast<long>(xs.size())) {
        *clipped = true;
        return dir < 0 ? lo : hi;
      }
      if (es[static_cast<std::size_t>(next)] > out->threshold_j) {
        const double inside =
            j == static_cast<long>(i_min) ? x_min : xs[static_cast<std::size_t>(j)];
        const double outside = xs[static_cast<std::size_t>(next)];
        const double ga = g(inside);
        const double gb = es[static_cast<std::size_t>(next)] - out->threshold_j;
        if (failed || !(ga <= 0.0)) return inside;
        boost::uintmax_t iters = 60;
        try {
          const double x0 = std::min(inside, outside), x1 = std::max(inside, outside);
          const auto rr = boost::math::tools::toms748_solve(
              g, x0, x1, x0 == inside ? ga : gb, x0 == inside ? gb : ga,
              [&](double l, double r) { return r - l <= 2.0 * x_tolerance_m; }, iters);
          const double root = 0.5 * (rr.first + rr.second);
          const double slope = std::abs(gb - ga) / std::abs(outside - inside);
          err_edges =
              std::max(err_edges, (rr.second - rr.first) + (slope > 0.0 ? err_e / slope : 0.0));
          return root;
        } catch (const std::exception& e) {
          failed = true;
          *error = std::string("least_sting_zone: root finding failed: ") + e.what();
          return inside;
        }
      }
      j = next;
    }
  };
  bool clip_lo = false, clip_hi = false;
  out->from_knob_m = edge(-1, &clip_lo);
  out->to_knob_m = edge(+1, &clip_hi);
  if (failed) return false;
  out->clipped_at_hands = clip_lo;
  out->clipped_at_tip = clip_hi;
  out->error_estimate_m = std::max(err_x, err_edges);
  return true;
}

}  // namespace sweetspot::core
