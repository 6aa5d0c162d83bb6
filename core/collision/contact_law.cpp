// contact_law: implementation; the law is stated at the top of contact_law.hpp.
#include "core/collision/contact_law.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/units.hpp"

namespace sweetspot::core {

BallPowerLaw::BallPowerLaw(double ball_stiffness, double ball_exponent, double surface_stiffness)
    : k_(ball_stiffness), p_(ball_exponent), kk_(surface_stiffness) {
  if (kk_ > 0.0 && p_ == 1.5) {
    // Two 3/2-power springs in series are a 3/2-power spring (exact).
    const double kb = std::cbrt(1.0 / (k_ * k_));
    const double ks = std::cbrt(1.0 / (kk_ * kk_));
    k_eff_ = std::pow(kb + ks, -1.5);
  }
}

double BallPowerLaw::BallShare(double delta_m) const {
  const double d = delta_m;
  if (d <= 0.0) return 0.0;
  if (kk_ <= 0.0) return d;
  // delta_b + a delta_b^e = d with a = (k / K)^{2/3}, e = 2p/3.
  const double a = std::cbrt((k_ / kk_) * (k_ / kk_));
  if (p_ == 1.5) return d / (1.0 + a);
  const double e = 2.0 * p_ / 3.0;
  double lo = 0.0, hi = d, db = d / (1.0 + a * std::pow(d, e - 1.0));
  for (int it = 0; it < 60; ++it) {
    const double g = db + a * std::pow(db, e) - d;
    if (g > 0.0) {
      hi = db;
    } else {
      lo = db;
    }
    const double dg = 1.0 + a * e * std::pow(db, e - 1.0);
    double next = db - g / dg;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - db) <= 1e-15 * d) return next;
    db = next;
  }
  return db;
}

double BallPowerLaw::LoadingWork(double force_n, double delta_m) const {
  // F delta minus the complementary energy of each spring: p/(p+1) F delta_b and 3/5 F delta_s.
  const double fm = force_n;
  double comp = p_ / (p_ + 1.0) * std::pow(fm / k_, 1.0 / p_) * fm;
  if (kk_ > 0.0) comp += 0.6 * std::cbrt((fm / kk_) * (fm / kk_)) * fm;
  return fm * delta_m - comp;
}

double BallPowerLaw::UnloadingExponent(double force_max_n, double delta_max_m, double cor) const {
  return force_max_n * delta_max_m / (cor * cor * LoadingWork(force_max_n, delta_max_m)) - 1.0;
}

void ContactBranch::StartUnloading(const BallPowerLaw& law, double delta_max, double force_max,
                                   double cor) {
  unloading = true;
  delta_max_m = delta_max;
  force_max_n = force_max;
  exponent = law.UnloadingExponent(force_max, delta_max, cor);
}

double ContactCompressionScaleM(double c11_per_kg, double stiffness, double exponent,
                                double approach_speed_mps) {
  const double p1 = exponent + 1.0;
  return std::pow(p1 * approach_speed_mps * approach_speed_mps / (2.0 * c11_per_kg * stiffness),
                  1.0 / p1);
}

double ElasticContactTimeS(double c11_per_kg, double stiffness, double exponent,
                           double approach_speed_mps) {
  const double p1 = exponent + 1.0;
  const double d_max =
      ContactCompressionScaleM(c11_per_kg, stiffness, exponent, approach_speed_mps);
  const double a = 1.0 / p1;
  const double beta = std::tgamma(a) * std::sqrt(kPi) / std::tgamma(a + 0.5);
  return 2.0 * d_max / approach_speed_mps * beta / p1;
}

double BatSurfaceHertzStiffness(double youngs_modulus_pa, double poissons_ratio,
                                double ball_radius_m, double bat_radius_m) {
  const double e_star = youngs_modulus_pa / (1.0 - poissons_ratio * poissons_ratio);
  const double r1 = ball_radius_m;
  const double r2 = 1.0 / (1.0 / ball_radius_m + 1.0 / bat_radius_m);
  return 4.0 / 3.0 * e_star * std::sqrt(std::sqrt(r1 * r2));
}

}  // namespace sweetspot::core
