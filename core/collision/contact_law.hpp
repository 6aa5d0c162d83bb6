// contact_law: the ball's force law against the bat's surface, the one copy both contact models
// use (core/collision/hertz_contact.cpp and core/collision/flexible_impact.cpp; docs/models.md,
// "Contact laws").
//
// The ball's own nonlinear stiffness F = k delta_b^p is in series with the bat surface's Hertz
// contact F = K delta_s^{3/2} (delta = delta_b + delta_s). Loading follows that virgin curve;
// from a maximum (delta_max, F_max) the contact unloads along F_max (delta / delta_max)^q with
// q chosen so the unloading returns e^2 of the loading work (a two-body impact then has a COR
// of exactly e); above delta_max it reloads along the virgin curve. SI throughout.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace sweetspot::core {

/// The virgin loading curve of the ball in series with the bat surface, and its inverse.
class BallPowerLaw {
 public:
  BallPowerLaw() = default;
  /// k in F = k delta_b^p (N/m^p, > 0), p (in [1, 3]) and the surface's Hertz K
  /// (N/m^1.5, >= 0; 0 = a rigid surface).
  BallPowerLaw(double ball_stiffness, double ball_exponent, double surface_stiffness);

  double ball_stiffness() const { return k_; }      ///< k, N/m^p.
  double ball_exponent() const { return p_; }       ///< p (dimensionless).
  double surface_stiffness() const { return kk_; }  ///< K, N/m^1.5 (0 = rigid surface).

  /// Force on the virgin curve at total compression delta_m (m), N (0 for delta_m <= 0).
  double LoadingForce(double delta_m) const;
  /// The compression split: the ball's share delta_b (m) of a total compression delta_m (m),
  /// the root of delta_b + (k delta_b^p / K)^{2/3} = delta_m. Closed form for a rigid surface
  /// (delta_b = delta) and for p = 3/2 (delta_b = delta / (1 + (k/K)^{2/3})); otherwise a
  /// Newton iteration safeguarded by bisection on [0, delta_m] (the left side is increasing).
  double BallShare(double delta_m) const;
  /// The ball's compression (F / k)^{1/p} at force force_n (N), m.
  double BallCompression(double force_n) const;
  /// The surface's compression (F / K)^{2/3} at force force_n (N), m (0 for a rigid surface).
  double SurfaceCompression(double force_n) const;
  /// Total compression on the virgin curve at force force_n (N), m: LoadingForce's inverse.
  double LoadingCompression(double force_n) const;
  /// LoadingCompression for p = 3/2 only, as one 3/2-power spring (the ball's in series with the
  /// surface's, exact) with one cbrt instead of two: equal to it but for rounding, m.
  double LoadingCompressionThreeHalves(double force_n) const;
  /// Work done along the virgin curve up to (delta_m, force_n), J (closed form).
  double LoadingWork(double force_n, double delta_m) const;
  /// The unloading exponent q = F_max delta_max / (e^2 W_load) - 1 for which unloading from
  /// (delta_max_m, force_max_n) returns cor^2 of the loading work (dimensionless; cor > 0).
  double UnloadingExponent(double force_max_n, double delta_max_m, double cor) const;

 private:
  double k_ = 0.0;      // N/m^p
  double p_ = 1.5;      // dimensionless
  double kk_ = 0.0;     // N/m^1.5
  double k_eff_ = 0.0;  // series stiffness (k^{-2/3} + K^{-2/3})^{-3/2} when p = 3/2, N/m^1.5
};

/// Which branch of the hysteresis loop a contact is on.
struct ContactBranch {
  bool unloading = false;    ///< False: the virgin curve; true: unloading from the maximum.
  double delta_max_m = 0.0;  ///< Compression where unloading began, m.
  double force_max_n = 0.0;  ///< The force there, N.
  double exponent = 1.5;     ///< q of the unloading curve (dimensionless).

  /// Force at compression delta_m (m) on this branch, N: the virgin curve while loading and at
  /// or above delta_max, F_max (delta / delta_max)^q below it while unloading.
  double Force(const BallPowerLaw& law, double delta_m) const;
  /// Compression (m), compliance d(delta)/dF (m/N) and its rate d2(delta)/dF2 (m/N^2) at force
  /// force_n (N > 0) on this branch.
  void CompressionAndCompliance(const BallPowerLaw& law, double force_n, double* delta_m,
                                double* compliance_m_n, double* compliance_rate_m_n2) const;
  /// Starts unloading at (delta_max_m, force_max_n) with q from the law and cor (> 0).
  void StartUnloading(const BallPowerLaw& law, double delta_max_m, double force_max_n, double cor);
};

/// Force (N) of the contact on `branch` in series with a linear spring of compliance
/// `compliance_m_n` (m/N, > 0) at total compression delta_m (m): the root F of
/// compression(F) + c F = delta, by Newton's method safeguarded by bisection on the bracket
/// (0, min(delta / c, the force without the spring)]. *warm_start_n (N) is the first guess when
/// it lies in the bracket and receives the root (a cache only: any value is safe).
double SeriesContactForce(const BallPowerLaw& law, const ContactBranch& branch,
                          double compliance_m_n, double delta_m, double* warm_start_n);

/// The contact's compression scale, m: the maximum compression of an elastic ball of law
/// k delta^p striking a rigid body of inverse effective mass c11 (1/kg, ball included) at v0,
/// ((p+1) v0^2 / (2 c11 k))^(1/(p+1)). The contact models scale their state by it.
double ContactCompressionScaleM(double c11_per_kg, double stiffness, double exponent,
                                double approach_speed_mps);

/// The contact time of the same elastic impact (closed form), s:
/// 2 (delta_max / v0) B(1/(p+1), 1/2) / (p+1), delta_max = ContactCompressionScaleM.
double ElasticContactTimeS(double c11_per_kg, double stiffness, double exponent,
                           double approach_speed_mps);

/// The bat surface's Hertz stiffness K = (4/3) E* sqrt(R*), N/m^1.5, for a rigid ball of radius
/// `ball_radius_m` on a bat of local radius `bat_radius_m`: E* = E / (1 - nu^2), and the
/// sphere-on-cylinder ellipse is replaced by a circle of radius R* = sqrt(R' R''),
/// 1/R' = 1/R_ball, 1/R'' = 1/R_ball + 1/R_bat.
double BatSurfaceHertzStiffness(double youngs_modulus_pa, double poissons_ratio,
                                double ball_radius_m, double bat_radius_m);

// The right-hand sides call these at every evaluation: defined here so they inline (as out-of-line
// calls from another translation unit they cost the flexible impact a few percent).

inline double BallPowerLaw::LoadingForce(double delta_m) const {
  const double d = delta_m;
  if (d <= 0.0) return 0.0;
  if (kk_ <= 0.0) return k_ * std::pow(d, p_);
  if (p_ == 1.5) return k_eff_ * d * std::sqrt(d);
  return k_ * std::pow(BallShare(d), p_);
}

inline double BallPowerLaw::BallCompression(double force_n) const {
  if (force_n <= 0.0) return 0.0;
  if (p_ == 1.5) {  // cbrt for the default exponent: no pow
    const double c = std::cbrt(force_n / k_);
    return c * c;
  }
  return std::pow(force_n / k_, 1.0 / p_);
}

inline double BallPowerLaw::SurfaceCompression(double force_n) const {
  if (force_n <= 0.0 || kk_ <= 0.0) return 0.0;
  return std::cbrt((force_n / kk_) * (force_n / kk_));
}

inline double BallPowerLaw::LoadingCompression(double force_n) const {
  if (force_n <= 0.0) return 0.0;
  return BallCompression(force_n) + SurfaceCompression(force_n);
}

inline double BallPowerLaw::LoadingCompressionThreeHalves(double force_n) const {
  if (force_n <= 0.0) return 0.0;
  const double c = std::cbrt(force_n / (k_eff_ > 0.0 ? k_eff_ : k_));
  return c * c;
}

inline double ContactBranch::Force(const BallPowerLaw& law, double delta_m) const {
  if (delta_m <= 0.0) return 0.0;
  if (!unloading || delta_m >= delta_max_m) return law.LoadingForce(delta_m);
  return force_max_n * std::pow(delta_m / delta_max_m, exponent);
}

inline void ContactBranch::CompressionAndCompliance(const BallPowerLaw& law, double force_n,
                                                    double* delta_m, double* compliance_m_n,
                                                    double* compliance_rate_m_n2) const {
  // Each term is a F^r: its compliance r (a F^r) / F and that compliance's rate (r - 1) / F times
  // the compliance.
  const double f = force_n;
  const double inv_f = 1.0 / f;
  if (!unloading || f >= force_max_n) {
    if (law.ball_exponent() == 1.5) {  // one 3/2-power spring: r = 2/3
      *delta_m = law.LoadingCompressionThreeHalves(f);
      *compliance_m_n = 2.0 / 3.0 * *delta_m * inv_f;
      *compliance_rate_m_n2 = -1.0 / 3.0 * *compliance_m_n * inv_f;
      return;
    }
    const double ball = law.BallCompression(f);
    const double surface = law.SurfaceCompression(f);
    const double r = 1.0 / law.ball_exponent();
    const double ball_c = r * ball * inv_f;
    const double surface_c = 2.0 / 3.0 * surface * inv_f;
    *delta_m = ball + surface;
    *compliance_m_n = ball_c + surface_c;
    *compliance_rate_m_n2 = ((r - 1.0) * ball_c - 1.0 / 3.0 * surface_c) * inv_f;
    return;
  }
  const double r = 1.0 / exponent;
  *delta_m = delta_max_m * std::pow(f / force_max_n, r);
  *compliance_m_n = r * *delta_m * inv_f;
  *compliance_rate_m_n2 = (r - 1.0) * *compliance_m_n * inv_f;
}

inline double SeriesContactForce(const BallPowerLaw& law, const ContactBranch& branch,
                                 double compliance_m_n, double delta_m, double* warm_start_n) {
  const double d = delta_m;
  const double c = compliance_m_n;
  if (d <= 0.0) return 0.0;
  if (c <= 0.0) return branch.Force(law, d);
  // Bracket: 0 < F <= d / c (and <= the force without c, computed only for a cold start).
  double lo = 0.0, hi = d / c;
  double f = *warm_start_n;  // warm start: an integrator calls with nearby states
  if (!(f > 0.0 && f < hi)) {
    hi = std::min(hi, branch.Force(law, d));
    f = 0.5 * hi;
  }
  for (int it = 0; it < 60; ++it) {
    double comp = 0.0, compliance = 0.0, rate = 0.0;
    branch.CompressionAndCompliance(law, f, &comp, &compliance, &rate);
    const double g = comp + c * f - d;
    if (std::abs(g) <= 4.0 * std::numeric_limits<double>::epsilon() * d) return *warm_start_n = f;
    if (g > 0.0) {
      hi = f;
    } else {
      lo = f;
    }
    // Halley's step (g' = compliance + c > 0, g'' = rate), Newton's where its denominator is
    // not positive, bisection where the step leaves the bracket.
    const double g1 = compliance + c;
    const double denominator = 2.0 * g1 * g1 - g * rate;
    double next = denominator > 0.0 ? f - 2.0 * g * g1 / denominator : f - g / g1;
    if (!(next > lo && next < hi)) {
      next = 0.5 * (lo + hi);
    } else if (std::abs(next - f) <= 1e-6 * f) {
      // A step this small leaves an error below round-off. With compression(F) a sum of terms
      // a F^r, r in (0, 1] (1/p and 2/3 loading, 1/q unloading), Halley's error after a step s
      // is at most (g''^2 / (4 g'^2) + |g'''| / (6 g')) s^3 <= (1/4 + 1/3) s^3 / F^2, so below
      // 0.6e-18 F here: `next` is the root without one more evaluation.
      return *warm_start_n = next;
    }
    if (std::abs(next - f) <= 1e-14 * f) return *warm_start_n = next;
    f = next;
  }
  return *warm_start_n = f;
}

}  // namespace sweetspot::core
