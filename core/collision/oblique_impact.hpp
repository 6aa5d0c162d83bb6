// oblique_impact: the bat-ball impact off the line of centres (issue 34, section 2): what the
// ball does after the bat hits it below (or above) its centre: exit speed, launch angle and
// spin, from the impulses on both bodies.
//
// Geometry (the vertical plane of the swing; x toward the pitcher, i.e. toward the field, y up;
// the bat's long axis is perpendicular to the plane). Just before impact
//   ball:  v_ball = u (-cos delta, -sin delta)   (speed u, descent angle delta, + downward),
//          spin omega_z = -s_in                  (s_in = the pitch's backspin, + backspin: a
//                                                 pitch's backspin turns clockwise in this view),
//   bat:   v_bat  = V (cos A, sin A)             (speed V of the bat's axis at the impact point,
//                                                 attack angle A of its path, + upward).
// The relative velocity is w = v_ball - v_bat; e = -w/|w| is the direction the ball approaches
// from, seen from the bat, and p = e turned +90 degrees ("up" across the approach line). The
// undercut D is the impact parameter: the distance of the ball's centre from the line through
// the bat's axis along w, measured along p (for a level approach, the height of the ball's
// centre above the bat's axis; D > 0 gives backspin, D < 0 topspin). At contact the line of
// centres (the normal n, from the bat's axis to the ball's centre) is tilted from e by psi,
//   sin psi = D / (R + r),        R: ball radius, r: the bat's local radius,
// n = cos psi e + sin psi p, and the tangent t = n turned +90 degrees.
//
// Impulses (instantaneous impact; gravity and the hands neglected during it, as in every
// collision model here). The ball (mass m, moment of inertia alpha m R^2) receives J_n n + J_t t
// at its contact point -R n; the bat receives the opposite at its surface point r n. The bat's
// response at the contact point is that of a rigid body: 1/M_n = the normal model's inverse
// effective mass (1/M + b^2/I_cm for the free bat, z^2/J for the pivoted one), and along t
//   1/M_t = 1/M_n + r^2 / I_roll
// (translation and rocking of an axisymmetric bat respond alike to an impulse across the axis;
// the tangential impulse also spins the bat about its long axis, I_roll its moment of inertia
// about that axis). The normal and tangential responses are uncoupled (no cross term for an
// axisymmetric bat; the small velocity along the bat's axis is left out), so:
//  - Normal part: the approach speed along the line of centres v_n = |w| cos psi goes to the
//    scene's normal collision model, which answers the normal impulse J_n: the pair (M_n, e) in
//    closed form, J_n = (1 + e) v_n / (1/m + 1/M_n), or the model's own answer for that approach
//    speed (NormalImpactLaw::ball_normal_impulse_n_s: hertz, flexible, or any law of the speed).
//    With D = 0, no spin and collinear paths this is exactly the normal model's impact.
//  - Tangential part: the slip of the ball's contact point over the bat's surface,
//    s = w.t - R omega_z, changes by J_t / mu_t with 1/mu_t = (1 + alpha)/(alpha m) + 1/M_t.
//    The law is Cross's tangential ("horizontal") coefficient of restitution e_x with a
//    Coulomb bound (R. Cross, Am. J. Phys. 70, 482 and 1093 (2002); used for the baseball-bat
//    impact by Cross & Nathan, Am. J. Phys. 74, 896 (2006)):
//      gripping:  s' = -e_x s             J_t = -(1 + e_x) mu_t s,
//      sliding:   |J_t| <= mu_f J_n       J_t = -sign(s) mu_f J_n when the grip would need more.
//    e_x = 0 is rolling at separation, e_x > 0 the ball's tangential compliance giving back
//    part of the stored shear (the ball leaves spinning faster than rolling), mu_f = 0 a
//    frictionless contact. |J_t| <= (1 + e_x) mu_t |s| keeps s' in [-e_x s, s]: the tangential
//    work is never positive, and the normal part's is not either for e <= 1, so no energy is
//    created whatever the parameters.
// Afterwards v_ball' = v_ball + (J_n n + J_t t)/m, omega_z' = omega_z - J_t/(alpha m R); the
// bat's axis at the impact point changes velocity by -(J_n n + J_t t)/M_n and its roll rate by
// -r J_t / I_roll. The ball's angular momentum about the contact point, alpha m R^2 omega_z +
// m R (v.t), is conserved (the impulse acts there).
//
// Parameters (docs/models.md, "Oblique impact", says the same with the search record):
//  - e_x = 0.4 by default. Inferred, not read from a table: the stored copies of the papers
//    reachable here hold their abstracts and introductions only. Nathan, Cantakos, Kesman,
//    Mathew, Lukash, "Spin of a batted baseball", Procedia Eng. 34, 182 (2012): on a fixed
//    3-in wood cylinder (M_t infinite) the scattered spin is "nearly independent of the incident
//    spin"; in this law d(omega')/d(omega) = (alpha - e_x)/(1 + alpha), zero at e_x = alpha = 0.4.
//    Kensrud, Nathan, Smith, "Oblique collisions of baseballs and softballs with a bat",
//    Am. J. Phys. (2017) (arXiv 1610.03464): spin "up to 40 % greater than would be
//    obtained by rolling contact"; in this law the spin of a spinless ball is (1 + e_x) times
//    rolling's, so e_x <= 0.4. The spin scales with 1 + e_x: e_x = 0 gives 1/1.4 of the default.
//    Against the Statcast spin-launch relation of Nathan's trajectory calculator (backspin ~
//    -763 + 120 LA rpm) the default gives about 1.5x the game spin at fly-ball launch angles,
//    e_x = 0.2 within about 15 % (docs/validation.md): the value for distance is the lead's call.
//  - mu_f = 0.5 by default: no measured baseball-on-wood value was found. Sawicki, Hubbard,
//    Stronge, Am. J. Phys. 71, 1152 (2003) (abstract): "post-impact conditions are found to be
//    independent of the ball-bat coefficient of friction"; here too the grip needs
//    |J_t| / J_n ~ 0.3 tan psi with the defaults, so mu_f binds only beyond psi ~ 60 degrees or for
//    a large incoming spin.
//  - alpha = 0.4 (a uniform sphere) by default: a baseball's layered core is close to uniform;
//    no measured value was found (flight-notes.md uses 0.4 as well).
//
// Cost: a closed form (a few dozen flops, two sin/cos pairs, sqrt, asin, atan2): ~120 ns of CPU
// with its Summary (bench/core_collision.cpp, BM_ObliqueImpact).
//
// ---------------------------------------------------------------------------------------------
// Interface note for OptimalUndercutForDistance (the later "distance_sweet_spot" output: impact
// position x undercut for the longest carry). Not implemented here; what it can rely on:
//  - The adapter from a scene (issue 34's fields): ball.speed_mps -> ball_speed_mps,
//    ball.descent_angle_deg -> descent_angle_deg, ball.spin_rpm -> ball_backspin_rad_s
//    (RpmToRadPerSecond), swing.attack_angle_deg -> attack_angle_deg, contact.undercut_m ->
//    undercut_m; per impact position x: bat_speed_mps = omega (x - pivot) (the resolved swing),
//    bat_radius_m = Bat::RadiusAtM(x), normal = the model's law at x; once per bat:
//    bat_roll_moi_kg_m2 = BatRollMoiKgM2(bat); the ball's mass and radius from its preset.
//  - SolveObliqueImpact is pure and re-entrant (value in, value out, never throws), so a grid or
//    a search may call it from many threads.
//  - Over the undercut it is continuous and piecewise smooth: kinks only where the tangential
//    regime changes (ObliqueImpactResult::regime), which for the defaults happens only at very
//    large |D|; the search range is |D| < R + r (MaxUndercutM), in practice
//    |D| <= 0.9 (R + r) (beyond that the ball barely touches the bat).
//  - Per impact position, the normal law is what changes with the position: for rigid_pivot and
//    free_bat build NormalImpactLaw{M_n(x), e(x)} once per position (closed form). For hertz and
//    flexible the normal impulse depends on v_n = |w| cos psi, which changes with the undercut:
//    call the ODE model through ball_normal_impulse_n_s per (x, D), or, cheaper, tabulate
//    J_n(v_n) at a few speeds per position (it is smooth in v_n) and interpolate.
//  - The ball leaves with (exit_speed_mps, launch_angle_deg, backspin_rpm): exactly the flight
//    model's launch inputs; sidespin is 0 in this 2-D model (a bat swung level in the plane).
//  - A suggested shape: `UndercutOptimum OptimalUndercutForDistance(const ObliqueImpactInputs&
//    base, Carry carry_m, double min_undercut_m, double max_undercut_m, ...)`, Carry a callable
//    (exit speed, launch angle, backspin) -> carry in metres; a bracketing search (Brent) in D
//    after a coarse scan, since the carry is unimodal in D only for typical inputs.
#pragma once

#include <functional>
#include <limits>
#include <string>

#include "core/bat/bat.hpp"
#include "core/summary.hpp"
#include "core/units.hpp"

namespace sweetspot::core {

/// Radians per second in one revolution per minute.
inline constexpr double kRadPerSecondPerRpm = 2.0 * kPi / 60.0;
/// rpm to rad/s.
constexpr double RpmToRadPerSecond(double rpm) { return rpm * kRadPerSecondPerRpm; }
/// rad/s to rpm.
constexpr double RadPerSecondToRpm(double rad_s) { return rad_s / kRadPerSecondPerRpm; }

/// The default tangential COR e_x (header comment: inferred from Nathan et al. 2012 and
/// Kensrud et al. 2017).
inline constexpr double kDefaultTangentialCor = 0.4;
/// The default Coulomb friction coefficient of the ball on the bat (no measured value found).
inline constexpr double kDefaultBallBatFriction = 0.5;
/// I / (m R^2) of a uniform sphere: the default for a baseball.
inline constexpr double kUniformSphereGyrationRatio = 0.4;
/// Default moment of inertia of a solid wood bat about its long axis, kg m^2: between the
/// presets' BatRollMoiKgM2, 3.6e-4 (wood-34-ash) and 4.7e-4 (paper-wood). The scene should pass
/// its bat's own (BatRollMoiKgM2).
inline constexpr double kDefaultBatRollMoiKgM2 = 4.0e-4;

/// A bat's moment of inertia about its long axis, kg m^2: its material's density times the
/// integral of pi (r_o^4 - r_i^4) / 2 along the profile (exact per segment: the mass properties'
/// own cross-section integrals, core/bat/geometry_integrals.hpp), plus a fill's excess
/// density times pi r_f^4 depth / 2. What ObliqueImpactInputs::bat_roll_moi_kg_m2 wants; the
/// bat must be valid (Bat::Validate).
double BatRollMoiKgM2(const Bat& bat);

/// How the tangential impulse came out.
enum class TangentialRegime {
  kNoSlip,           ///< The contact point did not slip before impact (s = 0): no tangential impulse.
  kGripped,          ///< The ball gripped: s' = -e_x s (the tangential COR law).
  kFrictionLimited,  ///< The slip passed zero but the grip needed more than mu_f J_n: J_t at
                     ///< the friction bound.
  kSlidThroughout,   ///< The ball slid throughout (mu_f J_n too small to stop the slip).
};

/// Stable lower-case name: "no_slip", "gripped", "friction_limited", "slid_throughout".
const char* TangentialRegimeName(TangentialRegime regime);

/// The tangential law: Cross's tangential COR with a Coulomb bound.
struct TangentialLaw {
  /// e_x: the slip of the contact point reverses to -e_x times its value when the ball grips
  /// (0 = rolling at separation), in [0, 1].
  double tangential_cor = kDefaultTangentialCor;
  /// mu_f: |J_t| <= mu_f J_n (0 = frictionless), in [0, inf] (inf = the grip is never limited).
  double friction_coefficient = kDefaultBallBatFriction;

  /// True when both are in range; otherwise the refusal ("tangential.tangential_cor = 1.5:
  /// must be in [0, 1]").
  bool Validate(Refusal* refusal) const;
};

/// The normal part, from the scene's collision model.
struct NormalImpactLaw {
  /// M_n: the bat's effective mass at the impact point along the line of centres, kg (> 0; inf =
  /// an immovable bat, as the fixed cylinder of Nathan et al. 2012). free_bat: 1 / (1/M +
  /// b^2/I_cm); rigid_pivot: J_pivot / z^2. Sets the bat's recoil (and the tangential effective
  /// mass), and the normal impulse when `ball_normal_impulse_n_s` is empty.
  double bat_effective_mass_kg = std::numeric_limits<double>::infinity();
  /// e: the normal COR at the impact point, in [0, 1] (used when `ball_normal_impulse_n_s` is
  /// empty): J_n = (1 + e) v_n / (1/m + 1/M_n).
  double cor = 0.5;
  /// Optional: the normal model's own answer, the impulse on the ball (N s) for a normal
  /// approach speed v_n (m/s, > 0) with the bat at rest at the impact point: what every model
  /// here reports as `ball_impulse_n_s` when fired at v_n (hertz, flexible: run at that
  /// approach speed). Must return a finite J_n in [0, 2 v_n / (1/m + 1/M_n)] (e in [0, 1]).
  std::function<double(double)> ball_normal_impulse_n_s;

  /// True when in range; otherwise the refusal ("normal.cor = 2: must be in [0, 1]").
  bool Validate(Refusal* refusal) const;
};

/// Everything the oblique impact needs (SI; angles in degrees as named).
struct ObliqueImpactInputs {
  double ball_speed_mps = 40.2336;  ///< u, the pitch's speed at the plate, m/s (>= 0; 90 mph).
  double descent_angle_deg = 6.0;   ///< delta, the pitch's path below horizontal, deg (+ down),
                                    ///< in [-89, 89].
  double ball_backspin_rad_s = 0.0;  ///< s_in, the pitch's spin, rad/s (+ backspin, - topspin);
                                     ///< RpmToRadPerSecond converts.
  double bat_speed_mps = 31.2928;    ///< V, the speed of the bat's axis at the impact point, m/s
                                     ///< (>= 0; 70 mph).
  double attack_angle_deg = 10.0;    ///< A, the bat path above horizontal, deg (+ up), in [-89, 89].
  double undercut_m = 0.0;  ///< D, the ball's centre above the bat's axis across the approach
                            ///< line, m (+ backspin), |D| < ball radius + bat radius.
  double bat_radius_m = 0.0334;  ///< r, the bat's radius at the impact point, m (> 0; 2.63 in).
  double ball_mass_kg = 0.145;   ///< m, kg (> 0).
  double ball_radius_m = 0.0366;  ///< R, m (> 0; 9.125 in circumference: 0.03689, rounded).
  double ball_gyration_ratio =
      kUniformSphereGyrationRatio;  ///< alpha = I / (m R^2), in (0, 2/3] (2/3: a thin shell).
  double bat_roll_moi_kg_m2 = kDefaultBatRollMoiKgM2;  ///< I_roll, the bat's moment of inertia
                                                       ///< about its long axis, kg m^2 (> 0;
                                                       ///< inf = the bat does not roll).
  NormalImpactLaw normal;    ///< The normal part (the scene's collision model).
  TangentialLaw tangential;  ///< The tangential law.

  /// True when every field is in range; otherwise the refusal in *refusal (if non-null):
  /// "undercut_m = 0.08: must be in (-0.0700, 0.0700) ...".
  bool Validate(Refusal* refusal) const;
};

/// The largest |undercut| at which the ball still touches the bat: R + r, m.
inline double MaxUndercutM(const ObliqueImpactInputs& in) {
  return in.ball_radius_m + in.bat_radius_m;
}

/// What the oblique impact gives.
struct ObliqueImpactResult {
  double exit_speed_mps = 0.0;    ///< The ball's speed after impact, m/s.
  double launch_angle_deg = 0.0;  ///< Its direction above horizontal, deg (atan2: near +-180
                                  ///< for a ball driven back toward the catcher).
  double backspin_rpm = 0.0;      ///< omega_z': + backspin for a ball leaving toward the field
                                  ///< (top of the ball turning back), rpm.
  double backspin_rad_s = 0.0;    ///< The same, rad/s.
  double velocity_x_mps = 0.0;    ///< The ball's velocity toward the field after impact, m/s.
  double velocity_y_mps = 0.0;    ///< The ball's upward velocity after impact, m/s.
  double normal_impulse_n_s = 0.0;      ///< J_n, on the ball along n (>= 0), N s.
  double tangential_impulse_n_s = 0.0;  ///< J_t, on the ball along t, N s (< 0 for an undercut).
  double incidence_angle_deg = 0.0;     ///< psi, the line of centres from the approach line, deg.
  double relative_speed_mps = 0.0;      ///< |w|, the ball's speed seen from the bat, m/s.
  double normal_approach_speed_mps = 0.0;  ///< v_n = |w| cos psi, m/s: what the normal model saw.
  double normal_cor = 0.0;  ///< The normal separation over approach speed that J_n implies.
  double slip_before_mps = 0.0;  ///< s, the contact point's slip along t before, m/s.
  double slip_after_mps = 0.0;   ///< s', after, m/s (0 = rolling at separation).
  TangentialRegime regime = TangentialRegime::kNoSlip;  ///< How J_t came out.
  bool slid_throughout = false;  ///< regime == kSlidThroughout: the ball never gripped.
  double bat_normal_effective_mass_kg = 0.0;      ///< M_n used, kg.
  double bat_tangential_effective_mass_kg = 0.0;  ///< M_t = 1 / (1/M_n + r^2/I_roll), kg.
  double bat_velocity_change_x_mps = 0.0;  ///< The bat's axis at the impact point, m/s.
  double bat_velocity_change_y_mps = 0.0;  ///< The same, upward, m/s.
  double bat_roll_rate_change_rad_s = 0.0;  ///< The bat's spin about its long axis, rad/s (+
                                            ///< counter-clockwise in this view).
  double ball_energy_before_j = 0.0;  ///< (1/2) m v^2 + (1/2) I omega^2 before, J.
  double ball_energy_after_j = 0.0;   ///< The same after, J.
  double bat_energy_change_j = 0.0;   ///< The bat's kinetic energy change, J (lab frame).
  double energy_lost_j = 0.0;  ///< -(ball + bat energy changes): >= 0 (rounding aside), J.
  Summary summary;  ///< "closed_form", models_used {"oblique_impact"}; refusals as data.
};

/// One oblique impact. Never throws; invalid inputs (and a normal law that answers out of
/// range) are reported in the summary, the numbers then left at zero.
ObliqueImpactResult SolveObliqueImpact(const ObliqueImpactInputs& inputs);

}  // namespace sweetspot::core
