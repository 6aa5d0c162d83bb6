// exit_speed_profile: implementation; the model's assumptions are stated at the top of
// exit_speed_profile.hpp.
#include "core/collision/exit_speed_profile.hpp"

#include <cmath>
#include <limits>

#include "core/collision/exit_speed_algebra.hpp"
#include "core/numerics/limits.hpp"

namespace sweetspot::core {
namespace {

exit_speed::Form<double> FormOf(const ExitSpeedProfile& p) {
  return {p.ball_speed_mps, p.gain_kg_m2,   p.approach_mps,
          p.inertia_kg_m2,  p.ball_mass_kg, p.angular_speed_rad_s};
}

}  // namespace

double ExitSpeedProfile::ExitSpeedMps(double x_m) const {
  return exit_speed::ExitSpeedAt(FormOf(*this), x_m);
}

double ExitSpeedProfile::DerivativePerS(double x_m) const {
  return exit_speed::DerivativeAt(FormOf(*this), x_m);
}

ProfileMaximum ExitSpeedProfile::Maximum() const {
  ProfileMaximum out;
  const double j = inertia_kg_m2;
  const double m = ball_mass_kg;
  const double w = approach_mps;
  const exit_speed::Maximum<double> mx = exit_speed::MaximumOf(FormOf(*this));
  out.x_m = mx.x_m;
  out.exit_speed_mps = -ball_speed_mps + mx.peak_mps;
  out.flat = mx.flat;
  if (angular_speed_rad_s == 0.0) {
    out.curvature_per_m_s = -2.0 * m * gain_kg_m2 * w / (j * j);
    out.error_estimate_m = 0.0;
    out.error_estimate_mps = 4.0 * kEps * (ball_speed_mps + std::abs(gain_kg_m2 * w / j));
    return out;
  }
  const double den = j + m * out.x_m * out.x_m;
  out.curvature_per_m_s = -2.0 * m * gain_kg_m2 * (w + angular_speed_rad_s * out.x_m) / (den * den);
  // Each closed form is a handful of correctly rounded operations (hypot, sqrt, *, /, one
  // addition of same-sign terms): a few ulps of each result; the final -u + peak is the
  // only subtraction, bounded by eps times the sum of magnitudes.
  out.error_estimate_m = 8.0 * kEps * out.x_m;
  out.error_estimate_mps = 8.0 * kEps * (ball_speed_mps + mx.peak_mps);
  return out;
}

double ExitSpeedProfile::DeficitMps(double x_m) const {
  const exit_speed::Form<double> form = FormOf(*this);
  return exit_speed::DeficitAt(form, exit_speed::MaximumOf(form), x_m);
}

ProfileInterval ExitSpeedProfile::ZoneAround(double delta_mps) const {
  const exit_speed::Form<double> form = FormOf(*this);
  const exit_speed::Zone<double> zone =
      exit_speed::ZoneAround(form, exit_speed::MaximumOf(form), delta_mps);
  return {zone.lo_open ? -kInf : zone.lo_m, zone.hi_open ? kInf : zone.hi_m};
}

}  // namespace sweetspot::core
