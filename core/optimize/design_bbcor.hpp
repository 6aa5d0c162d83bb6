// Internal to core/optimize: the quasi-static trampoline's effective COR of a hollow design as a
// smooth function with exact first and second derivatives, for the `bbcor` rule's constraint (the
// NCAA protocol's ball, speed and pivot) and for the exit-speed objectives' COR of a hollow design
// hit by the scene's ball (DesignProblem::cor_from_barrel). Included only by core's .cpp files.
//
// The model is QuasiStaticTrampoline's (core/collision/barrel.hpp, docs/models.md "Barrel"): the
// wall a ring of mid radius R = r_out - h/2 with k_b = c (3/4) pi E' h^3 l / R^3,
// l = 2 R sqrt(R / h), the ball's power law in series with the surface's Hertz K(r_out), the bat's
// effective mass M_e at the impact point, the approach speed v0 and the ball's COR e. The peak
// force F is the root of
//   Phi(F, theta) = W_c(F) + F^2 / (2 k_b) - mu v0^2 / 2,   mu = m M_e / (m + M_e),
//   W_c(F) = F delta_b / (p + 1) + (2/5) F delta_s,  delta_b = (F/k)^(1/p), delta_s = (F/K)^(2/3)
// (BallPowerLaw::LoadingWork(F, LoadingCompression(F)) written out), found in double by
// QuasiStaticTrampoline's bisection. Its derivatives come from the implicit function theorem,
// done as Newton steps on jets with the value held at the root: from the constant F0, one step
// F1 = F0 - Phi(F0, theta) / Phi_F(F0, theta) has the exact gradient dF = -Phi_theta / Phi_F,
// and a second step from F1 the exact Hessian as well (Newton's quadratic convergence doubles the
// order of the Taylor coefficients that are right). Phi_F = delta_b / p + (2/3) delta_s + F / k_b.
// Then e_eff^2 = 1 - [(1 - e^2) W_c + loss W_b] / (W_c + W_b) (TrampolineCorOfWall).
//
// BBCOR (ComputeBbcor): M_e = I_pivot / z^2 for the bat pivoted at the protocol's pivot, z the
// impact point's distance beyond it; v0 and e the protocol's (BbcorOfWall). The scene's COR
// (EffectiveCorAt): M_e = 1 / (1/M + b^2 / I_cm) for the free bat, b the impact point's distance
// from the balance point; v0 the scene's normal speed there and e the ball's law at v0
// (BallCorLawAt), both functions of the design when the swing's omega is.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/ball/ball_catalogue.hpp"
#include "core/bat/material.hpp"
#include "core/collision/barrel.hpp"
#include "core/collision/contact_law.hpp"
#include "core/numerics/jet.hpp"
#include "core/units.hpp"

namespace sweetspot::core::design_detail {

/// The numbers of the quasi-static trampoline that do not depend on the design: the ball's
/// mass, radius and contact law, the bat material's elasticity and the barrel model's settings.
struct TrampolineConstants {
  double ball_mass_kg = 0.0;       ///< m, kg.
  double ball_radius_m = 0.0;      ///< Ball radius, m (the surface's Hertz K).
  double ball_stiffness = 0.0;     ///< k in F = k delta^p, N/m^p.
  double ball_exponent = 1.5;      ///< p.
  double youngs_modulus_pa = 0.0;  ///< The bat material's E, Pa.
  double poissons_ratio = 0.0;     ///< The bat material's nu.
  double shell_factor = 0.0;       ///< c in k_b = c k_ring.
  double barrel_loss = 0.0;        ///< The wall's loss (dimensionless).
};

/// The trampoline's constants for `ball` (a catalogue BallPreset or a scene's Ball: mass_kg,
/// radius_m, stiffness, stiffness_exponent) against a wall of `material` with `barrel`'s settings.
template <typename BallT>
TrampolineConstants TrampolineConstantsOf(const BallT& ball, const Material& material,
                                          const BarrelOptions& barrel) {
  TrampolineConstants k;
  k.ball_mass_kg = ball.mass_kg;
  k.ball_radius_m = ball.radius_m;
  k.ball_stiffness = ball.stiffness;
  k.ball_exponent = ball.stiffness_exponent;
  k.youngs_modulus_pa = material.youngs_modulus_pa;
  k.poissons_ratio = material.poissons_ratio;
  k.shell_factor = barrel.shell_factor;
  k.barrel_loss = barrel.barrel_loss;
  return k;
}

/// The numbers of the BBCOR protocol that the constraint needs (none depends on the design).
struct BbcorConstants {
  TrampolineConstants trampoline;  ///< The protocol's ball (ncaa-nfhs) and the bat's material.
  double ball_cor = 0.0;           ///< e of the ball at the protocol's speed.
  double speed_mps = 0.0;          ///< v0, m/s.
  double pivot_from_knob_m = 0.0;  ///< The protocol's pivot, m from the knob.
  double impact_from_tip_m = 0.0;  ///< The protocol's impact point, m from the tip.
};

/// The scene's COR of a hollow design (DesignProblem::cor_from_barrel): the scene's ball and
/// its COR law, at a point held at a fixed distance from the tip.
struct BarrelCorConstants {
  TrampolineConstants trampoline;  ///< The scene's ball and the bat's material.
  BallCorLaw cor_law;              ///< The ball's COR against a rigid surface vs. speed.
  double impact_from_tip_m = 0.0;  ///< The impact point, m from the tip (kCorReferenceFromTipM).
};

/// The peak force of the quasi-static trampoline, N: the root of W_c + W_b = energy_j by
/// QuasiStaticTrampoline's bracket and bisection (to 1e-15 relative).
inline double TrampolinePeakForce(const TrampolineConstants& c, double energy_j,
                                  double barrel_stiffness, double surface_stiffness) {
  const BallPowerLaw law(c.ball_stiffness, c.ball_exponent, surface_stiffness);
  auto works = [&](double f) {
    return law.LoadingWork(f, law.LoadingCompression(f)) + 0.5 * f * f / barrel_stiffness;
  };
  double lo = 0.0, hi = 1.0;
  while (works(hi) < energy_j && hi < 1e30) hi *= 2.0;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (works(mid) < energy_j ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

inline void SetJetValue(double* x, double v) { *x = v; }
template <int N, bool S>
void SetJetValue(jet::Jet<N, S>* x, double v) {
  x->v = v;
}

/// The ball's COR law at normal speed v (BallCorLaw::CorAt's arithmetic, so the value is
/// CorAt's bit for bit): e0 - k (v - v0) inside [min_speed, max_speed] and inside [0, 1], a
/// constant (zero derivatives) where CorAt clamps.
template <typename T>
T BallCorLawAt(const BallCorLaw& law, const T& v) {
  const double value = law.CorAt(jet::Value(v));
  const double vv = jet::Value(v);
  if (!(vv >= law.min_speed_mps && vv <= law.max_speed_mps && value > 0.0 && value < 1.0)) {
    return T(value);
  }
  return law.cor_at_reference - law.slope_per_mps * (v - law.reference_speed_mps);
}

/// e_eff of the quasi-static trampoline (the file comment) for a bat of effective mass m_e (kg)
/// at the impact point, approach speed (m/s), the ball's COR there, the outer radius r_out (m)
/// and the wall h (m) there. T = double (the value) or a jet; with a jet, newton_steps = 1 gives
/// the exact gradient, 2 the exact Hessian as well. NaN when the inputs are out of the model's
/// domain (h <= 0, r_out <= h, m_e <= 0, speed <= 0, ball_cor outside [0, 1]).
template <typename T>
T TrampolineCorOfWall(const TrampolineConstants& c, const T& m_e, const T& speed, const T& ball_cor,
                      const T& r_out, const T& h, int newton_steps) {
  if (!(jet::Value(h) > 0.0 && jet::Value(r_out) > jet::Value(h) && jet::Value(m_e) > 0.0 &&
        jet::Value(speed) > 0.0 && jet::Value(ball_cor) >= 0.0 && jet::Value(ball_cor) <= 1.0)) {
    return T(std::numeric_limits<double>::quiet_NaN());
  }
  const double e_prime = c.youngs_modulus_pa / (1.0 - c.poissons_ratio * c.poissons_ratio);
  const T r_mid = r_out - 0.5 * h;
  const T l = 2.0 * r_mid * jet::Sqrt(r_mid / h);
  const T k_b = (c.shell_factor * 0.75 * kPi * e_prime) * (h * h * h) * l / (r_mid * r_mid * r_mid);
  // BatSurfaceHertzStiffness: (4/3) E* (r1 r2)^(1/4), r2 = 1 / (1/r_ball + 1/r_out).
  const T r2 = 1.0 / (1.0 / c.ball_radius_m + 1.0 / r_out);
  const T k_s = ((4.0 / 3.0) * e_prime) * jet::Sqrt(jet::Sqrt(c.ball_radius_m * r2));
  const T mu = c.ball_mass_kg * m_e / (c.ball_mass_kg + m_e);
  const T energy = 0.5 * mu * speed * speed;
  const double f0 = TrampolinePeakForce(c, jet::Value(energy), jet::Value(k_b), jet::Value(k_s));
  const double p = c.ball_exponent;
  auto ball_share = [&](const T& f) { return jet::Pow(f * (1.0 / c.ball_stiffness), 1.0 / p); };
  auto surface_share = [&](const T& f) { return jet::Pow(f / k_s, 2.0 / 3.0); };
  T f(f0);
  for (int step = 0; step < newton_steps; ++step) {
    const T db = ball_share(f), ds = surface_share(f);
    const T phi = f * db * (1.0 / (p + 1.0)) + 0.4 * f * ds + 0.5 * f * f / k_b - energy;
    const T dphi = db * (1.0 / p) + (2.0 / 3.0) * ds + f / k_b;
    f = f - phi / dphi;
    SetJetValue(&f, f0);  // the root itself; the step only supplies the derivatives
  }
  const T w_c = f * ball_share(f) * (1.0 / (p + 1.0)) + 0.4 * f * surface_share(f);
  const T w_b = 0.5 * f * f / k_b;
  const T lost = ((1.0 - ball_cor * ball_cor) * w_c + c.barrel_loss * w_b) / (w_c + w_b);
  return jet::Sqrt(1.0 - lost);
}

/// The BBCOR (e_eff of the quasi-static trampoline) for a bat with moment of inertia
/// moi_pivot (kg m^2) about the protocol's pivot, the impact point z (m) beyond the pivot, the
/// outer radius r_out (m) and the wall h (m) there: TrampolineCorOfWall with M_e = I / z^2 and
/// the protocol's speed and ball COR. NaN out of the domain (also z <= 0, I <= 0).
template <typename T>
T BbcorOfWall(const BbcorConstants& c, const T& moi_pivot, const T& z, const T& r_out, const T& h,
              int newton_steps) {
  if (!(jet::Value(z) > 0.0 && jet::Value(moi_pivot) > 0.0)) {
    return T(std::numeric_limits<double>::quiet_NaN());
  }
  return TrampolineCorOfWall<T>(c.trampoline, moi_pivot / (z * z), T(c.speed_mps), T(c.ball_cor),
                                r_out, h, newton_steps);
}

}  // namespace sweetspot::core::design_detail
