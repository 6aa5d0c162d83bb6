// The certificate of a design answer and the merge of duplicated constraints. See
// certificate.hpp.
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

// Two constraints are the same function up to c_k = a c_l + b when, at every test point, the
// gradients agree to this (relative, max norm) and a and b stay the same to it: exact gradients
// of the same integrals agree to rounding (~1e-15).
constexpr double kDuplicateRelative = 1e-9;

// The merge's sums over a sparse row of at most this many entries have the dense sums' bits:
// two products (or squares) need one rounding in any order, and the zeros add nothing.
constexpr std::size_t kSparseExact = 2;

// A sparse row as a dense vector of n entries.
Eigen::VectorXd Dense(const DesignGradientRow& row, int n) {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
  for (const auto& [j, value] : row) v(j) = value;
  return v;
}

// The squared norm of a sparse row.
double SquaredNorm(const DesignGradientRow& row) {
  double s = 0.0;
  for (const auto& e : row) s += e.second * e.second;
  return s;
}

// The dot product of two sparse rows (both by increasing index).
double Dot(const DesignGradientRow& a, const DesignGradientRow& b) {
  double s = 0.0;
  for (std::size_t p = 0, q = 0; p < a.size() && q < b.size();) {
    if (a[p].first < b[q].first) {
      ++p;
    } else if (b[q].first < a[p].first) {
      ++q;
    } else {
      s += a[p++].second * b[q++].second;
    }
  }
  return s;
}

// max_j |a_j - t b_j| over two sparse rows (both by increasing index).
double MaxAbsDifference(const DesignGradientRow& a, double t, const DesignGradientRow& b) {
  double worst = 0.0;
  std::size_t p = 0, q = 0;
  while (p < a.size() || q < b.size()) {
    if (q == b.size() || (p < a.size() && a[p].first < b[q].first)) {
      worst = std::max(worst, std::abs(a[p++].second));
    } else if (p == a.size() || b[q].first < a[p].first) {
      worst = std::max(worst, std::abs(t * b[q++].second));
    } else {
      worst = std::max(worst, std::abs(a[p++].second - t * b[q++].second));
    }
  }
  return worst;
}

// A column of the fit: a constraint's or a bound's gradient with the sign its multiplier has.
struct Column {
  enum Kind { kConstraint, kLower, kUpper } kind = kConstraint;
  int index = 0;       // constraint or variable index
  double sign = 1.0;   // +1: upper side (or an equality), -1: lower side
  double slack = 0.0;  // scaled distance to the limit (>= 0)
  bool free = false;   // equality: either sign
};

std::string RangeText(double lo, double hi, const std::string& unit) {
  const std::string u = unit.empty() ? "" : " " + unit;
  if (lo == hi) return "= " + FormatNumber(lo) + u;
  if (std::isfinite(lo) && std::isfinite(hi))
    return "in [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]" + u;
  if (std::isfinite(hi)) return "<= " + FormatNumber(hi) + u;
  return ">= " + FormatNumber(lo) + u;
}

// Six significant digits (the relations of merged constraints).
std::string Short(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return buffer;
}

// [lo, hi] contains [a, b] (to rounding of the affine map: `slop`).
bool Contains(double lo, double hi, double a, double b, double slop) {
  return lo <= a + slop && hi >= b - slop;
}

// The test points: the base design, the box's middle and 0.3 of the way across it.
std::vector<std::vector<double>> TestPoints(const DesignModel& model) {
  std::vector<std::vector<double>> points = {model.BaseX()};
  for (double t : {0.5, 0.3}) {
    std::vector<double> x(static_cast<std::size_t>(model.n()));
    for (std::size_t j = 0; j < x.size(); ++j) {
      const DesignVariableSpec& v = model.variables()[j];
      x[j] = v.lower + t * (v.upper - v.lower);
    }
    points.push_back(std::move(x));
  }
  return points;
}

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

namespace {

// The merge's evaluations: the model at its test points, gradients by sparse rows.
struct MergePoints {
  std::vector<std::vector<double>> xs;  // the test points
  std::vector<DesignPoint> points;      // the evaluated ones
  std::vector<std::size_t> at;          // the x (index into xs) of each evaluated point
  const DesignGradientRow& row(std::size_t p, int k) const {
    return points[p].jacobian_rows[static_cast<std::size_t>(k)];
  }
};

// The model's own guards ("validity.*": a wall within every knot's radius, knots in order)
// are not the request's constraints: they are neither merged nor reported.
bool IsGuard(const DesignModel& model, int k) {
  return model.constraints()[static_cast<std::size_t>(k)].name.rfind("validity.", 0) == 0;
}

// A signature of each constraint's gradient direction at the first point (unit length, the
// largest entry positive, projected on a fixed vector), so that only neighbours in it are
// compared in full; sorted.
std::vector<std::pair<double, int>> Signatures(const DesignModel& model, const MergePoints& pts) {
  const int m = model.m(), n = model.n();
  Eigen::VectorXd probe(n);
  for (int j = 0; j < n; ++j) probe(j) = 1.0 + 0.5 * std::sin(1.0 + 0.7 * j);
  const double probe_norm = probe.norm();
  std::vector<std::pair<double, int>> signature;
  for (int k = 0; k < m; ++k) {
    if (IsGuard(model, k)) continue;
    const DesignGradientRow& r = pts.row(0, k);
    if (r.empty()) continue;  // fixed: no variable changes it
    if (r.size() > kSparseExact) {
      Eigen::VectorXd row = Dense(r, n);
      const double norm = row.norm();
      if (!(norm > 0.0) || !row.allFinite()) continue;
      Eigen::Index big = 0;
      row.cwiseAbs().maxCoeff(&big);
      row /= row(big) > 0 ? norm : -norm;
      signature.push_back({row.dot(probe) / probe_norm, k});
      continue;
    }
    // At most kSparseExact entries: every sum below has one rounding at most per term, in
    // any order, so the sparse sums have the dense ones' bits (the zeros add nothing).
    const double norm = std::sqrt(SquaredNorm(r));
    if (!(norm > 0.0) || !std::isfinite(norm)) continue;
    std::size_t big = 0;
    for (std::size_t e = 1; e < r.size(); ++e)
      if (std::abs(r[e].second) > std::abs(r[big].second)) big = e;
    const double divisor = r[big].second > 0 ? norm : -norm;
    double dot = 0.0;
    for (const auto& [j, v] : r) dot += (v / divisor) * probe(j);
    signature.push_back({dot / probe_norm, k});
  }
  std::sort(signature.begin(), signature.end());
  return signature;
}

// c_k = a c_l + b at every test point: *a, *b.
bool Affine(const MergePoints& pts, int n, int k, int l, double* a, double* b) {
  for (std::size_t p = 0; p < pts.points.size(); ++p) {
    const DesignGradientRow& rk = pts.row(p, k);
    const DesignGradientRow& rl = pts.row(p, l);
    double nl = 0.0, ap = 0.0, residual = 0.0, gk_max = 0.0;
    if (rk.size() > kSparseExact || rl.size() > kSparseExact) {
      const Eigen::VectorXd gk = Dense(rk, n), gl = Dense(rl, n);
      nl = gl.squaredNorm();
      if (!(nl > 0.0)) return false;
      ap = gk.dot(gl) / nl;
      residual = (gk - ap * gl).lpNorm<Eigen::Infinity>();
      gk_max = gk.lpNorm<Eigen::Infinity>();
    } else {
      nl = SquaredNorm(rl);
      if (!(nl > 0.0)) return false;
      ap = Dot(rk, rl) / nl;
      residual = MaxAbsDifference(rk, ap, rl);
      for (const auto& e : rk) gk_max = std::max(gk_max, std::abs(e.second));
    }
    if (residual > kDuplicateRelative * gk_max) return false;
    const double ck = pts.points[p].constraints[static_cast<std::size_t>(k)];
    const double cl = pts.points[p].constraints[static_cast<std::size_t>(l)];
    const double bp = ck - ap * cl;
    if (p == 0) {
      *a = ap;
      *b = bp;
    } else if (std::abs(ap - *a) > kDuplicateRelative * std::abs(*a) ||
               std::abs(bp - *b) > kDuplicateRelative * (std::abs(ck) + std::abs(ap * cl))) {
      return false;
    }
  }
  return std::isfinite(*a) && *a != 0.0 && std::isfinite(*b);
}

// Pairs of constraints on the same quantity (neighbours in the signature, affine in each other
// at every test point) that share a limit: the implied one is merged into the other.
void MergePairs(const DesignModel& model, const MergePoints& pts,
                const std::vector<std::pair<double, int>>& signature, std::vector<bool>* removed,
                std::vector<MergedConstraint>* merged) {
  const auto& cs = model.constraints();
  for (std::size_t p = 0; p < signature.size(); ++p) {
    for (std::size_t q = p + 1; q < signature.size(); ++q) {
      if (signature[q].first - signature[p].first > 1e-7) break;
      int k = signature[q].second, l = signature[p].second;
      if (k < l) std::swap(k, l);  // k the later constraint (removed on a tie)
      if ((*removed)[static_cast<std::size_t>(k)] || (*removed)[static_cast<std::size_t>(l)])
        continue;
      double a = 0.0, b = 0.0;
      if (!Affine(pts, model.n(), k, l, &a, &b)) continue;
      const DesignConstraintSpec& ck = cs[static_cast<std::size_t>(k)];
      const DesignConstraintSpec& cl = cs[static_cast<std::size_t>(l)];
      // c_k's range in c_l's quantity.
      double lo = (ck.lower - b) / a, hi = (ck.upper - b) / a;
      if (a < 0) std::swap(lo, hi);
      const double slop = 1e-12 * std::max({1.0, std::abs(cl.lower) * std::isfinite(cl.lower),
                                            std::abs(cl.upper) * std::isfinite(cl.upper)});
      // Only a pair that can be active together (a shared limit) is merged: a redundant
      // limit strictly inside the other's range never binds and changes nothing.
      const bool shares = (std::isfinite(lo) && (std::abs(lo - cl.lower) <= slop ||
                                                 std::abs(lo - cl.upper) <= slop)) ||
                          (std::isfinite(hi) &&
                           (std::abs(hi - cl.lower) <= slop || std::abs(hi - cl.upper) <= slop));
      if (!shares) continue;
      const std::string relation = ck.name + " = " + Short(a) + " " + cl.name +
                                   (b < 0 ? " - " : " + ") + Short(std::abs(b));
      int drop = -1, keep = -1;
      if (Contains(lo, hi, cl.lower, cl.upper, slop)) {
        drop = k;
        keep = l;
      } else if (Contains(cl.lower, cl.upper, lo, hi, slop)) {
        drop = l;
        keep = k;
      } else {
        continue;  // the ranges cross: both stay
      }
      const DesignConstraintSpec& d = cs[static_cast<std::size_t>(drop)];
      const DesignConstraintSpec& kept = cs[static_cast<std::size_t>(keep)];
      MergedConstraint mc;
      mc.name = d.name;
      mc.into = kept.name;
      mc.message = d.name + " (" + RangeText(d.lower, d.upper, d.unit) + ") and " + kept.name +
                   " (" + RangeText(kept.lower, kept.upper, kept.unit) +
                   ") constrain the same quantity (" + relation +
                   " for every design the "
                   "variables give) and share a limit: " +
                   kept.name + " implies " + d.name +
                   ", which is merged into it (its multiplier would not be unique)";
      merged->push_back(std::move(mc));
      (*removed)[static_cast<std::size_t>(drop)] = true;
    }
  }
}

// A constraint on one variable alone whose limit is one of the variable's bounds and whose
// range contains them: both would be active together; merged into the bounds.
void MergeIntoBounds(const DesignModel& model, const MergePoints& pts, std::vector<bool>* removed,
                     std::vector<MergedConstraint>* merged) {
  for (int k = 0; k < model.m(); ++k) {
    if ((*removed)[static_cast<std::size_t>(k)] || IsGuard(model, k)) continue;
    // One variable alone: every point's row has its one entry (the zeros are not kept).
    int var = -1;
    bool single = true;
    for (std::size_t p = 0; p < pts.points.size() && single; ++p) {
      for (const auto& e : pts.row(p, k)) {
        if (var >= 0 && var != e.first) single = false;
        var = e.first;
      }
    }
    if (!single || var < 0) continue;
    auto entry = [&pts, k](std::size_t p) {
      const DesignGradientRow& r = pts.row(p, k);
      return r.empty() ? 0.0 : r.front().second;
    };
    const double a = entry(0);
    bool linear = true;
    for (std::size_t p = 0; p < pts.points.size(); ++p)
      linear = linear && std::abs(entry(p) - a) <= kDuplicateRelative * std::abs(a);
    if (!linear) continue;
    const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
    const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(var)];
    const double b = pts.points.front().constraints[static_cast<std::size_t>(k)] -
                     a * pts.xs[pts.at.front()][static_cast<std::size_t>(var)];
    double lo = (c.lower - b) / a, hi = (c.upper - b) / a;
    if (a < 0) std::swap(lo, hi);
    const double slop = 1e-12 * std::max({1.0, std::abs(v.lower), std::abs(v.upper)});
    const bool shares = std::abs(lo - v.lower) <= slop || std::abs(hi - v.upper) <= slop;
    if (!shares || !Contains(lo, hi, v.lower, v.upper, slop)) continue;
    MergedConstraint mc;
    mc.name = c.name;
    mc.into = v.path;
    mc.message =
        c.name + " (" + RangeText(c.lower, c.upper, c.unit) + ") repeats a bound of " + v.path +
        " (in [" + FormatNumber(v.lower) + ", " + FormatNumber(v.upper) +
        "]) and shares a limit with them: the bounds imply it, so it is merged into them (its "
        "multiplier would not be unique)";
    merged->push_back(std::move(mc));
    (*removed)[static_cast<std::size_t>(k)] = true;
  }
}

}  // namespace

std::vector<MergedConstraint> MergeDuplicateConstraints(DesignModel* model) {
  std::vector<MergedConstraint> merged;
  const int m = model->m(), n = model->n();
  if (m == 0 || n == 0) return merged;
  try {
    MergePoints pts;
    pts.xs = TestPoints(*model);
    for (std::size_t i = 0; i < pts.xs.size(); ++i) {
      DesignPoint p;
      // The gradients by sparse rows (a knot's limit has 1 entry, the taper 2): the checks
      // below are O(entries), not O(m n), with the dense checks' bits (Row, Dot, Norm).
      if (!model->EvaluateRows(pts.xs[i].data(), &p)) continue;
      pts.points.push_back(std::move(p));
      pts.at.push_back(i);
    }
    if (pts.points.size() < 2) return merged;
    std::vector<bool> removed(static_cast<std::size_t>(m), false);
    MergePairs(*model, pts, Signatures(*model, pts), &removed, &merged);
    MergeIntoBounds(*model, pts, &removed, &merged);
    if (merged.empty()) return merged;
    std::vector<int> keep;
    for (int k = 0; k < m; ++k)
      if (!removed[static_cast<std::size_t>(k)]) keep.push_back(k);
    *model = model->WithConstraints(keep);
  } catch (const std::exception&) {
    merged.clear();
  }
  return merged;
}

}  // namespace sweetspot::core::design_detail
