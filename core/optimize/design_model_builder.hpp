// Internal to core/optimize: the steps of DesignModel::Build (design_model_build.cpp: scene,
// base design, variables, rules, objective; design_model_constraints.cpp: the constraints) and
// the helpers they share. Included only by those two files.
#pragma once

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"
#include "core/optimize/design_model.hpp"
#include "core/refusal.hpp"

namespace sweetspot::core::design_detail {

// Relative margin that turns the strict validity rules (wall < radius, bore inside the
// material) into closed constraints the solver can sit on.
constexpr double kStrictMargin = 1e-6;
// min_sting: modes kept per solve (the start, the end and the points evaluated twice).
constexpr std::size_t kStingModesCacheEntries = 16;

inline std::string Num(double v) { return FormatNumber(v); }

// Refusals are core's (core/refusal.hpp): Refuse(why, field, value, rule) for a number,
// Refuse(why, TextRefusal(...)) or QuotedRefusal(...) for the others.

// Floor of a constraint's scale by unit, so that a constraint whose value and bounds are 0
// still gets a sensible magnitude.
inline double ScaleFloor(const std::string& unit) {
  if (unit == "kg_m2") return 1e-4;
  return 1e-3;
}

// Whether a variable kind needs a positive lower bound (else non-negative).
inline bool NeedsPositive(DesignVariableKind kind) {
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

inline bool IsFillKind(DesignVariableKind kind) {
  return kind == DesignVariableKind::kFillDiameter || kind == DesignVariableKind::kFillDepth ||
         kind == DesignVariableKind::kFillDensity;
}

inline bool IsProfileKind(DesignVariableKind kind) {
  return kind == DesignVariableKind::kKnotRadius || kind == DesignVariableKind::kKnotPosition;
}

inline bool IsThreeSegmentKind(DesignVariableKind kind) {
  return kind == DesignVariableKind::kLength || kind == DesignVariableKind::kHandleRadius ||
         kind == DesignVariableKind::kBarrelRadius || kind == DesignVariableKind::kTaperStart ||
         kind == DesignVariableKind::kTaperEnd;
}

inline std::string RangeText(double lower, double upper) {
  if (lower == upper) return "= " + Num(lower);
  if (std::isinf(lower)) return "<= " + Num(upper);
  if (std::isinf(upper)) return ">= " + Num(lower);
  return "in [" + Num(lower) + ", " + Num(upper) + "]";
}

// The state of one Build: the request, the model being filled, and what later steps need of
// earlier ones. Each step returns false with the reason in *why when the request is refused.
struct ModelBuilder {
  ModelBuilder(const DesignProblem& p, const DesignOptions& o, Refusal* w)
      : problem(p), options(o), why(w) {}

  const DesignProblem& problem;
  const DesignOptions& options;
  Refusal* why;
  Refusal inner;
  Refusal* inner_ptr = why != nullptr ? &inner : nullptr;
  DesignModel model;
  bool exit_speed_objective = true;
  Bat base;
  DesignParameterLayout lay;
  bool density_variable = false;
  bool wall_variable = false;
  bool fill_density_variable = false;
  const DesignConstraints& cons = problem.constraints;
  std::vector<int> radius_knots;         // one knot per distinct radius parameter
  std::vector<std::string> knot_suffix;  // their names' suffixes

  double Param(int idx) const { return model.base_parameters_[static_cast<std::size_t>(idx)]; }

  // Scene and objective.
  bool CheckScene();
  // The base design and the COR.
  bool BaseDesign();
  // The design parameters of the base design.
  void Parameters();
  // The parameters a variable moves, with the flags the rules need.
  std::vector<int> ParametersOf(const DesignVariableRef& ref);
  // The field `path` (named `field` in a refusal) checked against the design: a variable path
  // that applies to it, not named before.
  bool CheckVariablePath(const std::string& field, const std::string& path,
                         const std::optional<DesignVariableRef>& ref, std::set<std::string>* seen);
  // Variable i's bounds: finite, ordered, within kMaxDesignBound.
  bool CheckBounds(std::size_t i, const DesignVariable& v);
  // Variable i checked against the design (refused with the reason in *why).
  bool CheckVariable(std::size_t i, const DesignVariable& v,
                     const std::optional<DesignVariableRef>& ref, std::set<std::string>* seen);
  // Scale variable i: its name, bounds and fields checked, then added with its parameters,
  // each parameter's coefficient the field's base value.
  bool AddScaleVariable(std::size_t i, std::set<std::string>* seen);
  // Variable i: checked, then added with its parameters.
  bool AddVariable(std::size_t i, std::set<std::string>* seen);
  // The least and largest value parameter `idx` can take within the variables' bounds.
  std::pair<double, double> ParamRange(int idx) const;
  double ParamLower(int idx) const;
  double ParamUpper(int idx) const;
  // Every variable.
  bool Variables();
  // Rules: the discrete limits.
  bool Rules();
  // Scene numbers and references.
  bool SceneNumbers();
  // A swing given by its bat speed: omega0 resolved once, or a function of the length.
  bool SwingByBatSpeed();
  // True when a variable changes the linear function `terms`.
  bool Depends(const std::vector<std::pair<int, double>>& terms) const;
  // The linear function's value at the base design.
  double LinearValue(const std::vector<std::pair<int, double>>& terms, double constant) const;
  // Adds a linear constraint, or checks it now when no variable changes it.
  void AddLinear(const std::string& name, const std::string& min_name, const std::string& max_name,
                 const std::string& unit, std::vector<std::pair<int, double>> terms,
                 double constant, double lower, double upper, bool property, bool skip_if_fixed);
  // Adds a nonlinear (mass property) constraint.
  void AddNonlinear(const std::string& name, const std::string& unit, DesignFunction f,
                    double lower, double upper);
  // A range from the request, checked.
  bool RangeOf(const char* field, const DesignRange& r, double cap, double* lower, double* upper);
  // Length: the request's range and the rules' maximum.
  bool LengthConstraint();
  // Mass properties and the rules' drop.
  bool PropertyConstraints();
  // The knots whose radii the diameter and wall constraints bound.
  void RadiusKnots();
  // Diameters: the tightest of the request and the rules.
  bool DiameterConstraints();
  // The knots (indices into radius_knots) the minimum diameter bounds: all, or those whose
  // neighbouring segments can reach into the handle region.
  bool HandleRegionKnots(std::vector<std::size_t>* out);
  // The first bending frequency (min_frequency_hz) on its fixed mesh.
  bool FrequencyConstraint();
  // The `bbcor` rule's BBCOR <= 0.50 on a hollow design (a nonlinear constraint).
  bool BbcorConstraint();
  // cor_from_barrel: the objective's COR from the design's barrel (design_bbcor.hpp).
  bool BarrelCor();
  // Taper: the knot pairs it bounds (refused when the request's knots are not in the profile).
  bool TaperPairs(std::vector<std::pair<int, int>>* pairs_out,
                  std::vector<std::string>* suffix_out);
  // Taper.
  bool TaperConstraints();
  // Rules: the cup of a solid wooden bat.
  void CupConstraints();
  // Validity of the bat (only where a variable can break it; the base bat is valid).
  void ValidityConstraints();
  // The least-squares objective's targets (least_squares_objective.cpp): required with
  // kLeastSquares, refused with any other objective.
  bool LeastSquaresObjective();
  // The shape fit's exact bore rules on a three-segment design with the least-squares
  // objective (design_bore.cpp): the bore inside the material at its bottom (kBoreBottom) and
  // at the tip; true when they replace the knots' conservative ones.
  bool BoreConstraints(double keep);
  // Validity of the fill: its depth and its bore inside the material.
  void FillValidityConstraints(double keep);
  // Objective and the scales.
  bool Objective();
  // Every step in order.
  bool Run();
};

}  // namespace sweetspot::core::design_detail
