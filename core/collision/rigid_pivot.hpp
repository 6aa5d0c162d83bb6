// rigid_pivot: the paper's collision model (eqs 3-6).
//
// Assumptions: the bat is a rigid body turning about a fixed pivot with angular speed
// omega >= 0 just before impact; the pivot stays fixed during the (instantaneous) impact,
// so angular momentum about the pivot is conserved; the ball (mass m, no spin, moving
// perpendicular to the bat) arrives with speed u >= 0 towards the bat; the normal
// coefficient of restitution e in [0, 1] relates the separation and approach speeds at
// the impact point. With x the impact's distance from the pivot and J the moment of
// inertia about the pivot, the ball leaves with
//   v2(x) = -u + J (1 + e) (u + omega x) / (J + m x^2)   (positive = away from the bat).
// The sweet spot (maximum of v2) is in closed form, written without cancellation
// (paper-notes.md section 3): x* = omega J / (m (u + S)), S = sqrt(u^2 + omega^2 J / m),
// v2max = ((1 + e) S - (1 - e) u) / 2. Gravity, the hands' force and bat flexibility are
// neglected during the impact.
#pragma once

#include "core/collision/exit_speed_profile.hpp"

namespace sweetspot::core {

/// Everything the rigid-pivot model needs (SI).
struct RigidPivotInputs {
  double bat_mass_kg = 0.0;      ///< M, kg (> 0).
  double balance_point_m = 0.0;  ///< C, the bat's centroid from the knob, m.
  double moi_pivot_kg_m2 = 0.0;  ///< J about the pivot, kg m^2 (> 0).
  double pivot_from_knob_m =
      0.0;                       ///< The pivot, m from the knob (may be negative: behind the knob).
  double ball_mass_kg = 0.145;   ///< m, kg (> 0).
  double ball_speed_mps = 27.7;  ///< u, the ball's incoming speed, m/s (>= 0).
  double angular_speed_rad_s =
      17.288;        ///< omega, the bat's angular speed about the pivot, rad/s (>= 0).
  double cor = 0.5;  ///< e, coefficient of restitution, in [0, 1].
};

/// One impact under the rigid-pivot model.
struct RigidPivotImpact {
  double impact_from_knob_m = 0.0;  ///< Where the ball hits, m from the knob.
  double x_from_pivot_m = 0.0;      ///< The same point, m from the pivot.
  double exit_speed_mps = 0.0;      ///< The ball's exit speed, m/s (positive = away from the bat).
  double bat_speed_at_impact_mps = 0.0;  ///< omega x before impact, m/s.
  double approach_speed_mps = 0.0;       ///< u + omega x, m/s.
  double collision_efficiency = 0.0;     ///< q = (e - r) / (1 + r), r = m x^2 / J (dimensionless).
  double ball_impulse_n_s = 0.0;         ///< m (v2 + u): impulse the bat gives the ball, N s.
  double pivot_impulse_n_s =
      0.0;  ///< Reaction impulse of the pivot on the bat (swing direction positive), N s.
  double angular_speed_after_rad_s = 0.0;  ///< The bat's angular speed after impact, rad/s.
};

/// The model's exit-speed profile, with x measured from the pivot.
ExitSpeedProfile RigidPivotProfile(const RigidPivotInputs& in);

/// v2 at an impact `impact_from_knob_m` metres from the knob, with the impulses.
RigidPivotImpact RigidPivotImpactAt(const RigidPivotInputs& in, double impact_from_knob_m);

}  // namespace sweetspot::core
