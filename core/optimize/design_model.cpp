// The design problem as a smooth NLP: parameters, constraints, mass integrals with exact
// first and second derivatives, the closed-form objectives. See design_model.hpp.
#include "core/optimize/design_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <set>

#include "core/bat/geometry_integrals.hpp"
#include "core/collision/exit_speed_algebra.hpp"
#include "core/collision/rigid_pivot.hpp"
#include "core/flexible/beam_frequency.hpp"
#include "core/geometry_format.hpp"
#include "core/numerics/jet.hpp"
#include "core/numerics/limits.hpp"
#include "core/optimize/design_bbcor.hpp"
#include "core/optimize/design_integrals.hpp"
#include "core/optimize/least_squares_objective.hpp"
#include "core/scene/collide.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/scene/swing_speed.hpp"
#include "core/sweet_spot/sweet_spot.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
namespace {

// I(p) = S2 + 2 (c0 - p) S1 + (c0 - p)^2 M: the exact moment about p from the moments about c0.
template <typename T>
T MoiAbout(const T* p, double c0, double pivot) {
  const double d = c0 - pivot;
  return p[2] + (2.0 * d) * p[1] + (d * d) * p[0];
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Integrals and their derivatives.

std::vector<double> DesignModel::ParametersAt(const double* x) const {
  std::vector<double> t = base_parameters_;
  for (std::size_t idx = 0; idx < t.size(); ++idx) {
    const int j = parameter_variable_[idx];
    // A coefficient of 1 (path, paths) gives x[j] itself, bit for bit.
    if (j >= 0) t[idx] = parameter_scale_[idx] * x[j];
  }
  return t;
}

// ---------------------------------------------------------------------------------------------
// Functions of P = (M, S1, S2, L).

template <typename T>
T DesignModel::AngularSpeedOf(const T* p) const {
  // A swing given by its bat speed on a bat whose length varies: omega0 is a function of L =
  // p[3], so its derivatives (d omega0/dL = -v / (L - d - pivot)^2, and the second) come with
  // the jet's.
  const T omega0 = SwingAngularSpeedAt(p[3]);
  if (objective_kind_ == DesignObjective::kMaxExitSpeedSwingWeight && jet::Value(omega0) > 0.0 &&
      swing_weight_exponent_ != 0.0) {
    return omega0 * SwingWeightSpeedFactor(MoiAbout(p, c0_, kSixInchPivotM), i6_ref_,
                                           swing_weight_exponent_);
  }
  return omega0;
}

template <typename T, typename E>
T DesignModel::ObjectiveOf(const T* p, const E& e) const {
  if (objective_kind_ == DesignObjective::kMinMoi) return MoiAbout(p, c0_, kSixInchPivotM);
  if (objective_kind_ == DesignObjective::kLeastSquares) {
    return design_detail::LeastSquaresOf(p, c0_, *least_squares_);
  }
  const double m = ball_mass_kg_;
  const double u = ball_speed_mps_;
  const double pivot = pivot_from_knob_m_;
  const T j = MoiAbout(p, c0_, pivot);
  const T omega = AngularSpeedOf(p);
  // The closed forms (exit_speed_algebra.hpp, the code ExitSpeedProfile runs): x from the pivot
  // (rigid_pivot, RigidPivotProfile) or from the balance point (free_bat, FreeBatProfile).
  T origin(pivot);
  exit_speed::Form<T> form;
  if (free_bat_) {
    // Moments about c0: S1 = M (C - c0), so C = c0 + S1/M and I_cm = S2 - S1^2/M.
    origin = c0_ + p[1] / p[0];
    const T i_cm = p[2] - p[1] * p[1] / p[0];
    form = {T(u), (1.0 + e) * i_cm, u + omega * (origin - pivot), i_cm * (1.0 + m / p[0]), T(m),
            omega};
  } else {
    // exit_speed::RigidPivotForm's fields, with e a double or a jet.
    form = {T(u), (1.0 + e) * j, T(u), j, T(m), omega};
  }
  const T lo = -origin;        // the knob
  const T hi = p[3] - origin;  // the tip
  const exit_speed::Maximum<T> mx = exit_speed::MaximumOf(form);
  const bool beyond_tip = jet::Value(mx.x_m) > jet::Value(hi);
  const bool before_knob = jet::Value(mx.x_m) < jet::Value(lo);
  if (objective_kind_ != DesignObjective::kWidestSweetZone) {
    if (beyond_tip) return exit_speed::ExitSpeedAt(form, hi);
    if (before_knob) return exit_speed::ExitSpeedAt(form, lo);
    return mx.peak_mps - u;
  }
  // The sweet zone (ClosedFormSweetZone's algebra): where f(x) >= f(x_c) - tolerance, x_c the
  // sweet spot on the bat, i.e. within tolerance + (f(x*) - f(x_c)) of the maximum.
  T delta(zone_tolerance_mps_);
  if (beyond_tip || before_knob) {
    delta = delta + exit_speed::DeficitAt(form, mx, beyond_tip ? hi : T(lo));
  }
  const exit_speed::Zone<T> zone = exit_speed::ZoneAround(form, mx, delta);
  const T top = (zone.hi_open || jet::Value(zone.hi_m) > jet::Value(hi)) ? hi : zone.hi_m;
  const T bottom = (zone.lo_open || jet::Value(zone.lo_m) < jet::Value(lo)) ? lo : zone.lo_m;
  return top - bottom;
}

template <typename T>
T DesignModel::FunctionOf(DesignFunction f, const T* p) const {
  switch (f) {
    case DesignFunction::kMass:
      return p[0];
    case DesignFunction::kBalancePoint:
      return c0_ + p[1] / p[0];
    case DesignFunction::kMoiSixInch:
      return MoiAbout(p, c0_, kSixInchPivotM);
    case DesignFunction::kDrop:
      return p[3] * (1.0 / kMetresPerInch) - p[0] * (1.0 / kKilogramsPerOunce);
    case DesignFunction::kObjective:  // with cor_from_barrel() a function of the wall instead
      return barrel_cor_ ? T(kNaN) : ObjectiveOf(p, cor_);
    case DesignFunction::kLinear:
    case DesignFunction::kFirstFrequency:  // not a function of P (FrequencyOf)
    case DesignFunction::kBbcor:           // nor this (BbcorOf)
    case DesignFunction::kBoreBottom:      // nor this (BoreBottomOf)
      break;
  }
  return T(kNaN);
}

template <typename T>
T DesignModel::SwingAngularSpeedAt(const T& length_m) const {
  if (!omega_from_length_) return T(omega0_rad_s_);
  // ResolveSwing's arithmetic, so a design's omega is the one the scenes give its bat.
  return bat_speed_mps_ / ((length_m - bat_speed_from_tip_m_) - pivot_from_knob_m_);
}

double DesignModel::AngularSpeedFor(double i6_kg_m2, double length_m) const {
  const double omega0 = SwingAngularSpeedAt(length_m);
  if (objective_kind_ != DesignObjective::kMaxExitSpeedSwingWeight || omega0 == 0.0 ||
      swing_weight_exponent_ == 0.0) {
    return omega0;
  }
  return omega0 * SwingWeightSpeedFactor(i6_kg_m2, i6_ref_, swing_weight_exponent_);
}

std::vector<double> DesignModel::BaseX() const {
  std::vector<double> x(variables_.size());
  for (std::size_t j = 0; j < variables_.size(); ++j) {
    x[j] = std::clamp(variables_[j].base, variables_[j].lower, variables_[j].upper);
  }
  return x;
}

bool DesignModel::FrequencyOf(const std::vector<double>& t, double* value, double* gradient_row,
                              int stride) const {
  *value = kNaN;
  if (frequency_beam_ == nullptr) return false;
  const FirstBendingMode mode =
      ComputeFirstBendingMode(*frequency_beam_, t, gradient_row != nullptr);
  if (!mode.ok || !(mode.frequency_hz > 0.0)) return false;
  *value = mode.frequency_hz;
  if (gradient_row != nullptr) {
    // f = sqrt(lambda) / (2 pi): df/dlambda = 1 / (4 pi sqrt(lambda)) = 1 / (8 pi^2 f).
    const double df_dlambda = 1.0 / (8.0 * kPi * kPi * mode.frequency_hz);
    for (std::size_t idx = 0; idx < parameter_variable_.size(); ++idx) {
      const int j = parameter_variable_[idx];
      if (j < 0) continue;
      gradient_row[j * stride] +=
          df_dlambda * parameter_scale_[idx] * mode.lambda_gradient[static_cast<Eigen::Index>(idx)];
    }
  }
  return std::isfinite(*value);
}

double DesignModel::FirstFrequencyAt(const double* x) const {
  double f = kNaN;
  if (!FrequencyOf(ParametersAt(x), &f, nullptr, 1)) return kNaN;
  return f;
}

int DesignModel::frequency_elements() const {
  return frequency_beam_ == nullptr ? 0 : frequency_beam_->Elements();
}

double DesignModel::cor_impact_from_tip_m() const {
  return barrel_cor_ == nullptr ? kNaN : barrel_cor_->impact_from_tip_m;
}

double DesignModel::LinearValueAt(const DesignFunctionSpec& f, const std::vector<double>& t) {
  double v = f.constant;
  for (const auto& [idx, k] : f.terms) v += k * t[static_cast<std::size_t>(idx)];
  return v;
}

double DesignModel::Value(const DesignFunctionSpec& f, const double* x) const {
  if (f.function == DesignFunction::kObjective && objective_kind_ == DesignObjective::kMinSting) {
    return StingOf(BatAt(x), false).sting_j;  // NaN when it cannot be computed
  }
  if (f.function == DesignFunction::kObjective &&
      objective_kind_ == DesignObjective::kMaxDistance) {
    return DistanceOf(BatAt(x)).distance_m;  // NaN when it cannot be computed
  }
  if (f.function == DesignFunction::kFirstFrequency) return FirstFrequencyAt(x);
  const std::vector<double> t = ParametersAt(x);
  if (f.function == DesignFunction::kBoreBottom) {
    double v = kNaN;
    return BoreBottomOf(t, &v, nullptr, 1) ? v : kNaN;
  }
  if (IsWallFunction(f.function)) {
    double v = kNaN;
    if (!WallFunctionOf(f.function, t, &v, nullptr, 1)) return kNaN;
    return v;
  }
  if (f.function == DesignFunction::kLinear) {
    double v = f.constant;
    for (const auto& [idx, k] : f.terms) v += k * t[static_cast<std::size_t>(idx)];
    return v;
  }
  design_detail::Integrals in;
  design_detail::ComputeIntegrals(
      {t, parameter_variable_, parameter_scale_, num_knots_, hollow_, has_fill_, rigid_, c0_}, n(),
      false, &in);
  if (!(in.p[0] > 0.0)) return kNaN;
  const double v = FunctionOf<double>(f.function, in.p.data());
  return std::isfinite(v) ? v : kNaN;
}

bool DesignModel::Evaluate(const double* x, bool with_gradients, DesignPoint* out) const {
  return EvaluateImpl(x, with_gradients, false, out);
}

bool DesignModel::EvaluateRows(const double* x, DesignPoint* out) const {
  return EvaluateImpl(x, true, true, out);
}

bool DesignModel::EvaluateFunction(const DesignFunctionSpec& f, const std::vector<double>& t,
                                   const design_detail::Integrals& in, double* value,
                                   double* gradient_row, int stride) const {
  if (f.function == DesignFunction::kLinear) {
    double v = f.constant;
    for (const auto& [idx, k] : f.terms) {
      v += k * t[static_cast<std::size_t>(idx)];
      const int j = parameter_variable_[static_cast<std::size_t>(idx)];
      if (gradient_row != nullptr && j >= 0) {
        gradient_row[j * stride] += k * parameter_scale_[static_cast<std::size_t>(idx)];
      }
    }
    *value = v;
    return std::isfinite(v);
  }
  if (f.function == DesignFunction::kFirstFrequency) {
    return FrequencyOf(t, value, gradient_row, stride);
  }
  if (f.function == DesignFunction::kBoreBottom) {
    return BoreBottomOf(t, value, gradient_row, stride);
  }
  if (IsWallFunction(f.function)) {
    return WallFunctionOf(f.function, t, value, gradient_row, stride);
  }
  const double* p = in.p.data();
  if (gradient_row == nullptr) {
    *value = FunctionOf<double>(f.function, p);
    return std::isfinite(*value);
  }
  using J = jet::Jet<4, false>;
  std::array<J, 4> pj;
  for (int c = 0; c < 4; ++c) pj[static_cast<std::size_t>(c)] = J::Variable(p[c], c);
  const J phi = FunctionOf<J>(f.function, pj.data());
  *value = phi.v;
  const int nv = n();
  for (int j = 0; j < nv; ++j) {
    double s = 0.0;
    for (int c = 0; c < 4; ++c) s += phi.g[static_cast<std::size_t>(c)] * in.dp(c, j);
    gradient_row[j * stride] += s;
  }
  return std::isfinite(phi.v);
}

bool DesignModel::EvaluateConstraintRows(const std::vector<double>& t,
                                         const design_detail::Integrals& in,
                                         DesignPoint* out) const {
  // Each row by its nonzero entries. A linear row sums its terms' coefficients per variable
  // in the dense path's order from 0 (the same bits); any other row is computed densely
  // (stride 1) and its nonzeros kept.
  const int mc = m(), nv = n();
  out->jacobian_rows.resize(static_cast<std::size_t>(mc));
  std::vector<double> dense;
  for (int k = 0; k < mc; ++k) {
    const DesignFunctionSpec& f = constraints_[static_cast<std::size_t>(k)].f;
    DesignGradientRow& row = out->jacobian_rows[static_cast<std::size_t>(k)];
    double& value = out->constraints[static_cast<std::size_t>(k)];
    if (f.function == DesignFunction::kLinear) {
      double v = f.constant;
      for (const auto& [idx, c] : f.terms) {
        v += c * t[static_cast<std::size_t>(idx)];
        const int j = parameter_variable_[static_cast<std::size_t>(idx)];
        if (j < 0) continue;
        const double d = c * parameter_scale_[static_cast<std::size_t>(idx)];
        auto it = std::find_if(row.begin(), row.end(),
                               [j](const std::pair<int, double>& e) { return e.first == j; });
        if (it == row.end()) {
          row.push_back({j, 0.0 + d});
        } else {
          it->second += d;
        }
      }
      value = v;
      if (!std::isfinite(v)) return false;
      std::sort(row.begin(), row.end());
    } else {
      dense.assign(static_cast<std::size_t>(nv), 0.0);
      if (!EvaluateFunction(f, t, in, &value, dense.data(), 1)) return false;
      for (int j = 0; j < nv; ++j) row.push_back({j, dense[static_cast<std::size_t>(j)]});
    }
    std::size_t kept = 0;
    for (const auto& e : row) {
      if (!std::isfinite(e.second)) return false;
      if (e.second != 0.0) row[kept++] = e;
    }
    row.resize(kept);
  }
  return out->objective_gradient.allFinite();
}

bool DesignModel::EvaluateImpl(const double* x, bool with_gradients, bool rows,
                               DesignPoint* out) const {
  const std::vector<double> t = ParametersAt(x);
  design_detail::Integrals in;
  const design_detail::IntegralContext context{
      t, parameter_variable_, parameter_scale_, num_knots_, hollow_, has_fill_, rigid_, c0_};
  design_detail::ComputeIntegrals(context, n(), with_gradients, &in);
  if (!(in.p[0] > 0.0) || !std::isfinite(in.p[1]) || !std::isfinite(in.p[2])) return false;
  const double* p = in.p.data();
  out->mass_kg = p[0];
  out->balance_point_m = c0_ + p[1] / p[0];
  out->moi_six_inch_kg_m2 = MoiAbout(p, c0_, kSixInchPivotM);
  out->length_m = p[3];

  const int nv = n();
  const int mc = m();
  out->constraints.assign(static_cast<std::size_t>(mc), 0.0);
  out->jacobian_rows.clear();
  if (with_gradients) {
    out->objective_gradient = Eigen::VectorXd::Zero(nv);
    if (rows) {
      out->jacobian.resize(0, 0);
    } else {
      out->jacobian = Eigen::MatrixXd::Zero(mc, nv);
    }
  }
  if (derivative_free()) {
    if (with_gradients) return false;  // the sting and the carry have no derivative
    out->objective = objective_kind_ == DesignObjective::kMaxDistance
                         ? DistanceOf(BatAt(x)).distance_m
                         : StingOf(BatAt(x), false).sting_j;
    if (!std::isfinite(out->objective)) return false;
  } else if (!EvaluateFunction(objective_, t, in, &out->objective,
                               with_gradients ? out->objective_gradient.data() : nullptr, 1)) {
    return false;
  }
  if (with_gradients && rows) return EvaluateConstraintRows(t, in, out);
  for (int k = 0; k < mc; ++k) {
    // Column-major m x n: row k, stride m between variables.
    double* row = with_gradients ? out->jacobian.data() + k : nullptr;
    if (!EvaluateFunction(constraints_[static_cast<std::size_t>(k)].f, t, in,
                          &out->constraints[static_cast<std::size_t>(k)], row, mc)) {
      return false;
    }
  }
  if (with_gradients && (!out->objective_gradient.allFinite() || !out->jacobian.allFinite())) {
    return false;
  }
  return true;
}

bool DesignModel::Hessian(const double* x, double objective_weight,
                          const double* constraint_weights, Eigen::MatrixXd* out) const {
  if (derivative_free() && objective_weight != 0.0) return false;
  const std::vector<double> t = ParametersAt(x);
  design_detail::Integrals in;
  const design_detail::IntegralContext context{
      t, parameter_variable_, parameter_scale_, num_knots_, hollow_, has_fill_, rigid_, c0_};
  design_detail::ComputeIntegrals(context, n(), true, &in);
  if (!(in.p[0] > 0.0)) return false;
  Eigen::Matrix4d big_w = Eigen::Matrix4d::Zero();
  std::array<double, 4> w{};
  bool available = true;
  double bbcor_weight = 0.0;
  double wall_objective_weight = 0.0;
  double bore_weight = 0.0;
  auto add = [&](const DesignFunctionSpec& f, double weight) {
    if (f.function == DesignFunction::kLinear || weight == 0.0) return;
    if (f.function == DesignFunction::kBoreBottom) {
      bore_weight += weight;  // a function of the parameters (AddBoreBottomHessian)
      return;
    }
    if (f.function == DesignFunction::kFirstFrequency) {
      available = false;  // no second derivatives of the eigenvalue (Build refuses kExact)
      return;
    }
    if (f.function == DesignFunction::kBbcor) {
      bbcor_weight += weight;  // its own local inputs (AddWallFunctionHessian)
      return;
    }
    if (IsWallFunction(f.function)) {
      wall_objective_weight += weight;  // the objective with the barrel's COR: the same
      return;
    }
    using J = jet::Jet<4, true>;
    std::array<J, 4> pj;
    for (int c = 0; c < 4; ++c)
      pj[static_cast<std::size_t>(c)] = J::Variable(in.p[static_cast<std::size_t>(c)], c);
    const J phi = FunctionOf<J>(f.function, pj.data());
    for (int a = 0; a < 4; ++a) {
      w[static_cast<std::size_t>(a)] += weight * phi.g[static_cast<std::size_t>(a)];
      for (int b = 0; b < 4; ++b)
        big_w(a, b) += weight * phi.h[static_cast<std::size_t>(a * 4 + b)];
    }
  };
  add(objective_, objective_weight);
  for (int k = 0; k < m(); ++k)
    add(constraints_[static_cast<std::size_t>(k)].f, constraint_weights[k]);
  if (!available) return false;
  *out = in.dp.transpose() * big_w * in.dp;
  // L is linear in x: only M, S1 and S2 have second derivatives.
  design_detail::AddIntegralHessian(context, {w[0], w[1], w[2]}, out);
  if (bore_weight != 0.0) AddBoreBottomHessian(t, bore_weight, out);
  if (bbcor_weight != 0.0 &&
      !AddWallFunctionHessian(DesignFunction::kBbcor, t, bbcor_weight, out)) {
    return false;
  }
  if (wall_objective_weight != 0.0 &&
      !AddWallFunctionHessian(DesignFunction::kObjective, t, wall_objective_weight, out)) {
    return false;
  }
  return out->allFinite();
}

bool DesignModel::IsFunctionOfP(DesignFunction f) const {
  switch (f) {
    case DesignFunction::kMass:
    case DesignFunction::kBalancePoint:
    case DesignFunction::kMoiSixInch:
    case DesignFunction::kDrop:
      return true;
    case DesignFunction::kObjective:
      return objective_kind_ != DesignObjective::kMinSting && barrel_cor_ == nullptr;
    default:
      return false;
  }
}

double DesignModel::FunctionOfP(DesignFunction f, const double* p, double* gradient,
                                double* hessian) const {
  if (!IsFunctionOfP(f)) return kNaN;
  if (gradient == nullptr && hessian == nullptr) return FunctionOf<double>(f, p);
  using J = jet::Jet<4, true>;
  std::array<J, 4> pj;
  for (int c = 0; c < 4; ++c) pj[static_cast<std::size_t>(c)] = J::Variable(p[c], c);
  const J phi = FunctionOf<J>(f, pj.data());
  for (std::size_t a = 0; a < 4; ++a) {
    if (gradient != nullptr) gradient[a] = phi.g[a];
    for (std::size_t b = 0; hessian != nullptr && b < 4; ++b) hessian[a * 4 + b] = phi.h[a * 4 + b];
  }
  return phi.v;
}

// ---------------------------------------------------------------------------------------------
// Designs.

// The jets design_model_wall.cpp evaluates these with (the barrel COR's derivatives): defined
// here, so that file links whatever unity batch, or none, it is compiled in.
template jet::Jet<9, false> DesignModel::AngularSpeedOf(const jet::Jet<9, false>* p) const;
template jet::Jet<9, true> DesignModel::AngularSpeedOf(const jet::Jet<9, true>* p) const;
template jet::Jet<9, false> DesignModel::ObjectiveOf(const jet::Jet<9, false>* p,
                                                     const jet::Jet<9, false>& e) const;
template jet::Jet<9, true> DesignModel::ObjectiveOf(const jet::Jet<9, true>* p,
                                                    const jet::Jet<9, true>& e) const;

}  // namespace sweetspot::core
