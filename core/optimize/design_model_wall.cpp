// The design model's functions of a hollow bat's wall at an impact point (the barrel's COR
// and BBCOR, their exact derivatives and Hessians through 9-variable jets): part of
// DesignModel (design_model.hpp), split from design_model.cpp by concept.
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

// The local inputs of a function of the wall at one impact point: (M, S1, S2, L, h, x_a, x_b,
// r_a, r_b), the impact point x = L - from_tip and the outer radius there.
namespace design_detail {
template <typename J>
struct WallInputs {
  std::array<J, 9> v;  // the local inputs (jet variables 0..8)
  J impact;            // x, m from the knob
  J r_out;             // the outer radius at x, m
};
}  // namespace design_detail

using design_detail::WallInputs;

template <typename J>
WallInputs<J> DesignModel::WallInputsAt(const std::vector<double>& t,
                                        const std::array<double, 3>& integrals, double from_tip_m,
                                        std::array<int, 9>* parameter_of) const {
  const DesignParameterLayout lay{num_knots_};
  auto at = [&](int idx) { return t[static_cast<std::size_t>(idx)]; };
  const int length_idx = lay.KnotPosition(num_knots_ - 1);
  const double x = at(length_idx) - from_tip_m;
  // The impact point's segment by Bat::RadiusAtM's rule: from the last knot at or before x to
  // the first beyond it (a constant radius before the first knot or from the last one).
  int b = 0;
  while (b < num_knots_ && !(at(lay.KnotPosition(b)) > x)) ++b;
  const bool inside = b > 0 && b < num_knots_;
  const int knot_b = std::min(b, num_knots_ - 1);
  const int knot_a = inside ? b - 1 : knot_b;
  *parameter_of = {-1,
                   -1,
                   -1,
                   length_idx,
                   lay.WallThickness(),
                   lay.KnotPosition(knot_a),
                   lay.KnotPosition(knot_b),
                   lay.KnotRadius(knot_a),
                   lay.KnotRadius(knot_b)};
  WallInputs<J> w;
  for (int i = 0; i < 9; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    w.v[ii] = J::Variable(i < 3 ? integrals[ii] : at((*parameter_of)[ii]), i);
  }
  w.impact = w.v[3] - from_tip_m;
  w.r_out =
      inside ? w.v[7] + (w.v[8] - w.v[7]) * ((w.impact - w.v[5]) / (w.v[6] - w.v[5])) : w.v[7];
  return w;
}

template <typename J>
J DesignModel::BarrelCorOf(const WallInputs<J>& w) const {
  const design_detail::BarrelCorConstants& c = *barrel_cor_;
  // EffectiveCorAt's free bat: M_e = 1 / (1/M + b^2 / I_cm), b = x - C, with the objective's
  // inertia model (the integrals are its), as ResolveScene's mass properties.
  const J& mass = w.v[0];
  const J balance = c0_ + w.v[1] / mass;
  const J i_cm = w.v[2] - w.v[1] * w.v[1] / mass;
  const J b = w.impact - balance;
  const J m_e = 1.0 / (1.0 / mass + b * b / i_cm);
  // ResolveScene's normal impact speed there: ball.speed + omega (x - pivot), the design's omega.
  const J speed = ball_speed_mps_ + AngularSpeedOf(w.v.data()) * (w.impact - pivot_from_knob_m_);
  const J ball_cor = design_detail::BallCorLawAt(c.cor_law, speed);
  if (!(jet::Value(w.impact) >= 0.0 && jet::Value(i_cm) > 0.0)) return J(kNaN);
  return design_detail::TrampolineCorOfWall<J>(c.trampoline, m_e, speed, ball_cor, w.r_out, w.v[4],
                                               J::kHessianSize > 0 ? 2 : 1);
}

template <typename J>
J DesignModel::WallJet(DesignFunction f, const std::vector<double>& t,
                       const std::array<double, 3>& integrals,
                       std::array<int, 9>* parameter_of) const {
  if (f == DesignFunction::kBbcor) {
    const design_detail::BbcorConstants& c = *bbcor_;
    const WallInputs<J> w = WallInputsAt<J>(t, integrals, c.impact_from_tip_m, parameter_of);
    const J z = w.impact - c.pivot_from_knob_m;
    const double d = c0_ - c.pivot_from_knob_m;
    const J moi = w.v[2] + (2.0 * d) * w.v[1] + (d * d) * w.v[0];  // MoiAbout the pivot
    return design_detail::BbcorOfWall<J>(c, moi, z, w.r_out, w.v[4], J::kHessianSize > 0 ? 2 : 1);
  }
  // The objective with the design's barrel COR: P = (M, S1, S2, L) are the first four inputs.
  const WallInputs<J> w =
      WallInputsAt<J>(t, integrals, barrel_cor_->impact_from_tip_m, parameter_of);
  const J e = BarrelCorOf(w);
  if (!std::isfinite(jet::Value(e))) return J(kNaN);
  return ObjectiveOf<J, J>(w.v.data(), e);
}

design_detail::IntegralContext DesignModel::WallIntegralContext(
    DesignFunction f, const std::vector<double>& t) const {
  // ComputeBbcor's I_pivot is the rigid body's (the cross-sections' own moments included),
  // whatever inertia model the objective uses; the objective's COR uses the objective's.
  const bool rigid = f == DesignFunction::kBbcor ? true : rigid_;
  return {t, parameter_variable_, parameter_scale_, num_knots_, hollow_, has_fill_, rigid, c0_};
}

bool DesignModel::WallIntegrals(DesignFunction f, const std::vector<double>& t, bool derivatives,
                                design_detail::Integrals* in) const {
  design_detail::ComputeIntegrals(WallIntegralContext(f, t), n(), derivatives, in);
  return in->p[0] > 0.0;
}

bool DesignModel::WallFunctionOf(DesignFunction f, const std::vector<double>& t, double* value,
                                 double* gradient_row, int stride) const {
  *value = kNaN;
  if (f == DesignFunction::kBbcor ? bbcor_ == nullptr : barrel_cor_ == nullptr) return false;
  design_detail::Integrals in;
  if (!WallIntegrals(f, t, gradient_row != nullptr, &in)) return false;
  std::array<int, 9> parameter_of{};
  const auto bj = WallJet<jet::Jet<9, false>>(f, t, {in.p[0], in.p[1], in.p[2]}, &parameter_of);
  *value = bj.v;
  if (!std::isfinite(bj.v)) return false;
  if (gradient_row != nullptr) {
    for (int j = 0; j < n(); ++j) {
      double s = 0.0;
      for (int q = 0; q < 3; ++q) s += bj.g[static_cast<std::size_t>(q)] * in.dp(q, j);
      gradient_row[j * stride] += s;
    }
    for (std::size_t q = 3; q < 9; ++q) {
      const auto idx = static_cast<std::size_t>(parameter_of[q]);
      const int j = parameter_variable_[idx];
      if (j >= 0) gradient_row[j * stride] += bj.g[q] * parameter_scale_[idx];
    }
  }
  return true;
}

bool DesignModel::AddWallFunctionHessian(DesignFunction f, const std::vector<double>& t,
                                         double weight, Eigen::MatrixXd* h) const {
  if (f == DesignFunction::kBbcor ? bbcor_ == nullptr : barrel_cor_ == nullptr) return false;
  design_detail::Integrals in;
  if (!WallIntegrals(f, t, true, &in)) return false;
  std::array<int, 9> parameter_of{};
  const auto bj = WallJet<jet::Jet<9, true>>(f, t, {in.p[0], in.p[1], in.p[2]}, &parameter_of);
  if (!std::isfinite(bj.v)) return false;
  // d(local inputs)/dx: the integrals' rows, then one coefficient per parameter (linear in x).
  Eigen::MatrixXd local = Eigen::MatrixXd::Zero(9, n());
  local.topRows(3) = in.dp.topRows(3);
  for (int q = 3; q < 9; ++q) {
    const auto idx = static_cast<std::size_t>(parameter_of[static_cast<std::size_t>(q)]);
    const int j = parameter_variable_[idx];
    if (j >= 0) local(q, j) += parameter_scale_[idx];
  }
  Eigen::Matrix<double, 9, 9> hb;
  for (int a = 0; a < 9; ++a) {
    for (int b = 0; b < 9; ++b) hb(a, b) = bj.h[static_cast<std::size_t>(a * 9 + b)];
  }
  *h += weight * (local.transpose() * hb * local);
  // M, S1 and S2 are nonlinear in x: their own second derivatives, weighted by dF/dP.
  design_detail::AddIntegralHessian(WallIntegralContext(f, t),
                                    {weight * bj.g[0], weight * bj.g[1], weight * bj.g[2]}, h);
  return h->allFinite();
}

double DesignModel::BbcorAt(const double* x) const {
  double v = kNaN;
  if (!WallFunctionOf(DesignFunction::kBbcor, ParametersAt(x), &v, nullptr, 1)) return kNaN;
  return v;
}

double DesignModel::CorAt(const double* x) const {
  if (barrel_cor_ == nullptr) return cor_;
  const std::vector<double> t = ParametersAt(x);
  design_detail::Integrals in;
  if (!WallIntegrals(DesignFunction::kObjective, t, false, &in)) return kNaN;
  std::array<int, 9> parameter_of{};
  const auto w = WallInputsAt<jet::Jet<9, false>>(t, {in.p[0], in.p[1], in.p[2]},
                                                  barrel_cor_->impact_from_tip_m, &parameter_of);
  const double e = BarrelCorOf(w).v;
  return std::isfinite(e) ? e : kNaN;
}

}  // namespace sweetspot::core
