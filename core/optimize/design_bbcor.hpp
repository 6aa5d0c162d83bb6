// Internal to core/optimize: the BBCOR of a hollow design (the `bbcor` rule's constraint) as a
// smooth function with exact first and second derivatives. Included only by core's .cpp files.
//
// The model is ComputeBbcor's (core/collision/barrel.hpp, docs/models.md "BBCOR"): the
// quasi-static trampoline at the protocol's impact point x = L - impact_from_tip, the bat pivoted
// at pivot_from_knob (z = x - pivot, M_e = I_pivot / z^2), the wall a ring of mid radius
// R = r_out - h/2 with k_b = c (3/4) pi E' h^3 l / R^3, l = 2 R sqrt(R / h), the ball's power law
// in series with the surface's Hertz K(r_out). The peak force F is the root of
//   Phi(F, theta) = W_c(F) + F^2 / (2 k_b) - mu v0^2 / 2,
//   W_c(F) = F delta_b / (p + 1) + (2/5) F delta_s,  delta_b = (F/k)^(1/p), delta_s = (F/K)^(2/3)
// (BallPowerLaw::LoadingWork(F, LoadingCompression(F)) written out), found in double by
// QuasiStaticTrampoline's bisection. Its derivatives come from the implicit function theorem,
// done as Newton steps on jets with the value held at the root: from the constant F0, one step
// F1 = F0 - Phi(F0, theta) / Phi_F(F0, theta) has the exact gradient dF = -Phi_theta / Phi_F,
// and a second step from F1 the exact Hessian as well (Newton's quadratic convergence doubles the
// order of the Taylor coefficients that are right). Phi_F = delta_b / p + (2/3) delta_s + F / k_b.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/collision/contact_law.hpp"
#include "core/numerics/jet.hpp"
#include "core/units.hpp"

namespace sweetspot::core::design_detail {

/// The numbers of the BBCOR protocol, the ball and the bat's material that the constraint
/// needs (none depends on the design variables).
struct BbcorConstants {
  double ball_mass_kg = 0.0;       ///< m, kg.
  double ball_radius_m = 0.0;      ///< Ball radius, m (the surface's Hertz K).
  double ball_stiffness = 0.0;     ///< k in F = k delta^p, N/m^p.
  double ball_exponent = 1.5;      ///< p.
  double ball_cor = 0.0;           ///< e of the ball at the protocol's speed.
  double speed_mps = 0.0;          ///< v0, m/s.
  double youngs_modulus_pa = 0.0;  ///< The bat material's E, Pa.
  double poissons_ratio = 0.0;     ///< The bat material's nu.
  double shell_factor = 0.0;       ///< c in k_b = c k_ring.
  double barrel_loss = 0.0;        ///< The wall's loss (dimensionless).
  double pivot_from_knob_m = 0.0;  ///< The protocol's pivot, m from the knob.
  double impact_from_tip_m = 0.0;  ///< The protocol's impact point, m from the tip.
};

/// The peak force of the quasi-static trampoline, N: the root of W_c + W_b = energy_j by
/// QuasiStaticTrampoline's bracket and bisection (to 1e-15 relative).
inline double BbcorPeakForce(const BbcorConstants& c, double energy_j, double barrel_stiffness,
                             double surface_stiffness) {
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

/// The BBCOR (e_eff of the quasi-static trampoline) for a bat with moment of inertia
/// moi_pivot (kg m^2) about the protocol's pivot, the impact point z (m) beyond the pivot, the
/// outer radius r_out (m) and the wall h (m) there. T = double (the value) or a jet; with a jet,
/// newton_steps = 1 gives the exact gradient, 2 the exact Hessian as well. NaN when the inputs
/// are out of the model's domain (h <= 0, R <= 0, z <= 0, I <= 0).
template <typename T>
T BbcorOfWall(const BbcorConstants& c, const T& moi_pivot, const T& z, const T& r_out, const T& h,
              int newton_steps) {
  if (!(jet::Value(h) > 0.0 && jet::Value(r_out) > jet::Value(h) && jet::Value(z) > 0.0 &&
        jet::Value(moi_pivot) > 0.0)) {
    return T(std::numeric_limits<double>::quiet_NaN());
  }
  const double e_prime = c.youngs_modulus_pa / (1.0 - c.poissons_ratio * c.poissons_ratio);
  const T r_mid = r_out - 0.5 * h;
  const T l = 2.0 * r_mid * jet::Sqrt(r_mid / h);
  const T k_b = (c.shell_factor * 0.75 * kPi * e_prime) * (h * h * h) * l / (r_mid * r_mid * r_mid);
  // BatSurfaceHertzStiffness: (4/3) E* (r1 r2)^(1/4), r2 = 1 / (1/r_ball + 1/r_out).
  const T r2 = 1.0 / (1.0 / c.ball_radius_m + 1.0 / r_out);
  const T k_s = ((4.0 / 3.0) * e_prime) * jet::Sqrt(jet::Sqrt(c.ball_radius_m * r2));
  const T m_e = moi_pivot / (z * z);
  const T mu = c.ball_mass_kg * m_e / (c.ball_mass_kg + m_e);
  const T energy = (0.5 * c.speed_mps * c.speed_mps) * mu;
  const double f0 = BbcorPeakForce(c, jet::Value(energy), jet::Value(k_b), jet::Value(k_s));
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
  const double e = c.ball_cor;
  const T lost = ((1.0 - e * e) * w_c + c.barrel_loss * w_b) / (w_c + w_b);
  return jet::Sqrt(1.0 - lost);
}

}  // namespace sweetspot::core::design_detail
