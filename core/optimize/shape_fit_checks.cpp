// The shape fit's checks of the family's validity on the parameters t, and its problem as a design
// problem. See shape_fit_checks.hpp.
#include "core/optimize/shape_fit_checks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/geometry_format.hpp"
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
double FamilyRadiusAt(const double* t, double y) {
  const double x1 = t[kIndex.x1];
  const double x2 = t[kIndex.x2];
  if (y <= x1) return t[kIndex.r1];
  if (y >= x2) return t[kIndex.r2];
  return t[kIndex.r1] + (t[kIndex.r2] - t[kIndex.r1]) * (y - x1) / (x2 - x1);
}

double ConstraintOf(FitConstraint kind, const double* t, bool hollow) {
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
      const double around =
          FamilyRadiusAt(t, t[kIndex.length] - t[kIndex.depth]) - (hollow ? t[kIndex.wall] : 0.0);
      return 0.5 * t[kIndex.diameter] - keep * around;
    }
    case FitConstraint::kBoreTip: {
      const double around = t[kIndex.r2] - (hollow ? t[kIndex.wall] : 0.0);
      return 0.5 * t[kIndex.diameter] - keep * around;
    }
  }
  return 0.0;
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
  return ConstraintOf(kind, t.data(), hollow);
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
      const double around = FamilyRadiusAt(t.data(), y) - (hollow ? wall : 0.0);
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
// The design problem.

DesignProblem FitDesignProblem(const ShapeFitProblem& problem, const ShapeFitOptions& options,
                               const std::vector<double>& t) {
  DesignProblem design;
  const auto value = [&t](DesignVariableKind v) { return FitValue(t, v); };
  design.three_segment = ThreeSegmentShape{
      value(DesignVariableKind::kLength), value(DesignVariableKind::kHandleRadius),
      value(DesignVariableKind::kBarrelRadius), value(DesignVariableKind::kTaperStart),
      value(DesignVariableKind::kTaperEnd)};
  design.bat.material = problem.material;
  design.bat.material.density_kg_m3 = value(DesignVariableKind::kDensity);
  design.bat.wall_thickness_m = value(DesignVariableKind::kWallThickness);
  design.bat.fill = problem.fill;
  if (design.bat.fill.has_value()) {
    design.bat.fill->diameter_m = value(DesignVariableKind::kFillDiameter);
    design.bat.fill->depth_m = value(DesignVariableKind::kFillDepth);
    design.bat.fill->material.density_kg_m3 = value(DesignVariableKind::kFillDensity);
  }
  for (const FitUnknown& u : problem.unknowns) {
    design.variables.push_back({DesignVariablePath(DesignVariableOf(u.variable)), u.min, u.max});
  }
  design.objective = DesignObjective::kLeastSquares;
  LeastSquaresTargets targets;
  targets.mass_kg = problem.targets.mass_kg;
  targets.balance_point_m = problem.targets.balance_point_m;
  if (targets.mass_kg.has_value()) {
    targets.mass_scale_kg = options.mass_scale_kg > 0.0 ? options.mass_scale_kg : *targets.mass_kg;
  }
  if (targets.balance_point_m.has_value()) {
    targets.balance_point_scale_m = options.balance_point_scale_m > 0.0
                                        ? options.balance_point_scale_m
                                        : *targets.balance_point_m;
  }
  targets.tolerance = options.tolerance;
  design.least_squares = targets;
  return design;
}

std::vector<double> UnknownValues(const ShapeFitProblem& problem, const std::vector<double>& t) {
  std::vector<double> values;
  for (const FitUnknown& u : problem.unknowns) values.push_back(FitValue(t, u.variable));
  return values;
}

}  // namespace sweetspot::core::fit_detail
