// The n-knot design problem shared by the optimiser tests (optimize_lifted_test.cpp,
// optimize_frontier_test.cpp, active_set_newton_test.cpp): bench/core_optimize.cpp's and
// bench/core_frontier.cpp's solid ash bat.
#pragma once

#include <cmath>
#include <string>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/units.hpp"

namespace sweetspot::core::knot_design_problems {

/// Max exit speed over the radii of knots 1..n-2 (0.0110 to 0.0332 m) of a solid ash bat,
/// 0.86 m long, on `n` evenly spaced knots (a logistic taper from 0.0125 to 0.0325 m); balance
/// point at most 0.60 m, diameters within [0.9, 2.61] in, non-decreasing taper. No mass
/// constraint: each test sets its own.
inline DesignProblem SolidAshKnots(int n) {
  DesignProblem p;
  const double length = 0.86;
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    p.bat.knots.push_back({length * s, 0.0125 + 0.020 / (1.0 + std::exp(-14.0 * (s - 0.55)))});
  }
  p.bat.material = *FindMaterial("ash");
  for (int i = 1; i <= n - 2; ++i) {
    p.variables.push_back({"profile.knots[" + std::to_string(i) + "].radius_m", 0.0110, 0.0332});
  }
  p.constraints.balance_point_m = DesignRange::AtMost(0.60);
  p.constraints.max_barrel_diameter_m = InchesToMetres(2.61);
  p.constraints.min_handle_diameter_m = InchesToMetres(0.9);
  p.constraints.taper = TaperRule::kNonDecreasing;
  return p;
}

/// SolidAshKnots(n) with its mass held at the base bat's (an equality): bench/core_optimize.cpp's
/// KnotProblem, the problem of the lifted and tapered formulations' tests.
inline DesignProblem SolidAshKnotsAtBaseMass(int n) {
  DesignProblem p = SolidAshKnots(n);
  p.constraints.mass_kg = DesignRange::Equal(ComputeMassProperties(p.bat).mass_kg);
  return p;
}

}  // namespace sweetspot::core::knot_design_problems
