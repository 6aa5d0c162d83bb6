// free_bat: the unpivoted rigid bat, described the way the bat-testing community does
// (collision efficiency q, "apparent COR").
//
// Assumptions: during the (instantaneous) impact the bat is a free rigid body: the
// hands exert no impulse. Before impact it moves as the swing prescribes (rotation at
// omega about the swing pivot, so a point z metres beyond the pivot moves at omega z).
// The ball (mass m, no spin) arrives perpendicular to the bat with speed u >= 0; the
// coefficient of restitution e in [0, 1] applies at the impact point. With b the impact's
// distance from the bat's centroid and I_cm the moment of inertia about the centroid,
//   r = m (1/M + b^2 / I_cm)   (the ball's mass over the bat's effective mass there),
//   q = (e - r) / (1 + r)      (collision efficiency),
//   exit speed = q u + (1 + q) v_bat,  v_bat = omega (impact - pivot).
// For a bat held on a fixed pivot the same formulas hold with r = m z^2 / I_pivot
// (z from the pivot): that is the rigid_pivot model, and the BBCOR-style block below.
#pragma once

#include <string>

#include "core/collision/exit_speed_profile.hpp"

namespace sweetspot::core {

/// Everything the free-bat model needs (SI).
struct FreeBatInputs {
  double bat_mass_kg = 0.0;         ///< M, kg (> 0).
  double balance_point_m = 0.0;     ///< C from the knob, m.
  double moi_centroid_kg_m2 = 0.0;  ///< I_cm, kg m^2 (> 0).
  double pivot_from_knob_m = 0.0;   ///< The swing's pivot (sets v_bat), m from the knob.
  double hands_from_knob_m =
      0.1524;                    ///< Where the hands are (for the jolt they feel), m from the knob.
  double ball_mass_kg = 0.145;   ///< m, kg (> 0).
  double ball_speed_mps = 27.7;  ///< u, incoming, m/s (>= 0).
  double angular_speed_rad_s = 17.288;  ///< omega about the pivot, rad/s (>= 0).
  double cor = 0.5;                     ///< e in [0, 1].
};

/// A BBCOR-style description of the same impact (NCAA BBCOR / ASTM F2219 test geometry):
/// the bat at rest on a pivot 6 in (0.1524 m) from the knob, the ball fired at the impact
/// point. The measured quantity is the apparent COR e_A = q with r6 = m z^2 / I_6in (z from
/// the 6-in pivot); the BBCOR is recovered from it as e_A (1 + r6) + r6, which for a rigid
/// bat is the model's e by construction. BESR = e_A + 1/2 (the older NCAA ratio).
struct BbcorStyle {
  bool applies = false;               ///< False when the impact is at or behind the 6-in pivot.
  double pivot_from_knob_m = 0.1524;  ///< The test pivot, m from the knob.
  double moi_pivot_kg_m2 = 0.0;       ///< I_6in, kg m^2.
  double recoil_factor = 0.0;         ///< r6 = m z^2 / I_6in (dimensionless).
  double apparent_cor = 0.0;          ///< e_A = (e - r6) / (1 + r6) (dimensionless).
  double bbcor = 0.0;                 ///< e_A (1 + r6) + r6 (dimensionless; = e for a rigid bat).
  double besr = 0.0;                  ///< Ball exit speed ratio e_A + 1/2 (dimensionless).
};

/// One impact under the free-bat model.
struct FreeBatImpact {
  double impact_from_knob_m = 0.0;       ///< m from the knob.
  double exit_speed_mps = 0.0;           ///< m/s, positive away from the bat.
  double recoil_factor = 0.0;            ///< r = m (1/M + b^2 / I_cm) (dimensionless).
  double collision_efficiency = 0.0;     ///< q = (e - r) / (1 + r) (dimensionless).
  double bat_speed_at_impact_mps = 0.0;  ///< v_bat = omega (impact - pivot), m/s.
  double approach_speed_mps = 0.0;       ///< u + v_bat, m/s.
  double ball_impulse_n_s = 0.0;         ///< Impulse the bat gives the ball, N s.
  double hands_velocity_change_mps =
      0.0;  ///< The bat's velocity change at the hands (swing direction positive), m/s; 0 at the
            ///< centre of percussion.
  BbcorStyle bbcor;  ///< The BBCOR-style values at this impact point.
};

/// The collision efficiency q = (e - r) / (1 + r) for a recoil factor r.
double CollisionEfficiency(double cor, double recoil_factor);

/// The free-bat exit-speed profile, with x measured from the centroid.
ExitSpeedProfile FreeBatProfile(const FreeBatInputs& in);

/// One impact at `impact_from_knob_m`.
FreeBatImpact FreeBatImpactAt(const FreeBatInputs& in, double impact_from_knob_m);

/// The BBCOR-style values for a bat of mass M, centroid C and I_cm struck at `impact_from_knob_m`.
BbcorStyle BbcorStyleAt(double bat_mass_kg, double balance_point_m, double moi_centroid_kg_m2,
                        double ball_mass_kg, double cor, double impact_from_knob_m);

}  // namespace sweetspot::core
