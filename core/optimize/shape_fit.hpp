// Shape fit: solve unknown dimensions of a three-segment bat (e.g. the taper
// start and end x1, x2, or the density) from a target mass and balance point,
// as the paper does with its eqs (1)-(2).
//
// The fit minimises the stated metric
//   phi = ((M - M*) / s_M)^2 + ((C - C*) / s_C)^2
// (only the targets given), with s_M = M* and s_C = C* unless the options set
// other scales, over the unknowns' bounds and the validity constraints of the
// bat (0 <= x1 <= x2 <= L; wall < r1, r2 for a hollow bat; a fill no deeper
// than L and strictly inside the material around it). When the minimum meets
// every target to the tolerance the fit has converged; otherwise no bat of the
// family meets the targets, and the result is the closest bat in that metric
// (Termination::kInfeasible), certified by a first-order (KKT) check. The
// paper's own Table 2 (paper-wood, M* = 0.885 kg, C* = 0.564 m, unknowns x1,
// x2) is such a case: the closest bat is x1 = 0.17964 m, x2 = L = 0.855 m
// (no barrel cylinder), M = 0.8920 kg, C = 0.5827 m.
//
// Method: the fit is a DesignProblem solved by the one solver layer (issue 33
// item 3): the unknowns are the design variables of the same fields
// (three_segment.*, material.density_kg_m3, ...), the objective the design
// model's least-squares objective (DesignObjective::kLeastSquares), the
// constraints its validity rules (with the exact bore rule). A deterministic
// low-discrepancy scan of the bounds gives the starts; OptimizeDesign runs NLopt
// SLSQP (exact gradients) from the best feasible scan points, then its
// Gauss-Newton polish on the residuals reaches machine precision when the
// targets are attainable (core/optimize/shape_fit_checks.hpp builds the problem).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/bat/bat.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/summary.hpp"

namespace sweetspot::core {

/// Largest bound of a fit's unknown given from outside (ShapeFitProblem::ValidateSize), in
/// the unknown's unit (m or kg/m³); core fits beyond it (tests/hard_cases: 1e6 kg/m³).
inline constexpr double kMaxFitBound = 1e5;
/// Largest target mass and mass scale of a fit, kg.
inline constexpr double kMaxFitMassKg = 1e4;
/// Smallest tolerance of a fit's targets (scaled residual, dimensionless).
inline constexpr double kMinFitTolerance = 1e-15;
/// Largest tolerance of a fit's targets (scaled residual, dimensionless).
inline constexpr double kMaxFitTolerance = 0.1;

/// The fit's unknowns: the design variables (DesignVariableKind) of a three-segment bat's ten
/// fields (every kind but the profile's knots), in the order their names are listed.
inline constexpr int kNumFitUnknowns = 10;
/// The kinds a fit unknown may be, in the order of FitUnknownName's names.
inline constexpr DesignVariableKind kFitUnknownKinds[kNumFitUnknowns] = {
    DesignVariableKind::kTaperStart,    DesignVariableKind::kTaperEnd,
    DesignVariableKind::kLength,        DesignVariableKind::kHandleRadius,
    DesignVariableKind::kBarrelRadius,  DesignVariableKind::kDensity,
    DesignVariableKind::kWallThickness, DesignVariableKind::kFillDiameter,
    DesignVariableKind::kFillDepth,     DesignVariableKind::kFillDensity};

/// Position of `kind` in kFitUnknownKinds, or -1 (a profile knot's kind is no fit unknown).
int FitUnknownIndex(DesignVariableKind kind);
/// The fit's name of a kind: "taper_start_m", "taper_end_m", "length_m", "handle_radius_m",
/// "barrel_radius_m", "density_kg_m3", "wall_thickness_m" (the bat stays hollow: min > 0),
/// "fill.diameter_m", "fill.depth_m", "fill.density_kg_m3" (the fill's need a fill);
/// "unknown" for a knot's kind.
const char* FitUnknownName(DesignVariableKind kind);
/// The kind the fit calls `name`, or nullopt.
std::optional<DesignVariableKind> FitUnknownFromName(std::string_view name);

/// One unknown and its bounds, in the variable's unit.
struct FitUnknown {
  /// What is unknown: one of kFitUnknownKinds.
  DesignVariableKind variable = DesignVariableKind::kTaperStart;
  /// Lower bound (unit of the variable), >= 0 (ShapeFitProblem::ValidateSize: <= kMaxFitBound).
  double min = 0.0;
  /// Upper bound (unit of the variable; > min; ShapeFitProblem::ValidateSize: <= kMaxFitBound).
  double max = 0.0;
};

/// What the fitted bat must weigh and where it must balance; at least one.
struct FitTargets {
  std::optional<double> mass_kg;  ///< Target mass, kg, in [1e-6, kMaxFitMassKg].
  /// Target balance point from the knob, m, in [1e-6, kMaxBatLengthM].
  std::optional<double> balance_point_m;
};

/// The bat family and the unknowns. Fields that are unknowns give the
/// starting value (clamped into the bounds); the others stay fixed.
struct ShapeFitProblem {
  ThreeSegmentShape shape;           ///< Known dimensions (and starting values).
  Material material;                 ///< The bat's material (density may be an unknown).
  double wall_thickness_m = 0.0;     ///< Hollow shell wall, m; 0 = solid.
  std::optional<Fill> fill;          ///< Optional fill.
  std::vector<FitUnknown> unknowns;  ///< 1 to 10 distinct unknowns.
  FitTargets targets;                ///< What to meet.
  /// The rigid-body mass properties of the bat as given (shape, material, wall, fill) when the
  /// caller has computed them (the api's ParseBat): used for the fit's design problem when its
  /// start is that bat (no unknown clamped), instead of computing them again. Unset = computed.
  std::optional<MassProperties> bat_mass_properties;

  /// True when the problem can be solved; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
  /// Validate, then every unknown's bounds at most kMaxFitBound ("unknowns[0].max = 2e+05:
  /// must be in [0, 1e+05]"); for a problem given from outside.
  bool ValidateSize(Refusal* refusal) const;
};

/// How the fit runs. Defaults are valid.
struct ShapeFitOptions {
  /// s_M of the metric, kg, in [0, kMaxFitMassKg] (0 = the target mass).
  double mass_scale_kg = 0.0;
  /// s_C of the metric, m, in [0, kMaxBatLengthM] (0 = the target balance point).
  double balance_point_scale_m = 0.0;
  /// Targets are met when every scaled residual |value - target| / s is at most this, in
  /// [kMinFitTolerance, kMaxFitTolerance].
  double tolerance = 1e-9;
  /// Relative first-order (KKT) residual below which the closest bat is certified (> 0).
  double kkt_tolerance = 1e-6;
  int scan_points = 256;        ///< Points of the initial scan of the bounds (>= 1).
  int local_starts = 4;         ///< SLSQP runs from the best scan points (>= 1).
  int max_evaluations = 20000;  ///< Budget of objective evaluations over the whole fit (>= 1).
  double max_time_s = 5.0;      ///< Wall-time budget, s (> 0).

  /// True when every field is in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// The fitted (or closest) bat and how it was found. The summary is always
/// filled: termination kConverged (targets met), kInfeasible (no bat meets
/// them; the result is the certified closest bat), kNoConvergence (best bat
/// found, not certified), kFailure or kInvalidInput (message names the field);
/// backend "nlopt:slsqp+gauss_newton"; raw_status = the NLopt result of the
/// SLSQP run that produced the result (OptimizeDesign's chosen start; 0 if none
/// ran); iterations = SLSQP runs + accepted Gauss-Newton steps; evaluations =
/// the scan's and the design layer's model evaluations;
/// objective = phi; constraint_violation in m; error_estimate = the largest
/// scaled residual when converged, else kkt_error; models_used =
/// {"mass_properties"}.
struct ShapeFitResult {
  Summary summary;                ///< How the fit went (see above).
  bool targets_met = false;       ///< Every target met to options.tolerance.
  ThreeSegmentShape shape;        ///< Fitted shape.
  Material material;              ///< Material (with the fitted density if it was unknown).
  double wall_thickness_m = 0.0;  ///< Fitted wall, m.
  std::optional<Fill> fill;       ///< Fitted fill.
  Bat bat;                        ///< The bat built from the above.
  MassProperties properties;      ///< Its mass properties (rigid body).
  std::vector<double> values;     ///< The unknowns' values, in the order of problem.unknowns.
  double mass_residual_kg = 0.0;  ///< M - M*, kg (0 when the mass is not a target).
  /// C - C*, m (0 when the balance point is not a target).
  double balance_point_residual_m = 0.0;
  double metric = 0.0;     ///< phi at the result (dimensionless).
  double kkt_error = 0.0;  ///< Relative first-order residual at the result (0 when converged).
};

/// Fits the unknowns. Never throws; for invalid input the summary says why
/// (kInvalidInput) and the bat is the problem's starting bat.
ShapeFitResult FitShape(const ShapeFitProblem& problem, const ShapeFitOptions& options = {});

}  // namespace sweetspot::core
