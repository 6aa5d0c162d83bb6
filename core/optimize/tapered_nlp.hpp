// Internal to core/optimize: the lifted formulation with the taper's steps as variables
// (issue 36, item 2: fewer rows in Ipopt's KKT system).
//
// In the lifted problem (lifted_nlp.hpp) a non-decreasing taper is one inequality row per pair
// of adjacent variable knots: Ipopt gives each a slack variable and a multiplier, so its KKT
// matrix has ~3n rows for n knot radii, and MUMPS's factorisation and solve grow with them.
// When the variables form one chain of such rows (s_{j_i} and s_{j_(i-1)} in row k_i:
// t_i(s) = p_i s_{j_i} + n_i s_{j_(i-1)} + c_i >= lo_i, p_i > 0 > n_i), this formulation solves
// over w = (y, q): the chain is cut into blocks of kTaperBlockSize positions; a block's head
// keeps its own s (y_i = s_{j_i}, its bounds; the taper row into it stays a row) and every
// other position its step y_i = t_i(s), whose row becomes the bound y_i >= lo_i. s is then an
// affine function of y (s_{j_i} = (y_i - c_i - n_i s_{j_(i-1)}) / p_i within a block), and a
// variable's own bounds, which the taper implies for all but a few (a non-decreasing profile
// between fixed end knots), stay rows only where not implied. The KKT matrix has ~n + n / 16
// rows; the Hessian over y is A^T H_s A (A = ds/dy, block lower triangular; computed in
// O(n^2) by recurrences), dense within a block plus each head's row against the previous
// block. The answer and its multipliers are mapped back to the lifted problem's and from there
// to the design's.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/optimize/lifted_nlp.hpp"

namespace sweetspot::core {

/// Knots per block of the taper's steps: each block's first knot keeps its radius as its
/// variable (and the taper row into it stays a row), so the Hessian over the steps is dense
/// only within a block (16 x 16) plus one row per block head. Instruction counts of the n-knot
/// design (bench/optimize_instructions.sh, 64 / 128 / 256 knots): blocks of 4: 38 / 60 / 115 M;
/// 8: 31 / 54 / 114 M; 12: 35 / 53 / 96 M; 16: 32 / 48 / 101 M; 20: 33 / 48 / 102 M;
/// 32: 35 / 55 / 104 M; one block: 44 / 118 / 766 M (MUMPS's dense front); the lifted
/// formulation over the radii: 48 / 87 / 160 M (docs/benchmarks.md, "Issue 36").
inline constexpr int kTaperBlockSize = 16;

/// The lifted NLP over w = (y, q): y the taper's chain (see the file comment), q the lifted
/// integrals. One per solve (not thread-safe).
class TaperedLiftedNlp {
 public:
  /// Builds over `lifted` (kept by reference), its linear rows read at s0's lifted point. ok()
  /// is false when its variables do not form one taper chain.
  TaperedLiftedNlp(LiftedDesignNlp& lifted, const std::vector<double>& s0, int block_size);
  bool ok() const { return ok_; }  ///< The chain covers every design variable.

  int n() const { return k_ + 3; }                                     ///< Variables: y, then q.
  int m() const { return static_cast<int>(rows_.size()); }             ///< Constraints.
  int design_variables() const { return lifted_.design_variables(); }  ///< Of the model.
  /// Bounds of w and of the constraints.
  void Bounds(std::vector<double>* w_lower, std::vector<double>* w_upper,
              std::vector<double>* g_lower, std::vector<double>* g_upper) const;
  /// The start from the design's scaled s0; false when not finite.
  bool Start(const std::vector<double>& s0, std::vector<double>* w) const;
  /// The lifted point z = (s, q) of w.
  std::vector<double> LiftedPoint(const double* w) const;
  /// The design's multipliers (Ipopt's signs, the dense problem's scaling) from these.
  void DesignMultipliers(const double* w_lower, const double* w_upper, const double* lambda,
                         std::vector<double>* design_lambda, std::vector<double>* design_z_lower,
                         std::vector<double>* design_z_upper) const;
  /// The Jacobian's structure (row, column), one entry per value of jacobian_values().
  const std::vector<std::pair<int, int>>& jacobian_structure() const { return jac_; }
  /// The Lagrangian Hessian's lower triangle (dense over y, q's 3 x 3 block).
  const std::vector<std::pair<int, int>>& hessian_structure() const { return hess_; }
  /// Evaluates at w (cached); false when not finite.
  bool Evaluate(const double* w, bool with_gradients);
  double f() const { return lifted_.f(); }                       ///< Scaled objective.
  const std::vector<double>& g() const { return g_; }            ///< Constraints (m).
  const std::vector<double>& grad_f() const { return grad_f_; }  ///< d f / d w.
  /// d g / d w at jacobian_structure()'s entries.
  const std::vector<double>& jacobian_values() const { return jac_values_; }
  /// sigma_f f + sum lambda_k g_k's Hessian at hessian_structure()'s entries.
  bool Hessian(const double* w, double sigma_f, const double* lambda, double* values);
  int evaluations() const { return lifted_.evaluations(); }  ///< Evaluations of P(x).

 private:
  // Per lifted row: its Jacobian entries on the design variables and on q.
  struct RowEntries {
    std::vector<std::vector<int>> design, q;
  };
  // Per chain position i >= 1: its taper row p s_i + q s_(i-1) + c >= lo.
  struct ChainRows {
    std::vector<double> p, q, c, lo;
  };
  // The chain of taper rows through every design variable (var_, chain_row_, pos_); false
  // when the rows do not form one.
  bool FindChain(const RowEntries& entries);
  // The blocks, the map s(y) and y's bounds; the taper rows that became bounds in *bound_row.
  ChainRows SetSteps(int block_size, const RowEntries& entries, const std::vector<double>& z0,
                     std::vector<bool>* bound_row);
  // The rows: the lifted ones but the bounds', then the variables' bounds not implied.
  void KeepRows(const ChainRows& chain, const std::vector<bool>& bound_row);
  // The Jacobian's and the Hessian's structures and the Hessian's index maps.
  void BuildStructures(const RowEntries& entries);
  bool IsHead(int i) const { return block_start_[static_cast<std::size_t>(i)] == i; }
  // A^T v (v over chain positions, in place): d/dy of a function with gradient v over s.
  void ApplyAT(std::vector<double>* v) const;
  // A u for u = e_i (the column of ds/dy for y_i), over chain positions.
  void ColumnOfA(int i, std::vector<double>* u) const;

  LiftedDesignNlp& lifted_;
  bool ok_ = false;
  int k_ = 0;                      // design variables (= chain length)
  std::vector<int> var_;           // chain position -> lifted variable
  std::vector<int> pos_;           // lifted variable -> chain position
  std::vector<int> chain_row_;     // chain position i >= 1 -> its lifted row (-1 for i = 0)
  std::vector<double> a_, c_, e_;  // s_i = a_i y_i + c_i s_(i-1) + e_i (chain positions)
  std::vector<double> y_lower_, y_upper_;
  // Rows: a lifted row (>= 0) or -(1 + chain position) for a variable's bounds kept as a row.
  std::vector<int> rows_;
  std::vector<double> row_lower_, row_upper_;
  std::vector<int> lifted_to_row_;  // lifted row -> row here (-1: a chain row)
  std::vector<std::pair<int, int>> jac_;
  std::vector<std::pair<int, int>> hess_;
  std::vector<double> z_lower_, z_upper_, lg_lower_, lg_upper_;  // the lifted problem's
  std::vector<double> g_, grad_f_, jac_values_;
  std::vector<double> last_w_;
  // The Hessian's scratch: per chain column the lifted entries (entry, other position) of H_s,
  // q's block entries (-1: none), B = H_s A (column-major), one column.
  std::vector<std::vector<std::pair<int, int>>> column_entries_;
  std::vector<int> q_block_entries_;
  std::vector<double> b_, column_;
  std::vector<int> block_start_;  // chain position -> its block's head
  std::vector<int> hess_index_;   // (row, column) of y, row-major -> Hessian entry (-1: none)
  bool have_values_ = false, have_gradients_ = false;
};

/// The Ipopt TNLP over `nlp` (ipopt_lifted.cpp), as NewLiftedTnlp.
Ipopt::TNLP* NewTaperedTnlp(TaperedLiftedNlp& nlp, const std::vector<double>& s0,
                            const LocalSolveSettings& settings, LocalSolveOutcome* out);

}  // namespace sweetspot::core
