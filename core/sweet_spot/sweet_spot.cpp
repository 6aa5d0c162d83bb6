#include "core/sweet_spot/sweet_spot.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"

namespace sweetspot::core {
namespace {

// A position x in a profile's coordinate (origin o from the knob) as metres from the knob, for
// x in [lo, hi] = [-o, L - o]: the ends map to 0 and L exactly, the rest is clamped to [0, L].
double FromProfile(double x, double o, double lo, double hi, double length_m) {
  if (x <= lo) return 0.0;
  if (x >= hi) return length_m;
  return std::clamp(x + o, 0.0, length_m);
}

}  // namespace

const char* PlacementName(Placement placement) {
  switch (placement) {
    case Placement::kOnBat:
      return "on_bat";
    case Placement::kBeyondTip:
      return "beyond_tip";
    case Placement::kBeforeKnob:
      return "before_knob";
  }
  return "on_bat";
}

ClosedFormMaximum ClosedFormMaximumOnBat(const ExitSpeedProfile& profile, double length_m) {
  ClosedFormMaximum out;
  const ProfileMaximum mx = profile.Maximum();
  const double lo = -profile.origin_from_knob_m;            // the knob, profile coordinate
  const double hi = length_m - profile.origin_from_knob_m;  // the tip
  const double xc = std::clamp(mx.x_m, lo, hi);
  double best_x = xc;
  double best_f = xc == mx.x_m ? mx.exit_speed_mps : profile.ExitSpeedMps(xc);
  for (double cand : {lo, hi}) {
    const double fc = profile.ExitSpeedMps(cand);
    if (fc > best_f) {
      best_f = fc;
      best_x = cand;
    }
  }
  // Back to the knob's coordinate; an end of the bat is that end exactly (o + (L - o) need not
  // round to L: with the pivot 100 m away the tip came back as L + 4e-15, off the bat).
  out.position_from_knob_m = FromProfile(best_x, profile.origin_from_knob_m, lo, hi, length_m);
  out.exit_speed_mps = best_f;
  out.unconstrained_position_from_knob_m = mx.x_m + profile.origin_from_knob_m;
  out.flat = mx.flat;
  if (mx.flat) {
    out.placement = Placement::kOnBat;
  } else if (best_x == hi && mx.x_m > hi) {
    out.placement = Placement::kBeyondTip;
  } else if (best_x == lo && mx.x_m < lo) {
    out.placement = Placement::kBeforeKnob;
  } else if (best_x != xc) {
    out.placement = best_x == hi ? Placement::kBeyondTip : Placement::kBeforeKnob;
  }
  if (out.placement == Placement::kOnBat) {
    out.error_estimate_m = mx.error_estimate_m;
    out.error_estimate_mps = mx.error_estimate_mps;
  } else {
    out.error_estimate_m = 0.0;  // an end of the bat, exactly
    out.error_estimate_mps = 8.0 * kEps * (profile.ball_speed_mps + std::abs(best_f));
  }
  return out;
}

MaxExitSpeedResult ClosedFormMaxExitSpeed(const ExitSpeedProfile& profile, double length_m) {
  MaxExitSpeedResult out;
  out.method = "closed_form";
  out.summary.backend = "closed_form";
  out.summary.iterations = 0;
  out.summary.evaluations = 1;
  const ClosedFormMaximum mx = ClosedFormMaximumOnBat(profile, length_m);
  out.position_from_knob_m = mx.position_from_knob_m;
  out.exit_speed_mps = mx.exit_speed_mps;
  out.unconstrained_position_from_knob_m = mx.unconstrained_position_from_knob_m;
  out.placement = mx.placement;
  out.error_estimate_m = mx.error_estimate_m;
  out.error_estimate_mps = mx.error_estimate_mps;
  if (mx.flat) {
    out.summary.warnings.emplace_back(
        "the exit speed is the same at every impact position (no swing, no incoming ball "
        "speed); the pivot's position (clamped to the bat) is reported");
  } else if (out.placement != Placement::kOnBat) {
    out.summary.warnings.push_back(
        std::string("the unconstrained maximiser (") +
        FormatNumber17(out.unconstrained_position_from_knob_m) + " m from the knob) is " +
        (out.placement == Placement::kBeyondTip ? "beyond the tip" : "before the knob") +
        "; the end of the bat is reported");
  }
  out.summary.termination = Termination::kConverged;
  out.summary.message = "closed form";
  out.summary.objective = out.exit_speed_mps;
  out.summary.error_estimate = out.error_estimate_m;
  out.summary.solve_time_s = 0.0;
  return out;
}

SweetZoneResult ClosedFormSweetZone(const ExitSpeedProfile& profile, double length_m,
                                    const MaxExitSpeedResult& max, double tolerance_mps) {
  SweetZoneResult out;
  out.method = "closed_form";
  out.tolerance_mps = tolerance_mps;
  out.threshold_mps = max.exit_speed_mps - tolerance_mps;
  const double o = profile.origin_from_knob_m;
  const double lo = -o;
  const double hi = length_m - o;
  const double xc = max.position_from_knob_m - o;
  // Tolerance measured from the unconstrained maximum: tolerance + (f(x*) - f(x_c)).
  const double delta = tolerance_mps + profile.DeficitMps(xc);
  const ProfileInterval zone = profile.ZoneAround(delta);
  out.clipped_at_knob = zone.lo_m < lo;
  out.clipped_at_tip = zone.hi_m > hi;
  const double zlo = std::clamp(zone.lo_m, lo, hi);
  const double zhi = std::clamp(zone.hi_m, lo, hi);
  out.from_knob_m = FromProfile(zlo, o, lo, hi, length_m);
  out.to_knob_m = FromProfile(zhi, o, lo, hi, length_m);
  // Each end moves by (rounding of f) / |f'| there; at a double root (tolerance -> 0) by
  // sqrt(2 rounding / |f''|) instead.
  const ProfileMaximum mx = profile.Maximum();
  const double f_noise = 8.0 * kEps * (profile.ball_speed_mps + std::abs(max.exit_speed_mps));
  double err = 0.0;
  for (double x : {zlo, zhi}) {
    if ((x == lo && out.clipped_at_knob) || (x == hi && out.clipped_at_tip)) continue;
    const double slope = std::abs(profile.DerivativePerS(x));
    double e = slope > 0.0 ? f_noise / slope : std::numeric_limits<double>::infinity();
    if (mx.curvature_per_m_s < 0.0) {
      e = std::min(e, std::sqrt(2.0 * f_noise / -mx.curvature_per_m_s));
    }
    if (std::isfinite(e)) err = std::max(err, e + 8.0 * kEps * std::abs(x + o));
  }
  out.error_estimate_m = err;
  return out;
}

std::optional<CenterOfPercussionResult> CenterOfPercussion(const MassProperties& mass_properties,
                                                           double hands_from_knob_m,
                                                           double length_m, std::string* why) {
  Refusal refusal;
  auto out = CenterOfPercussion(mass_properties, hands_from_knob_m, length_m, &refusal);
  if (!out.has_value() && why != nullptr) *why = refusal.Message();
  return out;
}

std::optional<CenterOfPercussionResult> CenterOfPercussion(const MassProperties& mass_properties,
                                                           double hands_from_knob_m,
                                                           double length_m, Refusal* why) {
  const double arm = mass_properties.balance_point_m - hands_from_knob_m;
  if (!(arm > 0.0)) {
    if (why != nullptr) {
      *why = Number17Refusal("swing.hands_from_knob_m", hands_from_knob_m,
                             "must be closer to the knob than the balance point (" +
                                 FormatNumber17(mass_properties.balance_point_m) +
                                 " m) for a centre of percussion to exist");
    }
    return std::nullopt;
  }
  CenterOfPercussionResult out;
  out.hands_from_knob_m = hands_from_knob_m;
  // I_h = I_cm + M (C - h)^2, so CoP - h = I_h / (M (C - h)) = I_cm / (M (C - h)) + (C - h):
  // the second form adds two positive terms (no cancellation).
  const double m = mass_properties.mass_kg;
  out.moi_hands_kg_m2 = mass_properties.moi_centroid_kg_m2 + m * arm * arm;
  out.position_from_knob_m =
      mass_properties.balance_point_m + mass_properties.moi_centroid_kg_m2 / (m * arm);
  out.placement = out.position_from_knob_m > length_m ? Placement::kBeyondTip : Placement::kOnBat;
  out.error_estimate_m = 8.0 * kEps * out.position_from_knob_m +
                         4.0 * kEps * std::abs(hands_from_knob_m) *
                             (mass_properties.moi_centroid_kg_m2 / (m * arm * arm));
  return out;
}

}  // namespace sweetspot::core
