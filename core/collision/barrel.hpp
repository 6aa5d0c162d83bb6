// barrel: the trampoline effect of a hollow barrel (issue 18 item 2; docs/models.md, "Barrel").
//
// The wall at an impact point is a thin ring of mid-surface radius R = r_out - h/2, thickness h,
// of the bat's material (E, nu, rho), in plane strain (E' = E / (1 - nu^2): a ring cut from a
// long cylinder). Its lowest ovaling ("hoop") mode n = 2 has the inextensional thin-ring
// frequency (A. E. H. Love, A Treatise on the Mathematical Theory of Elasticity, 4th ed., sec.
// 293; W. Soedel, Vibrations of Shells and Plates, ring modes)
//   omega_n^2 = E' h^2 n^2 (n^2 - 1)^2 / (12 rho R^4 (n^2 + 1)),
//   n = 2: omega^2 = 3 E' h^2 / (5 rho R^4).
// A slice of length l of that ring, loaded radially at one point, has for the n = 2 mode
// (w = A cos 2 theta, v = -(A/2) sin 2 theta) the modal mass and stiffness referred to the
// displacement A under the load
//   m_eff  = pi rho h R l (1 + 1/n^2) = (5/4) pi rho h R l,
//   k_ring = pi E' (h^3 / 12) l (n^2 - 1)^2 / R^3 = (3/4) pi E' h^3 l / R^3
//          (= m_eff omega^2, tested).
// l = 2 R sqrt(R/h), twice the axial decay length R sqrt(R/h) of an n = 2 load on a long cylinder
// (the semi-membrane length of shell theory); with it k_ring = (3/2) pi E' h^(5/2) / R^(3/2), the
// h^(5/2) R^(-3/2) scaling of a point-loaded long cylinder. A ring cannot carry load by membrane
// action along the axis, which the barrel does: the barrel's stiffness under the ball is
// k_b = c k_ring with one shell factor c (BarrelOptions::shell_factor), CALIBRATED (not derived):
// c is set so that the `bbcor-33-aluminium` preset, a drop-3 alloy bat whose wall is fixed by its
// 30 oz, measures BBCOR 0.50 (the limit such bats are designed to) under the protocol below.
// A ring finite-element model (straight frame elements, axial + Euler-Bernoulli bending,
// consistent mass) checks the frequency (RingFeHoopFrequencyHz).
//
// The trampoline (the two-spring model of A. M. Nathan, D. A. Russell and L. V. Smith, "The
// physics of the trampoline effect in baseball and softball bats", Engineering of Sport 5
// (2004)): the ball's nonlinear contact (core/collision/contact_law.hpp) in series with the barrel
// spring k_b. At the peak force F the energy of the approach, mu v0^2 / 2 (mu = m M_e / (m + M_e),
// M_e the bat's effective mass at the impact point), is stored as W_c (ball and surface, the
// contact law's loading work) and W_b = F^2 / (2 k_b) (barrel). The ball returns e^2 of its share
// (its COR against a rigid surface), the barrel (1 - barrel_loss) of its own:
//   e_eff^2 = 1 - [(1 - e^2) W_c + barrel_loss W_b] / (W_c + W_b)      (QuasiStaticTrampolineCor).
// This is the quasi-static limit: the wall moves with the force (hoop period short against the
// contact). The dynamic version, the wall's modal mass m_eff on k_b with a dashpot, integrated
// with the contact engine (TrampolineImpact, Dormand-Prince 5(4)), tends to it as m_eff -> 0
// (tested) and gives e_eff = P (1 + m/M_e)/(m v0) - 1 from the ball's impulse P; with the single
// ring mode's mass it depends on the wall's phase when the ball leaves (not monotone in h), so
// the outputs use the quasi-static form. Solid bats have no barrel: nothing here changes them.
#pragma once

#include <string>
#include <vector>

#include "core/bat/bat.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/collision/contact_law.hpp"

namespace sweetspot::core {

/// The n-th inextensional mode frequency of a thin ring in plane strain, Hz: the formula of the
/// file comment (mid-surface radius_m, thickness_m, E, nu, rho; n >= 2).
double RingModeFrequencyHz(double youngs_modulus_pa, double poissons_ratio, double density_kg_m3,
                           double radius_m, double thickness_m, int n = 2);

/// The same ring's n = 2 frequency from a finite-element model: `elements` straight frame
/// elements (axial + Euler-Bernoulli bending, consistent mass, plane strain) around the
/// circle; the lowest elastic eigenvalue of the generalised problem K x = w^2 M x, Hz.
double RingFeHoopFrequencyHz(double youngs_modulus_pa, double poissons_ratio, double density_kg_m3,
                             double radius_m, double thickness_m, int elements = 64);

/// The calibrated shell factor c (the file comment): 6.98 puts the `bbcor-33-aluminium` preset at
/// BBCOR 0.500 exactly; rounded to 7 (BarrelTest re-derives it).
inline constexpr double kBarrelShellFactor = 7.0;

/// Settings of the barrel model.
struct BarrelOptions {
  /// Fraction of the energy stored in the wall that it does not return (its own loss over a
  /// half cycle), in [0, 1). Metal shells ring for many cycles: small.
  double barrel_loss = 0.01;
  /// Axial length of the ring slice in the hoop mode, m; 0 = the default 2 R sqrt(R / h).
  double effective_length_m = 0.0;
  /// c in k_b = c k_ring: the shell's stiffening over the ring slice (calibrated, see the file
  /// comment), > 0.
  double shell_factor = kBarrelShellFactor;
  /// Dopri5 tolerance on the scaled state (dimensionless), in [1e-13, 1e-2].
  double relative_tolerance = 1e-8;
  int max_steps = 200000;  ///< Accepted integrator steps per impact (>= 10).

  /// True when every field is in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "barrel.field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// The wall at one point along a hollow bat.
struct BarrelWall {
  bool hollow = false;              ///< False for a solid bat (or outside it): nothing else is set.
  double outer_radius_m = 0.0;      ///< Outer radius there, m.
  double thickness_m = 0.0;         ///< h, m.
  double mid_radius_m = 0.0;        ///< R = outer - h/2, m.
  double effective_length_m = 0.0;  ///< l, m.
  double hoop_frequency_hz = 0.0;   ///< n = 2 ring frequency, Hz.
  double modal_mass_kg = 0.0;       ///< m_eff = (5/4) pi rho h R l, kg.
  double ring_stiffness_n_m = 0.0;  ///< k_ring = (3/4) pi E' h^3 l / R^3 = m_eff omega^2, N/m.
  double stiffness_n_m = 0.0;       ///< k_b = c k_ring, N/m.
  double barrel_loss = 0.0;         ///< The options' barrel_loss (dimensionless).
  double damping_ratio = 0.0;       ///< zeta from barrel_loss (dimensionless).
};

/// The wall of `bat` at `x_m` from the knob (closed forms of the file comment).
BarrelWall BarrelWallAt(const Bat& bat, double x_m, const BarrelOptions& options = {});

/// One impact of the trampoline model.
struct TrampolineProblem {
  double ball_mass_kg = 0.145;         ///< m, kg (> 0).
  double ball_stiffness = 4.0e7;       ///< k in F = k delta^p, N/m^p (> 0).
  double ball_exponent = 1.5;          ///< p, in [1, 3].
  double surface_stiffness = 0.0;      ///< Hertz K of the bat's surface, N/m^1.5 (0 = rigid).
  double ball_cor = 0.5;               ///< e of the ball against a rigid surface, in (0, 1].
  double bat_effective_mass_kg = 0.0;  ///< M_e at the impact point, kg (> modal mass).
  double approach_speed_mps = 0.0;     ///< v0, m/s (> 0).
  double barrel_stiffness_n_m = 0.0;   ///< k_b, N/m (> 0).
  double barrel_modal_mass_kg = 0.0;   ///< m_eff, kg (> 0).
  double barrel_damping_ratio = 0.0;   ///< zeta (>= 0; dynamic model).
  double barrel_loss = 0.0;  ///< Loss of the barrel's energy, [0, 1) (quasi-static model).
};

/// What the trampoline impact gives.
struct TrampolineResult {
  bool ok = false;                       ///< False: the integration failed (message).
  std::string message;                   ///< Why it failed.
  double effective_cor = 0.0;            ///< e_eff (dimensionless).
  double ball_impulse_n_s = 0.0;         ///< P, N s.
  double contact_time_s = 0.0;           ///< s.
  double peak_force_n = 0.0;             ///< N.
  double max_barrel_deflection_m = 0.0;  ///< Largest wall deflection, m.
  double barrel_energy_fraction = 0.0;   ///< Wall's share of the stored energy at peak force.
  int steps = 0;                         ///< Accepted integrator steps.
};

/// Integrates one trampoline impact (never throws; a failure is ok = false).
TrampolineResult TrampolineImpact(const TrampolineProblem& problem,
                                  const BarrelOptions& options = {});

/// The quasi-static (massless wall) trampoline: e_eff^2 = 1 - [(1 - e^2) W_c + loss W_b] /
/// (W_c + W_b), the works at the peak force where W_c + W_b = mu v0^2 / 2, mu = m M_e/(m + M_e)
/// (the peak force by bisection to 1e-15 relative). Also the shares and the force.
TrampolineResult QuasiStaticTrampoline(const TrampolineProblem& problem);
/// QuasiStaticTrampoline(problem).effective_cor.
double QuasiStaticTrampolineCor(const TrampolineProblem& problem);

/// The NCAA BBCOR protocol as this model runs it (docs/models.md, "BBCOR").
struct BbcorProtocol {
  std::string ball = "ncaa-nfhs";           ///< The catalogue ball fired.
  double ball_speed_mps = 136.0 * 0.44704;  ///< Ball speed onto the bat at rest, m/s (136 mph).
  double pivot_from_knob_m = 0.1524;        ///< The bat's pivot, m from the knob (6 in).
  /// The impact point, m from the barrel end (6 in; see docs/models.md, "BBCOR": the lab locates
  /// the sweet spot by testing, which a model without bending losses cannot do).
  double impact_from_tip_m = 0.1524;
  /// The BBCOR scan's range (ComputeBbcorScan, bbcor_scan.hpp), m from the barrel end: this
  /// service's choice (no source gives one), 4.0 to 8.0 in every 0.5 in. first <= last, step > 0,
  /// at most 201 points.
  double scan_first_from_tip_m = 4.0 * 0.0254;
  double scan_last_from_tip_m = 8.0 * 0.0254;  ///< m from the barrel end.
  double scan_step_m = 0.5 * 0.0254;           ///< m.
};

/// The method of the certified BBCOR (CertifiedBbcorOf, bbcor_scan.hpp): the flexible scan's
/// maximum over the barrel.
inline constexpr const char* kCertifiedBbcorMethod = "flexible_scan_max";

/// The BBCOR of a bat by the protocol: ComputeBbcor's fixed-point estimate (method "rigid" or
/// "trampoline_quasi_static"), or the certified value (method "flexible_scan_max",
/// CertifiedBbcorOf in bbcor_scan.hpp) with that estimate beside it.
struct BbcorResult {
  bool ok = false;                    ///< False: a model failure or invalid input (message).
  std::string message;                ///< Why not.
  /// BBCOR at the impact point: the fixed point's (estimate) or the scan's maximum (certified).
  double value = 0.0;
  std::string ball;                   ///< Ball used.
  double ball_speed_mps = 0.0;        ///< m/s.
  double ball_cor = 0.0;              ///< The ball's COR against solid wood at that speed.
  double impact_from_knob_m = 0.0;    ///< The impact point, m from the knob.
  double pivot_from_knob_m = 0.0;     ///< m.
  std::string method;                 ///< "rigid" (solid bat) or "trampoline_quasi_static".
  double hoop_frequency_hz = 0.0;     ///< At the impact point (0 for a solid bat), Hz.
  double barrel_stiffness_n_m = 0.0;  ///< k_b at the impact point (0 for a solid bat), N/m.
  // Certified only (method "flexible_scan_max"):
  double impact_from_tip_m = 0.0;     ///< The maximum's location, m from the barrel end.
  std::string refinement;             ///< The scan's ("polished" or "none").
  double error_estimate = 0.0;        ///< The scan's impact error estimate (dimensionless).
  std::vector<std::string> warnings;  ///< The scan's warnings.
  double estimate_value = 0.0;        ///< ComputeBbcor's fixed-point value (dimensionless).
  double estimate_from_tip_m = 0.0;   ///< Its point, m from the barrel end.
  std::string estimate_method;        ///< Its method ("rigid", "trampoline_quasi_static").
  double estimate_error = 0.0;        ///< estimate_value - value (dimensionless).
  double solve_time_s = 0.0;          ///< The scan's wall time, s.
};

/// The FAST ESTIMATE of the BBCOR of `bat` by `protocol` (the certified value is the flexible
/// scan's maximum, CertifiedBbcorOf in bbcor_scan.hpp; docs/validation.md gives this estimate's
/// measured error against it). A solid bat gives the ball's COR at the protocol's speed (a
/// rigid bat's BBCOR is e by construction); a hollow one the trampoline's e_eff for the bat
/// pivoted at the protocol's pivot (M_e = I_pivot / z^2) at the protocol's impact point.
/// `rigid_body_properties`: the bat's mass properties under InertiaModel::kRigidBody when the
/// caller has computed them (a scene's, once per request); null: computed here.
BbcorResult ComputeBbcor(const Bat& bat, const BbcorProtocol& protocol = {},
                         const BarrelOptions& options = {},
                         const MassProperties* rigid_body_properties = nullptr);

/// The effective COR (quasi-static trampoline) of a hollow bat at `x_m` for a ball of
/// `ball_mass_kg`, `ball_radius_m`, `ball_stiffness`, `ball_exponent`, COR `ball_cor`,
/// approaching at approach_speed_mps, the bat (of `mass_properties`) free
/// (M_e = 1/(1/M + b^2/I_cm)); `ball_cor` itself
/// (exactly) for a solid bat.
TrampolineResult EffectiveCorAt(const Bat& bat, const MassProperties& mass_properties, double x_m,
                                double ball_mass_kg, double ball_radius_m, double ball_stiffness,
                                double ball_exponent, double ball_cor, double approach_speed_mps,
                                const BarrelOptions& options = {});

/// The effective COR at one point along the barrel.
struct BarrelCorPoint {
  double position_from_knob_m = 0.0;  ///< m from the knob.
  double approach_speed_mps = 0.0;    ///< Normal impact speed there, m/s.
  double ball_cor = 0.0;              ///< The ball's COR against a rigid surface there.
  double effective_cor = 0.0;         ///< e_eff (the ball's COR for a solid bat).
};

/// The `barrel` output of a scene.
struct BarrelOutput {
  bool hollow = false;                  ///< False: a solid bat (no hoop mode; COR unchanged).
  double position_from_knob_m = 0.0;    ///< The reference point (6 in from the tip), m.
  BarrelWall wall;                      ///< The wall there (hollow only).
  double shell_factor = 0.0;            ///< c used (hollow only).
  double effective_cor = 0.0;           ///< e_eff at the reference point.
  double barrel_energy_fraction = 0.0;  ///< The barrel's share of the stored energy there.
  std::vector<BarrelCorPoint> effective_cor_curve;  ///< e_eff every inch over the last 10 in.
  std::string method;                               ///< "trampoline_quasi_static" or "solid".
};

}  // namespace sweetspot::core
