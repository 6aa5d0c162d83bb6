// exit_speed_profile: implementation; the model's assumptions are stated at the top of exit_speed_profile.hpp.
#include "core/collision/exit_speed_profile.hpp"

#include <algorithm>
#include <cmath>

namespace sweetspot::core {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kInf = std::numeric_limits<double>::infinity();

// w + S without cancellation: for w < 0 use (S^2 - w^2) / (S - w) = omega^2 (J/m) / (S - w).
double ApproachPlusS(double w, double s, double omega2_j_over_m) {
  return w >= 0.0 ? w + s : omega2_j_over_m / (s - w);
}

}  // namespace

double ExitSpeedProfile::ExitSpeedMps(double x_m) const {
  const double den = inertia_kg_m2 + ball_mass_kg * x_m * x_m;
  return -ball_speed_mps + gain_kg_m2 * (approach_mps + angular_speed_rad_s * x_m) / den;
}

double ExitSpeedProfile::DerivativePerS(double x_m) const {
  const double den = inertia_kg_m2 + ball_mass_kg * x_m * x_m;
  const double num = angular_speed_rad_s * inertia_kg_m2 -
                     ball_mass_kg * x_m * (angular_speed_rad_s * x_m + 2.0 * approach_mps);
  return gain_kg_m2 * num / (den * den);
}

ProfileMaximum ExitSpeedProfile::Maximum() const {
  ProfileMaximum out;
  const double j = inertia_kg_m2;
  const double m = ball_mass_kg;
  const double w = approach_mps;
  const double omega = angular_speed_rad_s;
  if (omega == 0.0) {
    // f(x) = -u + c w / (J + m x^2): maximum at x = 0 when w > 0, flat when w = 0.
    out.x_m = 0.0;
    out.exit_speed_mps = -ball_speed_mps + gain_kg_m2 * w / j;
    out.flat = !(w > 0.0);
    out.curvature_per_m_s = -2.0 * m * gain_kg_m2 * w / (j * j);
    out.error_estimate_m = 0.0;
    out.error_estimate_mps = 4.0 * kEps * (ball_speed_mps + std::abs(gain_kg_m2 * w / j));
    return out;
  }
  const double omega2_j_over_m = omega * omega * (j / m);
  const double s = std::hypot(w, omega * std::sqrt(j / m));
  const double ws = ApproachPlusS(w, s, omega2_j_over_m);  // w + S > 0 because omega > 0
  out.x_m = omega * j / (m * ws);
  const double peak = gain_kg_m2 * ws / (2.0 * j);  // c G with G = (w + S) / (2 J)
  out.exit_speed_mps = -ball_speed_mps + peak;
  const double den = j + m * out.x_m * out.x_m;
  out.curvature_per_m_s = -2.0 * m * gain_kg_m2 * (w + omega * out.x_m) / (den * den);
  // Each closed form is a handful of correctly rounded operations (hypot, sqrt, *, /, one
  // addition of same-sign terms): a few ulps of each result; the final -u + peak is the
  // only subtraction, bounded by eps times the sum of magnitudes.
  out.error_estimate_m = 8.0 * kEps * out.x_m;
  out.error_estimate_mps = 8.0 * kEps * (ball_speed_mps + peak);
  return out;
}

double ExitSpeedProfile::DeficitMps(double x_m) const {
  const ProfileMaximum mx = Maximum();
  if (mx.flat) return 0.0;
  const double peak = mx.exit_speed_mps + ball_speed_mps;  // c G
  const double d = x_m - mx.x_m;
  return peak * ball_mass_kg * d * d / (inertia_kg_m2 + ball_mass_kg * x_m * x_m);
}

ProfileInterval ExitSpeedProfile::ZoneAround(double delta_mps) const {
  const ProfileMaximum mx = Maximum();
  ProfileInterval all;  // (-inf, inf)
  if (mx.flat) return all;
  const double xs = mx.x_m;
  if (!(delta_mps > 0.0)) return {xs, xs};
  const double m = ball_mass_kg;
  const double j = inertia_kg_m2;
  const double cg = mx.exit_speed_mps + ball_speed_mps;  // c G > 0
  // f(x*) - f(x) <= delta  <=>  a x^2 - 2 b x + c0 <= 0 with
  const double a = m * (cg - delta_mps);
  const double b = cg * m * xs;
  const double c0 = cg * m * xs * xs - delta_mps * j;
  // b^2 - a c0, expanded so that the leading terms cancel exactly on paper, not in floating point:
  const double disc = m * delta_mps * (cg * (j + m * xs * xs) - delta_mps * j);
  if (a > 0.0) {
    if (!(disc > 0.0)) return {xs, xs};
    const double q = b + std::sqrt(disc);  // b >= 0
    if (q == 0.0) return {xs, xs};
    const double r1 = q / a;
    const double r2 = c0 / q;
    return {std::min(r1, r2), std::max(r1, r2)};
  }
  if (a == 0.0) {
    if (b > 0.0) return {c0 / (2.0 * b), kInf};
    return all;
  }
  // a < 0: the inequality holds outside the roots (or everywhere); keep the part holding x*.
  if (!(disc >= 0.0)) return all;
  const double q = b + std::sqrt(disc);
  if (q == 0.0) return all;
  const double r1 = q / a;
  const double r2 = c0 / q;
  const double lo = std::min(r1, r2);
  const double hi = std::max(r1, r2);
  if (xs >= hi) return {hi, kInf};
  return {-kInf, lo};
}

}  // namespace sweetspot::core
