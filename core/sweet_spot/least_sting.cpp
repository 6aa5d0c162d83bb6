#include "core/sweet_spot/least_sting.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <utility>

#include <boost/math/tools/minima.hpp>
#include <boost/math/tools/roots.hpp>

#include "core/geometry_format.hpp"

namespace sweetspot::core {

namespace {

// Brent's minimisation (parabolic steps safeguarded by golden sections; R. P. Brent,
// "Algorithms for Minimization without Derivatives", 1973, ch. 5) of f on [a, b], started from
// three points already evaluated: x (the lowest, inside), w and v (the other two, lowest
// first). The first step is the parabola through them, not a golden section: the sweep's
// samples around its minimum are such a triple. Stops when the bracket's half-width around x
// is below x_tolerance_m (then the minimiser of a unimodal f is within x_tolerance_m of x) or
// after max_evaluations; returns x and f(x) with the evaluations made in *evaluations.
template <class F>
std::pair<double, double> StingBrentFromTriple(F&& f, double a, double b, double x, double fx,
                                               double w, double fw, double v, double fv,
                                               double x_tolerance_m, int max_evaluations,
                                               int* evaluations) {
  constexpr double kGolden = 0.3819660112501051;  // (3 - sqrt(5)) / 2
  const double tol1 = 0.5 * x_tolerance_m;
  // The last two steps (Brent's e and d), as if both were the whole bracket: the first two
  // steps may then be parabolic (a zero d would force a golden section on the second).
  double d = b - a, e = b - a;
  *evaluations = 0;
  while (*evaluations < max_evaluations) {
    const double mid = 0.5 * (a + b);
    if (std::abs(x - mid) <= 2.0 * tol1 - 0.5 * (b - a)) break;
    bool golden = true;
    if (std::abs(e) > tol1) {
      // The parabola through (v, w, x); its vertex x + p / q.
      double r = (x - w) * (fx - fv);
      double q = (x - v) * (fx - fw);
      double p = (x - v) * q - (x - w) * r;
      q = 2.0 * (q - r);
      if (q > 0.0) p = -p;
      q = std::abs(q);
      const double e_prev = e;
      e = d;
      // Accept it when it falls inside the bracket and moves less than half the step before
      // last (otherwise it may not converge).
      if (std::abs(p) < std::abs(0.5 * q * e_prev) && p > q * (a - x) && p < q * (b - x)) {
        d = p / q;
        const double u = x + d;
        if (u - a < 2.0 * tol1 || b - u < 2.0 * tol1) d = mid >= x ? tol1 : -tol1;
        golden = false;
      }
    }
    if (golden) {
      e = x >= mid ? a - x : b - x;
      d = kGolden * e;
    }
    // Never a step below tol1: two evaluations closer than that tell nothing apart.
    const double u = std::abs(d) >= tol1 ? x + d : x + (d > 0.0 ? tol1 : -tol1);
    const double fu = f(u);
    ++*evaluations;
    if (fu <= fx) {
      (u >= x ? a : b) = x;
      v = w;
      fv = fw;
      w = x;
      fw = fx;
      x = u;
      fx = fu;
    } else {
      (u < x ? a : b) = u;
      if (fu <= fw || w == x) {
        v = w;
        fv = fw;
        w = u;
        fw = fu;
      } else if (fu <= fv || v == x || v == w) {
        v = u;
        fv = fu;
      }
    }
  }
  return {x, fx};
}

// The impacts of one zone search: each impact's warnings gathered into *warnings (once each),
// the first unusable impact's message kept in *error (then `failed`).
struct StingSearch {
  const StingImpact* solve = nullptr;
  std::vector<std::string>* warnings = nullptr;
  std::string* error = nullptr;
  bool failed = false;

  // The impact `s` m from the knob, of the kind `run`.
  FlexibleImpactResult Impact(double s, StingRun run) {
    FlexibleImpactResult fr = (*solve)(s, run);
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
  }
  // The hands' vibration energy (J) of a search impact `s` m from the knob.
  double Energy(double s) { return Impact(s, StingRun::kSearch).hands_vibration_energy_j; }
};

// The curve point of the sample impact `fr` at `s` m from the knob (SI, as the impact's).
StingPoint StingPointOf(double s, const FlexibleImpactResult& fr) {
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
  return p;
}

// The sampled sweep and its refined minimum, as the zone's edges read them.
struct StingSweep {
  std::vector<double> xs, es;       // the samples: from the knob (m), hands' energy (J)
  std::size_t i_min = 0;            // the least sample
  double x_min = 0.0, e_min = 0.0;  // the refined minimum: from the knob (m), energy (J)
};

// Refines sweep->x_min and e_min (from the least sample) between the neighbouring samples
// [a, b] (m from the knob) by Brent's method to x_tolerance_m, started from the three samples
// around it (their parabola is the first step). At an end of the sweep [lo, hi] there is no
// such triple: boost's Brent on [end, neighbour] (its tolerance is relative to |x|, and
// 2 tol (|x| + 1/4) bounds its final half-bracket). Returns false when an impact failed.
bool RefineStingMinimum(StingSearch* search, double a, double b, double lo, double hi,
                        double x_tolerance_m, StingSweep* sweep) {
  auto energy = [search](double s) { return search->Energy(s); };
  const std::vector<double>& xs = sweep->xs;
  const std::vector<double>& es = sweep->es;
  const std::size_t i_min = sweep->i_min;
  if (i_min > 0 && i_min + 1 < xs.size()) {
    const std::size_t lo_i = i_min - 1, hi_i = i_min + 1;
    const std::size_t w_i = es[lo_i] <= es[hi_i] ? lo_i : hi_i;
    const std::size_t v_i = w_i == lo_i ? hi_i : lo_i;
    int evaluations = 0;
    const auto m = StingBrentFromTriple(energy, a, b, sweep->x_min, sweep->e_min, xs[w_i], es[w_i],
                                        xs[v_i], es[v_i], x_tolerance_m, 60, &evaluations);
    if (search->failed) return false;
    sweep->x_min = m.first;
    sweep->e_min = m.second;
  } else if (b > a) {
    const double rel = x_tolerance_m / (2.0 * (std::max(std::abs(lo), std::abs(hi)) + 0.25));
    const int bits = static_cast<int>(std::floor(1.0 - std::log2(rel)));
    boost::uintmax_t iters = 60;
    const auto m = boost::math::tools::brent_find_minima(energy, a, b, bits, iters);
    if (search->failed) return false;
    if (m.second <= sweep->e_min) {
      sweep->x_min = m.first;
      sweep->e_min = m.second;
    }
  }
  return true;
}

// The zone's edge on the side `dir` (-1: towards the knob, +1: the tip), m from the knob: the
// first sample beyond threshold_j (J) walking away from the minimum, then the crossing between
// it and the sample inside by TOMS 748 to x_tolerance_m. *clipped when no sample of the sweep
// [lo, hi] is beyond it (the edge is then lo or hi). *err_edges takes the larger of it and the
// edge's error (m): the root's bracket plus how far err_e (J, the energy's error) moves it.
double StingZoneEdge(StingSearch* search, const StingSweep& sweep, double threshold_j, double lo,
                     double hi, double x_tolerance_m, double err_e, int dir, bool* clipped,
                     double* err_edges) {
  const std::vector<double>& xs = sweep.xs;
  const std::vector<double>& es = sweep.es;
  const std::size_t i_min = sweep.i_min;
  auto g = [&](double s) { return search->Energy(s) - threshold_j; };
  long j = static_cast<long>(i_min);
  while (true) {
    const long next = j + dir;
    if (next < 0 || next >= static_cast<long>(xs.size())) {
      *clipped = true;
      return dir < 0 ? lo : hi;
    }
    if (es[static_cast<std::size_t>(next)] > threshold_j) {
      const double inside =
          j == static_cast<long>(i_min) ? sweep.x_min : xs[static_cast<std::size_t>(j)];
      const double outside = xs[static_cast<std::size_t>(next)];
      // The energy inside is known: the minimum's, or a sample's (the same impact; the
      // samples compute the hands' loads besides, which do not change the energy).
      const double ga =
          (j == static_cast<long>(i_min) ? sweep.e_min : es[static_cast<std::size_t>(j)]) -
          threshold_j;
      const double gb = es[static_cast<std::size_t>(next)] - threshold_j;
      if (search->failed || !(ga <= 0.0)) return inside;
      boost::uintmax_t iters = 60;
      try {
        const double x0 = std::min(inside, outside), x1 = std::max(inside, outside);
        const auto rr = boost::math::tools::toms748_solve(
            g, x0, x1, x0 == inside ? ga : gb, x0 == inside ? gb : ga,
            [&](double l, double r) { return r - l <= 2.0 * x_tolerance_m; }, iters);
        const double root = 0.5 * (rr.first + rr.second);
        const double slope = std::abs(gb - ga) / std::abs(outside - inside);
        *err_edges =
            std::max(*err_edges, (rr.second - rr.first) + (slope > 0.0 ? err_e / slope : 0.0));
        return root;
      } catch (const std::exception& e) {
        search->failed = true;
        *search->error = std::string("least_sting_zone: root finding failed: ") + e.what();
        return inside;
      }
    }
    j = next;
  }
}

}  // namespace

bool LeastStingZone(const StingImpact& solve, double from_knob_m, double to_knob_m, int samples,
                    double fraction, double x_tolerance_m, std::vector<std::string>* warnings,
                    LeastStingZoneResult* out, std::string* error) {
  const double lo = from_knob_m;
  const double hi = to_knob_m;
  StingSearch search;
  search.solve = &solve;
  search.warnings = warnings;
  search.error = error;
  const int n = samples;
  StingSweep sweep;
  std::vector<double>& xs = sweep.xs;
  std::vector<double>& es = sweep.es;
  double err_e = 0.0;
  for (int i = 0; i < n; ++i) {
    const double s = i + 1 == n ? hi : lo + (hi - lo) * i / (n - 1);
    const FlexibleImpactResult fr = search.Impact(s, StingRun::kSample);
    if (search.failed) return false;
    out->curve.push_back(StingPointOf(s, fr));
    out->modes_used = std::max(out->modes_used, fr.modes_used);
    xs.push_back(s);
    es.push_back(fr.hands_vibration_energy_j);
    err_e = std::max(err_e, fr.error_estimate_hands_energy_j);
  }
  out->fraction = fraction;
  const std::size_t i_min =
      static_cast<std::size_t>(std::min_element(es.begin(), es.end()) - es.begin());
  sweep.i_min = i_min;
  out->max_hands_energy_j = *std::max_element(es.begin(), es.end());
  const double a = xs[i_min == 0 ? 0 : i_min - 1];
  const double b = xs[std::min(i_min + 1, xs.size() - 1)];
  sweep.x_min = xs[i_min];
  sweep.e_min = es[i_min];
  double err_x = 0.5 * (b - a);
  if (!RefineStingMinimum(&search, a, b, lo, hi, x_tolerance_m, &sweep)) return false;
  // The least-sting impact once more, with the refinement check: the exit speed there and the
  // error of the hands' energy (integration + mode truncation) that the ends' estimates use.
  const FlexibleImpactResult checked = search.Impact(sweep.x_min, StingRun::kChecked);
  if (search.failed) return false;
  err_e = std::max(err_e, checked.error_estimate_hands_energy_j);
  if (b > a) {
    // Brent's bracket, widened by how far the energy's own error moves a flat minimum.
    const double h = 0.5 * (b - a);
    const double curv = (es[std::min(i_min + 1, es.size() - 1)] + es[i_min == 0 ? 0 : i_min - 1] -
                         2.0 * es[i_min]) /
                        (h * h);
    err_x = x_tolerance_m + (curv > 0.0 ? std::sqrt(2.0 * err_e / curv) : 0.5 * (b - a));
  }
  out->min_position_from_knob_m = sweep.x_min;
  out->min_hands_energy_j = sweep.e_min;
  out->exit_speed_at_min_mps = checked.exit_speed_mps;
  out->threshold_j = sweep.e_min + fraction * (out->max_hands_energy_j - sweep.e_min);
  double err_edges = 0.0;
  bool clip_lo = false, clip_hi = false;
  out->from_knob_m = StingZoneEdge(&search, sweep, out->threshold_j, lo, hi, x_tolerance_m, err_e,
                                   -1, &clip_lo, &err_edges);
  out->to_knob_m = StingZoneEdge(&search, sweep, out->threshold_j, lo, hi, x_tolerance_m, err_e, +1,
                                 &clip_hi, &err_edges);
  if (search.failed) return false;
  out->clipped_at_hands = clip_lo;
  out->clipped_at_tip = clip_hi;
  out->error_estimate_m = std::max(err_x, err_edges);
  return true;
}

}  // namespace sweetspot::core
