// The shape fit as a least-squares design problem: the design code's parametrisation and mass
// integrals, the family's validity constraints, the first-order check. See shape_fit_model.hpp.
#include "core/optimize/shape_fit_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "core/geometry_format.hpp"
#include "core/numerics/jet.hpp"
#include "core/numerics/limits.hpp"
#include "core/optimize/design_integrals.hpp"

namespace sweetspot::core::fit_detail {
namespace {

// Relative margin that turns the strict rules (wall < radius, bore inside the
// material) into closed constraints the solver can sit on.
constexpr double kStrictMargin = 1e-9;

const DesignParameterLayout kLayout{4};

// The parameters of the family (DesignParameterLayout{4}): r1 is knots 0 and 1, r2 knots 2 and
// 3; the constraints read r1 at knot 1 and r2 at knot 2 (the chain rule over a variable's
// parameters sums both).
struct Index {
  int x1 = kLayout.KnotPosition(1);
  int x2 = kLayout.KnotPosition(2);
  int length = kLayout.KnotPosition(3);
  int r1 = kLayout.KnotRadius(1);
  int r2 = kLayout.KnotRadius(2);
  int wall = kLayout.WallThickness();
  int diameter = kLayout.FillDiameter();
  int depth = kLayout.FillDepth();
};
const Index kIndex;

constexpr const char* kField[kNumFitVariables] = {
    "shape.taper_start_m",        "shape.taper_end_m",     "shape.length_m",
    "shape.handle_radius_m",      "shape.barrel_radius_m", "material.density_kg_m3",
    "wall_thickness_m",           "fill.diameter_m",       "fill.depth_m",
    "fill.material.density_kg_m3"};

std::vector<int> ParametersOf(DesignVariableKind variable) {
  return design_detail::DesignParametersOf(DesignVariableOf(variable), kLayout);
}

double At(const std::vector<double>& t, int index) { return t[static_cast<std::size_t>(index)]; }

// Outer radius of the three-segment profile at y.
template <typename T>
T FamilyRadiusAt(const T* t, const T& y) {
  const T& x1 = t[kIndex.x1];
  const T& x2 = t[kIndex.x2];
  if (jet::Value(y) <= jet::Value(x1)) return t[kIndex.r1];
  if (jet::Value(y) >= jet::Value(x2)) return t[kIndex.r2];
  return t[kIndex.r1] + (t[kIndex.r2] - t[kIndex.r1]) * (y - x1) / (x2 - x1);
}

template <typename T>
T ConstraintOf(FitConstraint kind, const T* t, bool hollow) {
  const double keep = 1.0 - kStrictMargin;
  switch (kind) {
    case FitConstraint::kStart:
      return -t[kIndex.x1];
    case FitConstraint::kOrder:
      return t[kIndex.x1] - t[kIndex.x2];
    case FitConstraint::kEnd:
      return t[kIndex.x2] - t[kIndex.length];
    case FitConstraint::kWallHandle:
      return t[kIndex.wall] - keep * t[kIndex.r1];
    case FitConstraint::kWallBarrel:
      return t[kIndex.wall] - keep * t[kIndex.r2];
    case FitConstraint::kFillDepth:
      return t[kIndex.depth] - t[kIndex.length];
    case FitConstraint::kBoreBottom: {
      const T around = FamilyRadiusAt<T>(t, T(t[kIndex.length] - t[kIndex.depth])) -
                       (hollow ? t[kIndex.wall] : T(0.0));
      return 0.5 * t[kIndex.diameter] - keep * around;
    }
    case FitConstraint::kBoreTip: {
      const T around = t[kIndex.r2] - (hollow ? t[kIndex.wall] : T(0.0));
      return 0.5 * t[kIndex.diameter] - keep * around;
    }
  }
  return T(0.0);
}

// The parameters each constraint depends on.
std::vector<int> ConstraintParameters(FitConstraint kind) {
  const Index& i = kIndex;
  switch (kind) {
    case FitConstraint::kStart:
      return {i.x1};
    case FitConstraint::kOrder:
      return {i.x1, i.x2};
    case FitConstraint::kEnd:
      return {i.x2, i.length};
    case FitConstraint::kWallHandle:
      return {i.wall, i.r1};
    case FitConstraint::kWallBarrel:
      return {i.wall, i.r2};
    case FitConstraint::kFillDepth:
      return {i.depth, i.length};
    case FitConstraint::kBoreBottom:
      return {i.diameter, i.x1, i.x2, i.length, i.r1, i.r2, i.depth, i.wall};
    case FitConstraint::kBoreTip:
      return {i.diameter, i.r2, i.wall};
  }
  return {};
}

bool Involves(FitConstraint kind, const std::vector<int>& parameters) {
  const std::vector<int> depends = ConstraintParameters(kind);
  for (int p : parameters) {
    if (std::find(depends.begin(), depends.end(), p) != depends.end()) return true;
  }
  return false;
}

}  // namespace

DesignVariableRef DesignVariableOf(DesignVariableKind variable) {
  DesignVariableRef ref;
  ref.kind = FitUnknownIndex(variable) >= 0 ? variable : DesignVariableKind::kTaperStart;
  return ref;
}

const char* FitUnknownField(DesignVariableKind variable) {
  const int i = FitUnknownIndex(variable);
  return i >= 0 ? kField[i] : "";
}

bool IsFillVariable(DesignVariableKind variable) {
  return variable == DesignVariableKind::kFillDiameter ||
         variable == DesignVariableKind::kFillDepth || variable == DesignVariableKind::kFillDensity;
}

std::vector<double> BaseParameters(const ShapeFitProblem& problem) {
  Bat base;
  base.material = problem.material;
  base.wall_thickness_m = problem.wall_thickness_m;
  base.fill = problem.fill;
  return design_detail::ThreeSegmentParameters(base, problem.shape);
}

std::vector<double> StartParameters(const ShapeFitProblem& problem) {
  std::vector<double> t = BaseParameters(problem);
  for (const FitUnknown& u : problem.unknowns) {
    const std::vector<int> parameters = ParametersOf(u.variable);
    const double v = At(t, parameters.front());
    const double start = std::isfinite(v) ? std::clamp(v, u.min, u.max) : 0.5 * (u.min + u.max);
    for (int p : parameters) t[static_cast<std::size_t>(p)] = start;
  }
  return t;
}

double FitValue(const std::vector<double>& t, DesignVariableKind variable) {
  return At(t, ParametersOf(variable).front());
}

bool HollowOf(const ShapeFitProblem& problem) {
  if (problem.wall_thickness_m > 0.0) return true;
  for (const FitUnknown& u : problem.unknowns) {
    if (u.variable == DesignVariableKind::kWallThickness) return true;
  }
  return false;
}

std::vector<FitConstraint> ApplicableConstraints(bool hollow, bool has_fill) {
  std::vector<FitConstraint> out = {FitConstraint::kStart, FitConstraint::kOrder,
                                    FitConstraint::kEnd};
  if (hollow) {
    out.push_back(FitConstraint::kWallHandle);
    out.push_back(FitConstraint::kWallBarrel);
  }
  if (has_fill) {
    out.push_back(FitConstraint::kFillDepth);
    out.push_back(FitConstraint::kBoreBottom);
    out.push_back(FitConstraint::kBoreTip);
  }
  return out;
}

bool ConstraintInvolves(FitConstraint kind, const std::vector<bool>& unknown) {
  for (int i = 0; i < kNumFitVariables && i < static_cast<int>(unknown.size()); ++i) {
    if (unknown[static_cast<std::size_t>(i)] && Involves(kind, ParametersOf(kFitUnknownKinds[i]))) {
      return true;
    }
  }
  return false;
}

double ConstraintValue(FitConstraint kind, const std::vector<double>& t, bool hollow) {
  return ConstraintOf<double>(kind, t.data(), hollow);
}

Refusal ConstraintRefusal(FitConstraint kind, const std::vector<double>& t, bool hollow) {
  const auto field = [](DesignVariableKind v) { return FitUnknownField(v); };
  const double x1 = At(t, kIndex.x1);
  const double x2 = At(t, kIndex.x2);
  const double length = At(t, kIndex.length);
  const double wall = At(t, kIndex.wall);
  const double diameter = At(t, kIndex.diameter);
  const double depth = At(t, kIndex.depth);
  switch (kind) {
    case FitConstraint::kStart:
      return NumberRefusal(field(DesignVariableKind::kTaperStart), x1, "must be non-negative");
    case FitConstraint::kOrder:
      return NumberRefusal(field(DesignVariableKind::kTaperStart), x1,
                           std::string("must not exceed shape.taper_end_m = ") + FormatNumber(x2));
    case FitConstraint::kEnd:
      return NumberRefusal(field(DesignVariableKind::kTaperEnd), x2,
                           "must not exceed shape.length_m = " + FormatNumber(length));
    case FitConstraint::kWallHandle:
      return NumberRefusal(
          field(DesignVariableKind::kWallThickness), wall,
          "must be less than shape.handle_radius_m = " + FormatNumber(At(t, kIndex.r1)));
    case FitConstraint::kWallBarrel:
      return NumberRefusal(
          field(DesignVariableKind::kWallThickness), wall,
          "must be less than shape.barrel_radius_m = " + FormatNumber(At(t, kIndex.r2)));
    case FitConstraint::kFillDepth:
      return NumberRefusal(field(DesignVariableKind::kFillDepth), depth,
                           "must not exceed shape.length_m = " + FormatNumber(length));
    case FitConstraint::kBoreBottom:
    case FitConstraint::kBoreTip: {
      const double y = kind == FitConstraint::kBoreTip ? length : length - depth;
      const double around = FamilyRadiusAt<double>(t.data(), y) - (hollow ? wall : 0.0);
      return NumberRefusal(field(DesignVariableKind::kFillDiameter), diameter,
                           "the bore radius " + FormatNumber(0.5 * diameter) +
                               " must be less than the " + (hollow ? "inner" : "outer") +
                               " radius " + FormatNumber(around) + " at x_m = " + FormatNumber(y) +
                               " (over the fill's depth)");
    }
  }
  return Refusal{};
}

std::string ConstraintMessage(FitConstraint kind, const std::vector<double>& t, bool hollow) {
  return ConstraintRefusal(kind, t, hollow).Message();
}

// ---------------------------------------------------------------------------------------------
// The model.

ShapeFitModel::ShapeFitModel(const ShapeFitProblem& problem, const ShapeFitOptions& options)
    : base_(StartParameters(problem)),
      hollow_(HollowOf(problem)),
      has_fill_(problem.fill.has_value()),
      parameter_variable_(static_cast<std::size_t>(kNumFitParameters), -1),
      parameter_scale_(static_cast<std::size_t>(kNumFitParameters), 1.0) {
  for (const FitUnknown& u : problem.unknowns) {
    for (int p : ParametersOf(u.variable)) {
      parameter_variable_[static_cast<std::size_t>(p)] = static_cast<int>(variables_.size());
    }
    variables_.push_back(ParametersOf(u.variable));
    lo_.push_back(u.min);
    hi_.push_back(u.max);
  }
  if (problem.targets.mass_kg.has_value()) {
    targets_.push_back(*problem.targets.mass_kg);
    scales_.push_back(options.mass_scale_kg > 0.0 ? options.mass_scale_kg
                                                  : *problem.targets.mass_kg);
    kinds_.push_back(0);
  }
  if (problem.targets.balance_point_m.has_value()) {
    targets_.push_back(*problem.targets.balance_point_m);
    scales_.push_back(options.balance_point_scale_m > 0.0 ? options.balance_point_scale_m
                                                          : *problem.targets.balance_point_m);
    kinds_.push_back(1);
  }
  // Constraints that involve an unknown; the others hold at the fixed
  // values (ShapeFitProblem::IsValid checked them).
  double length_scale = At(base_, kIndex.length);
  for (const FitUnknown& u : problem.unknowns) {
    if (u.variable == DesignVariableKind::kLength) length_scale = std::max(length_scale, u.max);
  }
  length_scale_ = length_scale > 0.0 ? length_scale : 1.0;
  for (FitConstraint kind : ApplicableConstraints(hollow_, has_fill_)) {
    bool involved = false;
    for (const std::vector<int>& parameters : variables_) {
      involved = involved || Involves(kind, parameters);
    }
    if (involved) constraints_.push_back(kind);
  }
}

std::vector<double> ShapeFitModel::ToParameters(const double* s) const {
  std::vector<double> t = base_;
  for (int j = 0; j < n(); ++j) {
    const double sj = std::clamp(s[j], 0.0, 1.0);
    const double x =
        lo_[static_cast<std::size_t>(j)] * (1.0 - sj) + hi_[static_cast<std::size_t>(j)] * sj;
    for (int p : variables_[static_cast<std::size_t>(j)]) t[static_cast<std::size_t>(p)] = x;
  }
  return t;
}

std::vector<double> ShapeFitModel::StartS() const {
  std::vector<double> s(static_cast<std::size_t>(n()));
  for (std::size_t j = 0; j < s.size(); ++j) {
    s[j] = (At(base_, variables_[j].front()) - lo_[j]) / (hi_[j] - lo_[j]);
  }
  return s;
}

void ShapeFitModel::Residuals(const double* s, Eigen::VectorXd* r, Eigen::MatrixXd* jacobian) {
  ++evaluations_;
  const std::vector<double> t = ToParameters(s);
  design_detail::Integrals in;
  // S1 about the knob (c0 = 0): C = S1 / M. S2 is not used (rigid = false skips the disks).
  const design_detail::IntegralContext context{
      t, parameter_variable_, parameter_scale_, 4, hollow_, has_fill_, false, 0.0};
  design_detail::ComputeIntegrals(context, n(), jacobian != nullptr, &in);
  const double mass = in.p[0];
  const double balance = in.p[1] / mass;
  r->resize(m());
  if (jacobian != nullptr) jacobian->resize(m(), n());
  for (int i = 0; i < m(); ++i) {
    const std::size_t k = static_cast<std::size_t>(i);
    const double value = kinds_[k] == 0 ? mass : balance;
    (*r)[i] = (value - targets_[k]) / scales_[k];
    if (jacobian == nullptr) continue;
    for (int j = 0; j < n(); ++j) {
      // dC = (dS1 - C dM) / M.
      const double d = kinds_[k] == 0 ? in.dp(0, j) : (in.dp(1, j) - balance * in.dp(0, j)) / mass;
      (*jacobian)(i, j) =
          d * (hi_[static_cast<std::size_t>(j)] - lo_[static_cast<std::size_t>(j)]) / scales_[k];
    }
  }
}

double ShapeFitModel::Objective(const double* s, double* grad) {
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  Residuals(s, &r, grad != nullptr ? &jac : nullptr);
  if (grad != nullptr) {
    const Eigen::VectorXd g = 2.0 * jac.transpose() * r;
    for (int j = 0; j < n(); ++j) grad[j] = g[j];
  }
  return r.squaredNorm();
}

double ShapeFitModel::Constraint(FitConstraint kind, const double* s, double* grad) const {
  const std::vector<double> t = ToParameters(s);
  if (grad == nullptr) return ConstraintOf<double>(kind, t.data(), hollow_) / length_scale_;
  // Jet variable j is unknown j: the chain rule over the parameters it sets (two for a radius)
  // is the AD's own.
  using J = jet::Jet<kNumFitVariables, false>;
  std::array<J, kNumFitParameters> tj;
  for (int p = 0; p < kNumFitParameters; ++p) tj[static_cast<std::size_t>(p)] = J(At(t, p));
  for (int j = 0; j < n(); ++j) {
    for (int p : variables_[static_cast<std::size_t>(j)]) {
      tj[static_cast<std::size_t>(p)] = J::Variable(At(t, p), j);
    }
  }
  const J g = ConstraintOf<J>(kind, tj.data(), hollow_);
  for (int j = 0; j < n(); ++j) {
    const std::size_t k = static_cast<std::size_t>(j);
    grad[j] = g.g[k] * (hi_[k] - lo_[k]) / length_scale_;
  }
  return g.v / length_scale_;
}

double ShapeFitModel::MaxViolationM(const double* s) const {
  if (constraints_.empty()) return 0.0;
  const std::vector<double> t = ToParameters(s);
  double worst = -std::numeric_limits<double>::infinity();
  for (FitConstraint kind : constraints_) {
    worst = std::max(worst, ConstraintOf<double>(kind, t.data(), hollow_));
  }
  return worst;
}

// ---------------------------------------------------------------------------------------------
// The first-order check.

// min over lambda >= 0 of |grad phi + A^T lambda| by a small active-set loop, relative to
// 2 |J| |r|.
double KktError(ShapeFitModel& model, const std::vector<double>& s) {
  const int n = model.n();
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  model.Residuals(s.data(), &r, &jac);
  const Eigen::VectorXd grad = 2.0 * jac.transpose() * r;
  const double scale = 2.0 * jac.norm() * r.norm();
  if (!(scale > 0.0)) return 0.0;
  // A metric flat to rounding: moving the unknowns over their whole bounds (s in [0, 1])
  // changes no scaled residual by more than the mass properties resolve (a few eps of values
  // of size 1 + |r|), e.g. where a taper between equal radii starts and ends. Every point is
  // then stationary; without this, rounding noise divided by a scale made of the same noise
  // read as a first-order residual of ~1 (a flat fit was reported as not certified).
  if (jac.lpNorm<Eigen::Infinity>() <= 64.0 * kEps * (1.0 + r.lpNorm<Eigen::Infinity>())) {
    return 0.0;
  }
  std::vector<Eigen::VectorXd> normals;
  constexpr double kActive = 1e-9;
  for (int j = 0; j < n; ++j) {
    if (s[static_cast<std::size_t>(j)] <= kActive) normals.push_back(-Eigen::VectorXd::Unit(n, j));
    if (s[static_cast<std::size_t>(j)] >= 1.0 - kActive)
      normals.push_back(Eigen::VectorXd::Unit(n, j));
  }
  for (FitConstraint kind : model.constraints()) {
    Eigen::VectorXd g(n);
    const double value = model.Constraint(kind, s.data(), g.data());
    if (value >= -kActive) normals.push_back(g);
  }
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

}  // namespace sweetspot::core::fit_detail
