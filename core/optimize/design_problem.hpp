// Bat design optimisation: what may change (variables with bounds), what must hold
// (constraints, league rule sets), what to improve (objective) for a scene, and the answer
// (the optimised bat, its properties, the objective, a Summary, the active constraints with
// their multipliers, the conflicts of an infeasible request, the spread of a multi-start).
// Solved with Ipopt (default), NLopt SLSQP or, for the derivative-free min_sting objective, NLopt
// COBYLA; the solvers' headers stay in core's .cpp files.
// Value in, value out; never throws; thread-safe (Ipopt solves are serialised by one
// process-wide lock: see docs/optimization.md). Everything SI; names carry units.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/bat/bat.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/optimize/certificate.hpp"
#include "core/optimize/least_squares_objective.hpp"
#include "core/optimize/rules.hpp"
#include "core/progress.hpp"
#include "core/scene/batted_ball.hpp"
#include "core/scene/collide.hpp"
#include "core/summary.hpp"

namespace sweetspot::core {

/// Largest magnitude of a design variable's bounds, in the field's unit (m or kg/m³).
inline constexpr double kMaxDesignBound = 1e12;
/// Largest mass a design constraint names (constraints.mass_kg), kg.
inline constexpr double kMaxDesignMassKg = 1e4;
/// Largest MOI a design constraint names (constraints.moi_six_inch_kg_m2), kg·m².
inline constexpr double kMaxDesignMoiKgM2 = 1e4;
/// Largest diameter a design constraint names (max_barrel_diameter_m, min_handle_diameter_m), m.
inline constexpr double kMaxDesignDiameterM = 10.0;
/// Largest first bending frequency a design constraint names (constraints.min_frequency_hz), Hz.
inline constexpr double kMaxDesignFrequencyHz = 1e5;
/// Largest taper slope a design constraint allows (constraints.max_taper_slope), m per m.
inline constexpr double kMaxTaperSlope = 100.0;
/// Largest sweet-zone tolerance of the widest_sweet_zone objective, m/s.
inline constexpr double kMaxDesignZoneToleranceMps = 100.0;

/// What a design variable changes. The stable name of each is the request path of the field.
enum class DesignVariableKind {
  kKnotRadius,     ///< "profile.knots[i].radius_m": outer radius of knot i, m.
  kKnotPosition,   ///< "profile.knots[i].x_m": knot i from the knob, m (i >= 1; the last is L).
  kLength,         ///< "three_segment.length_m": L, m.
  kHandleRadius,   ///< "three_segment.handle_radius_m": r1, m.
  kBarrelRadius,   ///< "three_segment.barrel_radius_m": r2, m.
  kTaperStart,     ///< "three_segment.taper_start_m": x1, m.
  kTaperEnd,       ///< "three_segment.taper_end_m": x2, m.
  kDensity,        ///< "material.density_kg_m3": the bat material's density, kg/m³.
  kWallThickness,  ///< "wall_thickness_m": the shell's wall, m (the bat stays hollow).
  kFillDiameter,   ///< "fill.diameter_m": m.
  kFillDepth,      ///< "fill.depth_m": m.
  kFillDensity,    ///< "fill.material.density_kg_m3": kg/m³ (0 = an empty bore).
};

/// A parsed variable path.
struct DesignVariableRef {
  DesignVariableKind kind = DesignVariableKind::kKnotRadius;  ///< Which field.
  int knot = -1;  ///< Knot index for kKnotRadius / kKnotPosition; -1 otherwise.
};

/// The variable named by `path` ("profile.knots[3].radius_m", "fill.depth_m", ...), or nullopt.
std::optional<DesignVariableRef> ParseDesignVariablePath(std::string_view path);
/// The path of `ref` (inverse of ParseDesignVariablePath).
std::string DesignVariablePath(const DesignVariableRef& ref);

/// A field the optimiser may change, with its bounds in the field's unit; or a scale variable:
/// a dimensionless factor s that sets several fields to the base design's value times s.
struct DesignVariable {
  /// The field (see DesignVariableKind), e.g. "three_segment.taper_start_m"; for a scale
  /// variable its name (not a variable path: the answer lists it beside its fields).
  std::string path;
  /// Lower bound, field unit (a scale variable: dimensionless), in
  /// [-kMaxDesignBound, kMaxDesignBound].
  double min = 0.0;
  double max = 0.0;  ///< Upper bound, same unit, in (min, kMaxDesignBound].
  /// Further fields set to the same value (a request's "paths": one barrel diameter is two
  /// knots' radii), each a variable path of the same design, none repeated.
  std::vector<std::string> linked_paths = {};
  /// When not empty, a scale variable (a request's "scale_paths"): each of these fields is the
  /// base design's value times the variable's value (the base design is the value 1). Each a
  /// variable path of the same design, none repeated, none 0 in the base design; every field
  /// obeys its own rules over [min, max] times its base value (a radius stays positive).
  /// linked_paths must then be empty.
  std::vector<std::string> scale_paths = {};
};

/// A constraint's allowed values: equality when min == max; either side may be open.
struct DesignRange {
  std::optional<double> min;  ///< Lower limit (unit of the constrained quantity).
  std::optional<double> max;  ///< Upper limit (unit of the constrained quantity).

  /// [v, v].
  static DesignRange Equal(double v) { return {v, v}; }
  /// [lo, hi].
  static DesignRange Between(double lo, double hi) { return {lo, hi}; }
  /// (-inf, hi].
  static DesignRange AtMost(double hi) { return {std::nullopt, hi}; }
  /// [lo, inf).
  static DesignRange AtLeast(double lo) { return {lo, std::nullopt}; }
  /// True when both limits are set and equal.
  bool IsEquality() const { return min.has_value() && max.has_value() && *min == *max; }
};

/// How the radius may vary along the taper.
enum class TaperRule {
  kNone,           ///< No rule.
  kNonDecreasing,  ///< r(i+1) >= r(i) over the knot range (three-segment: r1 <= r2).
  kMaxSlope,       ///< |r(i+1) - r(i)| <= max_taper_slope (x(i+1) - x(i)) over the knot range.
};

/// What must hold. Names of the constraints (for active constraints and conflicts) are given
/// per field; a range reports "<name>.min" / "<name>.max" when one side is active.
struct DesignConstraints {
  /// "length_m": L, m; limits in (0, kMaxBatLengthM].
  std::optional<DesignRange> length_m;
  std::optional<DesignRange> mass_kg;  ///< "mass_kg": kg; limits in (0, kMaxDesignMassKg].
  /// "balance_point_m": from the knob, m; limits in (0, kMaxBatLengthM].
  std::optional<DesignRange> balance_point_m;
  /// "moi_six_inch_kg_m2": about 0.1524 m, kg·m²; limits in (0, kMaxDesignMoiKgM2].
  std::optional<DesignRange> moi_six_inch_kg_m2;
  /// "max_barrel_diameter_m.knots[i]": every knot's diameter at most this, m, in
  /// (0, kMaxDesignDiameterM].
  std::optional<double> max_barrel_diameter_m;
  /// "min_handle_diameter_m.knots[i]": the diameter at least this, m, in
  /// (0, kMaxDesignDiameterM], over the whole bat or over handle_region_from_knob_m.
  std::optional<double> min_handle_diameter_m;
  /// Where min_handle_diameter_m applies: [from, to] m from the knob, 0 <= from < to <=
  /// kMaxBatLengthM (the grip). The profile is linear between knots, so the diameter over the
  /// region is at least the limit when every knot whose neighbouring segments can reach into
  /// the region (given the variables' bounds) is: those knots are constrained (a three-segment
  /// design: r1 when the region can start before x2, r2 when it can end after x1). Unset = every
  /// knot (the whole bat).
  std::optional<std::pair<double, double>> handle_region_from_knob_m;
  /// "min_frequency_hz": the first free-free bending frequency at least this, Hz, in
  /// (0, kMaxDesignFrequencyHz]. Computed by the flexible beam (problem.flexible's theory) on
  /// a mesh fixed for the whole optimisation: the final mesh of the modes code (vibration_node's
  /// settings, problem.flexible.frequency_tolerance) for the start design, its nodes kept as
  /// fractions of the length. Exact gradient (phi' (dK - lambda dM) phi); with it the exact
  /// Hessian is not available (options.hessian must be limited_memory).
  std::optional<double> min_frequency_hz;
  TaperRule taper = TaperRule::kNone;  ///< "taper.knots[i]" / "max_slope.knots[i]" (i to i+1).
  /// kMaxSlope: largest |dr/dx|, m per m, in (0, kMaxTaperSlope].
  double max_taper_slope = 0.0;
  int taper_first_knot = 0;    ///< Profile: the taper rule starts at this knot (>= 0).
  int taper_last_knot = -1;    ///< Profile: ... and ends at this knot (-1 = the last).
  std::vector<RuleSet> rules;  ///< League rule sets ("rules.<name>.<limit>").
  /// "bbcor_max": THE BBCOR (the flexible scan's maximum, bbcor_constraint.hpp) at most this,
  /// dimensionless, in (0, 1]: a margin below the rule's 0.50 (e.g. 0.49). Hollow designs only
  /// (the base bat hollow or wall_thickness_m a variable).
  std::optional<double> bbcor_max;
  /// Internal (set by OptimizeDesign's certification rounds, bbcor_constraint.hpp; 0 from a
  /// request): the scan's maximum minus the fixed-point estimate, subtracted from the BBCOR
  /// bound of the estimate the design model constrains.
  double bbcor_estimate_offset = 0.0;
};

/// What to improve.
enum class DesignObjective {
  /// "max_exit_speed": the rigid-pivot maximum exit speed over the bat, m/s (maximise).
  kMaxExitSpeed,
  /// "max_exit_speed_swing_weight": the same with omega = omega0 (I6 / I6_ref)^-n, m/s (maximise).
  kMaxExitSpeedSwingWeight,
  /// "widest_sweet_zone": length of the bat within sweet_zone_tolerance_mps of the max, m
  /// (maximise).
  kWidestSweetZone,
  /// "min_moi": the MOI about the 6-in point, kg·m² (minimise).
  kMinMoi,
  /// "min_sting": the hands' vibration energy left by an impact at the design's rigid-pivot
  /// max-exit-speed point (the flexible beam, as least_sting_zone measures sting), J
  /// (minimise). No derivative exists (adaptive mesh and integration): solved by NLopt COBYLA.
  kMinSting,
  /// "max_distance": the carry of the design's distance sweet spot (the impact position and
  /// undercut that carry the ball farthest, DistanceSweetSpot) in the problem's scene (ball with
  /// its descent angle and spin, swing with its attack angle, environment, aero), m (maximise).
  /// An adaptive flight integration inside an iterative 2-D search: solved by NLopt COBYLA
  /// (docs/optimization.md, "max_distance", says why no gradient is used).
  kMaxDistance,
  /// "least_squares" (the shape fit's, FitShape; not a request objective): the metric
  /// ((M - M*)/s_M)^2 + ((C - C*)/s_C)^2 of DesignProblem::least_squares, dimensionless
  /// (minimise).
  kLeastSquares,
};

/// Stable name (quoted above).
const char* DesignObjectiveName(DesignObjective objective);
/// The objective called `name`, or nullopt.
std::optional<DesignObjective> ParseDesignObjective(std::string_view name);

/// A design problem: a base design, what may change, what must hold, what to improve.
struct DesignProblem {
  /// The base design: material, wall, fill and (without three_segment) the profile. It is the
  /// first start (clamped into the variables' bounds) and supplies every fixed field.
  Bat bat;
  /// When set, the bat's profile is this three-segment shape (bat.knots is ignored) and the
  /// "three_segment.*" variables apply; "profile.*" variables do not.
  std::optional<ThreeSegmentShape> three_segment;
  std::vector<DesignVariable> variables;                       ///< 1 to 200 distinct variables.
  DesignConstraints constraints;                               ///< What must hold.
  DesignObjective objective = DesignObjective::kMaxExitSpeed;  ///< What to improve.
  /// kMaxExitSpeedSwingWeight: n in omega = omega0 (I6 / I6_ref)^-n (SwingWeightSpeedFactor,
  /// core/scene/swing_speed.hpp: Cross & Bower 2006), in [0, kMaxSwingWeightExponent]; I6_ref is
  /// swing_weight_reference_kg_m2 when set, else the base design's MOI about the 6-in point (so
  /// the base design swings at omega0).
  double swing_weight_exponent = kSwingWeightExponent;
  /// kMaxExitSpeedSwingWeight: I6_ref, the MOI about the 6-in point that swings at omega0,
  /// kg·m², in (0, kMaxDesignMoiKgM2]; unset = the base design's. Refused with any other
  /// objective (it would have no effect).
  std::optional<double> swing_weight_reference_kg_m2;
  /// kWidestSweetZone: the zone is where the exit speed is within this of the max, m/s, in
  /// (0, kMaxDesignZoneToleranceMps].
  double sweet_zone_tolerance_mps = 1.0;
  Ball ball;  ///< The pitched ball.
  /// The swing (pivot and omega0); the hands (hands_from_knob_m) only for min_sting. Given by
  /// its bat speed (bat_speed_mps), omega0 = v / (L - bat_speed_from_tip_m - pivot) for each
  /// design's own length L: resolved once when no variable moves L, else a function of L with
  /// its exact derivatives; the shortest bat the bounds allow must keep the point beyond the
  /// pivot (ResolveSwing's rules).
  Swing swing;
  std::optional<double> cor;  ///< COR in [0, 1]; unset = the bat material's default.
  /// The exit-speed objectives' COR from the design's own barrel (issue 18 item 2): when true,
  /// the COR of each design is the quasi-static trampoline's e_eff of this ball against the
  /// design's wall (EffectiveCorAt, default BarrelOptions) at kCorReferenceFromTipM from the
  /// design's tip, for the normal impact speed there, ball.speed_mps + omega (x - pivot) with the
  /// design's own omega, and the ball's COR law at that speed: what ResolveScene gives that bat,
  /// recomputed for every design with exact first and second derivatives. The exit speed's
  /// maximum over the impact point treats this e as constant along the bat, as every scene does.
  /// Requires `cor` unset, ball.cor_law set, a hollow design (the base bat, or wall_thickness_m
  /// a variable), objective max_exit_speed, max_exit_speed_swing_weight or widest_sweet_zone and
  /// the shortest bat longer than kCorReferenceFromTipM. False: `cor` (or the material's) is
  /// held fixed.
  bool cor_from_barrel = false;
  InertiaModel inertia_model = InertiaModel::kRigidBody;  ///< How moments are computed.
  /// The exit-speed model of the objectives, the reported sweet spot and min_sting's impact
  /// point: kRigidPivot (the paper's pinned bat) or kFreeBat (the free bat in the swing's
  /// velocity field); both closed forms. The api resolves "auto" as the scenes do.
  CollisionModel model = CollisionModel::kRigidPivot;
  /// kMinSting: the flexible beam's settings (theory, modes, tolerances, grip length; defaults as
  /// for /v1/sweet-spot). flexible.modes_cache is not used: every design has new modes, so each
  /// solve keeps its own small cache (repeated points) instead of filling a shared one.
  FlexibleOptions flexible;
  /// kMaxDistance: the air the batted ball flies through (the scene's `environment`; the
  /// flight's defaults: 70 F, sea level, 50 %, 29.92 inHg, calm).
  flight::Environment environment;
  /// kMaxDistance: the flight's aero model (the scene's `aero`; default nathan-2016).
  flight::AeroOptions aero;
  /// kMaxDistance: the distance sweet spot's search region and tolerances (/v1/sweet-spot's
  /// options.distance; its defaults).
  DistanceOptions distance;
  /// The base design's mass properties under inertia_model when the caller has computed them
  /// already (the api's ParseBat): the design model uses them instead of computing them again
  /// (DesignProblem::Validate and OptimizeDesign each build one). Must be those of `bat` (with
  /// three_segment's knots when given); unset = computed. OptimizeOverMaterials drops them (each
  /// material is another bat).
  std::optional<MassProperties> base_mass_properties;
  /// kLeastSquares: its targets and scales (required then, refused with any other objective).
  std::optional<LeastSquaresTargets> least_squares;

  /// True when the problem is well formed (variables parse and apply to this design, bounds
  /// finite and ordered, constraints finite, the base bat valid, the rules' discrete limits
  /// met); otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// How the Lagrangian's Hessian is obtained (Ipopt).
enum class HessianMode {
  kLimitedMemory,  ///< Ipopt's L-BFGS approximation (hessian_approximation = limited-memory).
  /// Second derivatives by second-order forward-mode AD of the closed-form integrals and sweet
  /// spot: exact up to rounding (no difference quotients).
  kExact,
};

/// Which solver runs each local solve.
enum class DesignBackend {
  kIpopt,       ///< Ipopt 3.11 (interior point, MUMPS). The default.
  kNloptSlsqp,  ///< NLopt LD_SLSQP (for cross-checks; multipliers estimated by least squares).
  /// NLopt LN_COBYLA: derivative-free (linear models of the objective and constraints over a
  /// simplex). Always used for min_sting, whatever is asked; no multipliers for min_sting.
  kNloptCobyla,
};

/// Ipopt's derivative checker, run at the first start.
enum class DerivativeCheck {
  kNone,         ///< Not run.
  kFirstOrder,   ///< derivative_test = first-order (gradient and Jacobian).
  kSecondOrder,  ///< derivative_test = second-order (also the Hessian; needs kExact).
};

/// How the optimisation runs. Defaults are valid.
struct DesignOptions {
  DesignBackend backend = DesignBackend::kIpopt;      ///< The local solver (min_sting: COBYLA).
  HessianMode hessian = HessianMode::kLimitedMemory;  ///< Ipopt's Hessian.
  int max_iterations = 300;  ///< Per local solve (1..100000); COBYLA: evaluations per start.
  /// Wall-clock budget of the whole call (all starts and the infeasibility analysis), s (> 0).
  /// Checked in Ipopt's intermediate callback and in every NLopt evaluation: a solve past it
  /// stops as no_convergence.
  double max_time_s = 10.0;
  /// Ipopt's max_cpu_time per local solve, s; 0 = not set. Ipopt 3.11 counts the CPU time of
  /// every thread of the process, so under load it fires early: prefer max_time_s.
  double max_cpu_time_s = 0.0;
  /// Ipopt tol / NLopt ftol_rel and xtol_rel (scaled problem, > 0, < 1). COBYLA uses
  /// max(tolerance, kDerivativeFreeTolerance).
  double tolerance = 1e-9;
  /// Largest violation accepted for a converged point, relative to each constraint's scale
  /// (Ipopt constr_viol_tol; > 0, < 1).
  double constraint_tolerance = 1e-10;
  /// The verdicts' tolerance: a constraint holds (DesignActiveConstraint::satisfied, a feasible
  /// design, the bbcor rule's re-check) when it is met to this, relative to its scale (a
  /// solver lands on an active bound from either side: a drop of 3.0000000002 holds "drop <=
  /// 3"); in (0, 0.01]. Also the certificate's largest violation (DesignCertificate).
  double feasibility_tolerance = kDefaultFeasibilityTolerance;
  int starts = 1;          ///< Local solves (1..64): the base design, then seeded random designs.
  std::uint64_t seed = 1;  ///< Seed of the random starts (std::mt19937_64).
  /// Given starts: start i is start_points[i] (the variables' values, field units, clamped into
  /// their bounds) while there is one, start 0 included (the base design then supplies only the
  /// fixed fields), then the base design or the random designs (the random design of start i
  /// stays the same). The shape fit's scan gives its best points here.
  std::vector<std::vector<double>> start_points;
  /// Smallest gap between neighbouring knots when knot positions are variables, m (> 0).
  double min_knot_gap_m = 1e-4;
  /// On an infeasible result, find which constraints conflict and by how much (a few small
  /// solves).
  bool explain_infeasibility = true;
  DerivativeCheck derivative_check = DerivativeCheck::kNone;  ///< Ipopt's checker (first start).
  /// Most continuous variables a problem may have (>= 1). The api sets it from its configured
  /// limit (ApiLimits::max_design_variables, server flag --max-design-variables).
  int max_variables = 1000;
  /// Ipopt: when every variable is a knot radius and the objective and constraints are linear
  /// or functions of the mass integrals P = (M, S1, S2, L), solve the lifted formulation (P as
  /// variables, its definition as sparse equality constraints: a sparse exact Hessian, whatever
  /// `hessian` says; core/optimize/lifted_nlp.hpp). false: always the dense formulation over
  /// the variables alone.
  bool lift = true;
  /// With `lift`: when the knot radii form one chain of non-decreasing taper rows, solve with
  /// the taper's steps as variables in blocks of kTaperBlockSize knots (each step's row becomes
  /// a bound; core/optimize/tapered_nlp.hpp). false: the lifted formulation over the radii.
  bool taper_steps = true;
  /// Let the optimiser choose the backend (the api's default when a request names none):
  /// NLopt SLSQP for a problem that qualifies for the lifted formulation with at most
  /// kChosenSlsqpMaxVariables variables, its answer kept only when certified (converged,
  /// feasible, KKT residual at most kChosenSlsqpMaxKkt), otherwise Ipopt from the start again;
  /// Ipopt for every other problem. `backend` is then ignored (core/optimize/backend_choice.hpp).
  bool choose_backend = false;
  /// The answer's certificate (DesignCertificate): largest relative stationarity residual of a
  /// certified answer, in (0, 1). A solve whose backend reports convergence is converged only
  /// when its certificate holds.
  double stationarity_tolerance = kDefaultStationarityTolerance;
  /// The certificate's largest complementarity product (relative), in (0, 1).
  double complementarity_tolerance = kDefaultComplementarityTolerance;

  /// True when every field is in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// Smallest relative tolerance (ftol_rel and xtol_rel of the scaled problem) COBYLA is run
/// with: each evaluation is a flexible impact (~5 ms), and the sting jumps by ~3e-5 relative
/// where the FE mesh changes, so a tighter one only spends evaluations on the model's own error.
inline constexpr double kDerivativeFreeTolerance = 1e-6;

/// A variable's value in the answer. DesignResult::variables lists the variables in request
/// order, each followed by its linked fields (the same value) or, for a scale variable, by its
/// fields (each its base value times the factor).
struct DesignValue {
  std::string path;    ///< The variable's path (a scale variable: its name).
  double value = 0.0;  ///< Its value, field unit (a scale variable: the dimensionless factor).
  /// True for a scale variable's own value (a factor, not a field of the bat).
  bool scale_factor = false;
};

/// A constraint or variable bound that holds the design back.
struct DesignActiveConstraint {
  /// e.g. "mass_kg", "balance_point_m.max", "three_segment.barrel_radius_m.max",
  /// "rules.bbcor.drop", "max_barrel_diameter_m.knots[5]".
  std::string name;
  std::string unit;    ///< Unit of value and bound ("kg", "m", "kg_m2", "kg_m3", "" = none).
  double value = 0.0;  ///< The constrained quantity at the optimum.
  double bound = 0.0;  ///< The limit it sits on.
  /// Sensitivity of the optimal objective to the bound: objective unit per constraint unit
  /// (first order, the certificate's own multiplier estimate, never the backend's). Positive:
  /// raising the bound raises the objective value (better when maximising, worse when
  /// minimising). NaN for min_sting (the sting has no derivative, so no multiplier can be
  /// estimated) and when the active gradients are dependent (no unique multiplier).
  double multiplier = 0.0;
  /// The verdict: the value is within the bound to `tolerance` (DesignOptions::
  /// feasibility_tolerance of the constraint's scale).
  bool satisfied = true;
  /// The largest overshoot of the bound that still holds, in the constraint's unit (>= 0).
  double tolerance = 0.0;
};

/// Which finding a DesignConflict states; code tells conflicts apart by this, never by reading
/// their message back.
enum class ConflictKind {
  /// A constraint no design variable changes is violated (found when the problem is built,
  /// without solving).
  kFixed,
  /// The variable bounds and the geometric constraints alone admit no design.
  kGeometric,
  /// One property constraint lies beyond what the bounds and the geometric constraints reach.
  kUnreachable,
  /// Two property constraints, each reachable alone, exclude each other.
  kPair,
  /// The solver found no feasible point and no smaller conflict explains it: what the
  /// least-violating design misses.
  kNotIsolated,
};

/// What a design's summary message states (DesignResult::message_kind).
enum class DesignMessageKind {
  kRefused,     ///< The input was refused before solving (summary.refusal).
  kSolver,      ///< The chosen start's solver status: "<status>[: <solver message>]".
  kConverged,   ///< "converged (<status>)".
  kCancelled,   ///< The chosen start was cut by a cancel: "cancelled (...); the best ... kept".
  kTimeBudget,  ///< The chosen start reached max_time_s: "time budget max_time_s = ... reached".
  /// Progress::Cancel() cut the multi-start: "cancelled after i of n starts (...)".
  kCancelledStarts,
  kInvalidBat,   ///< "the optimised bat is invalid: ...".
  kStingFailed,  ///< "the sting of the optimised bat cannot be computed: ...".
  /// "the distance sweet spot of the optimised bat cannot be computed: ..." (max_distance).
  kDistanceFailed,
  kInfeasible,   ///< "infeasible: ..." (the conflicts), or the BBCOR rule's refusal of the answer.
  kNoDesign,     ///< "no local solve returned a design (...)".
  /// The backend reported convergence but the certificate failed: "not certified: <status>
  /// reported convergence but <what failed>; ...".
  kNotCertified,
  kFailure,      ///< An internal failure ("out of memory", "failure: ...").
};

/// A conflict found for an infeasible request.
struct DesignConflict {
  ConflictKind kind = ConflictKind::kNotIsolated;  ///< Which finding this is.
  std::vector<std::string> constraints;            ///< The constraints involved, by name.
  std::string unit;                                ///< Unit of the numbers below.
  double requested_min = 0.0;   ///< What the first constraint asks (-inf if open).
  double requested_max = 0.0;   ///< (+inf if open).
  double achievable_min = 0.0;  ///< The least value reachable under the others (NaN if unknown).
  double achievable_max = 0.0;  ///< The largest value reachable under the others (NaN if unknown).
  double shortfall = 0.0;       ///< Distance between the two intervals (unit above; >= 0).
  std::string message;          ///< One sentence, e.g. "mass_kg = 0.5 is below ...".
};

/// One local solve of a multi-start.
struct DesignStart {
  int index = 0;                                    ///< 0 = the base design.
  Termination termination = Termination::kFailure;  ///< Its outcome.
  int raw_status = 0;                               ///< Backend status.
  int iterations = 0;                               ///< Iterations.
  double objective = 0.0;                           ///< Objective at its end (NaN if none).
  double constraint_violation = 0.0;                ///< Largest relative violation there.
};

/// The spread of the objective over the starts that ended feasible.
struct DesignSpread {
  int starts = 0;                 ///< Local solves run.
  int converged = 0;              ///< Of which converged.
  int feasible = 0;               ///< Of which ended feasible (converged or not).
  int best_start = -1;            ///< Index of the start that gave the answer (-1 = none).
  double objective_min = 0.0;     ///< Least objective over feasible ends (NaN if none).
  double objective_max = 0.0;     ///< Largest (NaN if none).
  double objective_median = 0.0;  ///< Median (NaN if none).
  std::vector<DesignStart> runs;  ///< Every start, in order.
};

/// The sting of the answer (min_sting), recomputed through the public path: the rigid-pivot
/// sweet spot in closed form, then Collide(kFlexible) there with problem.flexible.
struct DesignSting {
  double impact_from_knob_m = 0.0;        ///< The impact point (the rigid max-exit-speed point), m.
  double hands_vibration_energy_j = 0.0;  ///< The sting: vibration energy in the grip, J.
  /// Its estimated error (integration + mode truncation; 0 without refine_check), J.
  double error_estimate_j = 0.0;
  FlexibleImpactResult impact;  ///< Everything the flexible model knows about that impact.
};

/// The first bending mode of the answer (constraints.min_frequency_hz), recomputed by the modes
/// code (ComputeBatModes with problem.flexible's vibration_node settings) on its own adaptive
/// mesh, beside the optimisation's fixed-mesh value that the constraint holds.
struct DesignFrequency {
  double frequency_hz = 0.0;        ///< The modes code's first bending frequency, Hz.
  double error_estimate_hz = 0.0;   ///< Its error estimate, Hz.
  int elements = 0;                 ///< Elements of its final mesh.
  double model_frequency_hz = 0.0;  ///< The fixed mesh's value (the constrained one), Hz.
  int model_elements = 0;           ///< Elements of the fixed mesh.
};

/// The answer of OptimizeDesign. The summary is always filled:
/// - termination: converged (the backend converged, its answer's certificate holds and the
///   design meets every constraint when re-checked through ComputeMassProperties), no_convergence (stopped by iterations, time,
///   cancellation or round-off; best design kept), infeasible (no design meets the
///   constraints: `conflicts` says why; the least-violating design is returned), failure,
///   invalid_input (message names the field; the bat is the base design);
/// - backend "ipopt", "nlopt:LD_SLSQP" or "nlopt:LN_COBYLA"; raw_status = that solver's status
///   of the chosen start (Ipopt ApplicationReturnStatus, NLopt result); iterations and
///   evaluations summed over all solves; objective = objective_value; constraint_violation =
///   the largest violation of a constraint or bound, each in its own unit, re-checked through
///   the public mass properties; error_estimate = certificate.stationarity, the relative
///   first-order optimality (KKT) residual of the scaled problem at the answer (NaN for
///   min_sting: no derivative);
///   solve_time_s = wall time of the call.
struct DesignResult {
  Summary summary;  ///< How it went (see above).
  /// What summary.message states; code tells the outcomes apart by this, never by reading
  /// the message back.
  DesignMessageKind message_kind = DesignMessageKind::kRefused;
  Bat bat;                                         ///< The optimised bat.
  std::optional<ThreeSegmentShape> three_segment;  ///< Its shape, for three-segment designs.
  std::vector<DesignValue> variables;              ///< The variables' values (see DesignValue).
  MassProperties properties;                       ///< Its mass properties (problem.inertia_model).
  double objective_value = 0.0;                    ///< The objective, in objective_unit.
  std::string objective_unit;  ///< "mps", "m" (also max_distance), "kg_m2" or "j" (joules).
  double cor = 0.0;  ///< The COR used (NaN when none is known: min_moi without one).
  /// problem.cor_from_barrel: the answer's COR is its own barrel's, recomputed through the public
  /// path (EffectiveCorAt at cor_impact_from_knob_m and cor_impact_speed_mps); NaN otherwise.
  double cor_impact_from_knob_m = std::numeric_limits<double>::quiet_NaN();
  /// The normal impact speed the answer's barrel COR was evaluated at, m/s (NaN otherwise).
  double cor_impact_speed_mps = std::numeric_limits<double>::quiet_NaN();
  /// The ball's COR (its law) at cor_impact_speed_mps (NaN otherwise).
  double cor_ball = std::numeric_limits<double>::quiet_NaN();
  /// Sweet spot of the answer (rigid pivot, closed form, at angular_speed_rad_s), m from the
  /// knob; NaN when no COR is known (min_moi without one).
  double sweet_spot_from_knob_m = 0.0;
  double max_exit_speed_mps = 0.0;  ///< Max exit speed there, m/s (NaN as above).
  /// omega of the swing for the answer, rad/s (from its swing weight and, for a bat speed,
  /// its length).
  double angular_speed_rad_s = 0.0;
  /// Where the sweet spot's unconstrained maximum lies: kBeyondTip / kBeforeKnob when the
  /// reported point is the bat's end it was clamped to.
  Placement sweet_spot_placement = Placement::kOnBat;
  std::vector<DesignActiveConstraint> active_constraints;  ///< What holds the design back.
  std::vector<DesignConflict> conflicts;                   ///< For an infeasible request: why.
  DesignSpread spread;                                     ///< Over the starts.
  std::optional<DesignSting> sting;  ///< min_sting: the answer's impact (else empty).
  /// max_distance: the answer's distance sweet spot, recomputed through the public path
  /// (EvaluateDistance: ResolveScene of the answer's bat, then DistanceSweetSpot), else empty.
  std::optional<DistanceSweetSpotResult> distance_sweet_spot;
  /// constraints.min_frequency_hz: the answer's first bending mode (else empty).
  std::optional<DesignFrequency> first_bending_mode;
  /// rules bbcor or constraints.bbcor_max on a hollow answer: THE BBCOR (the flexible scan's
  /// maximum, its fixed-point estimate beside it) recomputed on the answer (BbcorRuleHolds; above
  /// the bound by more than the feasibility tolerance the termination is infeasible).
  std::optional<BbcorResult> bbcor;
  /// The certification rounds (bbcor_constraint.hpp): optimisations run (0 without a BBCOR
  /// bound) and the last one's estimate offset (scan maximum - estimate, dimensionless).
  int bbcor_rounds = 0;
  double bbcor_estimate_offset = 0.0;  ///< Dimensionless.
  /// The service's own first-order optimality check of the answer (not checked for min_sting,
  /// refused input or no design). active_constraints' multipliers are its estimates, NaN when
  /// certificate.multipliers_unique is false.
  DesignCertificate certificate;
  /// Constraints found before the solve to repeat another (or a variable's bounds) and merged.
  std::vector<MergedConstraint> merged_constraints;
  /// Errors reported by Ipopt's derivative checker (-1 = not run).
  int derivative_check_errors = -1;
  std::string derivative_check_report;  ///< The checker's output (empty if not run).
};

/// Optimises the design. Never throws. `progress` (may be null) receives the fraction of
/// starts done and is polled for cancellation (a cancelled solve ends no_convergence with a
/// message saying so, also when its chosen start converged but later starts were not run).
DesignResult OptimizeDesign(const DesignProblem& problem, const DesignOptions& options = {},
                            Progress* progress = nullptr);

/// One material's solve in OptimizeOverMaterials.
struct MaterialDesignResult {
  std::string material;  ///< The material's name.
  DesignResult result;   ///< Its optimisation.
};

/// The answer of OptimizeOverMaterials.
struct MaterialChoiceResult {
  Summary summary;  ///< Termination of the best material's solve (or why none is usable).
  int best = -1;    ///< Index into per_material of the best usable design (-1 = none).
  std::vector<MaterialDesignResult> per_material;  ///< Every material, in the order given.
};

/// A discrete choice of material: solves `problem` once per material (the base bat's
/// material replaced; the COR: problem.cor if set, else each design's own barrel's with
/// problem.cor_from_barrel, else the material's; rule sets apply
/// per material, so e.g. mlb-wood refuses aluminium as invalid_input for that material) and
/// picks the best usable design: converged ones first, then by objective. options.max_time_s
/// bounds the whole call (one budget for all materials); `progress` covers all materials and is
/// polled for cancellation inside each solve. Never throws.
MaterialChoiceResult OptimizeOverMaterials(const DesignProblem& problem,
                                           const std::vector<Material>& materials,
                                           const DesignOptions& options = {},
                                           Progress* progress = nullptr);

}  // namespace sweetspot::core
