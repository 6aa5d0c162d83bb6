// Internal to core (public only so that tests can check it): the shape fit
// (core/optimize/shape_fit.hpp) as a design problem with a least-squares objective. No solver
// headers here.
//
// One parametrisation: the design code's (design_integrals.hpp). A fit unknown is the design
// variable of the same field ("three_segment.taper_start_m", "material.density_kg_m3", ...);
// the bat is the 4-knot parameter vector t of DesignParameterLayout{4}, and each unknown sets
// the parameters DesignParametersOf gives (two for a radius). The residuals
// r = ((M - M*) / s_M, (C - C*) / s_C) come from the design model's mass integrals, their
// Jacobian from its forward-mode AD; the validity constraints (0 <= x1 <= x2 <= L, wall < r1,
// r2, a fill no deeper than L and strictly inside the material) are differentiated with the
// same AD type (jet.hpp). The solvers see the unknowns scaled to s in [0, 1]^n.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

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

/// The fit in scaled unknowns s in [0, 1]^n: x_j = lo_j (1 - s_j) + hi_j s_j. Counts its
/// evaluations; one per fit (not thread-safe).
class ShapeFitModel {
 public:
  /// The model of a valid problem (ShapeFitProblem::IsValid) with the options' scales.
  ShapeFitModel(const ShapeFitProblem& problem, const ShapeFitOptions& options);

  int n() const { return static_cast<int>(variables_.size()); }  ///< Unknowns.
  int m() const { return static_cast<int>(targets_.size()); }    ///< Residuals (targets).
  /// Constraints that involve an unknown (the others hold at the fixed values).
  const std::vector<FitConstraint>& constraints() const { return constraints_; }
  /// The constraints' scale, m: the largest length the bat can have.
  double length_scale() const { return length_scale_; }
  int evaluations() const { return evaluations_; }  ///< Residual evaluations so far.

  /// The parameters t at s (s clamped into [0, 1]).
  std::vector<double> ToParameters(const double* s) const;
  /// The starting point in s.
  std::vector<double> StartS() const;

  /// Scaled residuals r (size m) and, if jacobian != nullptr, dr/ds (m x n).
  void Residuals(const double* s, Eigen::VectorXd* r, Eigen::MatrixXd* jacobian);
  /// The least-squares objective phi = |r|^2 and, if grad != nullptr, dphi/ds into grad[0..n).
  double Objective(const double* s, double* grad);
  /// Constraint value divided by the length scale and, if grad != nullptr, its gradient in s.
  double Constraint(FitConstraint kind, const double* s, double* grad) const;
  /// Largest constraint value at s, m (<= 0 when feasible; 0 without constraints).
  double MaxViolationM(const double* s) const;
  /// True when every constraint holds at s.
  bool Feasible(const double* s) const { return MaxViolationM(s) <= 0.0; }

 private:
  std::vector<double> base_;  // parameters of the fixed fields
  bool hollow_ = false;
  bool has_fill_ = false;
  std::vector<std::vector<int>> variables_;  // per unknown: the parameters it sets
  std::vector<int> parameter_variable_;      // parameter -> unknown index, or -1
  std::vector<double> parameter_scale_;      // d parameter / d its unknown: all 1 here
  std::vector<double> lo_, hi_;
  std::vector<double> targets_, scales_;
  std::vector<int> kinds_;  // 0 = mass, 1 = balance point
  std::vector<FitConstraint> constraints_;
  double length_scale_ = 1.0;
  int evaluations_ = 0;
};

/// First-order optimality residual of phi at s over the active bounds and constraints,
/// relative to the size of phi's gradient terms (2 |J| |r|); 0 where phi is flat to rounding.
double KktError(ShapeFitModel& model, const std::vector<double>& s);

}  // namespace sweetspot::core::fit_detail
