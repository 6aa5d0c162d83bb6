#include "core/shape_fit.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <new>
#include <stdexcept>

#include <Eigen/Dense>
#include <unsupported/Eigen/AutoDiff>

#include "core/geometry_format.hpp"
#include "core/geometry_integrals.hpp"
#include "core/optimize/nlopt_run.hpp"
#include "core/optimize/termination.hpp"

namespace sweetspot::core {
namespace {

// The family's parameters, in FitVariable order.
constexpr int kNumParams = 10;
enum ParamIndex : int {
  kX1 = 0,
  kX2 = 1,
  kLen = 2,
  kR1 = 3,
  kR2 = 4,
  kRho = 5,
  kWall = 6,
  kDiam = 7,
  kDepth = 8,
  kRhoS = 9,
};
constexpr const char* kParamField[kNumParams] = {
    "shape.taper_start_m",        "shape.taper_end_m",     "shape.length_m",
    "shape.handle_radius_m",      "shape.barrel_radius_m", "material.density_kg_m3",
    "wall_thickness_m",           "fill.diameter_m",       "fill.depth_m",
    "fill.material.density_kg_m3"};
constexpr const char* kVariableName[kNumParams] = {
    "taper_start_m",   "taper_end_m",       "length_m",         "handle_radius_m",
    "barrel_radius_m", "density_kg_m3",     "wall_thickness_m", "fill.diameter_m",
    "fill.depth_m",    "fill.density_kg_m3"};

// Relative margin that turns the strict rules (wall < radius, bore inside the
// material) into closed constraints the solver can sit on.
constexpr double kStrictMargin = 1e-9;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using Ad = Eigen::AutoDiffScalar<Eigen::Matrix<double, kNumParams, 1>>;
template <typename T>
using Params = std::array<T, kNumParams>;

inline double Value(double v) { return v; }
inline double Value(const Ad& v) { return v.value(); }

// The three-segment profile as 4 knots; coincident knots are fine here (the
// integrals never divide by a segment's length), so the map from parameters
// to knots is smooth everywhere, including x1 = x2, x1 = 0 and x2 = L.
template <typename T>
struct ThreeSegmentProfile {
  std::array<T, 4> xs;
  std::array<T, 4> rs;
  std::size_t size() const { return 4; }
  T x(std::size_t i) const { return xs[i]; }
  T r(std::size_t i) const { return rs[i]; }
};

template <typename T>
geometry::MassMoment<T> EvaluateFamily(const Params<T>& p, bool hollow, bool has_fill) {
  ThreeSegmentProfile<T> profile{{T(0.0), p[kX1], p[kX2], p[kLen]},
                                 {p[kR1], p[kR1], p[kR2], p[kR2]}};
  geometry::BodyScalars<T> body;
  body.density = p[kRho];
  body.wall = p[kWall];
  body.hollow = hollow;
  body.has_fill = has_fill;
  body.fill_radius = 0.5 * p[kDiam];
  body.fill_depth = p[kDepth];
  body.fill_density = p[kRhoS];
  return geometry::ComputeMassMoment<T>(profile, body);
}

// Outer radius of the three-segment profile at y.
template <typename T>
T FamilyRadiusAt(const Params<T>& p, const T& y) {
  if (Value(y) <= Value(p[kX1])) return p[kR1];
  if (Value(y) >= Value(p[kX2])) return p[kR2];
  return p[kR1] + (p[kR2] - p[kR1]) * (y - p[kX1]) / (p[kX2] - p[kX1]);
}

// Validity constraints g(p) <= 0 of the family, all in metres.
enum class ConstraintKind {
  kStart,       // -x1 <= 0
  kOrder,       // x1 - x2 <= 0
  kEnd,         // x2 - L <= 0
  kWallHandle,  // t < r1
  kWallBarrel,  // t < r2
  kFillDepth,   // d <= L
  kBoreBottom,  // bore radius < material around it at L - d
  kBoreTip,     // bore radius < material around it at L
};

template <typename T>
T ConstraintValue(ConstraintKind kind, const Params<T>& p, bool hollow) {
  const double keep = 1.0 - kStrictMargin;
  switch (kind) {
    case ConstraintKind::kStart:
      return -p[kX1];
    case ConstraintKind::kOrder:
      return p[kX1] - p[kX2];
    case ConstraintKind::kEnd:
      return p[kX2] - p[kLen];
    case ConstraintKind::kWallHandle:
      return p[kWall] - keep * p[kR1];
    case ConstraintKind::kWallBarrel:
      return p[kWall] - keep * p[kR2];
    case ConstraintKind::kFillDepth:
      return p[kDepth] - p[kLen];
    case ConstraintKind::kBoreBottom: {
      const T around = FamilyRadiusAt<T>(p, T(p[kLen] - p[kDepth])) - (hollow ? p[kWall] : T(0.0));
      return 0.5 * p[kDiam] - keep * around;
    }
    case ConstraintKind::kBoreTip: {
      const T around = p[kR2] - (hollow ? p[kWall] : T(0.0));
      return 0.5 * p[kDiam] - keep * around;
    }
  }
  return T(0.0);
}

// Which parameters each constraint depends on.
std::array<bool, kNumParams> ConstraintDepends(ConstraintKind kind) {
  std::array<bool, kNumParams> d{};
  switch (kind) {
    case ConstraintKind::kStart:
      d[kX1] = true;
      break;
    case ConstraintKind::kOrder:
      d[kX1] = d[kX2] = true;
      break;
    case ConstraintKind::kEnd:
      d[kX2] = d[kLen] = true;
      break;
    case ConstraintKind::kWallHandle:
      d[kWall] = d[kR1] = true;
      break;
    case ConstraintKind::kWallBarrel:
      d[kWall] = d[kR2] = true;
      break;
    case ConstraintKind::kFillDepth:
      d[kDepth] = d[kLen] = true;
      break;
    case ConstraintKind::kBoreBottom:
      d[kDiam] = d[kX1] = d[kX2] = d[kLen] = d[kR1] = d[kR2] = d[kDepth] = d[kWall] = true;
      break;
    case ConstraintKind::kBoreTip:
      d[kDiam] = d[kR2] = d[kWall] = true;
      break;
  }
  return d;
}

// "field = value: rule" for a violated constraint at the fixed values p.
std::string ConstraintMessage(ConstraintKind kind, const Params<double>& p, bool hollow) {
  switch (kind) {
    case ConstraintKind::kStart:
      return RefusalMessage(kParamField[kX1], p[kX1], "must be non-negative");
    case ConstraintKind::kOrder:
      return RefusalMessage(
          kParamField[kX1], p[kX1],
          std::string("must not exceed shape.taper_end_m = ") + FormatNumber(p[kX2]));
    case ConstraintKind::kEnd:
      return RefusalMessage(kParamField[kX2], p[kX2],
                            "must not exceed shape.length_m = " + FormatNumber(p[kLen]));
    case ConstraintKind::kWallHandle:
      return RefusalMessage(kParamField[kWall], p[kWall],
                            "must be less than shape.handle_radius_m = " + FormatNumber(p[kR1]));
    case ConstraintKind::kWallBarrel:
      return RefusalMessage(kParamField[kWall], p[kWall],
                            "must be less than shape.barrel_radius_m = " + FormatNumber(p[kR2]));
    case ConstraintKind::kFillDepth:
      return RefusalMessage(kParamField[kDepth], p[kDepth],
                            "must not exceed shape.length_m = " + FormatNumber(p[kLen]));
    case ConstraintKind::kBoreBottom:
    case ConstraintKind::kBoreTip: {
      const double y = kind == ConstraintKind::kBoreTip ? p[kLen] : p[kLen] - p[kDepth];
      const double around = FamilyRadiusAt<double>(p, y) - (hollow ? p[kWall] : 0.0);
      return RefusalMessage(kParamField[kDiam], p[kDiam],
                            "the bore radius " + FormatNumber(0.5 * p[kDiam]) +
                                " must be less than the " + (hollow ? "inner" : "outer") +
                                " radius " + FormatNumber(around) + " at x_m = " + FormatNumber(y) +
                                " (over the fill's depth)");
    }
  }
  return "";
}

bool IsFillVariable(int index) { return index == kDiam || index == kDepth || index == kRhoS; }

Params<double> BaseParams(const ShapeFitProblem& problem) {
  Params<double> p{};
  p[kX1] = problem.shape.taper_start_m;
  p[kX2] = problem.shape.taper_end_m;
  p[kLen] = problem.shape.length_m;
  p[kR1] = problem.shape.handle_radius_m;
  p[kR2] = problem.shape.barrel_radius_m;
  p[kRho] = problem.material.density_kg_m3;
  p[kWall] = problem.wall_thickness_m;
  if (problem.fill.has_value()) {
    p[kDiam] = problem.fill->diameter_m;
    p[kDepth] = problem.fill->depth_m;
    p[kRhoS] = problem.fill->material.density_kg_m3;
  }
  return p;
}

// The starting values: unknowns clamped into their bounds.
Params<double> StartParams(const ShapeFitProblem& problem) {
  Params<double> p = BaseParams(problem);
  for (const FitUnknown& u : problem.unknowns) {
    double& v = p[static_cast<int>(u.variable)];
    v = std::isfinite(v) ? std::clamp(v, u.min, u.max) : 0.5 * (u.min + u.max);
  }
  return p;
}

bool HollowOf(const ShapeFitProblem& problem) {
  if (problem.wall_thickness_m > 0.0) return true;
  for (const FitUnknown& u : problem.unknowns) {
    if (u.variable == FitVariable::kWallThickness) return true;
  }
  return false;
}

std::vector<ConstraintKind> ApplicableConstraints(bool hollow, bool has_fill) {
  std::vector<ConstraintKind> out = {ConstraintKind::kStart, ConstraintKind::kOrder,
                                     ConstraintKind::kEnd};
  if (hollow) {
    out.push_back(ConstraintKind::kWallHandle);
    out.push_back(ConstraintKind::kWallBarrel);
  }
  if (has_fill) {
    out.push_back(ConstraintKind::kFillDepth);
    out.push_back(ConstraintKind::kBoreBottom);
    out.push_back(ConstraintKind::kBoreTip);
  }
  return out;
}

// Builds the bat of the family at parameters p.
void BuildBat(const ShapeFitProblem& problem, const Params<double>& p, ShapeFitResult* out) {
  out->shape.taper_start_m = p[kX1];
  out->shape.taper_end_m = p[kX2];
  out->shape.length_m = p[kLen];
  out->shape.handle_radius_m = p[kR1];
  out->shape.barrel_radius_m = p[kR2];
  out->material = problem.material;
  out->material.density_kg_m3 = p[kRho];
  out->wall_thickness_m = p[kWall];
  out->fill = problem.fill;
  if (out->fill.has_value()) {
    out->fill->diameter_m = p[kDiam];
    out->fill->depth_m = p[kDepth];
    out->fill->material.density_kg_m3 = p[kRhoS];
  }
  out->bat = MakeThreeSegmentBat(out->shape, out->material);
  out->bat.wall_thickness_m = out->wall_thickness_m;
  out->bat.fill = out->fill;
  out->properties = ComputeMassProperties(out->bat, InertiaModel::kRigidBody);
  out->values.clear();
  for (const FitUnknown& u : problem.unknowns)
    out->values.push_back(p[static_cast<int>(u.variable)]);
}

// The fit in scaled unknowns s in [0, 1]^n: p = lo (1 - s) + hi s.
class FitContext {
 public:
  FitContext(const ShapeFitProblem& problem, const ShapeFitOptions& options)
      : base_(StartParams(problem)),
        hollow_(HollowOf(problem)),
        has_fill_(problem.fill.has_value()) {
    for (const FitUnknown& u : problem.unknowns) {
      index_.push_back(static_cast<int>(u.variable));
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
    double length_scale = base_[kLen];
    for (const FitUnknown& u : problem.unknowns) {
      if (u.variable == FitVariable::kLength) length_scale = std::max(length_scale, u.max);
    }
    length_scale_ = length_scale > 0.0 ? length_scale : 1.0;
    for (ConstraintKind kind : ApplicableConstraints(hollow_, has_fill_)) {
      const auto depends = ConstraintDepends(kind);
      bool involved = false;
      for (int idx : index_) involved = involved || depends[idx];
      if (involved) constraints_.push_back(kind);
    }
  }

  int n() const { return static_cast<int>(index_.size()); }
  int m() const { return static_cast<int>(targets_.size()); }
  bool hollow() const { return hollow_; }
  const std::vector<ConstraintKind>& constraints() const { return constraints_; }
  double length_scale() const { return length_scale_; }
  int evaluations() const { return evaluations_; }

  Params<double> ToParams(const double* s) const {
    Params<double> p = base_;
    for (int j = 0; j < n(); ++j) {
      const double sj = std::clamp(s[j], 0.0, 1.0);
      p[index_[j]] = lo_[j] * (1.0 - sj) + hi_[j] * sj;
    }
    return p;
  }

  // Scaled residuals r (size m) and, if jacobian != nullptr, dr/ds (m x n).
  void Residuals(const double* s, Eigen::VectorXd* r, Eigen::MatrixXd* jacobian) {
    ++evaluations_;
    const Params<double> p = ToParams(s);
    Params<Ad> pa;
    for (int i = 0; i < kNumParams; ++i) pa[i] = Ad(p[i], kNumParams, i);
    const geometry::MassMoment<Ad> mm = EvaluateFamily<Ad>(pa, hollow_, has_fill_);
    const Ad balance = mm.moment / mm.mass;
    r->resize(m());
    if (jacobian != nullptr) jacobian->resize(m(), n());
    for (int i = 0; i < m(); ++i) {
      const Ad& value = kinds_[i] == 0 ? mm.mass : balance;
      (*r)[i] = (value.value() - targets_[i]) / scales_[i];
      if (jacobian != nullptr) {
        for (int j = 0; j < n(); ++j) {
          (*jacobian)(i, j) = value.derivatives()[index_[j]] * (hi_[j] - lo_[j]) / scales_[i];
        }
      }
    }
  }

  double Objective(const double* s, double* grad) {
    Eigen::VectorXd r;
    Eigen::MatrixXd jac;
    Residuals(s, &r, grad != nullptr ? &jac : nullptr);
    if (grad != nullptr) {
      const Eigen::VectorXd g = 2.0 * jac.transpose() * r;
      for (int j = 0; j < n(); ++j) grad[j] = g[j];
    }
    return r.squaredNorm();
  }

  // Constraint value (divided by the length scale) and its gradient in s.
  double Constraint(ConstraintKind kind, const double* s, double* grad) const {
    const Params<double> p = ToParams(s);
    Params<Ad> pa;
    for (int i = 0; i < kNumParams; ++i) pa[i] = Ad(p[i], kNumParams, i);
    const Ad g = ConstraintValue<Ad>(kind, pa, hollow_);
    if (grad != nullptr) {
      for (int j = 0; j < n(); ++j) {
        grad[j] = g.derivatives()[index_[j]] * (hi_[j] - lo_[j]) / length_scale_;
      }
    }
    return g.value() / length_scale_;
  }

  // Largest constraint value at s, m (<= 0 when feasible).
  double MaxViolationM(const double* s) const {
    double worst = -std::numeric_limits<double>::infinity();
    for (ConstraintKind kind : constraints_) {
      worst = std::max(worst, Constraint(kind, s, nullptr) * length_scale_);
    }
    return constraints_.empty() ? 0.0 : worst;
  }

  bool Feasible(const double* s) const { return MaxViolationM(s) <= 0.0; }

  std::vector<double> StartS() const {
    std::vector<double> s(static_cast<std::size_t>(n()));
    for (int j = 0; j < n(); ++j) {
      s[static_cast<std::size_t>(j)] = (base_[index_[j]] - lo_[j]) / (hi_[j] - lo_[j]);
    }
    return s;
  }

 private:
  Params<double> base_;
  bool hollow_;
  bool has_fill_;
  std::vector<int> index_;
  std::vector<double> lo_, hi_;
  std::vector<double> targets_, scales_;
  std::vector<int> kinds_;  // 0 = mass, 1 = balance point
  std::vector<ConstraintKind> constraints_;
  double length_scale_ = 1.0;
  int evaluations_ = 0;
};

// Radical-inverse (Halton) point `index` in [0, 1)^n: a deterministic scan.
double RadicalInverse(int index, int base) {
  double result = 0.0;
  double f = 1.0 / base;
  while (index > 0) {
    result += f * (index % base);
    index /= base;
    f /= base;
  }
  return result;
}

// First-order optimality residual of phi at s over the active bounds and
// constraints, relative to the size of phi's gradient terms (2 |J| |r|):
// min over lambda >= 0 of |grad phi + A^T lambda|, by a small active-set loop.
double KktError(FitContext& context, const std::vector<double>& s) {
  const int n = context.n();
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  context.Residuals(s.data(), &r, &jac);
  const Eigen::VectorXd grad = 2.0 * jac.transpose() * r;
  const double scale = 2.0 * jac.norm() * r.norm();
  if (!(scale > 0.0)) return 0.0;
  // A metric flat to rounding: moving the unknowns over their whole bounds (s in [0, 1])
  // changes no scaled residual by more than the mass properties resolve (a few eps of values
  // of size 1 + |r|), e.g. where a taper between equal radii starts and ends. Every point is
  // then stationary; without this, rounding noise divided by a scale made of the same noise
  // read as a first-order residual of ~1 (a flat fit was reported as not certified).
  constexpr double kEps = std::numeric_limits<double>::epsilon();
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
  for (ConstraintKind kind : context.constraints()) {
    Eigen::VectorXd g(n);
    const double value = context.Constraint(kind, s.data(), g.data());
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

std::string DescribeTargets(const ShapeFitProblem& problem) {
  std::string out;
  if (problem.targets.mass_kg.has_value()) {
    out += "mass_kg = " + FormatNumber(*problem.targets.mass_kg);
  }
  if (problem.targets.balance_point_m.has_value()) {
    if (!out.empty()) out += " and ";
    out += "balance_point_m = " + FormatNumber(*problem.targets.balance_point_m);
  }
  return out;
}

std::string DescribeUnknowns(const ShapeFitProblem& problem) {
  std::string out;
  for (const FitUnknown& u : problem.unknowns) {
    if (!out.empty()) out += ", ";
    out += std::string(FitVariableName(u.variable)) + " in [" + FormatNumber(u.min) + ", " +
           FormatNumber(u.max) + "]";
  }
  return out;
}

// Smallest target or scale of the fit's metric, kg or m: residuals divided by
// less than this can overflow to inf.
constexpr double kMinMetricScale = 1e-6;

bool Refuse(std::string* why, std::string_view field, double value, std::string_view rule) {
  if (why != nullptr) *why = RefusalMessage(field, value, rule);
  return false;
}

}  // namespace

const char* FitVariableName(FitVariable variable) {
  const int i = static_cast<int>(variable);
  return (i >= 0 && i < kNumParams) ? kVariableName[i] : "unknown";
}

std::optional<FitVariable> FitVariableFromName(std::string_view name) {
  for (int i = 0; i < kNumParams; ++i) {
    if (name == kVariableName[i]) return static_cast<FitVariable>(i);
  }
  return std::nullopt;
}

bool ShapeFitOptions::IsValid(std::string* why) const {
  if (!std::isfinite(mass_scale_kg) || mass_scale_kg < 0.0) {
    return Refuse(why, "mass_scale_kg", mass_scale_kg,
                  "must be finite and non-negative (0 = the target)");
  }
  if (!std::isfinite(balance_point_scale_m) || balance_point_scale_m < 0.0) {
    return Refuse(why, "balance_point_scale_m", balance_point_scale_m,
                  "must be finite and non-negative (0 = the target)");
  }
  // Smaller scales overflow the scaled residuals to inf (found by fuzzing).
  if (mass_scale_kg > 0.0 && mass_scale_kg < kMinMetricScale) {
    return Refuse(why, "mass_scale_kg", mass_scale_kg, "must be 0 (the target) or at least 1e-06");
  }
  if (balance_point_scale_m > 0.0 && balance_point_scale_m < kMinMetricScale) {
    return Refuse(why, "balance_point_scale_m", balance_point_scale_m,
                  "must be 0 (the target) or at least 1e-06");
  }
  if (!std::isfinite(tolerance) || !(tolerance > 0.0)) {
    return Refuse(why, "tolerance", tolerance, "must be finite and positive");
  }
  if (!std::isfinite(kkt_tolerance) || !(kkt_tolerance > 0.0)) {
    return Refuse(why, "kkt_tolerance", kkt_tolerance, "must be finite and positive");
  }
  if (scan_points < 1) return Refuse(why, "scan_points", scan_points, "must be at least 1");
  if (local_starts < 1) return Refuse(why, "local_starts", local_starts, "must be at least 1");
  if (max_evaluations < 1) {
    return Refuse(why, "max_evaluations", max_evaluations, "must be at least 1");
  }
  if (!std::isfinite(max_time_s) || !(max_time_s > 0.0)) {
    return Refuse(why, "max_time_s", max_time_s, "must be finite and positive");
  }
  return true;
}

bool ShapeFitProblem::IsValid(std::string* why) const {
  if (!targets.mass_kg.has_value() && !targets.balance_point_m.has_value()) {
    if (why != nullptr) *why = "targets: must give mass_kg, balance_point_m or both";
    return false;
  }
  if (targets.mass_kg.has_value() && !(std::isfinite(*targets.mass_kg) && *targets.mass_kg > 0.0)) {
    return Refuse(why, "targets.mass_kg", *targets.mass_kg, "must be finite and positive");
  }
  if (targets.balance_point_m.has_value() &&
      !(std::isfinite(*targets.balance_point_m) && *targets.balance_point_m > 0.0)) {
    return Refuse(why, "targets.balance_point_m", *targets.balance_point_m,
                  "must be finite and positive");
  }
  // A target is the metric's default scale: a smaller one overflows it (found by fuzzing).
  if (targets.mass_kg.has_value() && *targets.mass_kg < kMinMetricScale) {
    return Refuse(why, "targets.mass_kg", *targets.mass_kg, "must be at least 1e-06");
  }
  if (targets.balance_point_m.has_value() && *targets.balance_point_m < kMinMetricScale) {
    return Refuse(why, "targets.balance_point_m", *targets.balance_point_m,
                  "must be at least 1e-06");
  }
  if (unknowns.empty() || unknowns.size() > static_cast<std::size_t>(kNumParams)) {
    return Refuse(why, "unknowns.size()", static_cast<double>(unknowns.size()),
                  "must be between 1 and 10");
  }
  std::array<bool, kNumParams> unknown{};
  for (std::size_t i = 0; i < unknowns.size(); ++i) {
    const FitUnknown& u = unknowns[i];
    const int idx = static_cast<int>(u.variable);
    if (idx < 0 || idx >= kNumParams) {
      return Refuse(why, IndexedField("unknowns", i, "variable"), idx, "is not a FitVariable");
    }
    const char* name = kVariableName[idx];
    if (unknown[idx]) {
      if (why != nullptr) {
        *why = IndexedField("unknowns", i, "variable") + " = " + name + ": appears more than once";
      }
      return false;
    }
    unknown[idx] = true;
    if (IsFillVariable(idx) && !fill.has_value()) {
      if (why != nullptr) {
        *why = IndexedField("unknowns", i, "variable") + " = " + name + ": the bat has no fill";
      }
      return false;
    }
    if (!std::isfinite(u.min)) {
      return why == nullptr
                 ? false
                 : Refuse(why, IndexedField("unknowns", i, "min"), u.min, "must be finite");
    }
    if (!std::isfinite(u.max)) {
      return why == nullptr
                 ? false
                 : Refuse(why, IndexedField("unknowns", i, "max"), u.max, "must be finite");
    }
    if (!(u.max > u.min)) {
      return why == nullptr ? false
                            : Refuse(why, IndexedField("unknowns", i, "max"), u.max,
                                     "must be greater than " + IndexedField("unknowns", i, "min") +
                                         " = " + FormatNumber(u.min));
    }
    const bool must_be_positive =
        idx == kLen || idx == kR1 || idx == kR2 || idx == kRho || idx == kWall;
    if (must_be_positive && !(u.min > 0.0)) {
      return why == nullptr ? false
                            : Refuse(why, IndexedField("unknowns", i, "min"), u.min,
                                     std::string("must be positive for ") + name +
                                         (idx == kWall ? " (the bat stays hollow)" : ""));
    }
    if (!must_be_positive && u.min < 0.0) {
      return why == nullptr ? false
                            : Refuse(why, IndexedField("unknowns", i, "min"), u.min,
                                     std::string("must be non-negative for ") + name);
    }
  }
  // The fixed values.
  const Params<double> p = StartParams(*this);
  for (int i = 0; i < kNumParams; ++i) {
    if (unknown[i] || (IsFillVariable(i) && !fill.has_value())) continue;
    if (!std::isfinite(p[i])) return Refuse(why, kParamField[i], p[i], "must be finite");
    const bool must_be_positive = i == kLen || i == kR1 || i == kR2 || i == kRho;
    if (must_be_positive && !(p[i] > 0.0))
      return Refuse(why, kParamField[i], p[i], "must be positive");
    if (p[i] < 0.0) return Refuse(why, kParamField[i], p[i], "must be non-negative");
  }
  Material m = material;
  m.density_kg_m3 = p[kRho];
  std::string inner;
  if (!m.IsValid(why != nullptr ? &inner : nullptr)) {
    if (why != nullptr) *why = "material." + inner;
    return false;
  }
  if (fill.has_value()) {
    Material f = fill->material;
    if (unknown[kRhoS]) f.density_kg_m3 = std::max(p[kRhoS], 1.0);  // check the other fields
    if (f.density_kg_m3 != 0.0 && !f.IsValid(why != nullptr ? &inner : nullptr)) {
      if (why != nullptr) *why = "fill.material." + inner;
      return false;
    }
  }
  const bool hollow = HollowOf(*this);
  for (ConstraintKind kind : ApplicableConstraints(hollow, fill.has_value())) {
    const auto depends = ConstraintDepends(kind);
    bool involved = false;
    for (int i = 0; i < kNumParams; ++i) involved = involved || (depends[i] && unknown[i]);
    if (!involved && ConstraintValue<double>(kind, p, hollow) > 0.0) {
      if (why != nullptr) *why = ConstraintMessage(kind, p, hollow);
      return false;
    }
  }
  return true;
}

ShapeFitResult FitShape(const ShapeFitProblem& problem, const ShapeFitOptions& options) {
  const auto start_time = std::chrono::steady_clock::now();
  const auto elapsed_s = [&start_time] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  };
  ShapeFitResult result;
  Summary& summary = result.summary;
  summary.models_used = {"mass_properties"};
  summary.backend = "nlopt:slsqp+gauss_newton";
  std::string why;
  bool invalid = false;
  if (!options.IsValid(&why)) {
    invalid = true;
    why = "options." + why;
  } else if (!problem.IsValid(&why)) {
    invalid = true;
  }
  if (invalid) {
    summary.termination = Termination::kInvalidInput;
    summary.message = why;
    BuildBat(problem, BaseParams(problem), &result);
    result.metric = result.mass_residual_kg = result.balance_point_residual_m = kNaN;
    summary.objective = kNaN;
    summary.solve_time_s = elapsed_s();
    return result;
  }

  try {
    FitContext context(problem, options);
    const int n = context.n();
    const auto budget_left = [&] { return options.max_evaluations - context.evaluations(); };

    // 1. Scan: the start and a Halton set; keep the feasible points.
    constexpr int kPrimes[kNumParams] = {2, 3, 5, 7, 11, 13, 17, 19, 23, 29};
    std::vector<std::pair<double, std::vector<double>>> candidates;
    std::vector<double> s = context.StartS();
    for (int k = 0; k <= options.scan_points && budget_left() > 0; ++k) {
      if (k > 0) {
        for (int j = 0; j < n; ++j) s[static_cast<std::size_t>(j)] = RadicalInverse(k, kPrimes[j]);
      }
      if (!context.Feasible(s.data())) continue;
      candidates.emplace_back(context.Objective(s.data(), nullptr), s);
    }
    if (candidates.empty()) {
      summary.termination = Termination::kInvalidInput;
      summary.message = "the unknowns' bounds (" + DescribeUnknowns(problem) +
                        ") admit no valid bat: every one of " +
                        std::to_string(options.scan_points + 1) + " points tried is invalid";
      BuildBat(problem, BaseParams(problem), &result);
      summary.evaluations = context.evaluations();
      summary.solve_time_s = elapsed_s();
      return result;
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<double> best = candidates.front().second;
    double best_phi = candidates.front().first;

    // 2. SLSQP from the best scan points.
    int local_runs = 0;
    int raw_status = 0;  // 0 = no SLSQP run
    bool improved = false;
    const std::vector<double> lower(static_cast<std::size_t>(n), 0.0);
    const std::vector<double> upper(static_cast<std::size_t>(n), 1.0);
    const NloptFunction objective = [&context](const double* x, double* grad) {
      return context.Objective(x, grad);
    };
    std::vector<NloptConstraintFunction> constraints;
    for (ConstraintKind kind : context.constraints()) {
      constraints.push_back({[&context, kind](const double* x, double* grad) {
                               return context.Constraint(kind, x, grad);
                             },
                             false, 0.0});
    }
    for (std::size_t c = 0; c < candidates.size() && local_runs < options.local_starts; ++c) {
      const double time_left = options.max_time_s - elapsed_s();
      if (budget_left() <= 0 || time_left <= 0.0) break;
      ++local_runs;
      NloptRunSettings run;
      run.algorithm = NloptAlgorithm::kLdSlsqp;
      run.lower = lower;
      run.upper = upper;
      run.x_tolerance_rel = 1e-14;
      run.f_tolerance_abs = 1e-30;
      run.max_evaluations = budget_left();
      run.max_time_s = time_left;
      std::vector<double> x = candidates[c].second;
      const int status = RunNlopt(objective, constraints, run, &x).raw_status;
      for (double& xj : x) xj = std::clamp(xj, 0.0, 1.0);
      if (status > 0 || status == kNloptRoundoffLimited) {  // x holds the best point: keep it
        const double phi = context.Objective(x.data(), nullptr);
        if (context.Feasible(x.data()) && phi < best_phi) {
          best_phi = phi;
          best = x;
          raw_status = status;
          improved = true;
        }
      }
      if (!improved) raw_status = status;
    }
    summary.raw_status = raw_status;
    if (raw_status == kNloptRoundoffLimited) {
      summary.warnings.push_back("NLopt SLSQP stopped round-off limited; its best point is kept");
    } else if (raw_status == kNloptMaxevalReached || raw_status == kNloptMaxtimeReached) {
      summary.warnings.push_back("NLopt SLSQP stopped at the evaluation or time budget");
    }

    // 3. Gauss-Newton on the residuals (keeps only feasible decreases).
    int gauss_newton_steps = 0;
    for (int iter = 0; iter < 50 && budget_left() > 0; ++iter) {
      Eigen::VectorXd r;
      Eigen::MatrixXd jac;
      context.Residuals(best.data(), &r, &jac);
      if (r.lpNorm<Eigen::Infinity>() <= 1e-3 * options.tolerance) break;
      const Eigen::VectorXd step = jac.completeOrthogonalDecomposition().solve(-r);
      bool accepted = false;
      double alpha = 1.0;
      for (int halving = 0; halving < 30; ++halving, alpha *= 0.5) {
        std::vector<double> trial = best;
        for (int j = 0; j < n; ++j) {
          trial[static_cast<std::size_t>(j)] =
              std::clamp(best[static_cast<std::size_t>(j)] + alpha * step[j], 0.0, 1.0);
        }
        if (!context.Feasible(trial.data())) continue;
        const double phi = context.Objective(trial.data(), nullptr);
        if (phi < best_phi) {
          best_phi = phi;
          best = trial;
          accepted = true;
          break;
        }
      }
      if (!accepted) break;
      ++gauss_newton_steps;
    }

    // 4. The result: repair the ordering round-off, build the bat, classify.
    Params<double> p = context.ToParams(best.data());
    p[kX1] = std::max(p[kX1], 0.0);
    p[kX2] = std::min(p[kX2], p[kLen]);
    p[kX1] = std::min(p[kX1], p[kX2]);
    BuildBat(problem, p, &result);
    summary.iterations = local_runs + gauss_newton_steps;
    summary.evaluations = context.evaluations();
    summary.constraint_violation = std::max(0.0, context.MaxViolationM(best.data()));
    std::string bat_why;
    if (!result.bat.IsValid(&bat_why)) {
      summary.termination = Termination::kFailure;
      summary.message = "the fitted bat is invalid: " + bat_why;
      summary.objective = best_phi;
      summary.solve_time_s = elapsed_s();
      return result;
    }
    double max_scaled = 0.0;
    result.metric = 0.0;
    if (problem.targets.mass_kg.has_value()) {
      result.mass_residual_kg = result.properties.mass_kg - *problem.targets.mass_kg;
      const double scaled =
          result.mass_residual_kg /
          (options.mass_scale_kg > 0.0 ? options.mass_scale_kg : *problem.targets.mass_kg);
      max_scaled = std::max(max_scaled, std::abs(scaled));
      result.metric += scaled * scaled;
    }
    if (problem.targets.balance_point_m.has_value()) {
      result.balance_point_residual_m =
          result.properties.balance_point_m - *problem.targets.balance_point_m;
      const double scaled =
          result.balance_point_residual_m / (options.balance_point_scale_m > 0.0
                                                 ? options.balance_point_scale_m
                                                 : *problem.targets.balance_point_m);
      max_scaled = std::max(max_scaled, std::abs(scaled));
      result.metric += scaled * scaled;
    }
    summary.objective = result.metric;
    const std::string achieved =
        "mass_kg = " + FormatNumber(result.properties.mass_kg) +
        ", balance_point_m = " + FormatNumber(result.properties.balance_point_m);
    if (max_scaled <= options.tolerance) {
      result.targets_met = true;
      summary.termination = Termination::kConverged;
      summary.error_estimate = max_scaled;
      summary.message = "targets met (" + DescribeTargets(problem) + "): " + achieved;
    } else {
      result.kkt_error = KktError(context, best);
      summary.error_estimate = result.kkt_error;
      const std::string metric =
          "metric ((M - M*)/s_M)^2 + ((C - C*)/s_C)^2 = " + FormatNumber(result.metric) + ": " +
          achieved;
      if (result.kkt_error <= options.kkt_tolerance) {
        summary.termination = Termination::kInfeasible;
        summary.message = "no bat with " + DescribeUnknowns(problem) + " meets " +
                          DescribeTargets(problem) + "; closest bat in the " + metric;
      } else {
        summary.termination = Termination::kNoConvergence;
        summary.message = "targets " + DescribeTargets(problem) + " not met with " +
                          DescribeUnknowns(problem) +
                          "; best bat found (not certified as closest: first-order residual " +
                          FormatNumber(result.kkt_error) + ") in the " + metric;
        summary.warnings.push_back("the closest point failed the first-order (KKT) check");
      }
    }
  } catch (const std::bad_alloc&) {
    summary.termination = Termination::kFailure;
    summary.message = "out of memory";
  } catch (const std::exception& e) {
    summary.termination = Termination::kFailure;
    summary.message = std::string("solver failure: ") + e.what();
  }
  summary.solve_time_s = elapsed_s();
  return result;
}

}  // namespace sweetspot::core
