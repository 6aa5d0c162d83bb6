// Internal to core: the design code's one parametrisation of a bat and its mass integrals,
// of the design model (design_model.cpp), whose problems the shape fit's are (shape_fit.cpp).
//
// Parameters: DesignParameterLayout order (core/bat/mass_properties.hpp): the knots' radii and
// positions, then density, wall, fill diameter, depth and density. A three-segment shape is
// the 4 knots (0, r1), (x1, r1), (x2, r2), (L, r2); each design variable sets one or two of
// these parameters (DesignParametersOf), each parameter its coefficient (parameter_scale: 1,
// or a scaled field's base value) times the variable. The integrals P = (M, S1, S2, L) and
// dP/dx over the variables x come from forward-mode AD (jet.hpp) of the closed forms per
// segment and fill.
// Included only by core's .cpp files.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "core/bat/bat.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/optimize/design_problem.hpp"

namespace sweetspot::core::design_detail {

/// The parameters of `base` (material, wall, fill) with the profile `s` as its 4 knots
/// (DesignParameterLayout{4} order; fill entries 0 without a fill).
std::vector<double> ThreeSegmentParameters(const Bat& base, const ThreeSegmentShape& s);

/// `shape` with its dimensions read from the 4-knot parameters t, less the round-off of
/// 0 <= x1 <= x2 <= L that a solver leaves (x1 raised to 0, x2 cut to L, x1 cut to x2).
ThreeSegmentShape ThreeSegmentShapeAt(const std::vector<double>& t, ThreeSegmentShape shape);

/// The parameters (DesignParameterLayout indices) that the variable `ref` sets: one, or two for
/// a three-segment radius (r1 = knots 0 and 1, r2 = knots 2 and 3; `lay` has 4 knots then).
std::vector<int> DesignParametersOf(const DesignVariableRef& ref, const DesignParameterLayout& lay);

/// P = (M kg, S1 kg·m, S2 kg·m², L m) and, when requested, dP/dx (4 x n, per unit of each
/// variable).
struct Integrals {
  std::array<double, 4> p{};                    ///< M, S1, S2, L.
  Eigen::Matrix<double, 4, Eigen::Dynamic> dp;  ///< dP/dx (when requested).
};

/// What the integrals of a design depend on.
struct IntegralContext {
  const std::vector<double>& t;                ///< Parameters (DesignParameterLayout order).
  const std::vector<int>& parameter_variable;  ///< Parameter -> variable index, or -1.
  const std::vector<double>& parameter_scale;  ///< Parameter -> d parameter / d its variable.
  int num_knots;                               ///< Knots of the profile.
  bool hollow;                                 ///< A shell of wall t[WallThickness()].
  bool has_fill;                               ///< The fill entries apply.
  bool rigid;                                  ///< S2 includes the cross-sections' own moments.
  double c0;                                   ///< Reference point of S1 and S2, m from the knob.
};

/// Computes P and, when `gradients`, dP/dx over the n variables into *out.
void ComputeIntegrals(const IntegralContext& c, int n, bool gradients, Integrals* out);

/// Adds sum_c w_c d2P_c/dx2 (c = M, S1, S2) into *h (n x n).
void AddIntegralHessian(const IntegralContext& c, const std::array<double, 3>& w,
                        Eigen::MatrixXd* h);

/// The same sum term by term, for a sparse Hessian (the lifted formulation, lifted_nlp.hpp):
/// add(j_a, j_b, v) for every pair of variables that share a segment or the fill (both orders,
/// the same pair several times; the caller sums), v possibly 0. Its calls at any point list
/// the Hessian's structure.
void VisitIntegralHessian(const IntegralContext& c, const std::array<double, 3>& w,
                          const std::function<void(int, int, double)>& add);

}  // namespace sweetspot::core::design_detail
