// hertz: the paper's contact extension (eqs 7-9) in its corrected reading
// (paper-notes.md section 2), with a physically realistic default.
//
// Assumptions: the impact lasts about a millisecond, so the bat's rotation during it is
// small: in the frame moving with the bat's pre-impact motion, the bat is a rigid body
// (mass M, centroid C, I_cm) held by the hands at h through a linear spring (and
// optional dashpot), the ball (mass m) approaches the impact point s at the relative
// speed v0 = u + omega (s - pivot). delta1 is the contact compression, delta2 the
// hands' compression. With b = s - C, b_h = h - C the inverse effective masses are
//   c11 = 1/m + 1/M + b^2/I,  c12 = 1/M + b b_h / I,  c22 = 1/M + b_h^2 / I,
// and the equations of motion are
//   delta1'' = -c11 F1 + c12 F_h,   delta2'' = c12 F1 - c22 F_h,   F_h = k_h delta2 + c_h delta2'.
// The paper's reading is the same system with the coefficients given directly:
//   delta1'' = -K1 max(delta1,0)^{3/2} + K2 delta2,  delta2'' = K3 max(delta1,0)^{3/2} - 2 K2
//   delta2,
// started at delta1 = 0, delta1' = v0, delta2 = delta2' = 0 and stopped when delta1 returns to 0.
//
// Contact laws:
//  - kPaperConstants: elastic, F1 proportional to delta^{3/2} with the paper's K1..K3 (about 20
//    microseconds of contact: far stiffer than a real baseball). Forces in newtons are derived
//    with the scene's effective masses (F1 = K1 delta^{3/2} / c11, F_h = 2 K2 delta2 / c22).
//  - kBallPowerLaw (default): core/collision/contact_law.hpp, shared with the flexible impact:
//    the ball's own nonlinear stiffness F = k delta_b^p in series with the bat surface's Hertz
//    stiffness F = K delta_s^{3/2}, K = (4/3) E* sqrt(R*), loaded along that curve and unloaded
//    along F = F_max (delta / delta_max)^q, with q chosen so that the unloading returns e^2 of
//    the loading work: a two-body impact then has a COR of exactly e.
//    Parameters and sources: docs/models.md.
// Integration: core/numerics/event_integrator.hpp (dense-output Dormand-Prince 5(4) from
// Boost.Odeint, event location, a step bound) on a state scaled by the contact scale; the
// events are the maximum compression, the separation and a reload; a failure is reported.
#pragma once

#include <string>

#include "core/collision/contact_law.hpp"
#include "core/summary.hpp"

namespace sweetspot::core {

/// How the contact force depends on the compression.
enum class ContactLaw {
  kBallPowerLaw,    ///< Soft ball (power law + hysteresis) in series with the bat surface's Hertz
                    ///< contact.
  kPaperConstants,  ///< The paper's K1..K3 (elastic 3/2-power law), as corrected in paper-notes.md.
};

/// Stable lower-case name: "ball_power_law", "paper_constants".
const char* ContactLawName(ContactLaw law);

/// The paper's constants (values as printed; units as the corrected equations need them).
struct PaperContactConstants {
  double k1 = 3.46e12;  ///< K1, m^-1/2 s^-2.
  double k2 = 7.69e11;  ///< K2, s^-2.
  double k3 = 2.18e10;  ///< K3, m^-1/2 s^-2.
};

/// The fully resolved contact problem: every coefficient the integrator uses (SI). The
/// scene layer fills it from the ball, bat and swing; it is returned with the result.
struct HertzProblem {
  ContactLaw law = ContactLaw::kBallPowerLaw;  ///< Which force law.
  double approach_speed_mps = 0.0;             ///< v0 = u + v_bat at the impact point, m/s (> 0).
  double ball_speed_mps =
      0.0;  ///< u, the ball's incoming speed, m/s (exit speed = -u + impulse / m).
  double ball_mass_kg = 0.0;    ///< m, kg.
  double c11_per_kg = 0.0;      ///< 1/m + 1/M + b^2/I_cm, 1/kg.
  double c12_per_kg = 0.0;      ///< 1/M + b b_h / I_cm, 1/kg.
  double c22_per_kg = 0.0;      ///< 1/M + b_h^2 / I_cm, 1/kg.
  double ball_stiffness = 0.0;  ///< k in F = k delta^p, N/m^p (kBallPowerLaw).
  double ball_exponent = 1.5;   ///< p (kBallPowerLaw).
  double surface_stiffness =
      0.0;           ///< Bat surface Hertz K = (4/3) E* sqrt(R*), N/m^1.5; 0 = rigid surface.
  double cor = 0.5;  ///< e: the unloading returns e^2 of the loading work (kBallPowerLaw).
  double hands_stiffness_n_m = 0.0;  ///< k_h, N/m (>= 0; 0 = free bat).
  double hands_damping_n_s_m = 0.0;  ///< c_h, N s/m (>= 0).
  PaperContactConstants paper;       ///< K1..K3 (kPaperConstants).

  /// True when the coefficients can be integrated; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// Integrator settings.
struct HertzSolverOptions {
  double relative_tolerance =
      1e-8;  ///< Dopri5 relative (and, on the scaled state, absolute) tolerance (in [1e-13, 1e-2]).
  int max_steps = 20000;  ///< Step bound; reaching it is a reported failure (>= 10).
  bool refine_check =
      true;  ///< Re-solve at tolerance / 16 and report the differences as error estimates.

  /// True when the options are in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// Default hands (grip) stiffness, N/m: an order-of-magnitude grip; with a bat of about 0.9 kg
/// the hands' period (~25 ms) is far longer than the ~1 ms contact, so results barely depend on it.
inline constexpr double kDefaultHandsStiffnessNM = 5.0e4;

/// Largest hands (grip) stiffness HertzOptions accepts, N/m.
inline constexpr double kMaxHandsStiffnessNM = 1e12;
/// Largest hands (grip) damping HertzOptions accepts, N s/m.
inline constexpr double kMaxHandsDampingNSM = 1e12;
/// Largest paper constant K1..K3 HertzOptions accepts (the paper's units).
inline constexpr double kMaxPaperConstant = 1e20;

/// Scene-level settings of the contact model (what a request may choose).
struct HertzOptions {
  ContactLaw law =
      ContactLaw::kBallPowerLaw;  ///< Force law; the paper's constants only on request.
  PaperContactConstants paper;    ///< K1..K3 for ContactLaw::kPaperConstants.
  double hands_stiffness_n_m = kDefaultHandsStiffnessNM;  ///< k_h, N/m (>= 0; 0 = free bat).
  double hands_damping_n_s_m = 0.0;                       ///< c_h, N s/m (>= 0).
  bool bat_surface_compliance =
      true;  ///< Include the bat surface's Hertz stiffness (needs the bat's geometry).
  HertzSolverOptions solver;  ///< Integrator settings.

  /// True when every field is in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// What the contact model knows about one impact.
struct HertzImpact {
  double contact_time_s = 0.0;        ///< From first touch until delta1 returns to 0, s.
  double max_compression_m = 0.0;     ///< Largest delta1, m.
  double peak_force_n = 0.0;          ///< Largest contact force, N.
  double ball_impulse_n_s = 0.0;      ///< Integral of the contact force, N s.
  double hands_impulse_n_s = 0.0;     ///< Integral of the hands' force on the bat during contact
                                      ///< (swing direction positive), N s.
  double separation_speed_mps = 0.0;  ///< -delta1' at separation, m/s.
  double apparent_cor = 0.0;          ///< separation / approach speed (dimensionless).
  double exit_speed_mps = 0.0;        ///< The ball's exit speed, m/s (positive away from the bat).
  double unloading_exponent =
      0.0;        ///< q of the last unloading branch (kBallPowerLaw; 0 otherwise).
  int steps = 0;  ///< Accepted integrator steps (both runs when refining).
  double error_estimate_contact_time_s =
      0.0;  ///< |t(tol) - t(tol/16)|, s (0 without refine_check).
  double error_estimate_exit_speed_mps = 0.0;  ///< |v(tol) - v(tol/16)|, m/s.
  double error_estimate_peak_force_n = 0.0;    ///< |F(tol) - F(tol/16)|, N.
  HertzProblem problem;                        ///< The coefficients used.
  Summary summary;  ///< Backend "odeint:runge_kutta_dopri5", steps, time, termination.
};

/// Integrates one impact. Never throws; failures (step bound, non-finite state, invalid
/// coefficients) are reported in the summary.
HertzImpact SolveHertzImpact(const HertzProblem& problem, const HertzSolverOptions& options);

}  // namespace sweetspot::core
