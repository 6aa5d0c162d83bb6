// ScaledDesignNlp: the design model as the solvers see it (variables scaled to [0, 1], scaled
// objective and constraints, cached values and gradients). See design_model.hpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/optimize/design_model.hpp"

namespace sweetspot::core {

// ---------------------------------------------------------------------------------------------
// ScaledDesignNlp.

ScaledDesignNlp::ScaledDesignNlp(const DesignModel& model) : model_(model) {
  const int n = model.n();
  width_.resize(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) {
    const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(j)];
    width_[static_cast<std::size_t>(j)] = v.upper - v.lower;
  }
  // Jacobian structure from a gradient at the start (linear rows: exact; nonlinear rows: all
  // variables, since every variable moves the mass integrals).
  structure_.resize(static_cast<std::size_t>(model.m()));
  // Parameter -> the variables that set it (a linear row's variables in O(its terms)).
  std::vector<std::vector<int>> setters;
  for (int j = 0; j < n; ++j) {
    for (int idx : model.variables()[static_cast<std::size_t>(j)].parameters) {
      if (idx >= static_cast<int>(setters.size())) setters.resize(static_cast<std::size_t>(idx) + 1);
      setters[static_cast<std::size_t>(idx)].push_back(j);
    }
  }
  for (int k = 0; k < model.m(); ++k) {
    const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
    std::vector<int>& row = structure_[static_cast<std::size_t>(k)];
    if (c.f.function == DesignFunction::kLinear) {
      for (const auto& [pidx, coef] : c.f.terms) {
        if (coef == 0.0 || pidx < 0 || pidx >= static_cast<int>(setters.size())) continue;
        for (int j : setters[static_cast<std::size_t>(pidx)]) row.push_back(j);
      }
      std::sort(row.begin(), row.end());  // sorted, distinct (a std::set allocated per entry)
      row.erase(std::unique(row.begin(), row.end()), row.end());
    } else {
      row.resize(static_cast<std::size_t>(n));
      for (int j = 0; j < n; ++j) row[static_cast<std::size_t>(j)] = j;
    }
  }
}

void ScaledDesignNlp::ConstraintBounds(std::vector<double>* lower,
                                       std::vector<double>* upper) const {
  lower->resize(static_cast<std::size_t>(m()));
  upper->resize(static_cast<std::size_t>(m()));
  for (int k = 0; k < m(); ++k) {
    const DesignConstraintSpec& c = model_.constraints()[static_cast<std::size_t>(k)];
    (*lower)[static_cast<std::size_t>(k)] = c.lower / c.scale;
    (*upper)[static_cast<std::size_t>(k)] = c.upper / c.scale;
  }
}

std::vector<double> ScaledDesignNlp::ToScaled(const std::vector<double>& x) const {
  std::vector<double> s(x.size());
  for (std::size_t j = 0; j < x.size(); ++j) {
    s[j] = (x[j] - model_.variables()[j].lower) / width_[j];
  }
  return s;
}

std::vector<double> ScaledDesignNlp::ToUser(const double* s) const {
  std::vector<double> x(width_.size());
  for (std::size_t j = 0; j < x.size(); ++j) {
    x[j] = model_.variables()[j].lower + width_[j] * s[j];
  }
  return x;
}

bool ScaledDesignNlp::Evaluate(const double* s, bool with_gradients) {
  const std::size_t n = width_.size();
  const bool same = have_values_ && std::equal(last_s_.begin(), last_s_.end(), s);
  if (same && (!with_gradients || have_gradients_)) return true;
  if (!same) {
    last_s_.assign(s, s + n);
    have_values_ = have_gradients_ = false;
  }
  const std::vector<double> x = ToUser(s);
  ++evaluations_;
  if (!model_.Evaluate(x.data(), with_gradients, &point_)) {
    have_values_ = false;
    return false;
  }
  const double sense = model_.maximize() ? -1.0 : 1.0;
  const double fs = sense / model_.objective_scale();
  f_ = fs * point_.objective;
  g_.resize(static_cast<std::size_t>(m()));
  for (int k = 0; k < m(); ++k) {
    g_[static_cast<std::size_t>(k)] = point_.constraints[static_cast<std::size_t>(k)] /
                                      model_.constraints()[static_cast<std::size_t>(k)].scale;
  }
  if (with_gradients) {
    grad_f_.resize(static_cast<Eigen::Index>(n));
    jacobian_.resize(m(), static_cast<Eigen::Index>(n));
    for (std::size_t j = 0; j < n; ++j) {
      const auto jj = static_cast<Eigen::Index>(j);
      grad_f_(jj) = fs * point_.objective_gradient(jj) * width_[j];
      for (int k = 0; k < m(); ++k) {
        jacobian_(k, jj) = point_.jacobian(k, jj) * width_[j] /
                           model_.constraints()[static_cast<std::size_t>(k)].scale;
      }
    }
    have_gradients_ = true;
  }
  have_values_ = true;
  return std::isfinite(f_);
}

bool ScaledDesignNlp::EvaluateRows(const double* s) {
  const std::size_t n = width_.size();
  // The values are cached for Evaluate(s, false); the dense Jacobian is not (Evaluate(s, true)
  // computes it again).
  last_s_.assign(s, s + n);
  have_values_ = have_gradients_ = false;
  const std::vector<double> x = ToUser(s);
  ++evaluations_;
  DesignPoint point;
  if (!model_.EvaluateRows(x.data(), &point)) return false;
  const double sense = model_.maximize() ? -1.0 : 1.0;
  const double fs = sense / model_.objective_scale();
  f_ = fs * point.objective;
  g_.resize(static_cast<std::size_t>(m()));
  rows_.resize(static_cast<std::size_t>(m()));
  for (int k = 0; k < m(); ++k) {
    const auto kk = static_cast<std::size_t>(k);
    const double scale = model_.constraints()[kk].scale;
    g_[kk] = point.constraints[kk] / scale;
    rows_[kk] = std::move(point.jacobian_rows[kk]);
    for (auto& [j, v] : rows_[kk]) v = v * width_[static_cast<std::size_t>(j)] / scale;
  }
  grad_f_.resize(static_cast<Eigen::Index>(n));
  for (std::size_t j = 0; j < n; ++j) {
    grad_f_(static_cast<Eigen::Index>(j)) =
        fs * point.objective_gradient(static_cast<Eigen::Index>(j)) * width_[j];
  }
  point_.objective = point.objective;
  have_values_ = true;
  return std::isfinite(f_);
}

bool ScaledDesignNlp::Hessian(const double* s, double sigma, const double* lambda,
                              Eigen::MatrixXd* out) const {
  const std::vector<double> x = ToUser(s);
  const double sense = model_.maximize() ? -1.0 : 1.0;
  std::vector<double> weights(static_cast<std::size_t>(m()));
  for (int k = 0; k < m(); ++k) {
    weights[static_cast<std::size_t>(k)] =
        lambda[k] / model_.constraints()[static_cast<std::size_t>(k)].scale;
  }
  if (!model_.Hessian(x.data(), sigma * sense / model_.objective_scale(), weights.data(), out)) {
    return false;
  }
  const Eigen::Map<const Eigen::VectorXd> w(width_.data(),
                                            static_cast<Eigen::Index>(width_.size()));
  *out = w.asDiagonal() * (*out) * w.asDiagonal();
  return out->allFinite();
}

double ScaledDesignNlp::Violation() const {
  double worst = 0.0;
  for (int k = 0; k < m(); ++k) {
    const DesignConstraintSpec& c = model_.constraints()[static_cast<std::size_t>(k)];
    const double g = g_[static_cast<std::size_t>(k)];
    worst = std::max({worst, c.lower / c.scale - g, g - c.upper / c.scale});
  }
  return worst;
}

}  // namespace sweetspot::core
