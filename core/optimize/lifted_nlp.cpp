// The lifted formulation of a design problem: see lifted_nlp.hpp.
#include "core/optimize/lifted_nlp.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "core/numerics/limits.hpp"

namespace sweetspot::core {

bool LiftedDesignNlp::Qualifies(const DesignModel& model, std::string* why) {
  auto no = [why](std::string reason) {
    if (why != nullptr) *why = std::move(reason);
    return false;
  };
  if (model.derivative_free()) return no("the objective has no derivatives");
  if (model.n() < 1) return no("no variables");
  const DesignParameterLayout lay{model.num_knots_};
  for (const DesignVariableSpec& v : model.variables()) {
    if (v.scale) return no("a scale variable (" + v.path + ")");
    for (int idx : v.parameters) {
      // Knot radii only: L (the last knot's position) stays fixed, so P's fourth entry is.
      if (idx < lay.KnotRadius(0) || idx > lay.KnotRadius(model.num_knots_ - 1)) {
        return no("a variable other than a knot radius (" + v.path + ")");
      }
    }
  }
  auto smooth = [&model](const DesignFunctionSpec& f) {
    return f.function == DesignFunction::kLinear || model.IsFunctionOfP(f.function);
  };
  if (!smooth(model.objective())) return no("the objective is not a function of P");
  for (const DesignConstraintSpec& c : model.constraints()) {
    if (!smooth(c.f)) return no("constraint " + c.name + " is not a function of P");
  }
  return true;
}

LiftedDesignNlp::LiftedDesignNlp(const ScaledDesignNlp& nlp)
    : model_(nlp.model()), nx_(nlp.n()), md_(nlp.m()) {
  const auto& vars = model_.variables();
  lower_.resize(static_cast<std::size_t>(nx_));
  width_.resize(static_cast<std::size_t>(nx_));
  for (int j = 0; j < nx_; ++j) {
    lower_[static_cast<std::size_t>(j)] = vars[static_cast<std::size_t>(j)].lower;
    width_[static_cast<std::size_t>(j)] =
        vars[static_cast<std::size_t>(j)].upper - vars[static_cast<std::size_t>(j)].lower;
  }
  // q's scales from the base design: M0, M0 L, M0 L^2 (S1 about the base's balance point is ~0
  // there, so its own value is no scale).
  const std::vector<double> x0 = model_.BaseX();
  const std::vector<double> t0 = model_.ParametersAt(x0.data());
  design_detail::Integrals in;
  design_detail::ComputeIntegrals(ContextAt(t0), nx_, false, &in);
  const double mass = std::isfinite(in.p[0]) && in.p[0] > 0.0 ? in.p[0] : 1.0;
  const double length = std::isfinite(in.p[3]) && in.p[3] > 0.0 ? in.p[3] : 1.0;
  sigma_ = {mass, mass * length, mass * length * length};
  const std::vector<std::map<int, double>> linear_rows = RowsToBounds(x0, t0);
  BuildJacobianStructure(linear_rows);
  SetLinearObjective();
  BuildHessianStructure(t0);
}

std::vector<std::map<int, double>> LiftedDesignNlp::RowsToBounds(const std::vector<double>& x0,
                                                                 const std::vector<double>& t0) {
  // A linear constraint of one variable s_j (g / scale = b + a s_j: a per-knot diameter limit)
  // becomes a bound on s_j (equalities stay rows); every other row is kept.
  const std::vector<int>& pvar = model_.parameter_variable_;
  const std::vector<double>& pscale = model_.parameter_scale_;
  s_lower_.assign(static_cast<std::size_t>(nx_), 0.0);
  s_upper_.assign(static_cast<std::size_t>(nx_), 1.0);
  lower_row_.assign(static_cast<std::size_t>(nx_), -1);
  upper_row_.assign(static_cast<std::size_t>(nx_), -1);
  lower_coef_.assign(static_cast<std::size_t>(nx_), 0.0);
  upper_coef_.assign(static_cast<std::size_t>(nx_), 0.0);
  std::vector<std::map<int, double>> linear_rows(static_cast<std::size_t>(md_));
  for (int k = 0; k < md_; ++k) {
    const DesignConstraintSpec& c = model_.constraints()[static_cast<std::size_t>(k)];
    if (c.f.function != DesignFunction::kLinear) {
      kept_.push_back(k);
      continue;
    }
    std::map<int, double>& row = linear_rows[static_cast<std::size_t>(k)];
    for (const auto& [idx, coef] : c.f.terms) {
      const int j = pvar[static_cast<std::size_t>(idx)];
      if (j < 0 || coef == 0.0) continue;
      row[j] += coef * pscale[static_cast<std::size_t>(idx)] *
                width_[static_cast<std::size_t>(j)] / c.scale;
    }
    if (row.size() != 1 || c.lower == c.upper || row.begin()->second == 0.0) {
      kept_.push_back(k);
      continue;
    }
    const auto j = static_cast<std::size_t>(row.begin()->first);
    const double coef = row.begin()->second;
    const double s0 = (x0[j] - lower_[j]) / width_[j];
    double v0 = c.f.constant;
    for (const auto& [idx, kc] : c.f.terms) v0 += kc * t0[static_cast<std::size_t>(idx)];
    const double b = v0 / c.scale - coef * s0;
    double lo = (c.lower / c.scale - b) / coef, hi = (c.upper / c.scale - b) / coef;
    if (coef < 0.0) std::swap(lo, hi);
    if (std::isfinite(lo) && lo > s_lower_[j]) {
      s_lower_[j] = lo;
      lower_row_[j] = k;
      lower_coef_[j] = coef;
    }
    if (std::isfinite(hi) && hi < s_upper_[j]) {
      s_upper_[j] = hi;
      upper_row_[j] = k;
      upper_coef_[j] = coef;
    }
  }
  bool bounds_ok = true;
  for (int j = 0; j < nx_; ++j) {
    bounds_ok = bounds_ok && s_lower_[static_cast<std::size_t>(j)] <=
                                 s_upper_[static_cast<std::size_t>(j)];
  }
  if (!bounds_ok) {  // an empty range: keep every row, so that Ipopt says infeasible
    kept_.clear();
    for (int k = 0; k < md_; ++k) kept_.push_back(k);
    s_lower_.assign(static_cast<std::size_t>(nx_), 0.0);
    s_upper_.assign(static_cast<std::size_t>(nx_), 1.0);
    lower_row_.assign(static_cast<std::size_t>(nx_), -1);
    upper_row_.assign(static_cast<std::size_t>(nx_), -1);
  }
  return linear_rows;
}

// The Jacobian: the kept rows (linear: the variables of their terms, constant values;
// functions of P: q's three columns), then the definitions (q_c, and every variable).
void LiftedDesignNlp::BuildJacobianStructure(
    const std::vector<std::map<int, double>>& linear_rows) {
  for (std::size_t r = 0; r < kept_.size(); ++r) {
    const int k = kept_[r];
    const DesignConstraintSpec& c = model_.constraints()[static_cast<std::size_t>(k)];
    row_start_.push_back(static_cast<int>(jac_.size()));
    if (c.f.function == DesignFunction::kLinear) {
      for (const auto& [j, v] : linear_rows[static_cast<std::size_t>(k)]) {
        jac_.push_back({static_cast<int>(r), j});
        linear_values_.push_back(v);
      }
    } else {
      for (int q = 0; q < 3; ++q) {
        jac_.push_back({static_cast<int>(r), nx_ + q});
        linear_values_.push_back(0.0);
      }
    }
  }
  const int mk = static_cast<int>(kept_.size());
  for (int q = 0; q < 3; ++q) {
    row_start_.push_back(static_cast<int>(jac_.size()));
    jac_.push_back({mk + q, nx_ + q});
    linear_values_.push_back(1.0);
    for (int j = 0; j < nx_; ++j) {
      jac_.push_back({mk + q, j});
      linear_values_.push_back(0.0);
    }
  }
  row_start_.push_back(static_cast<int>(jac_.size()));
  jac_values_.assign(jac_.size(), 0.0);
}

// A linear objective's constant gradient.
void LiftedDesignNlp::SetLinearObjective() {
  const std::vector<int>& pvar = model_.parameter_variable_;
  const std::vector<double>& pscale = model_.parameter_scale_;
  objective_linear_.assign(static_cast<std::size_t>(nx_), 0.0);
  if (model_.objective().function == DesignFunction::kLinear) {
    const double fs = (model_.maximize() ? -1.0 : 1.0) / model_.objective_scale();
    for (const auto& [idx, coef] : model_.objective().terms) {
      const int j = pvar[static_cast<std::size_t>(idx)];
      if (j < 0) continue;
      objective_linear_[static_cast<std::size_t>(j)] +=
          fs * coef * pscale[static_cast<std::size_t>(idx)] * width_[static_cast<std::size_t>(j)];
    }
  }
}

void LiftedDesignNlp::BuildHessianStructure(const std::vector<double>& t0) {
  // The Hessian's lower triangle: the pairs of variables the integrals couple (visited at the
  // base design; the structure does not depend on the point), then q's 3 x 3 block.
  std::set<std::pair<int, int>> pairs;
  design_detail::VisitIntegralHessian(ContextAt(t0), {1.0, 1.0, 1.0},
                                      [&pairs](int a, int b, double /*v*/) {
                                        if (a >= b) pairs.insert({a, b});
                                      });
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b <= a; ++b) pairs.insert({nx_ + a, nx_ + b});
  }
  // Explicit zeros within kHessianBand of the diagonal among the design variables (the
  // integrals couple adjacent knots only): the KKT matrix has the same values, but MUMPS's
  // elimination tree then has fewer, wider fronts, and its fixed cost per front, not the
  // arithmetic, is what a factorisation and a solve of this ~3n-row matrix cost (callgrind,
  // the n-knot design: -9 / -10 / -8 % instructions per solve at 64 / 128 / 256 knots with a
  // band of 4; 2 gives -7 %, 6 is worse at 128; docs/benchmarks.md, "Issue 36").
  constexpr int kHessianBand = 4;
  for (int a = 0; a < nx_; ++a) {
    for (int b = std::max(0, a - kHessianBand); b <= a; ++b) pairs.insert({a, b});
  }
  hess_.assign(pairs.begin(), pairs.end());
  hess_rows_.resize(static_cast<std::size_t>(n()));
  for (std::size_t e = 0; e < hess_.size(); ++e) {
    hess_rows_[static_cast<std::size_t>(hess_[e].first)].push_back(
        {hess_[e].second, static_cast<int>(e)});
  }
}

design_detail::IntegralContext LiftedDesignNlp::ContextAt(const std::vector<double>& t) const {
  return {t,
          model_.parameter_variable_,
          model_.parameter_scale_,
          model_.num_knots_,
          model_.hollow_,
          model_.has_fill_,
          model_.rigid_,
          model_.c0_};
}

std::vector<double> LiftedDesignNlp::XAt(const double* z) const {
  std::vector<double> x(static_cast<std::size_t>(nx_));
  for (std::size_t j = 0; j < x.size(); ++j) x[j] = lower_[j] + width_[j] * z[j];
  return x;
}

int LiftedDesignNlp::HessianIndex(int row, int col) const {
  for (const auto& [c, e] : hess_rows_[static_cast<std::size_t>(row)]) {
    if (c == col) return e;
  }
  return -1;
}

void LiftedDesignNlp::Bounds(std::vector<double>* z_lower, std::vector<double>* z_upper,
                             std::vector<double>* g_lower, std::vector<double>* g_upper) const {
  z_lower->assign(static_cast<std::size_t>(n()), -kInf);
  z_upper->assign(static_cast<std::size_t>(n()), kInf);
  std::copy(s_lower_.begin(), s_lower_.end(), z_lower->begin());
  std::copy(s_upper_.begin(), s_upper_.end(), z_upper->begin());
  g_lower->assign(static_cast<std::size_t>(m()), 0.0);
  g_upper->assign(static_cast<std::size_t>(m()), 0.0);
  for (std::size_t r = 0; r < kept_.size(); ++r) {
    const DesignConstraintSpec& c = model_.constraints()[static_cast<std::size_t>(kept_[r])];
    (*g_lower)[r] = c.lower / c.scale;
    (*g_upper)[r] = c.upper / c.scale;
  }
}

void LiftedDesignNlp::DesignMultipliers(const double* z_lower, const double* z_upper,
                                        const double* lambda, std::vector<double>* design_lambda,
                                        std::vector<double>* design_z_lower,
                                        std::vector<double>* design_z_upper) const {
  design_lambda->assign(static_cast<std::size_t>(md_), 0.0);
  for (std::size_t r = 0; r < kept_.size(); ++r) {
    (*design_lambda)[static_cast<std::size_t>(kept_[r])] = lambda[r];
  }
  design_z_lower->assign(z_lower, z_lower + nx_);
  design_z_upper->assign(z_upper, z_upper + nx_);
  // Stationarity in s_j: the bound's -z_L + z_U stands for the row's lambda_k a_k.
  for (std::size_t j = 0; j < static_cast<std::size_t>(nx_); ++j) {
    if (lower_row_[j] >= 0) {
      (*design_lambda)[static_cast<std::size_t>(lower_row_[j])] += -z_lower[j] / lower_coef_[j];
      (*design_z_lower)[j] = 0.0;
    }
    if (upper_row_[j] >= 0) {
      (*design_lambda)[static_cast<std::size_t>(upper_row_[j])] += z_upper[j] / upper_coef_[j];
      (*design_z_upper)[j] = 0.0;
    }
  }
}

bool LiftedDesignNlp::Start(const std::vector<double>& s0, std::vector<double>* z) const {
  const std::vector<double> x = XAt(s0.data());
  const std::vector<double> t = model_.ParametersAt(x.data());
  design_detail::Integrals in;
  design_detail::ComputeIntegrals(ContextAt(t), nx_, false, &in);
  z->assign(s0.begin(), s0.end());
  for (int q = 0; q < 3; ++q) {
    const double v = in.p[static_cast<std::size_t>(q)] / sigma_[static_cast<std::size_t>(q)];
    if (!std::isfinite(v)) return false;
    z->push_back(v);
  }
  return true;
}

bool LiftedDesignNlp::FunctionAt(const DesignFunctionSpec& f, const std::vector<double>& t,
                                 const double* p, double* value, double* gradient,
                                 double* hessian) const {
  if (f.function == DesignFunction::kLinear) {
    double v = f.constant;
    for (const auto& [idx, k] : f.terms) v += k * t[static_cast<std::size_t>(idx)];
    *value = v;
    return std::isfinite(v);
  }
  *value = model_.FunctionOfP(f.function, p, gradient, hessian);
  if (!std::isfinite(*value)) return false;
  for (int a = 0; gradient != nullptr && a < 4; ++a) {
    if (!std::isfinite(gradient[a])) return false;
  }
  for (int a = 0; hessian != nullptr && a < 16; ++a) {
    if (!std::isfinite(hessian[a])) return false;
  }
  return true;
}

bool LiftedDesignNlp::Evaluate(const double* z, bool with_gradients) {
  const std::size_t nz = static_cast<std::size_t>(n());
  const bool same = have_values_ && std::equal(last_z_.begin(), last_z_.end(), z);
  if (same && (!with_gradients || have_gradients_)) return true;
  if (!same) {
    last_z_.assign(z, z + nz);
    have_values_ = have_gradients_ = false;
  }
  ++evaluations_;
  const std::vector<double> x = XAt(z);
  const std::vector<double> t = model_.ParametersAt(x.data());
  design_detail::Integrals in;
  design_detail::ComputeIntegrals(ContextAt(t), nx_, with_gradients, &in);
  if (!(in.p[0] > 0.0) || !std::isfinite(in.p[1]) || !std::isfinite(in.p[2])) return false;
  // The lifted P: q's values, L the design's (fixed).
  const double p[4] = {sigma_[0] * z[nx_], sigma_[1] * z[nx_ + 1], sigma_[2] * z[nx_ + 2],
                       in.p[3]};
  const double fs = (model_.maximize() ? -1.0 : 1.0) / model_.objective_scale();
  double value = 0.0;
  double gradient[4] = {0, 0, 0, 0};
  if (!FunctionAt(model_.objective(), t, p, &value, with_gradients ? gradient : nullptr,
                  nullptr)) {
    return false;
  }
  f_ = fs * value;
  if (with_gradients) {
    grad_f_.assign(nz, 0.0);
    if (model_.objective().function == DesignFunction::kLinear) {
      std::copy(objective_linear_.begin(), objective_linear_.end(), grad_f_.begin());
    } else {
      for (int q = 0; q < 3; ++q) {
        grad_f_[static_cast<std::size_t>(nx_ + q)] =
            fs * gradient[q] * sigma_[static_cast<std::size_t>(q)];
      }
    }
    jac_values_ = linear_values_;
  }
  g_.assign(static_cast<std::size_t>(m()), 0.0);
  const int mk = static_cast<int>(kept_.size());
  for (int r = 0; r < mk; ++r) {
    const DesignConstraintSpec& c =
        model_.constraints()[static_cast<std::size_t>(kept_[static_cast<std::size_t>(r)])];
    const bool linear = c.f.function == DesignFunction::kLinear;
    if (!FunctionAt(c.f, t, p, &value, with_gradients && !linear ? gradient : nullptr, nullptr)) {
      return false;
    }
    g_[static_cast<std::size_t>(r)] = value / c.scale;
    if (with_gradients && !linear) {
      const int e = row_start_[static_cast<std::size_t>(r)];
      for (int q = 0; q < 3; ++q) {
        jac_values_[static_cast<std::size_t>(e + q)] =
            gradient[q] * sigma_[static_cast<std::size_t>(q)] / c.scale;
      }
    }
  }
  for (int q = 0; q < 3; ++q) {
    const auto qq = static_cast<std::size_t>(q);
    g_[static_cast<std::size_t>(mk + q)] = z[nx_ + q] - in.p[qq] / sigma_[qq];
    if (with_gradients) {
      // Entry row_start: q's column (1); then the variables in order.
      const int e = row_start_[static_cast<std::size_t>(mk + q)] + 1;
      for (int j = 0; j < nx_; ++j) {
        jac_values_[static_cast<std::size_t>(e + j)] =
            -in.dp(q, j) * width_[static_cast<std::size_t>(j)] / sigma_[qq];
      }
    }
  }
  if (!std::isfinite(f_) ||
      !std::all_of(g_.begin(), g_.end(), [](double v) { return std::isfinite(v); })) {
    return false;
  }
  if (with_gradients) {
    auto finite = [](double v) { return std::isfinite(v); };
    if (!std::all_of(grad_f_.begin(), grad_f_.end(), finite) ||
        !std::all_of(jac_values_.begin(), jac_values_.end(), finite)) {
      return false;
    }
    have_gradients_ = true;
  }
  have_values_ = true;
  return true;
}

bool LiftedDesignNlp::Hessian(const double* z, double sigma_f, const double* lambda,
                              double* values) {
  std::fill(values, values + hess_.size(), 0.0);
  const std::vector<double> x = XAt(z);
  const std::vector<double> t = model_.ParametersAt(x.data());
  // q's block: sigma_f f(P) + sum_k lambda_k g_k(P) over the functions of P.
  const double p[4] = {sigma_[0] * z[nx_], sigma_[1] * z[nx_ + 1], sigma_[2] * z[nx_ + 2],
                       t[static_cast<std::size_t>(
                           DesignParameterLayout{model_.num_knots_}.KnotPosition(
                               model_.num_knots_ - 1))]};
  double block[16] = {0};
  double hessian[16];
  double value = 0.0;
  auto add = [&](const DesignFunctionSpec& f, double weight) -> bool {
    if (f.function == DesignFunction::kLinear || weight == 0.0) return true;
    if (!FunctionAt(f, t, p, &value, nullptr, hessian)) return false;
    for (int a = 0; a < 16; ++a) block[a] += weight * hessian[a];
    return true;
  };
  const double fs = (model_.maximize() ? -1.0 : 1.0) / model_.objective_scale();
  if (!add(model_.objective(), sigma_f * fs)) return false;
  const int mk = static_cast<int>(kept_.size());
  for (int r = 0; r < mk; ++r) {
    const DesignConstraintSpec& c =
        model_.constraints()[static_cast<std::size_t>(kept_[static_cast<std::size_t>(r)])];
    if (!add(c.f, lambda[r] / c.scale)) return false;
  }
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b <= a; ++b) {
      values[HessianIndex(nx_ + a, nx_ + b)] = block[a * 4 + b] *
                                               sigma_[static_cast<std::size_t>(a)] *
                                               sigma_[static_cast<std::size_t>(b)];
    }
  }
  // The definitions' terms: -lambda_c / sigma_c d2P_c/dx2, chained to s (the widths).
  const std::array<double, 3> w = {-lambda[mk] / sigma_[0], -lambda[mk + 1] / sigma_[1],
                                   -lambda[mk + 2] / sigma_[2]};
  design_detail::VisitIntegralHessian(
      ContextAt(t), w, [this, values](int a, int b, double v) {
        if (a < b) return;  // the lower triangle (the visitor gives both orders)
        values[HessianIndex(a, b)] +=
            v * width_[static_cast<std::size_t>(a)] * width_[static_cast<std::size_t>(b)];
      });
  return std::all_of(values, values + hess_.size(), [](double v) { return std::isfinite(v); });
}

}  // namespace sweetspot::core
