// The least-squares objective of the design model (DesignObjective::kLeastSquares, issue 33
// item 3): the shape fit's metric
//   phi = ((M - M*) / s_M)^2 + ((C - C*) / s_C)^2
// over the targets given, a function of the mass integrals P = (M, S1, S2, L) like every other
// DesignFunction, so its gradient and Hessian come from the same jets (jet.hpp) as the others'.
// The targets and scales are the problem's (DesignProblem::least_squares). No solver headers.
#pragma once

#include <optional>

#include "core/summary.hpp"

namespace sweetspot::core {

/// The targets of the least-squares objective and the scales of its residuals.
struct LeastSquaresTargets {
  std::optional<double> mass_kg;  ///< M*, kg, finite and > 0 (at least one target is given).
  /// C*, m from the knob, finite and > 0.
  std::optional<double> balance_point_m;
  /// s_M, kg, finite and > 0 when the mass is a target (the shape fit: M* unless set).
  double mass_scale_kg = 1.0;
  /// s_C, m, finite and > 0 when the balance point is a target (the shape fit: C* unless set).
  double balance_point_scale_m = 1.0;
  /// The polish after the optimiser's stop (Gauss-Newton on the residuals) ends when every
  /// scaled residual is at most 1e-3 of this (the shape fit's tolerance), in (0, 0.1].
  double tolerance = 1e-9;

  /// True when at least one target is given, every given target and its scale is finite and
  /// positive and the tolerance in range; otherwise the refusal (field "least_squares.<name>",
  /// value, rule).
  bool Validate(Refusal* refusal) const;
  /// phi at a design of mass `mass_kg` and balance point `balance_point_m` (dimensionless).
  double Value(double mass_kg, double balance_point_m) const;
};

namespace design_detail {

/// phi of the mass integrals P = (M, S1, S2, L) about the reference point c0 (C = c0 + S1 / M),
/// for a double or a jet.
template <typename T>
T LeastSquaresOf(const T* p, double c0, const LeastSquaresTargets& targets) {
  T phi(0.0);
  if (targets.mass_kg.has_value()) {
    const T r = (p[0] - *targets.mass_kg) * (1.0 / targets.mass_scale_kg);
    phi = phi + r * r;
  }
  if (targets.balance_point_m.has_value()) {
    const T r =
        ((c0 - *targets.balance_point_m) + p[1] / p[0]) * (1.0 / targets.balance_point_scale_m);
    phi = phi + r * r;
  }
  return phi;
}

}  // namespace design_detail
}  // namespace sweetspot::core
