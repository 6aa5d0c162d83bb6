// rigid_pivot: implementation; the model's assumptions are stated at the top of rigid_pivot.hpp.
#include "core/collision/rigid_pivot.hpp"

namespace sweetspot::core {

ExitSpeedProfile RigidPivotProfile(const RigidPivotInputs& in) {
  ExitSpeedProfile p;
  p.ball_speed_mps = in.ball_speed_mps;
  p.gain_kg_m2 = (1.0 + in.cor) * in.moi_pivot_kg_m2;
  p.approach_mps = in.ball_speed_mps;
  p.inertia_kg_m2 = in.moi_pivot_kg_m2;
  p.ball_mass_kg = in.ball_mass_kg;
  p.angular_speed_rad_s = in.angular_speed_rad_s;
  p.origin_from_knob_m = in.pivot_from_knob_m;
  return p;
}

RigidPivotImpact RigidPivotImpactAt(const RigidPivotInputs& in, double impact_from_knob_m) {
  RigidPivotImpact out;
  const ExitSpeedProfile p = RigidPivotProfile(in);
  const double x = impact_from_knob_m - in.pivot_from_knob_m;
  const double j = in.moi_pivot_kg_m2;
  const double r = in.ball_mass_kg * x * x / j;
  out.impact_from_knob_m = impact_from_knob_m;
  out.x_from_pivot_m = x;
  out.exit_speed_mps = p.ExitSpeedMps(x);
  out.bat_speed_at_impact_mps = in.angular_speed_rad_s * x;
  out.approach_speed_mps = in.ball_speed_mps + out.bat_speed_at_impact_mps;
  out.collision_efficiency = (in.cor - r) / (1.0 + r);
  // Impulse on the ball: m (v2 - (-u)) = m J (1+e)(u + omega x)/(J + m x^2), no cancellation.
  const double impulse =
      in.ball_mass_kg * p.gain_kg_m2 * out.approach_speed_mps / (j + in.ball_mass_kg * x * x);
  out.ball_impulse_n_s = impulse;
  // The bat receives -impulse at x: J d(omega) = -impulse x, and M dv_c = -impulse + R with
  // dv_c = d(omega) (C - p), so R = impulse (1 - M x (C - p) / J): zero at the centre of
  // percussion x = J / (M (C - p)).
  const double arm = in.balance_point_m - in.pivot_from_knob_m;
  out.pivot_impulse_n_s = impulse * (1.0 - in.bat_mass_kg * x * arm / j);
  out.angular_speed_after_rad_s = in.angular_speed_rad_s - impulse * x / j;
  return out;
}

}  // namespace sweetspot::core
