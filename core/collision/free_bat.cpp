// free_bat: implementation; the model's assumptions are stated at the top of free_bat.hpp.
#include "core/collision/free_bat.hpp"

#include "core/units.hpp"

namespace sweetspot::core {

double CollisionEfficiency(double cor, double recoil_factor) {
  return (cor - recoil_factor) / (1.0 + recoil_factor);
}

ExitSpeedProfile FreeBatProfile(const FreeBatInputs& in) {
  // With b = impact - C and d = C - pivot:  1 + r = (I (1 + m/M) + m b^2) / I, so
  // exit = -u + (1+e)(u + v_bat)/(1 + r) = -u + (1+e) I (u + omega d + omega b) / (I' + m b^2).
  const double i = in.moi_centroid_kg_m2;
  ExitSpeedProfile p;
  p.ball_speed_mps = in.ball_speed_mps;
  p.gain_kg_m2 = (1.0 + in.cor) * i;
  p.approach_mps =
      in.ball_speed_mps + in.angular_speed_rad_s * (in.balance_point_m - in.pivot_from_knob_m);
  p.inertia_kg_m2 = i * (1.0 + in.ball_mass_kg / in.bat_mass_kg);
  p.ball_mass_kg = in.ball_mass_kg;
  p.angular_speed_rad_s = in.angular_speed_rad_s;
  p.origin_from_knob_m = in.balance_point_m;
  return p;
}

BbcorStyle BbcorStyleAt(double bat_mass_kg, double balance_point_m, double moi_centroid_kg_m2,
                        double ball_mass_kg, double cor, double impact_from_knob_m) {
  BbcorStyle out;
  out.pivot_from_knob_m = kSixInchPivotM;
  const double arm = balance_point_m - kSixInchPivotM;
  out.moi_pivot_kg_m2 = moi_centroid_kg_m2 + bat_mass_kg * arm * arm;
  const double z = impact_from_knob_m - kSixInchPivotM;
  out.applies = z > 0.0;
  out.recoil_factor = ball_mass_kg * z * z / out.moi_pivot_kg_m2;
  out.apparent_cor = CollisionEfficiency(cor, out.recoil_factor);
  out.bbcor = out.apparent_cor * (1.0 + out.recoil_factor) + out.recoil_factor;
  out.besr = out.apparent_cor + 0.5;
  return out;
}

FreeBatImpact FreeBatImpactAt(const FreeBatInputs& in, double impact_from_knob_m) {
  FreeBatImpact out;
  const double b = impact_from_knob_m - in.balance_point_m;
  const double i = in.moi_centroid_kg_m2;
  out.impact_from_knob_m = impact_from_knob_m;
  out.recoil_factor = in.ball_mass_kg * (1.0 / in.bat_mass_kg + b * b / i);
  out.collision_efficiency = CollisionEfficiency(in.cor, out.recoil_factor);
  out.bat_speed_at_impact_mps =
      in.angular_speed_rad_s * (impact_from_knob_m - in.pivot_from_knob_m);
  out.approach_speed_mps = in.ball_speed_mps + out.bat_speed_at_impact_mps;
  // q u + (1 + q) v_bat, written as -u + (1 + q)(u + v_bat) = -u + (1+e)(u + v_bat)/(1 + r).
  out.exit_speed_mps = FreeBatProfile(in).ExitSpeedMps(b);
  out.ball_impulse_n_s =
      in.ball_mass_kg * (1.0 + in.cor) * out.approach_speed_mps / (1.0 + out.recoil_factor);
  // The bat receives -J at b: dv_c = -J/M, d(omega) = -J b / I; at the hands (h - C from the
  // centroid) dv = -J (1/M + b (h - C) / I), zero when b = I / (M (C - h)).
  const double bh = in.hands_from_knob_m - in.balance_point_m;
  out.hands_velocity_change_mps = -out.ball_impulse_n_s * (1.0 / in.bat_mass_kg + b * bh / i);
  out.bbcor = BbcorStyleAt(in.bat_mass_kg, in.balance_point_m, i, in.ball_mass_kg, in.cor,
                           impact_from_knob_m);
  return out;
}

}  // namespace sweetspot::core
