// The distance searches of a scene's batted ball (DistanceSweetSpot, CarryMap): a coarse grid of
// (impact point, undercut), then for the sweet spot a local search; the model whose carry they
// read is BattedBallModel (batted_ball.hpp).
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/numerics/nlopt_run.hpp"
#include "core/numerics/termination.hpp"
#include "core/scene/batted_ball.hpp"

namespace sweetspot::core {

void DistancePositionRange(const DistanceOptions& options, double length_m, double* lo,
                           double* hi) {
  *lo = options.position_min_from_knob_m.value_or(0.5 * length_m);
  *hi = options.position_max_from_knob_m.value_or(length_m);
}

namespace batted_ball {
namespace {

// The region of valid `options` on the bat, or the refusal (of the options, then of the region).
bool RegionOnBat(const DistanceOptions& options, double length_m, double* lo, double* hi,
                 Summary* s) {
  if (Refusal why; !options.Validate(&why)) {
    s->SetRefusal(std::move(why));
    return false;
  }
  DistancePositionRange(options, length_m, lo, hi);
  const std::string rule = "must be within the bat [0, " + FormatNumber17(length_m) + "]";
  if (!(*lo >= 0.0 && *lo <= length_m)) {
    s->SetRefusal(Number17Refusal("distance.position_min_from_knob_m", *lo, rule));
    return false;
  }
  if (!(*hi >= 0.0 && *hi <= length_m)) {
    s->SetRefusal(Number17Refusal("distance.position_max_from_knob_m", *hi, rule));
    return false;
  }
  if (!(*lo < *hi)) {
    s->SetRefusal(Number17Refusal("distance.position_max_from_knob_m", *hi,
                                  "must be greater than the lowest position " +
                                      FormatNumber17(*lo) + " m (half the bat by default)"));
    return false;
  }
  return true;
}

// The i-th of n points evenly from lo to hi (hi exactly at i = n - 1), in their unit.
double Grid(double lo, double hi, int n, int i) {
  return i == n - 1 ? hi : lo + (hi - lo) * i / (n - 1);
}

}  // namespace
}  // namespace batted_ball

namespace batted_ball {
namespace {

// The best carry (m) seen at an impact point (m from the knob) and undercut (m).
struct CarryPoint {
  double carry_m = -kInf;
  double x_m = 0.0;
  double undercut_m = 0.0;
};

// The search's settings in *out (its region [lo, hi], m from the knob, its undercuts, m, and
// grid) and, for an integrated collision model, the normal law's table over the region: false
// (out->summary, *failure) when the table fails.
bool StartDistanceSearch(BattedBallModel& model, const DistanceOptions& options, double lo,
                         double hi, std::string* failure, DistanceSweetSpotResult* out) {
  Summary& s = out->summary;
  const double d_lo = options.undercut_min_m, d_hi = options.undercut_max_m;
  out->position_min_from_knob_m = lo;
  out->position_max_from_knob_m = hi;
  out->undercut_min_m = d_lo;
  out->undercut_max_m = d_hi;
  out->position_tolerance_m = options.position_tolerance_m;
  out->undercut_tolerance_m = options.undercut_tolerance_m;
  out->coarse_positions = options.coarse_positions;
  out->coarse_undercuts = options.coarse_undercuts;
  out->normal_law = model.integrated() ? "tabulated" : "closed_form";
  if (model.integrated()) {
    if (!model.TabulateNormalLaw(lo, hi, options.normal_table_positions, d_lo, d_hi,
                                 options.normal_table_speeds, failure)) {
      s.termination = Termination::kFailure;
      s.message = "distance_sweet_spot: the normal law's table: " + *failure;
      return false;
    }
    out->normal_table_positions = options.normal_table_positions;
    out->normal_table_speeds = options.normal_table_speeds;
  }
  return true;
}

// The coarse scan: the carry at every point of the coarse grid over [lo, hi] (m from the knob)
// and the options' undercuts, the best in *best; false (out->summary) when cancelled or when no
// point carries.
bool CoarseCarryScan(BattedBallModel& model, const DistanceOptions& options, double lo, double hi,
                     const flight::FlightOptions& fo, const Progress* progress,
                     DistanceSweetSpotResult* out, CarryPoint* best) {
  Summary& s = out->summary;
  const double d_lo = options.undercut_min_m, d_hi = options.undercut_max_m;
  const int np = options.coarse_positions, nu = options.coarse_undercuts;
  best->x_m = lo;
  for (int i = 0; i < np; ++i) {
    if (IsCancelled(progress)) {
      s.termination = Termination::kFailure;
      s.message = "cancelled";
      return false;
    }
    const double x = Grid(lo, hi, np, i);
    for (int j = 0; j < nu; ++j) {
      const double d = Grid(d_lo, d_hi, nu, j);
      const double c = model.CarryAt(x, d, fo);
      ++out->evaluations;
      if (c > best->carry_m) {
        best->carry_m = c;
        best->x_m = x;
        best->undercut_m = d;
      }
    }
  }
  if (!(best->carry_m > -kInf)) {
    s.termination = Termination::kFailure;
    s.message =
        "distance_sweet_spot: no point of the region carries (every ball misses the bat, "
        "is driven back or does not land): widen options.distance's ranges";
    return false;
  }
  return true;
}

// The local search (LN_BOBYQA) from the coarse scan's best point, in coordinates scaled to one
// coarse cell around it, within [lo, hi] (m from the knob) and the options' undercuts: the best
// carry it sees within the graze limit in *local (the coarse point's when none is better).
NloptRunOutcome LocalCarrySearch(BattedBallModel& model, const DistanceOptions& options, double lo,
                                 double hi, const flight::FlightOptions& fo,
                                 const Progress* progress, const CarryPoint& coarse,
                                 DistanceSweetSpotResult* out, CarryPoint* local) {
  const double d_lo = options.undercut_min_m, d_hi = options.undercut_max_m;
  const int np = options.coarse_positions, nu = options.coarse_undercuts;
  const double xb = coarse.x_m, db = coarse.undercut_m;
  const double cx = (hi - lo) / (np - 1), cd = (d_hi - d_lo) / (nu - 1);
  NloptRunSettings run;
  run.algorithm = NloptAlgorithm::kLnBobyqa;
  run.lower = {(std::max(lo, xb - cx) - xb) / cx, (std::max(d_lo, db - cd) - db) / cd};
  run.upper = {(std::min(hi, xb + cx) - xb) / cx, (std::min(d_hi, db + cd) - db) / cd};
  run.x_tolerance_abs =
      std::min(options.position_tolerance_m / cx, options.undercut_tolerance_m / cd);
  run.max_evaluations = options.max_evaluations;
  run.initial_step = 0.25;
  run.progress = progress;
  *local = coarse;
  const NloptFunction objective = [&](const double* p, double*) {
    const double x = xb + p[0] * cx;
    const double d = db + p[1] * cd;
    const double reach = model.UndercutReachAtM(x);
    const double dc = std::clamp(d, -reach, reach);
    const double c = model.CarryAt(x, dc, fo);
    ++out->evaluations;
    if (!std::isfinite(c)) return 1e6;  // no carry: far worse than any ball that lands
    if (dc == d && c > local->carry_m) {
      local->carry_m = c;
      local->x_m = x;
      local->undercut_m = d;
    }
    // Beyond the graze limit: the carry at the limit, less a steep penalty (continuous).
    return -c + 1e4 * std::abs(d - dc) / cd;
  };
  std::vector<double> p{0.0, 0.0};
  return RunNlopt(objective, {}, run, &p);
}

// The answer at the local search's best point `best` (the batted ball evaluated there, the
// bounds it touches within the tolerances, the counts and message) into *out; a refusal or
// failure of that evaluation (*failure) goes to out->summary.
void FinishDistanceSweetSpot(BattedBallModel& model, const DistanceOptions& options, double lo,
                             double hi, const flight::FlightOptions& fo,
                             const NloptRunOutcome& outcome, const CarryPoint& best,
                             std::string* failure, DistanceSweetSpotResult* out) {
  Summary& s = out->summary;
  const double d_lo = options.undercut_min_m, d_hi = options.undercut_max_m;
  const int np = options.coarse_positions, nu = options.coarse_undercuts;
  // The best carry seen (NLopt's point is that too, unless it stopped early).
  const double x = best.x_m, d = best.undercut_m;
  out->position_from_knob_m = x;
  out->undercut_m = d;
  const double table_carry = best.carry_m;
  Refusal refusal;
  if (!model.Evaluate(x, d, &out->ball, &refusal, failure, fo)) {
    if (!refusal.field.empty() || !refusal.rule.empty()) {
      s.SetRefusal(std::move(refusal));
    } else {
      s.termination = Termination::kFailure;
      s.message = "distance_sweet_spot: at the optimum: " + *failure;
    }
    return;
  }
  out->distance_m = out->ball.flight.distance_m;
  out->exit_speed_mps = out->ball.impact.exit_speed_mps;
  out->launch_angle_deg = out->ball.impact.launch_angle_deg;
  out->backspin_rpm = out->ball.impact.backspin_rpm;
  out->normal_table_error_m = model.integrated() ? out->distance_m - table_carry : 0.0;
  const double reach = model.UndercutReachAtM(x);
  out->at_position_bound =
      x - lo <= options.position_tolerance_m || hi - x <= options.position_tolerance_m;
  out->at_undercut_bound = d - std::max(d_lo, -reach) <= options.undercut_tolerance_m ||
                           std::min(d_hi, reach) - d <= options.undercut_tolerance_m;
  s.evaluations = out->evaluations;
  s.iterations = outcome.evaluations;
  s.objective = out->distance_m;
  s.error_estimate = out->ball.flight.error_estimate_m;
  s.message = std::string("coarse scan ") + std::to_string(np) + " x " + std::to_string(nu) +
              ", then LN_BOBYQA: " + NloptResultName(outcome.raw_status);
  if (s.termination == Termination::kInvalidInput) s.termination = Termination::kFailure;
}

}  // namespace
}  // namespace batted_ball

DistanceSweetSpotResult DistanceSweetSpot(BattedBallModel& model, double length_m,
                                          const DistanceOptions& options,
                                          const Progress* progress) {
  DistanceSweetSpotResult out;
  Summary& s = out.summary;
  s.backend = "nlopt:LN_BOBYQA";
  CatchInternalError(&s, [&] {
    double lo = 0.0, hi = 0.0;
    if (!batted_ball::RegionOnBat(options, length_m, &lo, &hi, &s)) return;
    std::string failure;
    if (!batted_ball::StartDistanceSearch(model, options, lo, hi, &failure, &out)) return;
    const flight::FlightOptions fo = BattedBallModel::SearchFlightOptions();
    batted_ball::CarryPoint coarse;
    if (!batted_ball::CoarseCarryScan(model, options, lo, hi, fo, progress, &out, &coarse)) return;
    batted_ball::CarryPoint local;
    const NloptRunOutcome outcome =
        batted_ball::LocalCarrySearch(model, options, lo, hi, fo, progress, coarse, &out, &local);
    s.raw_status = outcome.raw_status;
    s.termination = TerminationFromNloptResult(outcome.raw_status);
    if (outcome.cancelled) {
      s.termination = Termination::kFailure;
      s.message = "cancelled";
      return;
    }
    batted_ball::FinishDistanceSweetSpot(model, options, lo, hi, fo, outcome, local, &failure,
                                         &out);
  });
  return out;
}

CarryMapResult CarryMap(BattedBallModel& model, double length_m, const DistanceOptions& options,
                        const Progress* progress) {
  using batted_ball::Grid;
  CarryMapResult out;
  Summary& s = out.summary;
  s.backend = "grid";
  CatchInternalError(&s, [&] {
    double lo = 0.0, hi = 0.0;
    if (!batted_ball::RegionOnBat(options, length_m, &lo, &hi, &s)) return;
    const int np = options.map_positions, nu = options.map_undercuts;
    out.positions_from_knob_m.resize(np);
    out.undercuts_m.resize(nu);
    for (int i = 0; i < np; ++i) out.positions_from_knob_m[i] = Grid(lo, hi, np, i);
    for (int j = 0; j < nu; ++j)
      out.undercuts_m[j] = Grid(options.undercut_min_m, options.undercut_max_m, nu, j);
    out.normal_law = model.integrated() ? "tabulated" : "closed_form";
    if (model.integrated()) {
      std::string failure;
      if (!model.TabulateNormalLaw(lo, hi, np, options.undercut_min_m, options.undercut_max_m,
                                   options.normal_table_speeds, &failure)) {
        s.termination = Termination::kFailure;
        s.message = "carry_map: the normal law's table: " + failure;
        return;
      }
      out.normal_table_speeds = options.normal_table_speeds;
    }
    const flight::FlightOptions fo;  // the flight's defaults: 0.1 ft
    out.distance_m.assign(static_cast<std::size_t>(np) * nu, kNaN);
    double best = -kInf;
    for (int i = 0; i < np; ++i) {
      if (IsCancelled(progress)) {
        s.termination = Termination::kFailure;
        s.message = "cancelled";
        return;
      }
      for (int j = 0; j < nu; ++j) {
        const double c = model.CarryAt(out.positions_from_knob_m[i], out.undercuts_m[j], fo);
        out.distance_m[static_cast<std::size_t>(i) * nu + j] = c;
        if (c > best) {
          best = c;
          out.best_distance_m = c;
          out.best_position_from_knob_m = out.positions_from_knob_m[i];
          out.best_undercut_m = out.undercuts_m[j];
        }
      }
    }
    s.evaluations = np * nu;
    if (!(best > -kInf)) {
      s.termination = Termination::kFailure;
      s.message =
          "carry_map: no point of the grid carries (every ball misses the bat, is "
          "driven back or does not land): widen options.distance's ranges";
      return;
    }
    s.termination = Termination::kConverged;
    s.objective = best;
    s.message = "grid " + std::to_string(np) + " x " + std::to_string(nu);
  });
  return out;
}

}  // namespace sweetspot::core
