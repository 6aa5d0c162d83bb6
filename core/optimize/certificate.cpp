// The certificate of a design answer (the merge of duplicated constraints is in
// certificate_merge.cpp). See certificate.hpp.
#include "core/optimize/certificate.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <Eigen/SparseQR>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/optimize/design_model.hpp"

namespace sweetspot::core::design_detail {
namespace {

// Columns whose smallest singular value (unit columns, column-pivoted QR) is below this are
// dependent: the multipliers are then not unique. An exact duplicate (a drop limit with the
// length fixed beside a mass limit) gives ~1e-16; independent active sets of the design problems
// give >= 1e-4 (taper chains, bounds, mass and balance).
constexpr double kDependentColumns = 1e-9;

// Above CertificateTolerances::dense_max_variables (32) the active gradients (a mass and a
// balance column, the rest one or two entries: diameter limits, taper steps) are factorised by a
// sparse QR (COLAMD ordering) in O(n) instead of the dense column-pivoted QR's O(n k^2): 37 M
// instructions per fit and as many per uniqueness check at 254 variables, a quarter of the
// solve. Smaller problems (every golden answer) keep the dense path and its last bits.
using SparseQr = Eigen::SparseQR<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>>;

}  // namespace

Eigen::VectorXd NonNegativeLeastSquares(const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                                        const std::vector<bool>& free) {
  const Eigen::Index k = a.cols();
  Eigen::VectorXd c = Eigen::VectorXd::Zero(k);
  if (k == 0) return c;
  std::vector<bool> passive(free.begin(), free.end());
  // Least squares over the passive columns (minimum norm when they are dependent).
  auto solve_passive = [&](const std::vector<bool>& p) {
    std::vector<Eigen::Index> idx;
    for (Eigen::Index i = 0; i < k; ++i)
      if (p[static_cast<std::size_t>(i)]) idx.push_back(i);
    Eigen::VectorXd z = Eigen::VectorXd::Zero(k);
    if (idx.empty()) return z;
    Eigen::MatrixXd ap(a.rows(), static_cast<Eigen::Index>(idx.size()));
    for (std::size_t q = 0; q < idx.size(); ++q)
      ap.col(static_cast<Eigen::Index>(q)) = a.col(idx[q]);
    const Eigen::VectorXd zp = ap.completeOrthogonalDecomposition().solve(b);
    for (std::size_t q = 0; q < idx.size(); ++q) z(idx[q]) = zp(static_cast<Eigen::Index>(q));
    return z;
  };
  // Most answers: every column's least-squares coefficient already has its sign.
  {
    const std::vector<bool> all(static_cast<std::size_t>(k), true);
    const Eigen::VectorXd z = solve_passive(all);
    bool ok = true;
    for (Eigen::Index i = 0; i < k; ++i)
      ok = ok && (free[static_cast<std::size_t>(i)] || z(i) >= 0.0);
    if (ok) return z;
  }
  c = solve_passive(passive);  // the free columns alone
  const double scale =
      std::max(1.0, b.lpNorm<Eigen::Infinity>()) * std::max(1.0, a.cwiseAbs().maxCoeff());
  const double tol = 1e-13 * scale;
  std::vector<bool> excluded(static_cast<std::size_t>(k), false);
  for (int outer = 0; outer < 3 * static_cast<int>(k) + 10; ++outer) {
    const Eigen::VectorXd w = a.transpose() * (b - a * c);
    Eigen::Index j = -1;
    double best = tol;
    for (Eigen::Index i = 0; i < k; ++i) {
      const auto ii = static_cast<std::size_t>(i);
      if (passive[ii] || excluded[ii]) continue;
      if (w(i) > best) {
        best = w(i);
        j = i;
      }
    }
    if (j < 0) break;
    passive[static_cast<std::size_t>(j)] = true;
    for (int inner = 0; inner < 3 * static_cast<int>(k) + 10; ++inner) {
      const Eigen::VectorXd z = solve_passive(passive);
      bool feasible = true;
      double alpha = 1.0;
      for (Eigen::Index i = 0; i < k; ++i) {
        const auto ii = static_cast<std::size_t>(i);
        if (!passive[ii] || free[ii] || z(i) > 0.0) continue;
        feasible = false;
        const double denom = c(i) - z(i);
        alpha = std::min(alpha, denom > 0.0 ? c(i) / denom : 0.0);
      }
      if (feasible) {
        c = z;
        break;
      }
      c += alpha * (z - c);
      bool dropped = false;
      for (Eigen::Index i = 0; i < k; ++i) {
        const auto ii = static_cast<std::size_t>(i);
        if (passive[ii] && !free[ii] && c(i) <= 0.0) {
          passive[ii] = false;
          c(i) = 0.0;
          dropped = true;
          // A column that leaves at once adds nothing (dependent on the passive ones): not
          // tried again this round.
          if (i == j) excluded[ii] = true;
        }
      }
      if (!dropped) break;
    }
    for (Eigen::Index i = 0; i < k; ++i)
      if (passive[static_cast<std::size_t>(i)]) excluded[static_cast<std::size_t>(i)] = false;
  }
  return c;
}

namespace {

// A column of the fit: a constraint's or a bound's gradient with the sign its multiplier has.
struct Column {
  enum Kind { kConstraint, kLower, kUpper } kind = kConstraint;
  int index = 0;       // constraint or variable index
  double sign = 1.0;   // +1: upper side (or an equality), -1: lower side
  double slack = 0.0;  // scaled distance to the limit (>= 0)
  bool free = false;   // equality: either sign
};

// The active constraints and bounds at s (within kCertificateActiveTolerance), as columns.
std::vector<Column> ActiveColumns(const ScaledDesignNlp& nlp, const std::vector<double>& s) {
  const int n = nlp.n(), m = nlp.m();
  std::vector<double> lower, upper;
  nlp.ConstraintBounds(&lower, &upper);
  const double act = kCertificateActiveTolerance;
  std::vector<Column> columns;
  for (int k = 0; k < m; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    const double g = nlp.g()[kk];
    const bool equality = lower[kk] == upper[kk];
    const bool at_upper = std::isfinite(upper[kk]) && upper[kk] - g <= act;
    const bool at_lower = std::isfinite(lower[kk]) && g - lower[kk] <= act;
    if (equality || (at_upper && at_lower)) {
      columns.push_back({Column::kConstraint, k, 1.0, 0.0, true});
    } else if (at_upper) {
      columns.push_back({Column::kConstraint, k, 1.0, std::max(0.0, upper[kk] - g), false});
    } else if (at_lower) {
      columns.push_back({Column::kConstraint, k, -1.0, std::max(0.0, g - lower[kk]), false});
    }
  }
  for (int j = 0; j < n; ++j) {
    const double v = s[static_cast<std::size_t>(j)];
    if (v <= act) columns.push_back({Column::kLower, j, -1.0, v, false});
    if (v >= 1.0 - act) columns.push_back({Column::kUpper, j, 1.0, 1.0 - v, false});
  }
  return columns;
}

// The columns' gradients (n x columns) and which are free in sign.
Eigen::MatrixXd ColumnMatrix(const ScaledDesignNlp& nlp, const std::vector<Column>& columns,
                             std::vector<bool>* free) {
  const int n = nlp.n();
  Eigen::MatrixXd a(n, static_cast<Eigen::Index>(columns.size()));
  free->assign(columns.size(), false);
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const Column& col = columns[c];
    const auto cc = static_cast<Eigen::Index>(c);
    if (col.kind == Column::kConstraint) {
      // The dense row's bits: sign times each entry, sign times 0 elsewhere.
      a.col(cc).setConstant(col.sign * 0.0);
      for (const auto& [j, v] : nlp.jacobian_rows()[static_cast<std::size_t>(col.index)])
        a(j, cc) = col.sign * v;
    } else {
      a.col(cc) = col.sign * Eigen::VectorXd::Unit(n, col.index);
    }
    (*free)[c] = col.free;
  }
  return a;
}

// The multipliers: the known certificate's at the same point (each column's from its
// constraint's or bound's entry: the same bits, the signs being +-1), else fitted (sparse
// least squares above dense_max_variables when every sign holds, else NonNegativeLeastSquares).
Eigen::VectorXd MultipliersOf(const std::vector<Column>& columns, const Eigen::MatrixXd& a,
                              const Eigen::VectorXd& grad, const std::vector<bool>& free, int m,
                              const CertificateTolerances& tolerances,
                              const DesignCertificate* known) {
  const auto n = static_cast<int>(a.rows());
  const auto a_count = static_cast<Eigen::Index>(columns.size());
  Eigen::VectorXd mu;
  if (known != nullptr && known->checked && known->active == static_cast<int>(a_count) &&
      known->lambda.size() == static_cast<std::size_t>(m) &&
      known->z_lower.size() == static_cast<std::size_t>(n) &&
      known->z_upper.size() == static_cast<std::size_t>(n)) {
    mu.resize(a_count);
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const Column& col = columns[c];
      const auto idx = static_cast<std::size_t>(col.index);
      mu(static_cast<Eigen::Index>(c)) = col.kind == Column::kConstraint
                                             ? col.sign * known->lambda[idx]
                                         : col.kind == Column::kLower ? known->z_lower[idx]
                                                                      : known->z_upper[idx];
    }
    return mu;
  }
  if (n > tolerances.dense_max_variables && a_count > 0) {
    // NonNegativeLeastSquares's first step, sparse: the least squares over every column,
    // the answer when each coefficient has its sign (the usual case at an optimum).
    const Eigen::SparseMatrix<double> sparse = a.sparseView();
    SparseQr qr;
    qr.compute(sparse);
    if (qr.info() == Eigen::Success) {
      const Eigen::VectorXd z = qr.solve(Eigen::VectorXd(-grad));
      bool ok = qr.info() == Eigen::Success && z.size() == a_count && z.allFinite();
      for (Eigen::Index i = 0; ok && i < a_count; ++i)
        ok = free[static_cast<std::size_t>(i)] || z(i) >= 0.0;
      if (ok) mu = z;
    }
  }
  if (mu.size() != a_count) mu = NonNegativeLeastSquares(a, -grad, free);
  return mu;
}

// Whether the active columns are independent (unique multipliers): a pivoted QR of the
// normalised columns, sparse above dense_max_variables.
bool MultipliersUnique(const Eigen::MatrixXd& a, const CertificateTolerances& tolerances) {
  const Eigen::Index n = a.rows(), a_count = a.cols();
  if (a_count == 0) return true;
  if (a_count > n) return false;
  Eigen::MatrixXd unit = a;
  bool zero = false;
  for (Eigen::Index c = 0; c < a_count; ++c) {
    const double norm = unit.col(c).norm();
    zero = zero || !(norm > 0.0);
    if (norm > 0.0) unit.col(c) /= norm;
  }
  if (zero) return false;
  if (n > tolerances.dense_max_variables) {
    const Eigen::SparseMatrix<double> sparse = unit.sparseView();
    SparseQr qr;
    qr.setPivotThreshold(kDependentColumns);
    qr.compute(sparse);
    return qr.info() == Eigen::Success && qr.rank() == a_count;
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(unit);
  qr.setThreshold(kDependentColumns);
  return qr.rank() == a_count;
}

// The certificate's verdict: what failed, each measure against its tolerance.
void Verdict(const CertificateTolerances& tolerances, DesignCertificate* cert) {
  auto fail = [cert](const char* what, double value, double tolerance) {
    cert->failed += (cert->failed.empty() ? "" : "; ") + std::string(what) + " " +
                    FormatNumber(value) + " > " + FormatNumber(tolerance);
  };
  if (!(cert->stationarity <= tolerances.stationarity))
    fail("stationarity", cert->stationarity, tolerances.stationarity);
  if (!(cert->feasibility <= tolerances.feasibility))
    fail("feasibility", cert->feasibility, tolerances.feasibility);
  if (!(cert->complementarity <= tolerances.complementarity))
    fail("complementarity", cert->complementarity, tolerances.complementarity);
  cert->certified = cert->failed.empty();
}

}  // namespace

DesignCertificate Certify(const DesignModel& model, const std::vector<double>& x,
                          const CertificateTolerances& tolerances, bool check_uniqueness,
                          const DesignCertificate* known) {
  DesignCertificate cert;
  cert.stationarity_tolerance = tolerances.stationarity;
  cert.feasibility_tolerance = tolerances.feasibility;
  cert.complementarity_tolerance = tolerances.complementarity;
  if (model.derivative_free() || x.size() != static_cast<std::size_t>(model.n())) return cert;
  try {
    ScaledDesignNlp nlp(model);
    std::vector<double> s = nlp.ToScaled(x);
    for (double& v : s) v = std::clamp(v, 0.0, 1.0);
    // The constraints' gradients by sparse rows: only the active ones are read.
    if (!nlp.EvaluateRows(s.data())) return cert;
    const int n = nlp.n(), m = nlp.m();
    const Eigen::VectorXd grad = nlp.grad_f();
    const double g_norm = std::max(1.0, grad.lpNorm<Eigen::Infinity>());
    const std::vector<Column> columns = ActiveColumns(nlp, s);
    std::vector<bool> free;
    const Eigen::MatrixXd a = ColumnMatrix(nlp, columns, &free);
    const Eigen::VectorXd mu = MultipliersOf(columns, a, grad, free, m, tolerances, known);
    const Eigen::VectorXd r = grad + a * mu;

    cert.checked = true;
    cert.active = static_cast<int>(columns.size());
    cert.stationarity = r.lpNorm<Eigen::Infinity>() / g_norm;
    cert.feasibility = std::max(0.0, nlp.Violation());
    cert.complementarity = 0.0;
    cert.lambda.assign(static_cast<std::size_t>(m), 0.0);
    cert.z_lower.assign(static_cast<std::size_t>(n), 0.0);
    cert.z_upper.assign(static_cast<std::size_t>(n), 0.0);
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const Column& col = columns[c];
      const double v = mu(static_cast<Eigen::Index>(c));
      if (!col.free) cert.complementarity = std::max(cert.complementarity, v * col.slack / g_norm);
      const auto idx = static_cast<std::size_t>(col.index);
      if (col.kind == Column::kConstraint) cert.lambda[idx] = col.sign * v;
      if (col.kind == Column::kLower) cert.z_lower[idx] = v;
      if (col.kind == Column::kUpper) cert.z_upper[idx] = v;
    }
    if (!std::isfinite(cert.stationarity)) cert.stationarity = kInf;
    if (check_uniqueness) cert.multipliers_unique = MultipliersUnique(a, tolerances);
    Verdict(tolerances, &cert);
  } catch (const std::exception&) {
    cert = DesignCertificate{};
    cert.stationarity_tolerance = tolerances.stationarity;
    cert.feasibility_tolerance = tolerances.feasibility;
    cert.complementarity_tolerance = tolerances.complementarity;
  }
  return cert;
}

}  // namespace sweetspot::core::design_detail
