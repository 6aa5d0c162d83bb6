// Internal to core (public only so that tests can check it): the shape fit's checks (its names,
// ShapeFitProblem::Validate and ShapeFitOptions::Validate are defined in shape_fit_checks.cpp)
// and its problem as a design problem (core/optimize/shape_fit.hpp). No solver headers here.
//
// One parametrisation: the design code's (design_integrals.hpp). A fit unknown is the design
// variable of the same field ("three_segment.taper_start_m", "material.density_kg_m3", ...);
// the bat is the 4-knot parameter vector t of DesignParameterLayout{4}, and each unknown sets
// the parameters DesignParametersOf gives (two for a radius). The validity rules of the family
// (0 <= x1 <= x2 <= L, wall < r1, r2, a fill no deeper than L and strictly inside the
// material) are checked here on t, for the refusals of fixed values and for the scan; the
// solve is the design model's (FitDesignProblem, least_squares_objective.hpp).
#pragma once

#include <string>
#include <vector>

#include "core/optimize/design_problem.hpp"
#include "core/optimize/shape_fit.hpp"

namespace sweetspot::core::fit_detail {

/// Number of kinds a fit unknown may be.
inline constexpr int kNumFitVariables = kNumFitUnknowns;
/// Length of the parameter vector t: DesignParameterLayout{4}.Size().
inline constexpr int kNumFitParameters = 2 * 4 + 5;

/// The design variable that the fit variable `variable` is.
DesignVariableRef DesignVariableOf(DesignVariableKind variable);
/// The field of a fit variable in refusals ("shape.taper_start_m", ...; "" if out of range).
const char* FitUnknownField(DesignVariableKind variable);
/// True for the fill's variables (they need a fill).
bool IsFillVariable(DesignVariableKind variable);

/// The problem's bat as parameters t (DesignParameterLayout{4}; fill entries 0 without a fill).
std::vector<double> BaseParameters(const ShapeFitProblem& problem);
/// The starting parameters: unknowns clamped into their bounds (the middle when not finite).
std::vector<double> StartParameters(const ShapeFitProblem& problem);
/// The value of `variable` in the parameters t, in its unit.
double FitValue(const std::vector<double>& t, DesignVariableKind variable);
/// True when the bat is hollow (a wall, or the wall is an unknown).
bool HollowOf(const ShapeFitProblem& problem);

/// A validity constraint g(t) <= 0 of the family, in metres.
enum class FitConstraint {
  kStart,       ///< -x1 <= 0.
  kOrder,       ///< x1 - x2 <= 0.
  kEnd,         ///< x2 - L <= 0.
  kWallHandle,  ///< t < r1.
  kWallBarrel,  ///< t < r2.
  kFillDepth,   ///< d <= L.
  kBoreBottom,  ///< Bore radius < material around it at L - d.
  kBoreTip,     ///< Bore radius < material around it at L.
};

/// The constraints that apply to a bat (hollow, with a fill).
std::vector<FitConstraint> ApplicableConstraints(bool hollow, bool has_fill);
/// True when an unknown among `unknown` (indexed by FitUnknownIndex) can change the constraint.
bool ConstraintInvolves(FitConstraint kind, const std::vector<bool>& unknown);
/// g(t), m (<= 0 when it holds).
double ConstraintValue(FitConstraint kind, const std::vector<double>& t, bool hollow);
/// The refusal of the violated constraint at the fixed values t (field, value, rule).
Refusal ConstraintRefusal(FitConstraint kind, const std::vector<double>& t, bool hollow);
/// ConstraintRefusal as "field = value: rule".
std::string ConstraintMessage(FitConstraint kind, const std::vector<double>& t, bool hollow);

/// The fit as a design problem: the unknowns its variables (kFitUnknownKinds' paths, the
/// bounds the unknowns'), objective DesignObjective::kLeastSquares with the targets and the
/// options' scales (0 = the target) and tolerance, the base design the bat at parameters `t`
/// (DesignParameterLayout{4}): its fixed fields, and the start of the first local solve.
DesignProblem FitDesignProblem(const ShapeFitProblem& problem, const ShapeFitOptions& options,
                               const std::vector<double>& t);
/// The variables' values (field units, in the unknowns' order) at parameters t.
std::vector<double> UnknownValues(const ShapeFitProblem& problem, const std::vector<double>& t);

}  // namespace sweetspot::core::fit_detail
