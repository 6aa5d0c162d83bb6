// flexible: the ball against the free-free flexible bat, by modal superposition.
//
// Assumptions (docs/models.md, "Flexible collision"):
// - As in hertz_contact.hpp the impact lasts about a millisecond: in the frame moving with the
//   bat's pre-impact motion the bat is at rest and undeformed, the ball arrives at the impact
//   point s at v0 = u + omega (s - pivot), perpendicular to the axis; the swing's rotation
//   during the impact is neglected, and so are the hands (free-free: a grip of ~5e4 N/m has a
//   period of ~25 ms, far longer than the contact).
// - The bat's transverse displacement is w(x, t) = sum_k q_k(t) phi_k(x) over the two
//   rigid-body modes (translation, rotation about the centroid) and the flexible modes of
//   core/flexible/modes.hpp with f_k <= cutoff_factor / t_c (t_c: the contact time of a rigid
//   bat, estimated in closed form), all mass-normalised:
//     m z'' = -F,   q_k'' + omega_k^2 q_k = phi_k(s) F,   delta = z - w(s, t),
//   F = F(delta) the contact law of contact_law.hpp (hertz's ball_power_law) in series with the
//   static compliance of the modes left out (residual flexibility, optional): the ball's
//   k delta_b^p in series with the bat surface's Hertz contact on loading, unloading along
//   F_max (delta / delta_max)^q with q set so the unloading returns e^2 of the loading work;
//   a rise above delta_max reloads along the virgin curve. Undamped otherwise.
// - Integration: core/numerics/event_integrator.hpp (dense-output Dormand-Prince 5(4) from
//   Boost.Odeint) on a scaled state; events (maximum compression, reload, separation) located
//   on the dense output; the step count is bounded over all contacts. After a separation the motion
//   is free (exact: ballistic ball, harmonic modes); the gap is scanned (32 samples per period of
//   the highest mode) for a further contact until the bat's rigid-body recoil has outrun the
//   vibration amplitude; a new contact starts on the virgin curve.
// - Sting at the hands h: (1) hands_vibration_energy_j = sum_k E_k G_k, G_k the share of mode
//   k's mass-normalised kinetic energy in the grip segment [h - l/2, h + l/2] (the vibration
//   energy residing where the hands are; modes uncorrelated on average); (2) the peak shear
//   force and bending moment in the section at h over the contact and the following
//   sting window, from the inertia of the knob-side segment [0, h] (exact for the modes used,
//   and converging fast with their number: the mode-acceleration form).
#pragma once

#include <string>
#include <vector>

#include "core/bat/bat.hpp"
#include "core/collision/contact_law.hpp"
#include "core/flexible/modes.hpp"
#include "core/summary.hpp"

namespace sweetspot::core {

/// Settings of the flexible collision.
struct FlexibleImpactOptions {
  int max_modes = 12;  ///< Flexible modes computed for impacts (the cutoff picks), in [1, 50].
  double frequency_tolerance = 1e-3;  ///< Their relative frequency tolerance, in [1e-9, 0.1].
  double cutoff_factor = 10.0;        ///< Use modes with f <= cutoff_factor / t_c, in [1, 1000].
  double relative_tolerance = 1e-8;   ///< Dopri5 tolerance on the scaled state, in [1e-13, 1e-2].
  int max_steps = 200000;             ///< Integrator step bound (reaching it is a failure), >= 10.
  int max_contacts = 10;              ///< Contacts followed (then a warning), in [1, 1000].
  /// Put the static compliance of the modes left out (residual flexibility: the FE static
  /// flexibility at the impact point under inertia relief, minus the modes used) in series with
  /// the contact. The exit speed then converges much faster with the number of modes.
  bool static_correction = true;
  /// Repeat at tolerance / 16 and with half the cutoff; report the differences as errors.
  bool refine_check = true;
  double hands_grip_length_m = 0.15;  ///< Grip segment centred at the hands, m, in [0, 10].
  /// Window after the contact for the hands' peak forces, s (0 = one period of the first
  /// bending mode), in [0, 1].
  double sting_window_s = 0.0;
  /// Compute the hands' peak shear force and bending moment (sampled on every step and over
  /// the sting window). Off for the searches that read only the exit speed or the hands'
  /// vibration energy: the peaks are then reported as 0 and the impact costs ~30 % less.
  bool hands_loads = true;

  /// True when every field is in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "flexible.field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// One impact's inputs besides the bat and its modes (SI).
struct FlexibleImpactInputs {
  double impact_from_knob_m = 0.0;    ///< s, m from the knob.
  double hands_from_knob_m = 0.1524;  ///< h, m from the knob.
  double ball_mass_kg = 0.145;        ///< m, kg (> 0).
  double ball_speed_mps = 27.7;       ///< u, incoming, m/s (>= 0).
  double approach_speed_mps = 0.0;    ///< v0 = u + bat speed at s, m/s (> 0).
  double ball_stiffness = 4.0e7;      ///< k in F = k delta^p, N/m^p (> 0).
  double ball_exponent = 1.5;         ///< p, in [1, 3].
  double surface_stiffness = 0.0;     ///< Bat surface Hertz K, N/m^1.5 (0 = rigid surface).
  double cor = 0.5;                   ///< e in [0, 1].
  /// Compliance of a hollow barrel's wall at s, 1/k_b (BarrelWallAt), m/N (>= 0; 0 = a solid
  /// surface, the behaviour without it bit for bit). An elastic spring in series with the
  /// contact, as the residual static compliance is: the ball's hysteresis acts on the ball's
  /// compression only and the wall returns all its energy (BarrelOptions::barrel_loss is not
  /// applied here; for cor = 0 the wall's stored energy is counted with the released energy).
  double barrel_compliance_m_n = 0.0;

  /// True when the inputs can be integrated; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// What the flexible model knows about one impact.
struct FlexibleImpactResult {
  double exit_speed_mps = 0.0;        ///< The ball's exit speed, m/s (positive away from the bat).
  double rigid_exit_speed_mps = 0.0;  ///< The free rigid bat's (same e, same mass properties), m/s.
  double contact_time_s = 0.0;        ///< First touch to last separation, s.
  double contact_time_estimate_s = 0.0;  ///< Rigid-bat estimate that sets the cutoff, s.
  /// Static compliance of the modes left out at the impact point, m/N (0 without correction;
  /// the inputs' barrel_compliance_m_n, in series with it, is not included).
  double residual_compliance_m_n = 0.0;
  int contacts = 0;                  ///< Separate contacts (1 = a single one).
  double peak_force_n = 0.0;         ///< Largest contact force, N.
  double max_compression_m = 0.0;    ///< Largest contact compression, m.
  double ball_impulse_n_s = 0.0;     ///< Integral of the contact force, N s.
  double initial_energy_j = 0.0;     ///< m v0^2 / 2 (bat frame), J.
  double ball_energy_j = 0.0;        ///< The ball's kinetic energy after (bat frame), J.
  double rigid_body_energy_j = 0.0;  ///< The bat's rigid-body kinetic energy after, J.
  /// Energy left in the bending modes, J (for e = 0 also the static energy of the modes left
  /// out, released when the contact ends abruptly).
  double vibration_energy_j = 0.0;
  double contact_loss_j = 0.0;            ///< (1 - e^2) x loading work, summed over contacts, J.
  double contact_work_j = 0.0;            ///< Integral of F d(delta) (the same, integrated), J.
  double energy_balance_error_j = 0.0;    ///< initial - (ball + rigid + vibration + loss), J.
  double hands_vibration_energy_j = 0.0;  ///< Vibration energy in the grip segment, J.
  double hands_peak_shear_force_n = 0.0;  ///< Peak |shear force| in the section at the hands, N.
  double hands_peak_bending_moment_n_m = 0.0;   ///< Peak |bending moment| there, N m.
  std::vector<double> modal_energies_j;         ///< Energy of each flexible mode used, J.
  std::vector<double> mode_frequencies_hz;      ///< Frequencies of the modes used, Hz.
  int modes_used = 0;                           ///< Flexible modes in the superposition.
  double cutoff_hz = 0.0;                       ///< cutoff_factor / contact_time_estimate_s, Hz.
  int elements = 0;                             ///< Elements of the beam mesh.
  BeamTheory theory = BeamTheory::kTimoshenko;  ///< The beam theory.
  int steps = 0;                                ///< Accepted integrator steps (all runs).
  /// Integration + truncation, m/s (without the refinement check: the integration tolerance
  /// times the speeds, relative_tolerance (u + |v|)).
  double error_estimate_exit_speed_mps = 0.0;
  /// Integration + truncation, J (without the refinement check: relative_tolerance times it).
  double error_estimate_vibration_energy_j = 0.0;
  /// Integration + truncation, J (without the refinement check: relative_tolerance times it).
  double error_estimate_hands_energy_j = 0.0;
  double truncation_error_exit_speed_mps = 0.0;   ///< |v(cutoff) - v(cutoff / 2)|, m/s.
  double integration_error_exit_speed_mps = 0.0;  ///< |v(tol) - v(tol / 16)|, m/s.
  Summary summary;  ///< Backend "odeint:runge_kutta_dopri5", steps, time, termination.
};

/// Integrates one impact on `bat` with its `modes` (from ComputeBatModes on that bat). Never
/// throws; failures (step bound, non-finite state, invalid inputs) are in the summary.
FlexibleImpactResult SolveFlexibleImpact(const Bat& bat, const BatModes& modes,
                                         const FlexibleImpactInputs& inputs,
                                         const FlexibleImpactOptions& options);

}  // namespace sweetspot::core
