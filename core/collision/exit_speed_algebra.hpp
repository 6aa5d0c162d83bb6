// Internal to core: the exit-speed closed forms of exit_speed_profile.hpp templated on the
// scalar type (Ceres' Jet idiom): T is double (ExitSpeedProfile's path) or a
// jet::Jet<N, kSecond> (the design objectives, which need exact first and second
// derivatives). Branches are taken on the values (jet::Value), so a Jet follows the same
// arithmetic as the double and its derivatives are those of the branch taken. The formulas are
// those of exit_speed_profile.hpp (f(x) = -u + c (w + omega x) / (J + m x^2)), written without
// catastrophic cancellation. Included only by core's .cpp files.
#pragma once

#include <cmath>

#include "core/numerics/jet.hpp"

namespace sweetspot::core::exit_speed {

/// The coefficients of f(x) = -u + c (w + omega x) / (J + m x^2), in the scalar type T.
template <typename T>
struct Form {
  T ball_speed_mps;       ///< u, m/s.
  T gain_kg_m2;           ///< c, kg m^2.
  T approach_mps;         ///< w, m/s.
  T inertia_kg_m2;        ///< J, kg m^2 (> 0).
  T ball_mass_kg;         ///< m, kg (> 0).
  T angular_speed_rad_s;  ///< omega, rad/s (>= 0).
};

/// The rigid-pivot model's form (rigid_pivot.hpp): c = (1 + e) J, w = u, x from the pivot.
template <typename T>
Form<T> RigidPivotForm(const T& moi_pivot_kg_m2, double ball_mass_kg, double ball_speed_mps,
                       const T& angular_speed_rad_s, double cor) {
  return {T(ball_speed_mps), (1.0 + cor) * moi_pivot_kg_m2,
          T(ball_speed_mps), moi_pivot_kg_m2,
          T(ball_mass_kg),   angular_speed_rad_s};
}

/// f(x), m/s.
template <typename T>
T ExitSpeedAt(const Form<T>& f, const T& x_m) {
  const T den = f.inertia_kg_m2 + f.ball_mass_kg * x_m * x_m;
  return -f.ball_speed_mps + f.gain_kg_m2 * (f.approach_mps + f.angular_speed_rad_s * x_m) / den;
}

/// f'(x), 1/s.
template <typename T>
T DerivativeAt(const Form<T>& f, const T& x_m) {
  const T den = f.inertia_kg_m2 + f.ball_mass_kg * x_m * x_m;
  const T num = f.angular_speed_rad_s * f.inertia_kg_m2 -
                f.ball_mass_kg * x_m * (f.angular_speed_rad_s * x_m + 2.0 * f.approach_mps);
  return f.gain_kg_m2 * num / (den * den);
}

/// hypot(a, b) = sqrt(a^2 + b^2): std::hypot on doubles; on jets the value is std::hypot's and
/// the derivatives are those of sqrt(a^2 + b^2).
inline double Hypot(double a, double b) { return std::hypot(a, b); }
template <int N, bool S>
jet::Jet<N, S> Hypot(const jet::Jet<N, S>& a, const jet::Jet<N, S>& b) {
  jet::Jet<N, S> out = jet::Sqrt(a * a + b * b);
  out.v = std::hypot(a.v, b.v);
  return out;
}

/// The unconstrained maximum of f.
template <typename T>
struct Maximum {
  T x_m;              ///< x*, m from the form's origin.
  T peak_mps;         ///< c G = f(x*) + u, m/s (> 0 unless flat).
  bool flat = false;  ///< f is constant (omega = 0 and w = 0): x* = 0 by convention.
};

/// The maximum of f in closed form: x* = omega J / (m (w + S)), S = hypot(w, omega sqrt(J/m)),
/// c G = c (w + S) / (2 J); w + S without cancellation for w < 0.
template <typename T>
Maximum<T> MaximumOf(const Form<T>& f) {
  const T& j = f.inertia_kg_m2;
  const T& m = f.ball_mass_kg;
  const T& w = f.approach_mps;
  const T& omega = f.angular_speed_rad_s;
  if (jet::Value(omega) == 0.0) {
    // f(x) = -u + c w / (J + m x^2): maximum at x = 0 when w > 0, flat when w = 0.
    return {T(0.0), f.gain_kg_m2 * w / j, !(jet::Value(w) > 0.0)};
  }
  const T omega2_j_over_m = omega * omega * (j / m);
  const T s = Hypot(w, omega * jet::Sqrt(j / m));
  const T ws = jet::Value(w) >= 0.0 ? w + s : omega2_j_over_m / (s - w);  // w + S > 0
  return {omega * j / (m * ws), f.gain_kg_m2 * ws / (2.0 * j), false};
}

/// f(x*) - f(x) >= 0 in m/s, without cancellation: c G m (x - x*)^2 / (J + m x^2).
template <typename T>
T DeficitAt(const Form<T>& f, const Maximum<T>& mx, const T& x_m) {
  if (mx.flat) return T(0.0);
  const T d = x_m - mx.x_m;
  return mx.peak_mps * f.ball_mass_kg * d * d / (f.inertia_kg_m2 + f.ball_mass_kg * x_m * x_m);
}

/// An interval of the form's coordinate; an open side extends to infinity.
template <typename T>
struct Zone {
  T lo_m;                ///< Lower end, m (meaningless when lo_open).
  T hi_m;                ///< Upper end, m (meaningless when hi_open).
  bool lo_open = false;  ///< The zone extends to -infinity.
  bool hi_open = false;  ///< The zone extends to +infinity.
};

/// The connected interval around x* where f(x) >= f(x*) - delta (delta >= 0): f(x*) - f(x) <=
/// delta is a x^2 - 2 b x + c0 <= 0 with a = m (cG - delta), b = cG m x*, c0 = cG m x*^2 -
/// delta J, and the discriminant expanded so that its leading terms cancel on paper only.
template <typename T>
Zone<T> ZoneAround(const Form<T>& f, const Maximum<T>& mx, const T& delta_mps) {
  const T& xs = mx.x_m;
  if (mx.flat) return {xs, xs, true, true};
  if (!(jet::Value(delta_mps) > 0.0)) return {xs, xs};
  const T& m = f.ball_mass_kg;
  const T& j = f.inertia_kg_m2;
  const T& cg = mx.peak_mps;
  const T a = m * (cg - delta_mps);
  const T b = cg * m * xs;
  const T c0 = cg * m * xs * xs - delta_mps * j;
  const T disc = m * delta_mps * (cg * (j + m * xs * xs) - delta_mps * j);
  if (jet::Value(a) > 0.0) {
    if (!(jet::Value(disc) > 0.0)) return {xs, xs};
    const T q = b + jet::Sqrt(disc);  // b >= 0
    if (jet::Value(q) == 0.0) return {xs, xs};
    const T r1 = q / a;
    const T r2 = c0 / q;
    return jet::Value(r1) <= jet::Value(r2) ? Zone<T>{r1, r2} : Zone<T>{r2, r1};
  }
  if (jet::Value(a) == 0.0) {
    if (jet::Value(b) > 0.0) return {c0 / (2.0 * b), xs, false, true};
    return {xs, xs, true, true};
  }
  // a < 0: the inequality holds outside the roots (or everywhere); keep the part holding x*.
  if (!(jet::Value(disc) >= 0.0)) return {xs, xs, true, true};
  const T q = b + jet::Sqrt(disc);
  if (jet::Value(q) == 0.0) return {xs, xs, true, true};
  const T r1 = q / a;
  const T r2 = c0 / q;
  const bool order = jet::Value(r1) <= jet::Value(r2);
  const T& lo = order ? r1 : r2;
  const T& hi = order ? r2 : r1;
  if (jet::Value(xs) >= jet::Value(hi)) return {hi, xs, false, true};
  return {xs, lo, true, false};
}

}  // namespace sweetspot::core::exit_speed
