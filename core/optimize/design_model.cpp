// The design problem as a smooth NLP: parameters, constraints, mass integrals with exact
// first and second derivatives, the closed-form objectives. See design_model.hpp.
#include "core/optimize/design_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <set>

#include "core/collision/collide.hpp"
#include "core/collision/rigid_pivot.hpp"
#include "core/geometry_format.hpp"
#include "core/geometry_integrals.hpp"
#include "core/optimize/jet.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/sweet_spot/sweet_spot.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Relative margin that turns the strict validity rules (wall < radius, bore inside the
// material) into closed constraints the solver can sit on.
constexpr double kStrictMargin = 1e-6;
constexpr int kMaxVariables = 200;
// min_sting: modes kept per solve (the start, the end and the points evaluated twice).
constexpr std::size_t kStingModesCacheEntries = 16;

// Integrals of one segment or of the fill, in the scalar type T.
template <typename T>
struct Sums {
  T mass;  // kg
  T s1;    // first moment about c0, kg m
  T s2;    // second moment about c0 (+ own moments when rigid), kg m^2
};

template <typename T>
Sums<T> SegmentSums(const T& xa, const T& xb, const T& ra, const T& rb, const T& wall, const T& rho,
                    bool hollow, bool rigid, double c0) {
  const T h = xb - xa;
  const T d = 0.5 * (xa + xb) - c0;
  const geometry::SegmentIntegrals<T> s = geometry::IntegrateSegment<T>(h, ra, rb, wall, hollow);
  T q2 = (d * d) * s.volume + 2.0 * d * s.first + s.second;
  if (rigid) q2 += s.disk;
  return {rho * s.volume, rho * (d * s.volume + s.first), rho * q2};
}

template <typename T>
Sums<T> FillSums(const T& radius, const T& depth, const T& length, const T& fill_density,
                 const T& rho, bool hollow, bool rigid, double c0) {
  const T excess = hollow ? fill_density : fill_density - rho;
  const T volume = kPi * radius * radius * depth;
  const T e = length - 0.5 * depth - c0;
  T own = e * e + depth * depth * (1.0 / 12.0);
  if (rigid) own += 0.25 * radius * radius;
  const T mass = excess * volume;
  return {mass, mass * e, mass * own};
}

// I(p) = S2 + 2 (c0 - p) S1 + (c0 - p)^2 M: the exact moment about p from the moments about c0.
template <typename T>
T MoiAbout(const T* p, double c0, double pivot) {
  const double d = c0 - pivot;
  return p[2] + (2.0 * d) * p[1] + (d * d) * p[0];
}

std::string Num(double v) { return FormatNumber(v); }

bool Fail(std::string* why, const std::string& text) {
  if (why != nullptr) *why = text;
  return false;
}

bool Refuse(std::string* why, std::string_view field, double value, std::string_view rule) {
  if (why != nullptr) *why = RefusalMessage(field, value, rule);
  return false;
}

// Floor of a constraint's scale by unit, so that a constraint whose value and bounds are 0
// still gets a sensible magnitude.
double ScaleFloor(const std::string& unit) {
  if (unit == "kg_m2") return 1e-4;
  return 1e-3;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Integrals and their derivatives.

namespace {

struct Integrals {
  std::array<double, 4> p{};                    // M, S1, S2, L
  Eigen::Matrix<double, 4, Eigen::Dynamic> dp;  // dP/dx (when requested)
};

}  // namespace

std::vector<double> DesignModel::ParametersAt(const double* x) const {
  std::vector<double> t = base_parameters_;
  for (std::size_t j = 0; j < variables_.size(); ++j) {
    for (int idx : variables_[j].parameters) t[static_cast<std::size_t>(idx)] = x[j];
  }
  return t;
}

namespace {

// The local parameters of segment i and of the fill, with their chain-rule coefficients.
struct LocalMap {
  std::array<int, 6> index{};
  std::array<double, 6> coefficient{};
  int size = 0;
};

LocalMap SegmentMap(const DesignParameterLayout& lay, int i) {
  LocalMap m;
  m.index = {lay.KnotPosition(i),   lay.KnotPosition(i + 1), lay.KnotRadius(i),
             lay.KnotRadius(i + 1), lay.WallThickness(),     lay.Density()};
  m.coefficient = {1, 1, 1, 1, 1, 1};
  m.size = 6;
  return m;
}

LocalMap FillMap(const DesignParameterLayout& lay) {
  LocalMap m;
  // Local variables: bore radius (= diameter / 2), depth, L, fill density, bat density.
  m.index = {lay.FillDiameter(), lay.FillDepth(), lay.KnotPosition(lay.num_knots - 1),
             lay.FillDensity(),  lay.Density(),   0};
  m.coefficient = {0.5, 1, 1, 1, 1, 0};
  m.size = 5;
  return m;
}

}  // namespace

// Computes P and (optionally) dP/dx; with hessian_weights, adds
// sum_c w_c d2P_c/dx2 (c = M, S1, S2) into *hessian.
namespace design_detail {

struct IntegralContext {
  const std::vector<double>& t;
  const std::vector<int>& parameter_variable;
  int num_knots;
  bool hollow;
  bool has_fill;
  bool rigid;
  double c0;
};

void ComputeIntegrals(const IntegralContext& c, int n, bool gradients, Integrals* out) {
  const DesignParameterLayout lay{c.num_knots};
  out->p = {0.0, 0.0, 0.0, c.t[static_cast<std::size_t>(lay.KnotPosition(c.num_knots - 1))]};
  if (gradients) {
    out->dp = Eigen::Matrix<double, 4, Eigen::Dynamic>::Zero(4, n);
    const int l_var =
        c.parameter_variable[static_cast<std::size_t>(lay.KnotPosition(c.num_knots - 1))];
    if (l_var >= 0) out->dp(3, l_var) = 1.0;
  }
  auto at = [&](int idx) { return c.t[static_cast<std::size_t>(idx)]; };
  for (int i = 0; i + 1 < c.num_knots; ++i) {
    const LocalMap map = SegmentMap(lay, i);
    if (!gradients) {
      const Sums<double> s = SegmentSums<double>(
          at(map.index[0]), at(map.index[1]), at(map.index[2]), at(map.index[3]), at(map.index[4]),
          at(map.index[5]), c.hollow, c.rigid, c.c0);
      out->p[0] += s.mass;
      out->p[1] += s.s1;
      out->p[2] += s.s2;
      continue;
    }
    using J = jet::Jet<6, false>;
    std::array<J, 6> v;
    for (int a = 0; a < 6; ++a)
      v[static_cast<std::size_t>(a)] = J::Variable(at(map.index[static_cast<std::size_t>(a)]), a);
    const Sums<J> s = SegmentSums<J>(v[0], v[1], v[2], v[3], v[4], v[5], c.hollow, c.rigid, c.c0);
    out->p[0] += s.mass.v;
    out->p[1] += s.s1.v;
    out->p[2] += s.s2.v;
    for (int a = 0; a < 6; ++a) {
      const int j =
          c.parameter_variable[static_cast<std::size_t>(map.index[static_cast<std::size_t>(a)])];
      if (j < 0) continue;
      out->dp(0, j) += s.mass.g[static_cast<std::size_t>(a)];
      out->dp(1, j) += s.s1.g[static_cast<std::size_t>(a)];
      out->dp(2, j) += s.s2.g[static_cast<std::size_t>(a)];
    }
  }
  if (c.has_fill) {
    const LocalMap map = FillMap(lay);
    std::array<double, 5> local;
    for (int a = 0; a < 5; ++a) {
      local[static_cast<std::size_t>(a)] =
          map.coefficient[static_cast<std::size_t>(a)] * at(map.index[static_cast<std::size_t>(a)]);
    }
    if (!gradients) {
      const Sums<double> s = FillSums<double>(local[0], local[1], local[2], local[3], local[4],
                                              c.hollow, c.rigid, c.c0);
      out->p[0] += s.mass;
      out->p[1] += s.s1;
      out->p[2] += s.s2;
    } else {
      using J = jet::Jet<5, false>;
      std::array<J, 5> v;
      for (int a = 0; a < 5; ++a)
        v[static_cast<std::size_t>(a)] = J::Variable(local[static_cast<std::size_t>(a)], a);
      const Sums<J> s = FillSums<J>(v[0], v[1], v[2], v[3], v[4], c.hollow, c.rigid, c.c0);
      out->p[0] += s.mass.v;
      out->p[1] += s.s1.v;
      out->p[2] += s.s2.v;
      for (int a = 0; a < 5; ++a) {
        const int j =
            c.parameter_variable[static_cast<std::size_t>(map.index[static_cast<std::size_t>(a)])];
        if (j < 0) continue;
        const double k = map.coefficient[static_cast<std::size_t>(a)];
        out->dp(0, j) += k * s.mass.g[static_cast<std::size_t>(a)];
        out->dp(1, j) += k * s.s1.g[static_cast<std::size_t>(a)];
        out->dp(2, j) += k * s.s2.g[static_cast<std::size_t>(a)];
      }
    }
  }
}

// Adds sum_c w_c d2P_c/dx2 into *h (n x n).
void AddIntegralHessian(const IntegralContext& c, const std::array<double, 3>& w,
                        Eigen::MatrixXd* h) {
  const DesignParameterLayout lay{c.num_knots};
  auto at = [&](int idx) { return c.t[static_cast<std::size_t>(idx)]; };
  auto scatter = [&](const LocalMap& map, const auto& combined, int size) {
    for (int a = 0; a < size; ++a) {
      const int ja =
          c.parameter_variable[static_cast<std::size_t>(map.index[static_cast<std::size_t>(a)])];
      if (ja < 0) continue;
      const double ka = map.coefficient[static_cast<std::size_t>(a)];
      for (int b = 0; b < size; ++b) {
        const int jb =
            c.parameter_variable[static_cast<std::size_t>(map.index[static_cast<std::size_t>(b)])];
        if (jb < 0) continue;
        const double kb = map.coefficient[static_cast<std::size_t>(b)];
        (*h)(ja, jb) += ka * kb * combined.h[static_cast<std::size_t>(a * size + b)];
      }
    }
  };
  for (int i = 0; i + 1 < c.num_knots; ++i) {
    const LocalMap map = SegmentMap(lay, i);
    using J = jet::Jet<6, true>;
    std::array<J, 6> v;
    for (int a = 0; a < 6; ++a)
      v[static_cast<std::size_t>(a)] = J::Variable(at(map.index[static_cast<std::size_t>(a)]), a);
    const Sums<J> s = SegmentSums<J>(v[0], v[1], v[2], v[3], v[4], v[5], c.hollow, c.rigid, c.c0);
    const J combined = w[0] * s.mass + w[1] * s.s1 + w[2] * s.s2;
    scatter(map, combined, 6);
  }
  if (c.has_fill) {
    const LocalMap map = FillMap(lay);
    using J = jet::Jet<5, true>;
    std::array<J, 5> v;
    for (int a = 0; a < 5; ++a) {
      v[static_cast<std::size_t>(a)] = J::Variable(
          map.coefficient[static_cast<std::size_t>(a)] * at(map.index[static_cast<std::size_t>(a)]),
          a);
    }
    const Sums<J> s = FillSums<J>(v[0], v[1], v[2], v[3], v[4], c.hollow, c.rigid, c.c0);
    const J combined = w[0] * s.mass + w[1] * s.s1 + w[2] * s.s2;
    scatter(map, combined, 5);
  }
}

}  // namespace design_detail

// ---------------------------------------------------------------------------------------------
// Functions of P = (M, S1, S2, L).

template <typename T>
T DesignModel::ObjectiveOf(const T* p) const {
  if (objective_kind_ == DesignObjective::kMinMoi) return MoiAbout(p, c0_, kSixInchPivotM);
  const double m = ball_mass_kg_;
  const double u = ball_speed_mps_;
  const double e = cor_;
  const double pivot = pivot_from_knob_m_;
  const T j = MoiAbout(p, c0_, pivot);
  T omega(omega0_rad_s_);
  if (objective_kind_ == DesignObjective::kMaxExitSpeedSwingWeight && omega0_rad_s_ > 0.0 &&
      swing_weight_exponent_ != 0.0) {
    omega = omega0_rad_s_ *
            jet::Pow(MoiAbout(p, c0_, kSixInchPivotM) * (1.0 / i6_ref_), -swing_weight_exponent_);
  }
  const double lo = -pivot;   // the knob, in coordinates from the pivot
  const T hi = p[3] - pivot;  // the tip
  // The rigid-pivot closed form (paper-notes.md section 3), without cancellation.
  const T s = jet::Sqrt(u * u + omega * omega * j * (1.0 / m));
  const T xs = omega * j / (m * (u + s));
  auto exit_speed_at = [&](const T& x) {
    return (1.0 + e) * j * (u + omega * x) / (j + m * x * x) - u;
  };
  const bool beyond_tip = jet::Value(xs) > jet::Value(hi);
  const bool before_knob = jet::Value(xs) < lo;
  if (objective_kind_ != DesignObjective::kWidestSweetZone) {
    if (beyond_tip) return exit_speed_at(hi);
    if (before_knob) return exit_speed_at(T(lo));
    return 0.5 * ((1.0 + e) * s - (1.0 - e) * u);
  }
  // The sweet zone: where f(x) >= f(x_c) - tolerance, x_c the sweet spot on the bat. With
  // cG = (1 + e)(u + S) / 2, f(x*) - f(x) = cG m (x - x*)^2 / (J + m x^2), so the zone is
  // a x^2 - 2 b x + c <= 0 (as ExitSpeedProfile::ZoneAround, same algebra).
  const T cg = 0.5 * (1.0 + e) * (u + s);
  T delta(zone_tolerance_mps_);
  if (beyond_tip || before_knob) {
    const T xc = beyond_tip ? hi : T(lo);
    const T d = xc - xs;
    delta = delta + cg * m * d * d / (j + m * xc * xc);
  }
  const T a = m * (cg - delta);
  const T b = cg * m * xs;
  const T c = cg * m * xs * xs - delta * j;
  const T disc = m * delta * (cg * (j + m * xs * xs) - delta * j);
  T zlo = xs, zhi = xs;
  bool lo_open = false, hi_open = false;
  if (jet::Value(a) > 0.0) {
    if (jet::Value(disc) > 0.0) {
      const T q = b + jet::Sqrt(disc);
      const T r1 = q / a;
      const T r2 = c / q;
      const bool order = jet::Value(r1) <= jet::Value(r2);
      zlo = order ? r1 : r2;
      zhi = order ? r2 : r1;
    }
  } else if (jet::Value(a) == 0.0) {
    hi_open = true;
    if (jet::Value(b) > 0.0) {
      zlo = c / (2.0 * b);
    } else {
      lo_open = true;
    }
  } else if (!(jet::Value(disc) >= 0.0)) {
    lo_open = hi_open = true;
  } else {
    const T q = b + jet::Sqrt(disc);
    const T r1 = q / a;
    const T r2 = c / q;
    const T root_lo = jet::Value(r1) <= jet::Value(r2) ? r1 : r2;
    const T root_hi = jet::Value(r1) <= jet::Value(r2) ? r2 : r1;
    if (jet::Value(xs) >= jet::Value(root_hi)) {
      zlo = root_hi;
      hi_open = true;
    } else {
      zhi = root_lo;
      lo_open = true;
    }
  }
  const T top = (hi_open || jet::Value(zhi) > jet::Value(hi)) ? hi : zhi;
  const T bottom = (lo_open || jet::Value(zlo) < lo) ? T(lo) : zlo;
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
    case DesignFunction::kObjective:
      return ObjectiveOf(p);
    case DesignFunction::kLinear:
      break;
  }
  return T(kNaN);
}

double DesignModel::AngularSpeedFor(double i6_kg_m2) const {
  if (objective_kind_ != DesignObjective::kMaxExitSpeedSwingWeight || omega0_rad_s_ == 0.0 ||
      swing_weight_exponent_ == 0.0) {
    return omega0_rad_s_;
  }
  return omega0_rad_s_ * std::pow(i6_kg_m2 / i6_ref_, -swing_weight_exponent_);
}

std::vector<double> DesignModel::BaseX() const {
  std::vector<double> x(variables_.size());
  for (std::size_t j = 0; j < variables_.size(); ++j) {
    x[j] = std::clamp(variables_[j].base, variables_[j].lower, variables_[j].upper);
  }
  return x;
}

double DesignModel::Value(const DesignFunctionSpec& f, const double* x) const {
  if (f.function == DesignFunction::kObjective && objective_kind_ == DesignObjective::kMinSting) {
    return StingOf(BatAt(x), false).sting_j;  // NaN when it cannot be computed
  }
  const std::vector<double> t = ParametersAt(x);
  if (f.function == DesignFunction::kLinear) {
    double v = f.constant;
    for (const auto& [idx, k] : f.terms) v += k * t[static_cast<std::size_t>(idx)];
    return v;
  }
  Integrals in;
  design_detail::ComputeIntegrals(
      {t, parameter_variable_, num_knots_, hollow_, has_fill_, rigid_, c0_}, n(), false, &in);
  if (!(in.p[0] > 0.0)) return kNaN;
  const double v = FunctionOf<double>(f.function, in.p.data());
  return std::isfinite(v) ? v : kNaN;
}

bool DesignModel::Evaluate(const double* x, bool with_gradients, DesignPoint* out) const {
  const std::vector<double> t = ParametersAt(x);
  Integrals in;
  const design_detail::IntegralContext context{
      t, parameter_variable_, num_knots_, hollow_, has_fill_, rigid_, c0_};
  design_detail::ComputeIntegrals(context, n(), with_gradients, &in);
  if (!(in.p[0] > 0.0) || !std::isfinite(in.p[1]) || !std::isfinite(in.p[2])) return false;
  const double* p = in.p.data();
  out->mass_kg = p[0];
  out->balance_point_m = c0_ + p[1] / p[0];
  out->moi_six_inch_kg_m2 = MoiAbout(p, c0_, kSixInchPivotM);
  out->length_m = p[3];

  const int nv = n();
  auto evaluate = [&](const DesignFunctionSpec& f, double* value, double* gradient_row,
                      int stride) -> bool {
    if (f.function == DesignFunction::kLinear) {
      double v = f.constant;
      for (const auto& [idx, k] : f.terms) {
        v += k * t[static_cast<std::size_t>(idx)];
        const int j = parameter_variable_[static_cast<std::size_t>(idx)];
        if (gradient_row != nullptr && j >= 0) gradient_row[j * stride] += k;
      }
      *value = v;
      return std::isfinite(v);
    }
    if (gradient_row == nullptr) {
      *value = FunctionOf<double>(f.function, p);
      return std::isfinite(*value);
    }
    using J = jet::Jet<4, false>;
    std::array<J, 4> pj;
    for (int c = 0; c < 4; ++c) pj[static_cast<std::size_t>(c)] = J::Variable(p[c], c);
    const J phi = FunctionOf<J>(f.function, pj.data());
    *value = phi.v;
    for (int j = 0; j < nv; ++j) {
      double s = 0.0;
      for (int c = 0; c < 4; ++c) s += phi.g[static_cast<std::size_t>(c)] * in.dp(c, j);
      gradient_row[j * stride] += s;
    }
    return std::isfinite(phi.v);
  };

  const int mc = m();
  out->constraints.assign(static_cast<std::size_t>(mc), 0.0);
  if (with_gradients) {
    out->objective_gradient = Eigen::VectorXd::Zero(nv);
    out->jacobian = Eigen::MatrixXd::Zero(mc, nv);
  }
  if (derivative_free()) {
    if (with_gradients) return false;  // the sting has no derivative
    out->objective = StingOf(BatAt(x), false).sting_j;
    if (!std::isfinite(out->objective)) return false;
  } else if (!evaluate(objective_, &out->objective,
                       with_gradients ? out->objective_gradient.data() : nullptr, 1)) {
    return false;
  }
  for (int k = 0; k < mc; ++k) {
    // Column-major m x n: row k, stride m between variables.
    double* row = with_gradients ? out->jacobian.data() + k : nullptr;
    if (!evaluate(constraints_[static_cast<std::size_t>(k)].f,
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
  Integrals in;
  const design_detail::IntegralContext context{
      t, parameter_variable_, num_knots_, hollow_, has_fill_, rigid_, c0_};
  design_detail::ComputeIntegrals(context, n(), true, &in);
  if (!(in.p[0] > 0.0)) return false;
  Eigen::Matrix4d big_w = Eigen::Matrix4d::Zero();
  std::array<double, 4> w{};
  auto add = [&](const DesignFunctionSpec& f, double weight) {
    if (f.function == DesignFunction::kLinear || weight == 0.0) return;
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
  *out = in.dp.transpose() * big_w * in.dp;
  // L is linear in x: only M, S1 and S2 have second derivatives.
  design_detail::AddIntegralHessian(context, {w[0], w[1], w[2]}, out);
  return out->allFinite();
}

// ---------------------------------------------------------------------------------------------
// Designs.

std::optional<ThreeSegmentShape> DesignModel::ShapeAt(const double* x) const {
  if (!base_shape_.has_value()) return std::nullopt;
  const std::vector<double> t = ParametersAt(x);
  const DesignParameterLayout lay{num_knots_};
  ThreeSegmentShape s = *base_shape_;
  s.length_m = t[static_cast<std::size_t>(lay.KnotPosition(3))];
  s.handle_radius_m = t[static_cast<std::size_t>(lay.KnotRadius(0))];
  s.barrel_radius_m = t[static_cast<std::size_t>(lay.KnotRadius(2))];
  // The solver meets x1 <= x2 <= L and 0 <= x1 to its tolerance: remove that round-off.
  s.taper_start_m = std::max(t[static_cast<std::size_t>(lay.KnotPosition(1))], 0.0);
  s.taper_end_m = std::min(t[static_cast<std::size_t>(lay.KnotPosition(2))], s.length_m);
  s.taper_start_m = std::min(s.taper_start_m, s.taper_end_m);
  return s;
}

Bat DesignModel::BatAt(const double* x) const {
  const std::vector<double> t = ParametersAt(x);
  const DesignParameterLayout lay{num_knots_};
  Bat bat = base_bat_;
  if (base_shape_.has_value()) {
    bat.knots = ShapeAt(x)->Knots();
  } else {
    for (int i = 0; i < num_knots_; ++i) {
      bat.knots[static_cast<std::size_t>(i)].radius_m =
          t[static_cast<std::size_t>(lay.KnotRadius(i))];
      bat.knots[static_cast<std::size_t>(i)].x_m = t[static_cast<std::size_t>(lay.KnotPosition(i))];
    }
  }
  bat.material.density_kg_m3 = t[static_cast<std::size_t>(lay.Density())];
  bat.wall_thickness_m = t[static_cast<std::size_t>(lay.WallThickness())];
  if (bat.fill.has_value()) {
    bat.fill->diameter_m = t[static_cast<std::size_t>(lay.FillDiameter())];
    bat.fill->depth_m = t[static_cast<std::size_t>(lay.FillDepth())];
    bat.fill->material.density_kg_m3 = t[static_cast<std::size_t>(lay.FillDensity())];
  }
  return bat;
}

StingEvaluation EvaluateSting(const Bat& bat, const StingScene& scene, bool refine_check,
                              ModesCache* cache) {
  StingEvaluation out;
  try {
    const MassProperties p = ComputeMassProperties(bat, scene.inertia_model);
    const MaxExitSpeedResult max = ClosedFormMaxExitSpeed(
        RigidPivotProfile(RigidPivotInputsFor(p, scene.ball, scene.swing, scene.cor)),
        bat.LengthM());
    out.sweet_spot_from_knob_m = max.position_from_knob_m;
    Scene s;
    s.bat = bat;
    s.mass_properties = p;
    s.inertia_model = scene.inertia_model;
    s.ball = scene.ball;
    s.swing = scene.swing;
    s.cor = scene.cor;
    CollisionOptions options;
    options.flexible = scene.flexible;
    options.flexible.modes_cache = cache;
    options.flexible.impact.refine_check = refine_check && scene.flexible.impact.refine_check;
    const CollisionResult r =
        Collide(s, max.position_from_knob_m, CollisionModel::kFlexible, options);
    out.termination = r.summary.termination;
    out.message = r.summary.message;
    if (!r.summary.IsSolutionUsable() || !r.flexible.has_value()) return out;
    out.impact = *r.flexible;
    for (const std::string& w : r.summary.warnings) {
      if (std::find(out.impact.summary.warnings.begin(), out.impact.summary.warnings.end(), w) ==
          out.impact.summary.warnings.end()) {
        out.impact.summary.warnings.push_back(w);
      }
    }
    out.sting_j = r.flexible->hands_vibration_energy_j;
    out.ok = std::isfinite(out.sting_j);
    if (!out.ok) out.message = "the hands' vibration energy is not finite";
  } catch (const std::exception& e) {
    out.ok = false;
    out.message = std::string("internal error: ") + e.what();
  }
  if (!out.ok) out.sting_j = kNaN;
  return out;
}

StingEvaluation DesignModel::StingOf(const Bat& bat, bool refine_check) const {
  return EvaluateSting(bat, sting_scene_, refine_check, sting_modes_.get());
}

DesignModel DesignModel::WithObjective(const DesignFunctionSpec& f, bool maximize, double scale,
                                       const std::string& unit) const {
  DesignModel copy = *this;
  copy.objective_ = f;
  copy.maximize_ = maximize;
  copy.objective_scale_ = scale > 0.0 && std::isfinite(scale) ? scale : 1.0;
  copy.objective_unit_ = unit;
  return copy;
}

DesignModel DesignModel::WithConstraints(const std::vector<int>& keep) const {
  DesignModel copy = *this;
  copy.constraints_.clear();
  for (int k : keep) copy.constraints_.push_back(constraints_[static_cast<std::size_t>(k)]);
  return copy;
}

// ---------------------------------------------------------------------------------------------
// Build.

namespace {

// Whether a variable kind needs a positive lower bound (else non-negative).
bool NeedsPositive(DesignVariableKind kind) {
  switch (kind) {
    case DesignVariableKind::kKnotRadius:
    case DesignVariableKind::kKnotPosition:
    case DesignVariableKind::kLength:
    case DesignVariableKind::kHandleRadius:
    case DesignVariableKind::kBarrelRadius:
    case DesignVariableKind::kDensity:
    case DesignVariableKind::kWallThickness:
      return true;
    default:
      return false;
  }
}

bool IsFillKind(DesignVariableKind kind) {
  return kind == DesignVariableKind::kFillDiameter || kind == DesignVariableKind::kFillDepth ||
         kind == DesignVariableKind::kFillDensity;
}

bool IsProfileKind(DesignVariableKind kind) {
  return kind == DesignVariableKind::kKnotRadius || kind == DesignVariableKind::kKnotPosition;
}

bool IsThreeSegmentKind(DesignVariableKind kind) {
  return kind == DesignVariableKind::kLength || kind == DesignVariableKind::kHandleRadius ||
         kind == DesignVariableKind::kBarrelRadius || kind == DesignVariableKind::kTaperStart ||
         kind == DesignVariableKind::kTaperEnd;
}

std::string RangeText(double lower, double upper) {
  if (lower == upper) return "= " + Num(lower);
  if (std::isinf(lower)) return "<= " + Num(upper);
  if (std::isinf(upper)) return ">= " + Num(lower);
  return "in [" + Num(lower) + ", " + Num(upper) + "]";
}

}  // namespace

bool DesignModel::Build(const DesignProblem& problem, const DesignOptions& options,
                        DesignModel* out, std::string* why) {
  DesignModel model;
  std::string inner;
  std::string* inner_ptr = why != nullptr ? &inner : nullptr;

  // Scene and objective.
  if (ParseDesignObjective(DesignObjectiveName(problem.objective)) != problem.objective) {
    return Fail(why, "objective: not a known objective");
  }
  if (!problem.ball.IsValid(inner_ptr)) return Fail(why, inner);
  if (!problem.swing.IsValid(inner_ptr)) return Fail(why, inner);
  if (!(std::isfinite(problem.swing_weight_exponent) && problem.swing_weight_exponent >= 0.0 &&
        problem.swing_weight_exponent <= 0.5)) {
    return Refuse(why, "swing_weight_exponent", problem.swing_weight_exponent,
                  "must be in [0, 0.5]");
  }
  if (!(std::isfinite(problem.sweet_zone_tolerance_mps) &&
        problem.sweet_zone_tolerance_mps > 0.0)) {
    return Refuse(why, "sweet_zone_tolerance_mps", problem.sweet_zone_tolerance_mps,
                  "must be finite and positive");
  }
  const bool exit_speed_objective = problem.objective != DesignObjective::kMinMoi;
  if (exit_speed_objective && problem.ball.speed_mps == 0.0 &&
      problem.swing.angular_speed_rad_s == 0.0) {
    return Fail(why,
                "ball.speed_mps = 0 and swing.angular_speed_rad_s = 0: nothing moves, the "
                "exit speed is 0 everywhere (objective " +
                    std::string(DesignObjectiveName(problem.objective)) + ")");
  }
  if (problem.inertia_model != InertiaModel::kRigidBody &&
      problem.inertia_model != InertiaModel::kSlenderRod) {
    return Fail(why, "inertia_model: not a known inertia model");
  }
  if (problem.objective == DesignObjective::kMinSting && !problem.flexible.IsValid(inner_ptr)) {
    return Fail(why, inner);
  }

  // The base design.
  Bat base = problem.bat;
  if (problem.three_segment.has_value()) {
    if (!problem.three_segment->IsValid(inner_ptr)) return Fail(why, "three_segment." + inner);
    base.knots = problem.three_segment->Knots();
  }
  if (!base.IsValid(inner_ptr)) return Fail(why, "bat." + inner);
  if (problem.cor.has_value()) {
    if (!(std::isfinite(*problem.cor) && *problem.cor >= 0.0 && *problem.cor <= 1.0)) {
      return Refuse(why, "cor", *problem.cor, "must be in [0, 1]");
    }
    model.cor_ = *problem.cor;
  } else if (base.material.cor.has_value()) {
    model.cor_ = *base.material.cor;
  } else if (exit_speed_objective) {
    return Fail(why,
                "cor: not given, and material '" + base.material.name + "' has no default COR");
  } else {
    model.cor_ = 0.5;  // unused by min_moi; the rules' BBCOR check uses it only if given
  }

  // Parameters.
  model.base_bat_ = base;
  model.base_shape_ = problem.three_segment;
  model.hollow_ = base.IsHollow();
  model.has_fill_ = base.fill.has_value();
  model.rigid_ = problem.inertia_model == InertiaModel::kRigidBody;
  if (problem.three_segment.has_value()) {
    const ThreeSegmentShape& s = *problem.three_segment;
    Bat four = base;
    four.knots = {{0.0, s.handle_radius_m},
                  {s.taper_start_m, s.handle_radius_m},
                  {s.taper_end_m, s.barrel_radius_m},
                  {s.length_m, s.barrel_radius_m}};
    const Eigen::VectorXd p = DesignParameters(four);
    model.base_parameters_.assign(p.data(), p.data() + p.size());
    model.num_knots_ = 4;
  } else {
    const Eigen::VectorXd p = DesignParameters(base);
    model.base_parameters_.assign(p.data(), p.data() + p.size());
    model.num_knots_ = static_cast<int>(base.knots.size());
  }
  const DesignParameterLayout lay{model.num_knots_};
  model.parameter_variable_.assign(static_cast<std::size_t>(lay.Size()), -1);
  auto param = [&](int idx) { return model.base_parameters_[static_cast<std::size_t>(idx)]; };

  // Variables.
  if (problem.variables.empty() ||
      problem.variables.size() > static_cast<std::size_t>(kMaxVariables)) {
    return Refuse(why, "variables.size()", static_cast<double>(problem.variables.size()),
                  "must be between 1 and 200");
  }
  std::set<std::string> seen;
  bool density_variable = false, wall_variable = false, fill_density_variable = false;
  for (std::size_t i = 0; i < problem.variables.size(); ++i) {
    const DesignVariable& v = problem.variables[i];
    const std::string field = IndexedField("variables", i, "");
    const std::string path_field = field + "path = " + v.path + ": ";
    const std::optional<DesignVariableRef> ref = ParseDesignVariablePath(v.path);
    if (!ref.has_value()) {
      return Fail(why, path_field +
                           "not a design variable (known: profile.knots[i].radius_m, "
                           "profile.knots[i].x_m, three_segment.length_m, "
                           "three_segment.handle_radius_m, three_segment.barrel_radius_m, "
                           "three_segment.taper_start_m, three_segment.taper_end_m, "
                           "material.density_kg_m3, wall_thickness_m, fill.diameter_m, "
                           "fill.depth_m, fill.material.density_kg_m3)");
    }
    if (!seen.insert(v.path).second) return Fail(why, path_field + "appears more than once");
    if (IsProfileKind(ref->kind) && problem.three_segment.has_value()) {
      return Fail(why, path_field + "the design is a three_segment shape (use three_segment.*)");
    }
    if (IsThreeSegmentKind(ref->kind) && !problem.three_segment.has_value()) {
      return Fail(why, path_field + "the design is a profile, not a three_segment shape");
    }
    if (IsProfileKind(ref->kind) && ref->knot >= model.num_knots_) {
      return Fail(why,
                  path_field + "the profile has " + std::to_string(model.num_knots_) + " knots");
    }
    if (ref->kind == DesignVariableKind::kKnotPosition && ref->knot == 0) {
      return Fail(why, path_field + "must stay 0 (positions are measured from the knob)");
    }
    if (IsFillKind(ref->kind) && !base.fill.has_value()) {
      return Fail(why, path_field + "the bat has no fill");
    }
    if (!std::isfinite(v.min)) {
      return Refuse(why, field + "min", v.min,
                    "must be finite (an optimisation needs bounded variables)");
    }
    if (!std::isfinite(v.max)) {
      return Refuse(why, field + "max", v.max,
                    "must be finite (an optimisation needs bounded variables)");
    }
    if (!(v.max > v.min)) {
      return Refuse(why, field + "max", v.max,
                    "must be greater than " + field + "min = " + Num(v.min));
    }
    if (NeedsPositive(ref->kind) && !(v.min > 0.0)) {
      return Refuse(why, field + "min", v.min,
                    "must be positive for " + v.path +
                        (ref->kind == DesignVariableKind::kWallThickness
                             ? " (the bat stays hollow: wall = 0 is a solid bat, a jump)"
                             : ""));
    }
    if (!NeedsPositive(ref->kind) && v.min < 0.0) {
      return Refuse(why, field + "min", v.min, "must be non-negative for " + v.path);
    }
    DesignVariableSpec spec;
    spec.path = v.path;
    spec.ref = *ref;
    spec.lower = v.min;
    spec.upper = v.max;
    switch (ref->kind) {
      case DesignVariableKind::kKnotRadius:
        spec.parameters = {lay.KnotRadius(ref->knot)};
        break;
      case DesignVariableKind::kKnotPosition:
        spec.parameters = {lay.KnotPosition(ref->knot)};
        break;
      case DesignVariableKind::kLength:
        spec.parameters = {lay.KnotPosition(3)};
        break;
      case DesignVariableKind::kHandleRadius:
        spec.parameters = {lay.KnotRadius(0), lay.KnotRadius(1)};
        break;
      case DesignVariableKind::kBarrelRadius:
        spec.parameters = {lay.KnotRadius(2), lay.KnotRadius(3)};
        break;
      case DesignVariableKind::kTaperStart:
        spec.parameters = {lay.KnotPosition(1)};
        break;
      case DesignVariableKind::kTaperEnd:
        spec.parameters = {lay.KnotPosition(2)};
        break;
      case DesignVariableKind::kDensity:
        spec.parameters = {lay.Density()};
        density_variable = true;
        break;
      case DesignVariableKind::kWallThickness:
        spec.parameters = {lay.WallThickness()};
        wall_variable = true;
        break;
      case DesignVariableKind::kFillDiameter:
        spec.parameters = {lay.FillDiameter()};
        break;
      case DesignVariableKind::kFillDepth:
        spec.parameters = {lay.FillDepth()};
        break;
      case DesignVariableKind::kFillDensity:
        spec.parameters = {lay.FillDensity()};
        fill_density_variable = true;
        break;
    }
    spec.base = param(spec.parameters.front());
    for (int idx : spec.parameters) {
      model.parameter_variable_[static_cast<std::size_t>(idx)] =
          static_cast<int>(model.variables_.size());
    }
    model.variables_.push_back(spec);
  }
  if (wall_variable) model.hollow_ = true;
  if (fill_density_variable) {
    Material f = base.fill->material;
    f.density_kg_m3 = 1.0;  // check the other fields: the fill may become non-empty
    if (!f.IsValid(inner_ptr)) {
      return Fail(why, "fill.material." + inner +
                           " (fill.material.density_kg_m3 is a variable, so the fill material must "
                           "be complete)");
    }
  }

  // Rules: the discrete limits.
  {
    std::set<RuleSet> rules_seen;
    for (std::size_t i = 0; i < problem.constraints.rules.size(); ++i) {
      const RuleSet rule = problem.constraints.rules[i];
      if (!ParseRuleSet(RuleSetName(rule)).has_value()) {
        return Fail(why, IndexedField("constraints.rules", i, "") + ": not a known rule set");
      }
      if (!rules_seen.insert(rule).second) {
        return Fail(why, "constraints.rules: " + std::string(RuleSetName(rule)) +
                             " appears more than once");
      }
      RuleFacts facts;
      facts.material = base.material;
      facts.density_variable = density_variable;
      facts.wall_thickness_m = base.wall_thickness_m;
      facts.wall_variable = wall_variable;
      facts.has_fill = base.fill.has_value();
      facts.fill_density_kg_m3 = base.fill.has_value() ? base.fill->material.density_kg_m3 : 0.0;
      facts.fill_density_variable = fill_density_variable;
      facts.cor = model.cor_;
      if (!RuleAllowsDesign(rule, facts, inner_ptr)) return Fail(why, inner);
    }
  }

  // Scene numbers and references.
  model.ball_mass_kg_ = problem.ball.mass_kg;
  model.ball_speed_mps_ = problem.ball.speed_mps;
  model.omega0_rad_s_ = problem.swing.angular_speed_rad_s;
  model.pivot_from_knob_m_ = problem.swing.pivot_from_knob_m;
  model.swing_weight_exponent_ = problem.swing_weight_exponent;
  model.zone_tolerance_mps_ = problem.sweet_zone_tolerance_mps;
  model.objective_kind_ = problem.objective;
  if (problem.objective == DesignObjective::kMinSting) {
    model.sting_scene_.ball = problem.ball;
    model.sting_scene_.swing = problem.swing;
    model.sting_scene_.cor = model.cor_;
    model.sting_scene_.inertia_model = problem.inertia_model;
    model.sting_scene_.flexible = problem.flexible;
    model.sting_scene_.flexible.modes_cache = nullptr;  // the model's own cache instead
    model.sting_modes_ = std::make_shared<ModesCache>(kStingModesCacheEntries);
  }
  const MassProperties base_properties = ComputeMassProperties(base, problem.inertia_model);
  model.c0_ = base_properties.balance_point_m;
  model.i6_ref_ = base_properties.MoiSixInchKgM2();
  if (!(std::isfinite(model.c0_) && model.i6_ref_ > 0.0)) {
    return Fail(why, "bat: its mass properties are not finite");
  }

  // Constraints.
  const DesignConstraints& cons = problem.constraints;
  auto depends = [&](const std::vector<std::pair<int, double>>& terms) {
    for (const auto& [idx, k] : terms) {
      if (k != 0.0 && model.parameter_variable_[static_cast<std::size_t>(idx)] >= 0) return true;
    }
    return false;
  };
  auto linear_value = [&](const std::vector<std::pair<int, double>>& terms, double constant) {
    double v = constant;
    for (const auto& [idx, k] : terms) v += k * param(idx);
    return v;
  };
  // Adds a linear constraint, or checks it now when no variable changes it.
  auto add_linear = [&](const std::string& name, const std::string& min_name,
                        const std::string& max_name, const std::string& unit,
                        std::vector<std::pair<int, double>> terms, double constant, double lower,
                        double upper, bool property, bool skip_if_fixed) {
    DesignConstraintSpec c;
    c.name = name;
    c.min_name = min_name;
    c.max_name = max_name;
    c.unit = unit;
    c.f.function = DesignFunction::kLinear;
    c.f.terms = std::move(terms);
    c.f.constant = constant;
    c.lower = lower;
    c.upper = upper;
    c.property = property;
    if (!depends(c.f.terms)) {
      if (skip_if_fixed) return;
      const double v = linear_value(c.f.terms, c.f.constant);
      const double slack = 1e-12 * std::max({1.0, std::abs(lower) < kInf ? std::abs(lower) : 0.0,
                                             std::abs(upper) < kInf ? std::abs(upper) : 0.0});
      if (v < lower - slack || v > upper + slack) {
        const std::string& n = lower == upper ? name : (v < lower ? min_name : max_name);
        model.fixed_violations_.push_back(n + " = " + Num(v) + (unit.empty() ? "" : " " + unit) +
                                          " must be " + RangeText(lower, upper) +
                                          ", and no design variable changes it");
      }
      return;
    }
    model.constraints_.push_back(std::move(c));
  };
  auto add_nonlinear = [&](const std::string& name, const std::string& unit, DesignFunction f,
                           double lower, double upper) {
    DesignConstraintSpec c;
    c.name = name;
    c.min_name = lower == upper ? name : name + ".min";
    c.max_name = lower == upper ? name : name + ".max";
    c.unit = unit;
    c.f.function = f;
    c.lower = lower;
    c.upper = upper;
    c.property = true;
    model.constraints_.push_back(std::move(c));
  };
  // A range from the request, checked.
  auto range_of = [&](const char* field, const DesignRange& r, double* lower, double* upper) {
    *lower = r.min.value_or(-kInf);
    *upper = r.max.value_or(kInf);
    if (!r.min.has_value() && !r.max.has_value()) {
      return Fail(why, std::string("constraints.") + field + ": give min, max or both");
    }
    if (r.min.has_value() && !std::isfinite(*r.min)) {
      return Refuse(why, std::string("constraints.") + field + ".min", *r.min, "must be finite");
    }
    if (r.max.has_value() && !std::isfinite(*r.max)) {
      return Refuse(why, std::string("constraints.") + field + ".max", *r.max, "must be finite");
    }
    if (*lower > *upper) {
      return Refuse(
          why, std::string("constraints.") + field + ".max", *upper,
          "must not be less than constraints." + std::string(field) + ".min = " + Num(*lower));
    }
    return true;
  };

  // Length: the request's range and the rules' maximum.
  {
    double lower = -kInf, upper = kInf;
    std::string max_name = "length_m.max";
    bool equality = false;
    if (cons.length_m.has_value()) {
      if (!range_of("length_m", *cons.length_m, &lower, &upper)) return false;
      equality = cons.length_m->IsEquality();
    }
    for (RuleSet rule : cons.rules) {
      const RuleSetLimits limits = LimitsOf(rule);
      if (!limits.max_length_m.has_value() || !(*limits.max_length_m < upper)) continue;
      const std::string rule_name = std::string("rules.") + RuleSetName(rule) + ".length";
      if (equality) {
        if (lower > *limits.max_length_m) {
          model.fixed_violations_.push_back("length_m = " + Num(lower) + " m exceeds " + rule_name +
                                            ": at most " + Num(*limits.max_length_m) + " m");
        }
        continue;
      }
      upper = *limits.max_length_m;
      max_name = rule_name;
    }
    if (lower > upper) {
      model.fixed_violations_.push_back("length_m.min = " + Num(lower) + " m exceeds " + max_name +
                                        " = " + Num(upper) + " m");
    } else if (std::isfinite(lower) || std::isfinite(upper)) {
      const std::string name = equality || cons.length_m.has_value() ? "length_m" : max_name;
      add_linear(name, equality ? name : "length_m.min", equality ? name : max_name, "m",
                 {{lay.KnotPosition(model.num_knots_ - 1), 1.0}}, 0.0, lower, upper, true, false);
    }
  }
  // Mass properties.
  struct PropertyField {
    const char* name;
    const char* unit;
    const std::optional<DesignRange>* range;
    DesignFunction f;
  };
  const PropertyField properties[] = {
      {"mass_kg", "kg", &cons.mass_kg, DesignFunction::kMass},
      {"balance_point_m", "m", &cons.balance_point_m, DesignFunction::kBalancePoint},
      {"moi_six_inch_kg_m2", "kg_m2", &cons.moi_six_inch_kg_m2, DesignFunction::kMoiSixInch},
  };
  for (const PropertyField& pf : properties) {
    if (!pf.range->has_value()) continue;
    double lower = 0.0, upper = 0.0;
    if (!range_of(pf.name, **pf.range, &lower, &upper)) return false;
    add_nonlinear(pf.name, pf.unit, pf.f, lower, upper);
  }
  for (RuleSet rule : cons.rules) {
    const RuleSetLimits limits = LimitsOf(rule);
    if (limits.max_drop.has_value()) {
      DesignConstraintSpec c;
      c.name = c.min_name = c.max_name = std::string("rules.") + RuleSetName(rule) + ".drop";
      c.unit = "";
      c.f.function = DesignFunction::kDrop;
      c.upper = *limits.max_drop;
      c.property = true;
      model.constraints_.push_back(std::move(c));
    }
  }

  // Diameters: the tightest of the request and the rules.
  std::vector<int> radius_knots;  // one knot per distinct radius parameter
  std::vector<std::string> knot_suffix;
  if (problem.three_segment.has_value()) {
    radius_knots = {0, 2};
    knot_suffix = {".three_segment.handle_radius_m", ".three_segment.barrel_radius_m"};
  } else {
    for (int i = 0; i < model.num_knots_; ++i) {
      radius_knots.push_back(i);
      knot_suffix.push_back(".knots[" + std::to_string(i) + "]");
    }
  }
  {
    double max_d = kInf;
    std::string max_name;
    if (cons.max_barrel_diameter_m.has_value()) {
      if (!(std::isfinite(*cons.max_barrel_diameter_m) && *cons.max_barrel_diameter_m > 0.0)) {
        return Refuse(why, "constraints.max_barrel_diameter_m", *cons.max_barrel_diameter_m,
                      "must be finite and positive");
      }
      max_d = *cons.max_barrel_diameter_m;
      max_name = "max_barrel_diameter_m";
    }
    for (RuleSet rule : cons.rules) {
      const double d = LimitsOf(rule).max_diameter_m;
      if (d < max_d) {
        max_d = d;
        max_name = std::string("rules.") + RuleSetName(rule) + ".diameter";
      }
    }
    if (std::isfinite(max_d)) {
      for (std::size_t q = 0; q < radius_knots.size(); ++q) {
        const std::string n = max_name + knot_suffix[q];
        add_linear(n, n, n, "m", {{lay.KnotRadius(radius_knots[q]), 2.0}}, 0.0, -kInf, max_d, false,
                   false);
      }
    }
    if (cons.min_handle_diameter_m.has_value()) {
      if (!(std::isfinite(*cons.min_handle_diameter_m) && *cons.min_handle_diameter_m > 0.0)) {
        return Refuse(why, "constraints.min_handle_diameter_m", *cons.min_handle_diameter_m,
                      "must be finite and positive");
      }
      for (std::size_t q = 0; q < radius_knots.size(); ++q) {
        const std::string n = "min_handle_diameter_m" + knot_suffix[q];
        add_linear(n, n, n, "m", {{lay.KnotRadius(radius_knots[q]), 2.0}}, 0.0,
                   *cons.min_handle_diameter_m, kInf, false, false);
      }
    }
  }
  // Taper.
  if (cons.taper != TaperRule::kNone) {
    if (cons.taper == TaperRule::kMaxSlope &&
        !(std::isfinite(cons.max_taper_slope) && cons.max_taper_slope > 0.0)) {
      return Refuse(why, "constraints.max_taper_slope", cons.max_taper_slope,
                    "must be finite and positive");
    }
    std::vector<std::pair<int, int>> pairs;  // knot a, knot b (a before b)
    std::vector<std::string> suffix;
    if (problem.three_segment.has_value()) {
      pairs = {{1, 2}};
      suffix = {".three_segment"};
    } else {
      const int first = cons.taper_first_knot;
      const int last = cons.taper_last_knot < 0 ? model.num_knots_ - 1 : cons.taper_last_knot;
      if (first < 0 || first >= model.num_knots_) {
        return Refuse(why, "constraints.taper_first_knot", first,
                      "must be a knot index in [0, " + std::to_string(model.num_knots_ - 1) + "]");
      }
      if (last <= first || last >= model.num_knots_) {
        return Refuse(why, "constraints.taper_last_knot", cons.taper_last_knot,
                      "must be -1 (the last knot) or a knot index in (" + std::to_string(first) +
                          ", " + std::to_string(model.num_knots_ - 1) + "]");
      }
      for (int i = first; i < last; ++i) {
        pairs.push_back({i, i + 1});
        suffix.push_back(".knots[" + std::to_string(i) + "]");
      }
    }
    for (std::size_t q = 0; q < pairs.size(); ++q) {
      const auto [a, b] = pairs[q];
      if (cons.taper == TaperRule::kNonDecreasing) {
        const std::string n = "taper" + suffix[q];
        add_linear(n, n, n, "m", {{lay.KnotRadius(b), 1.0}, {lay.KnotRadius(a), -1.0}}, 0.0, 0.0,
                   kInf, false, false);
      } else {
        const double s = cons.max_taper_slope;
        const std::string rise = "max_slope" + suffix[q] + ".rise";
        const std::string fall = "max_slope" + suffix[q] + ".fall";
        add_linear(rise, rise, rise, "m",
                   {{lay.KnotRadius(b), 1.0},
                    {lay.KnotRadius(a), -1.0},
                    {lay.KnotPosition(b), -s},
                    {lay.KnotPosition(a), s}},
                   0.0, -kInf, 0.0, false, false);
        add_linear(fall, fall, fall, "m",
                   {{lay.KnotRadius(b), -1.0},
                    {lay.KnotRadius(a), 1.0},
                    {lay.KnotPosition(b), -s},
                    {lay.KnotPosition(a), s}},
                   0.0, -kInf, 0.0, false, false);
      }
    }
  }
  // Rules: the cup of a solid wooden bat.
  for (RuleSet rule : cons.rules) {
    const RuleSetLimits limits = LimitsOf(rule);
    if (!limits.solid_wood_only || !base.fill.has_value()) continue;
    const std::string prefix = std::string("rules.") + RuleSetName(rule);
    if (limits.max_cup_depth_m.has_value()) {
      const std::string n = prefix + ".cup_depth";
      add_linear(n, n, n, "m", {{lay.FillDepth(), 1.0}}, 0.0, -kInf, *limits.max_cup_depth_m, false,
                 false);
    }
    if (limits.min_cup_diameter_m.has_value() && limits.max_cup_diameter_m.has_value()) {
      const std::string n = prefix + ".cup_diameter";
      add_linear(n, n + ".min", n + ".max", "m", {{lay.FillDiameter(), 1.0}}, 0.0,
                 *limits.min_cup_diameter_m, *limits.max_cup_diameter_m, false, false);
    }
  }

  // Validity of the bat (only where a variable can break it; the base bat is valid).
  const double keep = 1.0 - kStrictMargin;
  if (problem.three_segment.has_value()) {
    add_linear("validity.three_segment.taper_order", "validity.three_segment.taper_order",
               "validity.three_segment.taper_order", "m",
               {{lay.KnotPosition(2), 1.0}, {lay.KnotPosition(1), -1.0}}, 0.0, 0.0, kInf, false,
               true);
    add_linear("validity.three_segment.taper_end", "validity.three_segment.taper_end",
               "validity.three_segment.taper_end", "m",
               {{lay.KnotPosition(3), 1.0}, {lay.KnotPosition(2), -1.0}}, 0.0, 0.0, kInf, false,
               true);
  } else {
    for (int i = 1; i < model.num_knots_; ++i) {
      const double base_gap = param(lay.KnotPosition(i)) - param(lay.KnotPosition(i - 1));
      const std::string n = "validity.knots[" + std::to_string(i) + "].x_m.gap";
      add_linear(n, n, n, "m", {{lay.KnotPosition(i), 1.0}, {lay.KnotPosition(i - 1), -1.0}}, 0.0,
                 std::min(options.min_knot_gap_m, base_gap), kInf, false, true);
    }
  }
  if (model.hollow_) {
    for (std::size_t q = 0; q < radius_knots.size(); ++q) {
      const std::string n = "validity.wall_thickness_m" + knot_suffix[q];
      add_linear(n, n, n, "m",
                 {{lay.KnotRadius(radius_knots[q]), keep}, {lay.WallThickness(), -1.0}}, 0.0, 0.0,
                 kInf, false, true);
    }
  }
  if (model.has_fill_) {
    const int last = lay.KnotPosition(model.num_knots_ - 1);
    add_linear("validity.fill.depth_m", "validity.fill.depth_m", "validity.fill.depth_m", "m",
               {{last, 1.0}, {lay.FillDepth(), -1.0}}, 0.0, 0.0, kInf, false, true);
    // The bore must stay inside the material over its depth. The profile is piecewise linear,
    // so its least radius over [L - d, L] is at a knot inside or at the bore's bottom, which
    // lies on the segment of the last knot at or before it: constrain every knot that can be
    // at or after the knot before the bottom (conservative when positions or depth vary).
    auto upper_of = [&](int idx) {
      const int j = model.parameter_variable_[static_cast<std::size_t>(idx)];
      return j >= 0 ? model.variables_[static_cast<std::size_t>(j)].upper : param(idx);
    };
    auto lower_of = [&](int idx) {
      const int j = model.parameter_variable_[static_cast<std::size_t>(idx)];
      return j >= 0 ? model.variables_[static_cast<std::size_t>(j)].lower : param(idx);
    };
    const double bottom_min = lower_of(last) - upper_of(lay.FillDepth());
    int first = model.num_knots_ - 1;
    while (first > 0 && upper_of(lay.KnotPosition(first)) >= bottom_min) --first;
    // `first` is now the last knot that is surely before the bottom (or knot 0).
    std::set<int> radius_params;
    for (int i = first; i < model.num_knots_; ++i) radius_params.insert(lay.KnotRadius(i));
    for (std::size_t q = 0; q < radius_knots.size(); ++q) {
      // For a three-segment design knots 0-1 share r1 and 2-3 share r2.
      const int k = radius_knots[q];
      const bool used =
          radius_params.count(lay.KnotRadius(k)) > 0 ||
          (problem.three_segment.has_value() && radius_params.count(lay.KnotRadius(k + 1)) > 0);
      if (!used) continue;
      const std::string n = "validity.fill.diameter_m" + knot_suffix[q];
      std::vector<std::pair<int, double>> terms = {{lay.KnotRadius(k), keep},
                                                   {lay.FillDiameter(), -0.5}};
      if (model.hollow_) terms.push_back({lay.WallThickness(), -keep});
      add_linear(n, n, n, "m", std::move(terms), 0.0, 0.0, kInf, false, true);
    }
  }

  // Objective.
  model.objective_.function = DesignFunction::kObjective;
  model.maximize_ = problem.objective != DesignObjective::kMinMoi &&
                    problem.objective != DesignObjective::kMinSting;
  model.objective_unit_ = problem.objective == DesignObjective::kMinMoi            ? "kg_m2"
                          : problem.objective == DesignObjective::kWidestSweetZone ? "m"
                          : problem.objective == DesignObjective::kMinSting        ? "j"
                                                                                   : "mps";
  const std::vector<double> x0 = model.BaseX();
  double f0 = kNaN;
  if (problem.objective == DesignObjective::kMinSting) {
    // The flexible model refuses some bats (too stubby for a beam, ...): say so by name.
    const StingEvaluation sting = model.StingOf(model.BatAt(x0.data()), false);
    if (!sting.ok) {
      return Fail(why,
                  "objective = min_sting: the sting of the start (the base design clamped "
                  "into the variables' bounds) cannot be computed: " +
                      sting.message);
    }
    f0 = sting.sting_j;
  } else {
    f0 = model.Value(model.objective_, x0.data());
  }
  if (!std::isfinite(f0)) {
    return Fail(why,
                "variables: the objective is not finite at the start (the base design "
                "clamped into the variables' bounds)");
  }
  model.objective_scale_ = std::abs(f0) > 0.0 ? std::abs(f0) : 1.0;
  for (DesignConstraintSpec& c : model.constraints_) {
    double s = std::abs(model.Value(c.f, x0.data()));
    if (!std::isfinite(s)) s = 0.0;
    if (std::isfinite(c.lower)) s = std::max(s, std::abs(c.lower));
    if (std::isfinite(c.upper)) s = std::max(s, std::abs(c.upper));
    c.scale = std::max(s, ScaleFloor(c.unit));
  }
  *out = std::move(model);
  return true;
}

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
  for (int k = 0; k < model.m(); ++k) {
    const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
    std::vector<int>& row = structure_[static_cast<std::size_t>(k)];
    if (c.f.function == DesignFunction::kLinear) {
      std::set<int> vars;
      for (int j = 0; j < n; ++j) {
        for (int idx : model.variables()[static_cast<std::size_t>(j)].parameters) {
          for (const auto& [pidx, coef] : c.f.terms) {
            if (pidx == idx && coef != 0.0) vars.insert(j);
          }
        }
      }
      row.assign(vars.begin(), vars.end());
    } else {
      for (int j = 0; j < n; ++j) row.push_back(j);
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
