// The certificate of a design answer: the service's own check of the first-order optimality
// (KKT) conditions at the point a backend returned, with multipliers it estimates itself (a
// non-negative least-squares fit of the active constraints' gradients to the objective's
// gradient; the backend's multipliers are not used), and the constraints found redundant or
// duplicated before the solve (merged, so that the active gradients stay independent).
// Everything is measured on the scaled problem the solvers see (ScaledDesignNlp: variables in
// [0, 1], objective / objective_scale, each constraint / its scale). No solver headers here.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace sweetspot::core {

class DesignModel;  // core/optimize/design_model.hpp

/// Default largest stationarity residual of a certified answer (relative, see
/// DesignCertificate::stationarity).
inline constexpr double kDefaultStationarityTolerance = 1e-6;
/// Default largest violation of a certified answer, relative to each constraint's scale (the
/// re-check's own acceptance, design_detail::kFeasibleRelative).
inline constexpr double kDefaultFeasibilityTolerance = 1e-6;
/// Default largest complementarity product of a certified answer (relative).
inline constexpr double kDefaultComplementarityTolerance = 1e-6;
/// A constraint or bound takes part in the multipliers' fit when within this of its limit
/// (scaled: relative to the constraint's scale, or to the variable's range). An interior-point
/// answer leaves its active constraints a little inside (Ipopt at 64 knots: slacks up to 3e-6
/// with multipliers 4e-6), so the limit is looser than the feasibility tolerance; a constraint
/// that is fitted but not at its limit shows in the complementarity (its multiplier times its
/// slack).
inline constexpr double kCertificateActiveTolerance = 1e-4;

/// The first-order optimality check of an answer. With G = max(1, |grad f|_inf) (f the scaled
/// objective, minimised):
/// - stationarity = |grad f + sum_k mu_k grad c_k|_inf / G over the active constraints and
///   bounds c_k, mu the non-negative least-squares multipliers (free in sign for equalities);
/// - feasibility = the largest violation of a constraint, relative to its scale (bounds hold:
///   the point is clamped into them);
/// - complementarity = max_k mu_k slack_k / G (slack relative to the constraint's scale or the
///   variable's range);
/// - certified = each at most its tolerance.
struct DesignCertificate {
  /// False when no check was made (the input was refused, no design was returned, or the
  /// objective has no derivative: min_sting); the numbers are then NaN and certified false.
  bool checked = false;
  double stationarity = std::numeric_limits<double>::quiet_NaN();       ///< See above.
  double feasibility = std::numeric_limits<double>::quiet_NaN();        ///< See above.
  double complementarity = std::numeric_limits<double>::quiet_NaN();    ///< See above.
  double stationarity_tolerance = kDefaultStationarityTolerance;        ///< Its limit.
  double feasibility_tolerance = kDefaultFeasibilityTolerance;          ///< Its limit.
  double complementarity_tolerance = kDefaultComplementarityTolerance;  ///< Its limit.
  bool certified = false;  ///< Every condition within its tolerance.
  /// The active constraints' and bounds' gradients are linearly independent (LICQ), so the
  /// multipliers are unique; false: the answer's multipliers are not reported (NaN).
  bool multipliers_unique = false;
  int active = 0;  ///< Active constraints and bounds at the point.
  /// What failed, e.g. "stationarity 1.2e-02 > 1e-06" ("; "-separated); empty when certified.
  std::string failed;
  /// The estimated multipliers of the scaled problem, Ipopt's signs (grad f + J^T lambda - z_L
  /// + z_U = 0): one per constraint, per lower and per upper bound (0 where inactive).
  std::vector<double> lambda, z_lower, z_upper;
};

/// A constraint removed before the solve because another constraint (or a variable's bounds)
/// implies it: the same quantity, up to an affine map, with a range that contains the kept one's.
struct MergedConstraint {
  std::string name;  ///< The removed constraint, e.g. "rules.bbcor.drop".
  /// What implies it: a constraint's name ("mass_kg") or a variable's bounds
  /// ("profile.knots[3].radius_m").
  std::string into;
  /// One sentence, e.g. "rules.bbcor.drop (<= 3) repeats mass_kg (= 0.8505 kg) with the length
  /// fixed: ...".
  std::string message;
};

namespace design_detail {

/// The tolerances of a certificate (DesignOptions' fields of the same names).
struct CertificateTolerances {
  double stationarity = kDefaultStationarityTolerance;        ///< See DesignCertificate.
  double feasibility = kDefaultFeasibilityTolerance;          ///< See DesignCertificate.
  double complementarity = kDefaultComplementarityTolerance;  ///< See DesignCertificate.
  /// Up to this many variables the active gradients are factorised densely (column-pivoted
  /// QR), above it by a sparse QR (certificate.cpp); the tests compare the two.
  int dense_max_variables = 32;
};

/// The certificate of `model` at x (user units, inside the bounds). `check_uniqueness`: also
/// decide whether the multipliers are unique (an SVD of the active gradients; only the answer's
/// point needs it). `known`: a certificate this function already returned for the same model,
/// x and tolerances: its multipliers are taken (the same bits) instead of fitted again (the fit
/// is a dense least-squares solve over the active gradients, O(n^3): a tenth of a 256-knot
/// solve).
/// Not checked (checked false) for a derivative-free model or when the model cannot be
/// evaluated at x. Never throws.
DesignCertificate Certify(const DesignModel& model, const std::vector<double>& x,
                          const CertificateTolerances& tolerances, bool check_uniqueness,
                          const DesignCertificate* known = nullptr);

/// Finds the constraints of `model` that repeat another one (the same function up to an affine
/// map, checked on the exact gradients and values at three points of the box: the base design,
/// the middle, and 0.3 of the way) or a variable's bounds (the model's own "validity.*" guards
/// aside), and removes each one whose range (in
/// the other's quantity) contains the other's: *model becomes the model without them. A pair whose
/// ranges cross is kept (the certificate's uniqueness check reports the multipliers). Returns
/// what was removed. Never throws.
std::vector<MergedConstraint> MergeDuplicateConstraints(DesignModel* model);

/// min |A c - b|_2 over c with c_i >= 0 where !free[i] (Lawson and Hanson's active-set method,
/// free variables never clamped). Exposed for its test.
Eigen::VectorXd NonNegativeLeastSquares(const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                                        const std::vector<bool>& free);

}  // namespace design_detail
}  // namespace sweetspot::core
