// The shape fit's checks of the family's validity on the parameters t, and its problem as a design
// problem. See shape_fit_checks.hpp.
#include "core/optimize/shape_fit_checks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <string_view>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/optimize/design_integrals.hpp"
#include "core/refusal.hpp"

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

// ---------------------------------------------------------------------------------------------
// The fit's names and the checks of its problem and options (shape_fit.hpp).

namespace sweetspot::core {
namespace {

using fit_detail::FitConstraint;
using fit_detail::kNumFitVariables;

constexpr const char* kVariableName[kNumFitVariables] = {
    "taper_start_m",   "taper_end_m",       "length_m",         "handle_radius_m",
    "barrel_radius_m", "density_kg_m3",     "wall_thickness_m", "fill.diameter_m",
    "fill.depth_m",    "fill.density_kg_m3"};

// Smallest target or scale of the fit's metric, kg or m: residuals divided by
// less than this can overflow to inf.
constexpr double kMinMetricScale = 1e-6;

}  // namespace

int FitUnknownIndex(DesignVariableKind kind) {
  for (int i = 0; i < kNumFitUnknowns; ++i) {
    if (kFitUnknownKinds[i] == kind) return i;
  }
  return -1;
}

const char* FitUnknownName(DesignVariableKind kind) {
  const int i = FitUnknownIndex(kind);
  return i >= 0 ? kVariableName[i] : "unknown";
}

std::optional<DesignVariableKind> FitUnknownFromName(std::string_view name) {
  for (int i = 0; i < kNumFitUnknowns; ++i) {
    if (name == kVariableName[i]) return kFitUnknownKinds[i];
  }
  return std::nullopt;
}

bool ShapeFitOptions::Validate(Refusal* why) const {
  if (!std::isfinite(mass_scale_kg) || mass_scale_kg < 0.0) {
    return Refuse(why, "mass_scale_kg", mass_scale_kg,
                  "must be finite and non-negative (0 = the target)");
  }
  if (!std::isfinite(balance_point_scale_m) || balance_point_scale_m < 0.0) {
    return Refuse(why, "balance_point_scale_m", balance_point_scale_m,
                  "must be finite and non-negative (0 = the target)");
  }
  if (mass_scale_kg > kMaxFitMassKg) {
    return Refuse(why, "mass_scale_kg", mass_scale_kg,
                  RangeRule(0.0, kMaxFitMassKg) + " (0 = the target)");
  }
  if (balance_point_scale_m > kMaxBatLengthM) {
    return Refuse(why, "balance_point_scale_m", balance_point_scale_m,
                  RangeRule(0.0, kMaxBatLengthM) + " (0 = the target)");
  }
  // Smaller scales overflow the scaled residuals to inf (found by fuzzing).
  if (mass_scale_kg > 0.0 && mass_scale_kg < kMinMetricScale) {
    return Refuse(why, "mass_scale_kg", mass_scale_kg, "must be 0 (the target) or at least 1e-06");
  }
  if (balance_point_scale_m > 0.0 && balance_point_scale_m < kMinMetricScale) {
    return Refuse(why, "balance_point_scale_m", balance_point_scale_m,
                  "must be 0 (the target) or at least 1e-06");
  }
  if (!CheckInRange(why, "tolerance", tolerance, kMinFitTolerance, kMaxFitTolerance)) return false;
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

namespace {

// The targets: at least one, each finite, positive and within its range (mass_kg: kg,
// balance_point_m: m from the knob).
bool ValidateFitTargets(const FitTargets& targets, Refusal* why) {
  if (!targets.mass_kg.has_value() && !targets.balance_point_m.has_value()) {
    return Refuse(why, TextRefusal("targets", "must give mass_kg, balance_point_m or both"));
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
  if (targets.mass_kg.has_value() && *targets.mass_kg > kMaxFitMassKg) {
    return Refuse(why, "targets.mass_kg", *targets.mass_kg,
                  RangeRule(kMinMetricScale, kMaxFitMassKg));
  }
  if (targets.balance_point_m.has_value() && *targets.balance_point_m > kMaxBatLengthM) {
    return Refuse(why, "targets.balance_point_m", *targets.balance_point_m,
                  RangeRule(kMinMetricScale, kMaxBatLengthM));
  }
  return true;
}

// The bounds of unknowns[i] `u` (named `name`, in its unit): finite, max > min, and min > 0
// for a length, radius, density or wall (>= 0 for the others). With why == nullptr no message
// is built.
bool ValidateFitUnknownBounds(const FitUnknown& u, std::size_t i, const char* name, Refusal* why) {
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
  const DesignVariableKind v = u.variable;
  const bool must_be_positive =
      v == DesignVariableKind::kLength || v == DesignVariableKind::kHandleRadius ||
      v == DesignVariableKind::kBarrelRadius || v == DesignVariableKind::kDensity ||
      v == DesignVariableKind::kWallThickness;
  if (must_be_positive && !(u.min > 0.0)) {
    return why == nullptr
               ? false
               : Refuse(why, IndexedField("unknowns", i, "min"), u.min,
                        std::string("must be positive for ") + name +
                            (v == DesignVariableKind::kWallThickness ? " (the bat stays hollow)"
                                                                     : ""));
  }
  if (!must_be_positive && u.min < 0.0) {
    return why == nullptr ? false
                          : Refuse(why, IndexedField("unknowns", i, "min"), u.min,
                                   std::string("must be non-negative for ") + name);
  }
  return true;
}

// The unknowns: 1 to 10, each a fit unknown once (a fill's only with a fill), with valid bounds;
// (*unknown)[k] says whether fit variable k is unknown.
bool ValidateFitUnknowns(const ShapeFitProblem& problem, std::vector<bool>* unknown, Refusal* why) {
  const std::vector<FitUnknown>& unknowns = problem.unknowns;
  if (unknowns.empty() || unknowns.size() > static_cast<std::size_t>(kNumFitVariables)) {
    return Refuse(why, "unknowns.size()", static_cast<double>(unknowns.size()),
                  "must be between 1 and 10");
  }
  unknown->assign(static_cast<std::size_t>(kNumFitVariables), false);
  for (std::size_t i = 0; i < unknowns.size(); ++i) {
    const FitUnknown& u = unknowns[i];
    const int idx = FitUnknownIndex(u.variable);
    if (idx < 0) {
      return Refuse(why, IndexedField("unknowns", i, "variable"), static_cast<int>(u.variable),
                    "is not a fit unknown (a profile knot's kind)");
    }
    const char* name = kVariableName[idx];
    if ((*unknown)[static_cast<std::size_t>(idx)]) {
      return Refuse(why, QuotedRefusal(IndexedField("unknowns", i, "variable"), name,
                                       "appears more than once"));
    }
    (*unknown)[static_cast<std::size_t>(idx)] = true;
    if (fit_detail::IsFillVariable(u.variable) && !problem.fill.has_value()) {
      return Refuse(
          why, QuotedRefusal(IndexedField("unknowns", i, "variable"), name, "the bat has no fill"));
    }
    if (!ValidateFitUnknownBounds(u, i, name, why)) return false;
  }
  return true;
}

// The fixed values (the fit variables not unknown, at the start parameters `t`): finite, and
// positive (a length, radius or density) or non-negative.
bool ValidateFitFixedValues(const ShapeFitProblem& problem, const std::vector<double>& t,
                            const std::vector<bool>& unknown, Refusal* why) {
  for (int i = 0; i < kNumFitVariables; ++i) {
    const DesignVariableKind v = kFitUnknownKinds[i];
    if (unknown[static_cast<std::size_t>(i)] ||
        (fit_detail::IsFillVariable(v) && !problem.fill.has_value()))
      continue;
    const double value = fit_detail::FitValue(t, v);
    const char* field = fit_detail::FitUnknownField(v);
    if (!std::isfinite(value)) return Refuse(why, field, value, "must be finite");
    const bool must_be_positive =
        v == DesignVariableKind::kLength || v == DesignVariableKind::kHandleRadius ||
        v == DesignVariableKind::kBarrelRadius || v == DesignVariableKind::kDensity;
    if (must_be_positive && !(value > 0.0)) return Refuse(why, field, value, "must be positive");
    if (value < 0.0) return Refuse(why, field, value, "must be non-negative");
  }
  return true;
}

// The bat's material and the fill's at the start parameters `t` (an unknown density at its
// start, at least 1 kg/m³ for the fill, so that the other fields are checked).
bool ValidateFitMaterials(const ShapeFitProblem& problem, const std::vector<double>& t,
                          const std::vector<bool>& unknown, Refusal* why) {
  Material m = problem.material;
  m.density_kg_m3 = fit_detail::FitValue(t, DesignVariableKind::kDensity);
  Refusal inner;
  if (!m.Validate(why != nullptr ? &inner : nullptr))
    return Refuse(why, Prefixed("material.", inner));
  if (problem.fill.has_value()) {
    Material f = problem.fill->material;
    if (unknown[static_cast<std::size_t>(FitUnknownIndex(DesignVariableKind::kFillDensity))]) {
      // check the other fields
      f.density_kg_m3 = std::max(fit_detail::FitValue(t, DesignVariableKind::kFillDensity), 1.0);
    }
    if (f.density_kg_m3 != 0.0 && !f.Validate(why != nullptr ? &inner : nullptr)) {
      return Refuse(why, Prefixed("fill.material.", inner));
    }
  }
  return true;
}

}  // namespace

bool ShapeFitProblem::Validate(Refusal* why) const {
  if (!ValidateFitTargets(targets, why)) return false;
  std::vector<bool> unknown;
  if (!ValidateFitUnknowns(*this, &unknown, why)) return false;
  const std::vector<double> t = fit_detail::StartParameters(*this);
  if (!ValidateFitFixedValues(*this, t, unknown, why)) return false;
  if (!ValidateFitMaterials(*this, t, unknown, why)) return false;
  // The constraints no unknown can move must hold at the start.
  const bool hollow = fit_detail::HollowOf(*this);
  for (FitConstraint kind : fit_detail::ApplicableConstraints(hollow, fill.has_value())) {
    if (!fit_detail::ConstraintInvolves(kind, unknown) &&
        fit_detail::ConstraintValue(kind, t, hollow) > 0.0) {
      return Refuse(why, fit_detail::ConstraintRefusal(kind, t, hollow));
    }
  }
  return true;
}

bool ShapeFitProblem::ValidateSize(Refusal* why) const {
  if (!Validate(why)) return false;
  for (std::size_t i = 0; i < unknowns.size(); ++i) {
    const FitUnknown& u = unknowns[i];
    if (u.min > kMaxFitBound || u.max > kMaxFitBound) {
      const bool min = u.min > kMaxFitBound;
      return why == nullptr ? false
                            : Refuse(why, IndexedField("unknowns", i, min ? "min" : "max"),
                                     min ? u.min : u.max, RangeRule(0.0, kMaxFitBound));
    }
  }
  return true;
}

}  // namespace sweetspot::core
