// The least-squares objective's residuals, the polish after the optimiser's stop and the
// first-order check. See least_squares_polish.hpp.
#include "core/optimize/least_squares_polish.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include <Eigen/Dense>

#include "core/numerics/limits.hpp"
#include "core/optimize/design_integrals.hpp"

namespace sweetspot::core {

bool DesignModel::LeastSquaresResiduals(const double* x, Eigen::VectorXd* r,
                                        Eigen::MatrixXd* jacobian) const {
  if (!least_squares_.has_value()) return false;
  const LeastSquaresTargets& targets = *least_squares_;
  const std::vector<double> t = ParametersAt(x);
  design_detail::Integrals in;
  design_detail::ComputeIntegrals(
      {t, parameter_variable_, parameter_scale_, num_knots_, hollow_, has_fill_, rigid_, c0_}, n(),
      jacobian != nullptr, &in);
  const double mass = in.p[0];
  if (!(mass > 0.0)) return false;
  const double offset = in.p[1] / mass;  // C - c0
  const int m = (targets.mass_kg ? 1 : 0) + (targets.balance_point_m ? 1 : 0);
  r->resize(m);
  if (jacobian != nullptr) jacobian->resize(m, n());
  int row = 0;
  if (targets.mass_kg.has_value()) {
    (*r)[row] = (mass - *targets.mass_kg) / targets.mass_scale_kg;
    if (jacobian != nullptr) jacobian->row(row) = in.dp.row(0) / targets.mass_scale_kg;
    ++row;
  }
  if (targets.balance_point_m.has_value()) {
    (*r)[row] = ((c0_ - *targets.balance_point_m) + offset) / targets.balance_point_scale_m;
    // dC = (dS1 - (C - c0) dM) / M.
    if (jacobian != nullptr) {
      jacobian->row(row) =
          (in.dp.row(1) - offset * in.dp.row(0)) / (mass * targets.balance_point_scale_m);
    }
  }
  return r->allFinite() && (jacobian == nullptr || jacobian->allFinite());
}

namespace design_detail {
namespace {

// True when every constraint of the model holds at the point.
bool MeetsConstraints(const DesignModel& model, const DesignPoint& point) {
  for (std::size_t k = 0; k < model.constraints().size(); ++k) {
    const DesignConstraintSpec& c = model.constraints()[k];
    const double g = point.constraints[k];
    if (!(g >= c.lower && g <= c.upper)) return false;
  }
  return true;
}

// The variables' widths upper - lower (the solvers' scaling).
Eigen::VectorXd Widths(const DesignModel& model) {
  Eigen::VectorXd w(model.n());
  for (int j = 0; j < model.n(); ++j) {
    const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(j)];
    w[j] = v.upper - v.lower;
  }
  return w;
}

// The Gauss-Newton step in s (minimum norm, least squares when the targets cannot be met)
// over the variables free to move: one at a bound that the step would push beyond it is held
// there, and the step recomputed without it (a closest point on a bound: the paper's Table 2).
Eigen::VectorXd ProjectedStep(const DesignModel& model, const std::vector<double>& x,
                              const Eigen::MatrixXd& jac_s, const Eigen::VectorXd& r) {
  const int n = model.n();
  std::vector<bool> held(static_cast<std::size_t>(n), false);
  Eigen::VectorXd step = Eigen::VectorXd::Zero(n);
  for (int pass = 0; pass <= n; ++pass) {
    std::vector<int> free;
    for (int j = 0; j < n; ++j) {
      if (!held[static_cast<std::size_t>(j)]) free.push_back(j);
    }
    step.setZero();
    if (free.empty()) break;
    Eigen::MatrixXd a(jac_s.rows(), static_cast<int>(free.size()));
    for (std::size_t c = 0; c < free.size(); ++c) a.col(static_cast<int>(c)) = jac_s.col(free[c]);
    const Eigen::VectorXd d = a.completeOrthogonalDecomposition().solve(-r);
    for (std::size_t c = 0; c < free.size(); ++c) step[free[c]] = d[static_cast<int>(c)];
    bool changed = false;
    for (int j : free) {
      const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(j)];
      const double xj = x[static_cast<std::size_t>(j)];
      if ((xj <= v.lower && step[j] < 0.0) || (xj >= v.upper && step[j] > 0.0)) {
        held[static_cast<std::size_t>(j)] = true;
        changed = true;
      }
    }
    if (!changed) break;
  }
  return step;
}

// |2 J_s^T r| over the components a move inside the bounds can follow (a variable at a bound
// whose descent direction leaves the bounds is left out): the first-order residual on the box.
double ProjectedGradientNorm(const DesignModel& model, const std::vector<double>& x,
                             const Eigen::MatrixXd& jac_s, const Eigen::VectorXd& r) {
  const Eigen::VectorXd g = 2.0 * jac_s.transpose() * r;
  double sum = 0.0;
  for (int j = 0; j < model.n(); ++j) {
    const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(j)];
    const double xj = x[static_cast<std::size_t>(j)];
    if ((xj <= v.lower && g[j] > 0.0) || (xj >= v.upper && g[j] < 0.0)) continue;
    sum += g[j] * g[j];
  }
  return std::sqrt(sum);
}

}  // namespace

std::vector<double> GivenStartOr(const DesignModel& model,
                                 const std::vector<std::vector<double>>& given, int i,
                                 std::vector<double> otherwise) {
  if (i < 0 || static_cast<std::size_t>(i) >= given.size()) return otherwise;
  std::vector<double> x = given[static_cast<std::size_t>(i)];
  if (x.size() != model.variables().size()) return otherwise;
  for (std::size_t j = 0; j < x.size(); ++j) {
    x[j] = std::clamp(x[j], model.variables()[j].lower, model.variables()[j].upper);
  }
  return x;
}

void PolishLeastSquares(const DesignModel& model, std::vector<double>* x, Summary* summary) {
  if (!model.least_squares()) return;
  const int n = model.n();
  const Eigen::VectorXd width = Widths(model);
  const double tolerance = 1e-3 * model.least_squares_tolerance();
  DesignPoint point;
  int evaluations = 1;
  if (!model.Evaluate(x->data(), false, &point)) {
    summary->evaluations += evaluations;
    return;
  }
  double best_phi = point.objective;
  int steps = 0;
  for (int iter = 0; iter < 50; ++iter) {
    Eigen::VectorXd r;
    Eigen::MatrixXd jac;
    ++evaluations;
    if (!model.LeastSquaresResiduals(x->data(), &r, &jac)) break;
    if (r.lpNorm<Eigen::Infinity>() <= tolerance) break;
    const Eigen::MatrixXd jac_s = jac * width.asDiagonal();  // d r / d s
    const Eigen::VectorXd step = ProjectedStep(model, *x, jac_s, r);
    const double gradient = ProjectedGradientNorm(model, *x, jac_s, r);
    bool accepted = false;
    double alpha = 1.0;
    for (int halving = 0; halving < 30; ++halving, alpha *= 0.5) {
      std::vector<double> trial = *x;
      for (int j = 0; j < n; ++j) {
        const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(j)];
        const double s = (trial[static_cast<std::size_t>(j)] - v.lower) / width[j];
        trial[static_cast<std::size_t>(j)] =
            v.lower + width[j] * std::clamp(s + alpha * step[j], 0.0, 1.0);
      }
      if (trial == *x) break;  // the step is below the variables' resolution
      DesignPoint q;
      ++evaluations;
      if (!model.Evaluate(trial.data(), false, &q) || !MeetsConstraints(model, q)) continue;
      // A decrease of phi beyond its rounding; or, where phi is flat to its rounding (near a
      // closest point that no target meets: phi changes by ~|dx|^2 there), a step that halves
      // the first-order residual, which locates the stationary point to the gradient's
      // rounding instead. phi's rounding: 2 |r|_1 times the residuals' (a few eps of values of
      // size 1), with a margin of 8.
      const double noise = 16.0 * kEps * r.lpNorm<1>();
      bool better = q.objective < best_phi - noise;
      if (!better && q.objective <= best_phi + noise) {
        Eigen::VectorXd rq;
        Eigen::MatrixXd jq;
        ++evaluations;
        better = model.LeastSquaresResiduals(trial.data(), &rq, &jq) &&
                 ProjectedGradientNorm(model, trial, jq * width.asDiagonal(), rq) < 0.5 * gradient;
      }
      if (better) {
        best_phi = std::min(best_phi, q.objective);
        *x = std::move(trial);
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
    ++steps;
  }
  summary->iterations += steps;
  summary->evaluations += evaluations;
}

double LeastSquaresKktError(const DesignModel& model, const std::vector<double>& x) {
  const int n = model.n();
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  if (!model.LeastSquaresResiduals(x.data(), &r, &jac)) return kNaN;
  const Eigen::VectorXd width = Widths(model);
  const Eigen::MatrixXd jac_s = jac * width.asDiagonal();
  const Eigen::VectorXd grad = 2.0 * jac_s.transpose() * r;
  const double scale = 2.0 * jac_s.norm() * r.norm();
  if (!(scale > 0.0)) return 0.0;
  // A metric flat to rounding: moving the unknowns over their whole bounds (s in [0, 1])
  // changes no scaled residual by more than the mass properties resolve (a few eps of values
  // of size 1 + |r|), e.g. where a taper between equal radii starts and ends. Every point is
  // then stationary; without this, rounding noise divided by a scale made of the same noise
  // reads as a first-order residual of ~1 (a flat fit reported as not certified).
  if (jac_s.lpNorm<Eigen::Infinity>() <= 64.0 * kEps * (1.0 + r.lpNorm<Eigen::Infinity>())) {
    return 0.0;
  }
  // The active bounds and constraints, each by its outward normal in s.
  std::vector<Eigen::VectorXd> normals;
  constexpr double kActive = 1e-9;
  for (int j = 0; j < n; ++j) {
    const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(j)];
    const double s = (x[static_cast<std::size_t>(j)] - v.lower) / width[j];
    if (s <= kActive) normals.push_back(-Eigen::VectorXd::Unit(n, j));
    if (s >= 1.0 - kActive) normals.push_back(Eigen::VectorXd::Unit(n, j));
  }
  DesignPoint point;
  if (!model.Evaluate(x.data(), true, &point)) return kNaN;
  for (int k = 0; k < model.m(); ++k) {
    const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
    const double g = point.constraints[static_cast<std::size_t>(k)];
    const Eigen::VectorXd normal = width.cwiseProduct(point.jacobian.row(k).transpose());
    const double near = kActive * std::max(c.scale, 1.0);
    if (std::isfinite(c.upper) && g >= c.upper - near) normals.push_back(normal);
    if (std::isfinite(c.lower) && g <= c.lower + near) normals.push_back(-normal);
  }
  // min over lambda >= 0 of |grad + A lambda| by a small active-set loop: drop the most
  // negative multiplier until none is.
  std::vector<bool> in(normals.size(), true);
  Eigen::VectorXd best = grad;
  for (std::size_t round = 0; round <= normals.size(); ++round) {
    std::vector<int> cols;
    for (std::size_t i = 0; i < normals.size(); ++i) {
      if (in[i]) cols.push_back(static_cast<int>(i));
    }
    if (cols.empty()) {
      best = grad;
      break;
    }
    Eigen::MatrixXd a(n, static_cast<int>(cols.size()));
    for (std::size_t c = 0; c < cols.size(); ++c) a.col(static_cast<int>(c)) = normals[cols[c]];
    const Eigen::VectorXd lambda = a.completeOrthogonalDecomposition().solve(-grad);
    int most_negative = -1;
    double lowest = 0.0;
    for (std::size_t c = 0; c < cols.size(); ++c) {
      if (lambda[static_cast<int>(c)] < lowest) {
        lowest = lambda[static_cast<int>(c)];
        most_negative = cols[c];
      }
    }
    best = grad + a * lambda;
    if (most_negative < 0) break;
    in[static_cast<std::size_t>(most_negative)] = false;
  }
  return best.norm() / scale;
}

}  // namespace design_detail
}  // namespace sweetspot::core
