// Internal to core/optimize: the lifted formulation of a design problem (issue 36, item 2).
//
// The objective and the property constraints are functions of P = (M, S1, S2, L) (the mass
// integrals, design_integrals.hpp), and P is a sum over segments of functions of two adjacent
// knots: the exact Hessian of f(P(x)) is banded plus a dense rank-3 term, so over x alone Ipopt
// gets a dense n x n Hessian and a dense KKT matrix. Lifted, the variables are (x, q) with q the
// integrals M, S1, S2 (scaled by sigma = (M0, M0 L, M0 L^2) of the start) and three equality
// constraints q_c - P_c(x) / sigma_c = 0: their Jacobian rows have n entries each, their
// Hessians are banded in x (the design model's own VisitIntegralHessian); the objective and the
// property constraints are functions of q alone (a 3 x 3 block: FunctionOfP), the linear
// constraints sparse rows in x. The Lagrangian's Hessian is then banded plus that small block
// and MUMPS factorises the KKT matrix in O(n).
//
// The variables x are the ScaledDesignNlp's (s in [0, 1]). A linear constraint of one variable
// (a per-knot diameter limit) becomes a bound on that variable; the other constraints keep their
// order and scaling (g_k / scale_k), the three definitions after them. DesignMultipliers maps
// the lifted multipliers back to the dense problem's (a bound's multiplier to its constraint's).
// No solver headers here: the Ipopt TNLP over this class is in ipopt_lifted.cpp (NewLiftedTnlp).
#pragma once

#include <array>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/optimize/design_backends.hpp"
#include "core/optimize/design_integrals.hpp"
#include "core/optimize/design_model.hpp"

namespace Ipopt {
class TNLP;  // coin/IpTNLP.hpp, included by ipopt_lifted.cpp only
}  // namespace Ipopt

namespace sweetspot::core {

/// The lifted NLP over z = (s, q): s the ScaledDesignNlp's variables, q = (M, S1, S2) / sigma.
/// One per solve (caches the last point; not thread-safe).
class LiftedDesignNlp {
 public:
  /// True when `model` can be lifted: a smooth objective (not the sting) and every variable a
  /// profile knot's radius (L, the wall, the fill and the density fixed), the objective and every
  /// constraint linear in the parameters or a function of P alone (IsFunctionOfP: no frequency,
  /// no BBCOR, no barrel COR). Otherwise false with the first reason in *why (if non-null).
  static bool Qualifies(const DesignModel& model, std::string* why);

  /// The lifted form of `nlp`'s model (which must qualify), with the same scaled variables.
  explicit LiftedDesignNlp(const ScaledDesignNlp& nlp);

  int n() const { return nx_ + 3; }  ///< Variables: s, then q.
  /// Constraints: the model's kept rows (not turned into bounds), then P's three definitions.
  int m() const { return static_cast<int>(kept_.size()) + 3; }
  int design_variables() const { return nx_; }  ///< Variables of the model (s).
  int design_constraints() const { return md_; }  ///< Constraints of the model.
  /// The model's multipliers (Ipopt's sign convention, the dense problem's scaling) from the
  /// lifted ones: the kept rows' lambda, and each bound's multiplier either its variable's or,
  /// when the bound came from a constraint of one variable, that constraint's.
  void DesignMultipliers(const double* z_lower, const double* z_upper, const double* lambda,
                         std::vector<double>* design_lambda, std::vector<double>* design_z_lower,
                         std::vector<double>* design_z_upper) const;
  const std::array<double, 3>& sigma() const { return sigma_; }  ///< Scales of q: kg, kg·m, kg·m².
  /// Bounds of z (s in [0, 1], q free: +-inf) and of the constraints (the model's scaled ones,
  /// then 0 = 0 for the three definitions).
  void Bounds(std::vector<double>* z_lower, std::vector<double>* z_upper,
              std::vector<double>* g_lower, std::vector<double>* g_upper) const;
  /// The lifted start from s0: (s0, P(x(s0)) / sigma); false when P is not finite there.
  bool Start(const std::vector<double>& s0, std::vector<double>* z) const;

  /// The Jacobian's structure (row, column), one entry per value of jacobian_values().
  const std::vector<std::pair<int, int>>& jacobian_structure() const { return jac_; }
  /// The Lagrangian Hessian's lower triangle (row >= column), one entry per value of Hessian():
  /// the pairs the integrals couple, q's block, and explicit zeros in a band of 4 around the
  /// diagonal of the design variables (fewer, wider fronts for MUMPS; lifted_nlp.cpp).
  const std::vector<std::pair<int, int>>& hessian_structure() const { return hess_; }

  /// Evaluates at z (cached); false when not finite (or M(x) <= 0).
  bool Evaluate(const double* z, bool with_gradients);
  double f() const { return f_; }                          ///< Scaled objective (minimised).
  const std::vector<double>& g() const { return g_; }      ///< Constraints (m).
  const std::vector<double>& grad_f() const { return grad_f_; }  ///< d f / d z (n).
  /// d g / d z at jacobian_structure()'s entries.
  const std::vector<double>& jacobian_values() const { return jac_values_; }
  /// sigma_f f + sum lambda_k g_k's Hessian at hessian_structure()'s entries into values;
  /// false when not finite.
  bool Hessian(const double* z, double sigma_f, const double* lambda, double* values);
  int evaluations() const { return evaluations_; }  ///< Evaluations of P(x) so far.

 private:
  // The constructor's steps. A linear row of one variable (a per-knot diameter limit) becomes
  // a bound on it (s_lower_/s_upper_, *_row_, *_coef_), the other rows are kept (kept_); returns
  // every linear row's coefficients over the scaled variables (x0, t0: the base design).
  std::vector<std::map<int, double>> RowsToBounds(const std::vector<double>& x0,
                                                  const std::vector<double>& t0);
  // The Jacobian's structure and its linear rows' constant values.
  void BuildJacobianStructure(const std::vector<std::map<int, double>>& linear_rows);
  // A linear objective's constant gradient (objective_linear_).
  void SetLinearObjective();
  // The Hessian's structure (at the base design's parameters t0) and its row index.
  void BuildHessianStructure(const std::vector<double>& t0);
  // A function's value, gradient over P (4) and Hessian (4 x 4) at t, P; the linear ones'
  // gradient is constant (linear_rows_); false when not finite.
  bool FunctionAt(const DesignFunctionSpec& f, const std::vector<double>& t, const double* p,
                  double* value, double* gradient, double* hessian) const;
  std::vector<double> XAt(const double* z) const;
  design_detail::IntegralContext ContextAt(const std::vector<double>& t) const;
  int HessianIndex(int row, int col) const;

  const DesignModel& model_;
  int nx_ = 0;
  int md_ = 0;
  std::vector<int> kept_;  // lifted row -> model row (the rows not turned into bounds)
  // Per variable: its bounds in s and the model row (or -1: [0, 1] itself) and coefficient
  // d g_k / d s_j of the row that sets each.
  std::vector<double> s_lower_, s_upper_;
  std::vector<int> lower_row_, upper_row_;
  std::vector<double> lower_coef_, upper_coef_;
  std::vector<double> lower_;  // the variables' lower bounds, field unit
  std::vector<double> width_;  // upper - lower
  std::array<double, 3> sigma_{};
  std::vector<std::pair<int, int>> jac_;
  std::vector<std::pair<int, int>> hess_;
  std::vector<std::vector<std::pair<int, int>>> hess_rows_;  // row -> (column, entry)
  // Per constraint row: the first Jacobian entry; linear rows' constant values.
  std::vector<int> row_start_;
  std::vector<double> linear_values_;   // at each entry (0 where not linear)
  std::vector<double> objective_linear_;  // d f / d s of a linear objective (nx)
  std::vector<double> last_z_;
  bool have_values_ = false;
  bool have_gradients_ = false;
  double f_ = 0.0;
  std::vector<double> g_;
  std::vector<double> grad_f_;
  std::vector<double> jac_values_;
  int evaluations_ = 0;
};

/// The Ipopt TNLP over `nlp` (ipopt_lifted.cpp), started at `s0`'s lifted point; writes the
/// design's point and multipliers (the first design_variables() and design_constraints()
/// entries) into *out. Owned by the caller's Ipopt::SmartPtr.
Ipopt::TNLP* NewLiftedTnlp(LiftedDesignNlp& nlp, const std::vector<double>& s0,
                           const LocalSolveSettings& settings, LocalSolveOutcome* out);

}  // namespace sweetspot::core
