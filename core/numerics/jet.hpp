// Internal: a forward-mode automatic-differentiation number that carries a value, its gradient
// and (when kSecond) its Hessian with respect to N local variables (truncated Taylor
// arithmetic). Products, quotients and smooth unary functions propagate the exact first and
// second derivatives of the operations performed: the derivatives are exact up to rounding,
// like the value itself, and not a difference quotient. Used by the mass properties' gradient
// (N = 5 per profile segment, 4 for the fill), the design model (the closed-form mass
// integrals: N = 6 per profile segment, 5 for the fill; the closed-form sweet spot: N = 4)
// and the shape fit. Included only by core's .cpp files.
//
// Speed: every operation writes a fresh result element by element from its operands, taken by
// const reference (no operand copied by value and then updated in place: GCC then moves the
// copies through the stack in 16-byte pieces that straddle the value and the gradient, and
// the loads stall on the stores), and a double operand has its own overload (a scale or a
// shift, never a full Jet product). A first-order Jet stores no Hessian at all.
#pragma once

#include <array>
#include <cmath>
#include <type_traits>

namespace sweetspot::core::jet {

/// The Hessian's storage of a first-order Jet: nothing.
struct NoHessian {};

/// Value, gradient and (when kSecond) the symmetric Hessian, stored in full (row-major).
template <int N, bool kSecond>
struct Jet {
  static constexpr int kHessianSize = kSecond ? N * N : 0;

  std::array<double, N> g{};  ///< d value / d variable i.
  double v = 0.0;             ///< The value.
  /// d2 value / d variable i d variable j, h[i * N + j] (kSecond only).
  [[no_unique_address]] std::conditional_t<kSecond, std::array<double, N * N>, NoHessian> h{};

  Jet() = default;
  /// A constant (zero derivatives). Implicit so that the integrals' templates can mix doubles in.
  Jet(double value) : v(value) {}  // NOLINT(google-explicit-constructor)

  /// The independent variable i with value `value`.
  static Jet Variable(double value, int i) {
    Jet out(value);
    out.g[static_cast<std::size_t>(i)] = 1.0;
    return out;
  }

  /// f(this) for a scalar function with value f0, first derivative f1, second derivative f2.
  Jet Apply(double f0, double f1, double f2) const {
    Jet out(f0);
    for (int i = 0; i < N; ++i) out.g[i] = f1 * g[i];
    if constexpr (kSecond) {
      for (int i = 0; i < N; ++i) {
        for (int j = 0; j < N; ++j) out.h[i * N + j] = f1 * h[i * N + j] + f2 * g[i] * g[j];
      }
    }
    return out;
  }

  Jet& operator+=(const Jet& b) { return *this = *this + b; }
  Jet& operator-=(const Jet& b) { return *this = *this - b; }
  Jet& operator*=(double s) { return *this = *this * s; }

  /// a s + b t: the sum, difference and scalings below are this one loop.
  static Jet Combine(const Jet& a, double s, const Jet& b, double t) {
    Jet out(s * a.v + t * b.v);
    for (int i = 0; i < N; ++i) out.g[i] = s * a.g[i] + t * b.g[i];
    if constexpr (kSecond) {
      for (int i = 0; i < kHessianSize; ++i) out.h[i] = s * a.h[i] + t * b.h[i];
    }
    return out;
  }
  /// s a + c for doubles s and c.
  static Jet Affine(double s, const Jet& a, double c) {
    Jet out(s * a.v + c);
    for (int i = 0; i < N; ++i) out.g[i] = s * a.g[i];
    if constexpr (kSecond) {
      for (int i = 0; i < kHessianSize; ++i) out.h[i] = s * a.h[i];
    }
    return out;
  }

  friend Jet operator+(const Jet& a, const Jet& b) {
    Jet out(a.v + b.v);
    for (int i = 0; i < N; ++i) out.g[i] = a.g[i] + b.g[i];
    if constexpr (kSecond) {
      for (int i = 0; i < kHessianSize; ++i) out.h[i] = a.h[i] + b.h[i];
    }
    return out;
  }
  friend Jet operator-(const Jet& a, const Jet& b) {
    Jet out(a.v - b.v);
    for (int i = 0; i < N; ++i) out.g[i] = a.g[i] - b.g[i];
    if constexpr (kSecond) {
      for (int i = 0; i < kHessianSize; ++i) out.h[i] = a.h[i] - b.h[i];
    }
    return out;
  }
  friend Jet operator-(const Jet& a) { return Affine(-1.0, a, 0.0); }
  friend Jet operator+(const Jet& a, double b) { return Affine(1.0, a, b); }
  friend Jet operator+(double a, const Jet& b) { return Affine(1.0, b, a); }
  friend Jet operator-(const Jet& a, double b) { return Affine(1.0, a, -b); }
  friend Jet operator-(double a, const Jet& b) { return Affine(-1.0, b, a); }
  friend Jet operator*(const Jet& a, double s) { return Affine(s, a, 0.0); }
  friend Jet operator*(double s, const Jet& a) { return Affine(s, a, 0.0); }
  friend Jet operator/(const Jet& a, double s) { return Affine(1.0 / s, a, 0.0); }
  friend Jet operator*(const Jet& a, const Jet& b) {
    Jet out(a.v * b.v);
    for (int i = 0; i < N; ++i) out.g[i] = a.v * b.g[i] + b.v * a.g[i];
    if constexpr (kSecond) {
      for (int i = 0; i < N; ++i) {
        for (int j = 0; j < N; ++j) {
          out.h[i * N + j] =
              a.v * b.h[i * N + j] + b.v * a.h[i * N + j] + a.g[i] * b.g[j] + b.g[i] * a.g[j];
        }
      }
    }
    return out;
  }
  friend Jet operator/(const Jet& a, const Jet& b) {
    const double inv = 1.0 / b.v;
    return a * b.Apply(inv, -inv * inv, 2.0 * inv * inv * inv);
  }
  friend Jet operator/(double a, const Jet& b) {
    const double inv = 1.0 / b.v;
    return b.Apply(a * inv, -a * inv * inv, 2.0 * a * inv * inv * inv);
  }
};

/// The value of a double or a Jet (for branches).
inline double Value(double x) { return x; }
template <int N, bool S>
double Value(const Jet<N, S>& x) {
  return x.v;
}

/// sqrt of a positive number.
inline double Sqrt(double x) { return std::sqrt(x); }
template <int N, bool S>
Jet<N, S> Sqrt(const Jet<N, S>& x) {
  const double r = std::sqrt(x.v);
  return x.Apply(r, 0.5 / r, -0.25 / (r * x.v));
}

/// x^p for a positive x and a constant exponent p.
inline double Pow(double x, double p) { return std::pow(x, p); }
template <int N, bool S>
Jet<N, S> Pow(const Jet<N, S>& x, double p) {
  const double f = std::pow(x.v, p);
  return x.Apply(f, p * f / x.v, p * (p - 1.0) * f / (x.v * x.v));
}

}  // namespace sweetspot::core::jet
