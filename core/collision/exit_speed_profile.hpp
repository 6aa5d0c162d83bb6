// The closed form shared by the rigid-body collision models (rigid_pivot, free_bat).
//
// Assumptions: both rigid models give the ball's exit speed as a function of the
// impact coordinate x (metres from a model-specific origin along the bat) of the form
//   f(x) = -u + c * (w + omega * x) / (J + m * x^2),
// with u the ball's incoming speed, c a gain (kg m^2), w the relative approach speed
// at the origin, J an inertia (kg m^2), m the ball's mass and omega >= 0 the bat's
// angular speed. Every formula below is exact algebra on that form, written so that
// no step cancels catastrophically (see docs/models.md, "Closed forms").
#pragma once

#include <limits>

namespace sweetspot::core {

/// A closed interval [lo_m, hi_m] in the profile's coordinate; infinite ends allowed.
struct ProfileInterval {
  double lo_m = -std::numeric_limits<double>::infinity();  ///< Lower end, m.
  double hi_m = std::numeric_limits<double>::infinity();   ///< Upper end, m.
};

/// The unconstrained maximum of an exit-speed profile.
struct ProfileMaximum {
  double x_m = 0.0;                ///< Maximiser, m from the profile's origin.
  double exit_speed_mps = 0.0;     ///< f(x*), m/s.
  double curvature_per_m_s = 0.0;  ///< f''(x*), 1/(m s) (<= 0).
  bool flat = false;  ///< True when f is constant (omega = 0 and w = 0): x* = 0 by convention.
  double error_estimate_m = 0.0;    ///< Rounding bound on x*, m.
  double error_estimate_mps = 0.0;  ///< Rounding bound on f(x*), m/s.
};

/// f(x) = -u + c (w + omega x) / (J + m x^2): exit speed (m/s, positive away from the bat).
struct ExitSpeedProfile {
  double ball_speed_mps = 0.0;       ///< u: the ball's incoming speed, m/s (>= 0).
  double gain_kg_m2 = 0.0;           ///< c: numerator gain, kg m^2 (>= 0).
  double approach_mps = 0.0;         ///< w: relative approach speed at the origin, m/s.
  double inertia_kg_m2 = 0.0;        ///< J: denominator inertia, kg m^2 (> 0).
  double ball_mass_kg = 0.0;         ///< m: ball mass, kg (> 0).
  double angular_speed_rad_s = 0.0;  ///< omega: the bat's angular speed, rad/s (>= 0).
  double origin_from_knob_m = 0.0;   ///< Where x = 0 lies, m from the knob.

  /// f(x) in m/s at x metres from the origin.
  double ExitSpeedMps(double x_m) const;
  /// f'(x), 1/s (exact).
  double DerivativePerS(double x_m) const;
  /// The unconstrained maximum (closed form, no cancellation).
  ProfileMaximum Maximum() const;
  /// f(x*) - f(x) >= 0 in m/s, computed without cancellation as c G m (x - x*)^2 / (J + m x^2).
  double DeficitMps(double x_m) const;
  /// The connected interval around x* where f(x) >= f(x*) - delta_mps (delta_mps >= 0).
  ProfileInterval ZoneAround(double delta_mps) const;
};

}  // namespace sweetspot::core
