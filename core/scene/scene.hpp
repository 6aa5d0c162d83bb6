// A scene: what is hit (the bat, or only its mass properties), by what (the ball), how (the
// swing), with which COR, and what is wanted (the outputs); and the settings of its
// computations (the collision models, the flexible beam, EvaluateScene's options). Plain values
// with Validate(Refusal*); the computations are in core/scene/evaluate_scene.hpp and
// core/scene/collide.hpp.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/ball/ball_catalogue.hpp"
#include "core/bat/bat.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/collision/barrel.hpp"
#include "core/collision/flexible_impact.hpp"
#include "core/collision/hertz_contact.hpp"
#include "core/flexible/beam_model.hpp"
#include "core/flexible/modes.hpp"
#include "core/flexible/modes_cache.hpp"
#include "core/flight/flight.hpp"
#include "core/numerics/nlopt_search.hpp"
#include "core/progress.hpp"
#include "core/refusal.hpp"
#include "core/scene/output_id.hpp"
#include "core/scene/swing_speed.hpp"
#include "core/sweet_spot/numeric.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {

/// Default ball stiffness k in F = k delta^p, N/m^1.5 (see docs/models.md for its calibration).
inline constexpr double kDefaultBallStiffness = 4.0e7;
/// Default ball stiffness exponent p (dimensionless).
inline constexpr double kDefaultBallStiffnessExponent = 1.5;
/// Smallest ball mass a scene accepts, kg (1 mg).
inline constexpr double kMinBallMassKg = 1e-6;
/// Smallest ball radius a scene accepts, m (1 µm).
inline constexpr double kMinBallRadiusM = 1e-6;
/// Largest ball mass a scene accepts, kg.
inline constexpr double kMaxBallMassKg = 1e3;
/// Largest ball radius a scene accepts, m.
inline constexpr double kMaxBallRadiusM = 10.0;
/// Largest incoming ball speed a scene accepts, m/s.
inline constexpr double kMaxBallSpeedMps = 1e3;
/// Largest ball stiffness k a scene accepts, N/m^p.
inline constexpr double kMaxBallStiffness = 1e15;
/// Largest swing angular speed a scene accepts, rad/s.
inline constexpr double kMaxSwingAngularSpeedRadS = 1e4;
/// Largest distance of the pivot or the hands from the knob a scene accepts, m (either side).
inline constexpr double kMaxSwingOffsetM = 100.0;
/// Largest bat speed (swing.bat_speed_mps) a scene accepts, m/s.
inline constexpr double kMaxBatSpeedMps = 1e3;
/// Largest reference swing weight (swing.reference_moi_kg_m2) a scene accepts, kg·m².
inline constexpr double kMaxSwingMoiKgM2 = 1e4;
/// Largest |angle| of a path (swing.attack_angle_deg, ball.descent_angle_deg), deg: the
/// oblique impact's own bound (ObliqueImpactInputs).
inline constexpr double kMaxPathAngleDeg = 89.0;
/// Largest |ball.spin_rpm| a scene accepts (the flight's spin bound).
inline constexpr double kMaxPitchSpinRpm = 10000.0;
/// Largest |contact.undercut_m| a scene accepts, m (4 in; the oblique impact refuses beyond
/// ball radius + bat radius at the point).
inline constexpr double kMaxUndercutM = 0.1016;

/// The ball. Defaults: a regulation baseball and the paper's Table 3 speed.
struct Ball {
  double mass_kg = 0.145;    ///< Mass, kg, in [kMinBallMassKg, kMaxBallMassKg].
  double radius_m = 0.0366;  ///< Radius, m, in [kMinBallRadiusM, kMaxBallRadiusM].
  double speed_mps = 27.7;   ///< Incoming speed towards the bat, m/s, in [0, kMaxBallSpeedMps].
  /// Contact models: k in F = k delta^p, N/m^p, in (0, kMaxBallStiffness].
  double stiffness = kDefaultBallStiffness;
  double stiffness_exponent = kDefaultBallStiffnessExponent;  ///< Contact models: p, in [1, 3].
  /// The pitch's path at the plate below horizontal, deg (+ down), in [-kMaxPathAngleDeg,
  /// kMaxPathAngleDeg]; the oblique impact's (batted_ball) only.
  double descent_angle_deg = 0.0;
  /// The pitch's spin, rpm (+ backspin), |value| <= kMaxPitchSpinRpm; batted_ball only.
  double spin_rpm = 0.0;
  /// The catalogue entry this ball came from ("" = none: today's default ball).
  std::string preset;
  /// The ball's COR against solid wood by impact speed (set by a preset). When set and the scene
  /// gives no `cor`, a solid bat's COR is this law at the scene's impact speed
  /// (ResolveScene); unset = the bat material's COR, as before.
  std::optional<BallCorLaw> cor_law;

  /// True when every field is in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "ball.field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// `ball` with the catalogue entry's mass, radius, contact law and COR law (its speed kept):
/// the values a request's explicit ball fields then override.
void ApplyBallPreset(const BallPreset& preset, Ball* ball);

/// Where a scene's ball COR law is evaluated when no impact point is given: 0.1524 m (6 in)
/// from the tip, the standard bat-speed point, near every model's sweet spot.
inline constexpr double kCorReferenceFromTipM = 0.1524;

/// Where swing.bat_speed_mps is measured.
enum class BatSpeedPoint {
  kFromTip,    ///< "distance": swing.bat_speed_from_tip_m from the tip (default 6 in).
  kSweetSpot,  ///< "sweet_spot": the bat's own max-exit-speed point, solved with the swing.
};
/// How the bat speed depends on the bat.
enum class SwingSpeedModel {
  kFixed,        ///< "fixed": every bat at the given speed (default).
  kSwingWeight,  ///< "swing_weight": the given speed is the reference bat's (swing_speed.hpp).
};
/// Stable names (quoted above).
const char* BatSpeedPointName(BatSpeedPoint point);
const char* SwingSpeedModelName(SwingSpeedModel model);
/// The speed model called `name`, or nullopt.
std::optional<SwingSpeedModel> ParseSwingSpeedModel(std::string_view name);

/// How a swing given by its bat speed was resolved for one bat (ResolveSceneSwing).
struct SwingResolution {
  double given_bat_speed_mps = 0.0;  ///< The request's bat speed (the reference bat's), m/s.
  /// This bat's speed at its bat-speed point, m/s: the given one times swing_weight_factor.
  double bat_speed_mps = 0.0;
  double position_from_knob_m = 0.0;  ///< The bat-speed point, m from the knob.
  double from_tip_m = 0.0;            ///< The same, m from the tip.
  /// kSweetSpot: the closed form whose max-exit-speed point it is ("rigid_pivot" or
  /// "free_bat"); "" for kFromTip.
  std::string point_model;
  double moi_hands_kg_m2 = 0.0;      ///< The bat's MOI about the hands, kg·m².
  double reference_moi_kg_m2 = 0.0;  ///< kSwingWeight: the reference swing weight, kg·m².
  double swing_weight_factor = 1.0;  ///< (moi_hands / reference)^-n; 1 for kFixed.
  /// kSweetSpot with hertz or flexible: the fixed-point iterations to the model's own maximum
  /// (SolveSweetSpotSwing); 0 for a closed form (solved exactly).
  int iterations = 0;
  /// ... and the speed at that maximum minus bat_speed_mps when they stopped, m/s.
  double speed_error_mps = 0.0;
};

/// The swing just before impact. Defaults: the paper's Table 3 and the standard grip.
struct Swing {
  /// Angular speed about the pivot, rad/s, in [0, kMaxSwingAngularSpeedRadS].
  double angular_speed_rad_s = 17.288;
  /// The pivot, m from the knob (negative = behind the knob), within ±kMaxSwingOffsetM.
  double pivot_from_knob_m = 0.0;
  double hands_from_knob_m = 0.1524;  ///< The hands, m from the knob (within the bat).
  /// The bat's speed at the bat-speed point, m/s, in [0, kMaxBatSpeedMps]: when set, it sets
  /// angular_speed_rad_s = bat_speed_mps / (L - bat_speed_from_tip_m - pivot_from_knob_m) once
  /// the bat length L is known (ResolveSwing, called by ResolveScene).
  std::optional<double> bat_speed_mps;
  /// Where bat_speed_mps is measured, m from the tip (the barrel end), in [0, kMaxSwingOffsetM];
  /// the default is 6 in, as swing sensors report.
  double bat_speed_from_tip_m = kCorReferenceFromTipM;
  /// Where bat_speed_mps is measured: bat_speed_from_tip_m, or the bat's own max-exit-speed
  /// point ("sweet_spot"; needs bat_speed_mps).
  BatSpeedPoint bat_speed_point = BatSpeedPoint::kFromTip;
  /// kSwingWeight (needs bat_speed_mps): bat_speed_mps is the speed of a bat whose MOI about
  /// the hands is reference_moi_kg_m2, and each bat is swung at bat_speed_mps (I_hands /
  /// reference)^-swing_weight_exponent (core/scene/swing_speed.hpp, Cross & Bower 2006).
  SwingSpeedModel speed_model = SwingSpeedModel::kFixed;
  /// kSwingWeight: the reference bat's MOI about the hands, kg·m², in (0, kMaxSwingMoiKgM2];
  /// unset = kSwingWeightReferenceMoiKgM2 (wood-34-ash about the 6-in point).
  std::optional<double> reference_moi_kg_m2;
  /// kSwingWeight: n in V = C / I^n, in [0, kMaxSwingWeightExponent] (default Cross & Bower's).
  double swing_weight_exponent = kSwingWeightExponent;
  /// The bat's path above horizontal, deg (+ up), within +-kMaxPathAngleDeg; batted_ball only.
  double attack_angle_deg = 0.0;
  /// Set on a resolved swing given by its bat speed (ResolveSceneSwing): how it was resolved.
  std::optional<SwingResolution> resolution;

  /// True when every field is finite and in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "swing.field = value: rule".
  bool Validate(Refusal* refusal) const;
  /// Validate's rules for bat_speed_point, speed_model, reference_moi_kg_m2 and
  /// swing_weight_exponent: each new setting needs bat_speed_mps, and the swing-weight settings
  /// need speed_model kSwingWeight (they would have no effect).
  bool ValidateSpeedModel(Refusal* refusal) const;
};

/// `swing` for a bat `length_m` long, into *resolved: a copy, with angular_speed_rad_s set from
/// bat_speed_mps when that is given (omega = v / (L - from_tip - pivot)). False, with the
/// refusal in *refusal (if non-null), when the bat-speed point is off the bat or not beyond the
/// pivot, or the omega it gives is over kMaxSwingAngularSpeedRadS. `swing` must be valid.
bool ResolveSwing(const Swing& swing, double length_m, Swing* resolved, Refusal* refusal);

/// Where the ball meets the bat across the bat's axis (the oblique impact, batted_ball).
struct Contact {
  /// The ball's centre above the bat's axis across the approach line, m (+ gives backspin),
  /// within +-kMaxUndercutM.
  double undercut_m = 0.0;

  /// True when in range; otherwise the refusal "contact.undercut_m = ...: ...".
  bool Validate(Refusal* refusal) const;
};

/// A scene: what is hit, how, and what is wanted.
struct Scene {
  std::optional<Bat> bat;  ///< The bat (needed for the contact model's surface stiffness).
  std::optional<MassProperties>
      mass_properties;    ///< Precomputed properties; used instead of computing them from `bat`.
  double length_m = 0.0;  ///< Bat length, m; needed only when `bat` is absent.
  InertiaModel inertia_model = InertiaModel::kRigidBody;  ///< When computing from `bat`.
  Ball ball;                                              ///< The ball.
  Swing swing;                                            ///< The swing.
  Contact contact;  ///< Where across the bat the ball meets it (batted_ball).
  /// The air the batted ball flies through (batted_ball, distance_sweet_spot, carry_map); the
  /// flight's defaults (70 F, sea level, 50 %, 29.92 inHg, calm).
  flight::Environment environment;
  /// The batted ball's aerodynamic model (the flight's; default nathan-2016).
  flight::AeroOptions aero;
  /// COR in [0, 1]; unset = the ball's COR law (a preset's) for a solid bat, else the bat
  /// material's default (ResolveScene).
  std::optional<double> cor;
  std::vector<SceneOutput> outputs = {
      SceneOutput::kMaxExitSpeed};  ///< What to compute (duplicates ignored).
  /// The bat is one of the paper's presets ("paper-wood", "paper-wood-m885"): model auto picks
  /// the paper's rigid_pivot for it, so the paper's numbers are reproduced.
  bool paper_bat = false;

  /// True when the scene is well formed; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
  /// Validate's rule for `cor` alone: absent, or finite and in [0, 1] (dimensionless).
  bool ValidateCor(Refusal* refusal) const;
};

/// A collision model.
enum class CollisionModel {
  kAuto,        ///< free_bat (rigid_pivot for the paper's bats); the result says which and why.
  kRigidPivot,  ///< The paper's pivoted rigid bat (closed form).
  kFreeBat,     ///< The free rigid bat, collision efficiency (closed form).
  kHertz,       ///< The contact model (ODE).
  kFlexible,    ///< The flexible free-free beam, modal superposition + the contact law (ODE).
};

/// Stable name: "auto", "rigid_pivot", "free_bat", "hertz", "flexible".
const char* CollisionModelName(CollisionModel model);
/// The model called `name`, or nullopt.
std::optional<CollisionModel> ParseCollisionModel(std::string_view name);

/// The exit-speed model `requested` resolves to for `scene` (kAuto: free_bat, or the paper's
/// rigid_pivot for a paper bat), and why in *reason ("requested", or "auto: ..." saying why).
CollisionModel ResolveExitModel(CollisionModel requested, const Scene& scene, std::string* reason);

/// How the sweet spot is found.
enum class SweetSpotMethod {
  /// Closed form where the model has one (rigid_pivot, free_bat); otherwise the bracketing
  /// search (flexible) or NLopt (hertz).
  kClosedForm,
  kNlopt,  ///< Always the NLopt search (the independent path).
};

/// The unit of the sweet-zone tolerance.
enum class ToleranceUnit {
  kMetersPerSecond,  ///< Absolute, m/s.
  kPercent,          ///< Percent of the maximum exit speed.
};

/// Scene-level settings of the flexible beam (vibration_node, model = flexible, least_sting_zone).
struct FlexibleOptions {
  BeamTheory theory = BeamTheory::kTimoshenko;  ///< Beam theory of every flexible output.
  /// vibration_node: relative tolerance of the first two frequencies, in [1e-9, 0.1].
  double frequency_tolerance = 1e-4;
  int max_elements = 512;        ///< Mesh bound of every modes computation, in [2, 4096].
  FlexibleImpactOptions impact;  ///< Flexible impacts (model = flexible, least_sting_zone).
  /// least_sting_zone: impacts from the hands to the tip, in [3, 1001]. 21 (every other one of
  /// the former 41): they only bracket the minimum and the ends, which the searches refine.
  int sting_samples = 21;
  /// least_sting_zone: the zone is E <= E_min + fraction (E_max - E_min), in (0, 1].
  double sting_zone_fraction = 0.1;
  /// max_exit_speed with model = flexible and method closed_form (the default): the
  /// bracketing search's samples, tolerance and budget (method nlopt runs the NLopt search).
  /// Its x_tolerance_m is also least_sting_zone's tolerance of the minimum and the ends.
  BracketSearchOptions search;
  /// Cross-request cache of modes, owned by the caller (the API's server context); null = none.
  /// Within a request the modes are computed once whatever this is.
  ModesCache* modes_cache = nullptr;

  /// True when every field is in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "flexible.field = value: rule".
  bool Validate(Refusal* refusal) const;
  /// The modes options of vibration_node (2 modes to frequency_tolerance).
  BeamModesOptions VibrationModes() const;
  /// The modes options of flexible impacts (impact.max_modes to impact.frequency_tolerance).
  BeamModesOptions ImpactModes() const;
};

/// Settings of distance_sweet_spot and carry_map: the region of impact positions x undercuts
/// searched or mapped, the searches' tolerances and the map's grid.
struct DistanceOptions {
  /// Lowest impact position searched or mapped, m from the knob; unset = half the bat length.
  std::optional<double> position_min_from_knob_m;
  /// Highest impact position, m from the knob; unset = the tip (the bat length).
  std::optional<double> position_max_from_knob_m;
  /// Lowest undercut, m (- = overcut: topspin), in [-kMaxUndercutM, kMaxUndercutM].
  double undercut_min_m = -0.0254;
  /// Highest undercut, m, in (undercut_min_m, kMaxUndercutM].
  double undercut_max_m = 0.0508;
  /// distance_sweet_spot's coarse scan: positions, in [2, 201].
  int coarse_positions = 13;
  /// distance_sweet_spot's coarse scan: undercuts, in [2, 201].
  int coarse_undercuts = 11;
  /// distance_sweet_spot's local search (NLopt LN_BOBYQA around the best coarse point): its
  /// absolute tolerance on the position, m, in [1e-7, 0.01].
  double position_tolerance_m = 1e-4;
  /// Its absolute tolerance on the undercut, m, in [1e-8, 0.01].
  double undercut_tolerance_m = 1e-5;
  /// Its evaluation budget, in [10, 100000].
  int max_evaluations = 400;
  /// carry_map: positions of the grid (evenly spaced over the position range), in [2, 401].
  int map_positions = 41;
  /// carry_map: undercuts of the grid (evenly spaced over the undercut range), in [2, 401].
  int map_undercuts = 21;
  /// hertz and flexible: the normal impulse J_n(v_n) is tabulated per position at this many
  /// normal approach speeds (Chebyshev nodes) and interpolated, in [2, 16].
  int normal_table_speeds = 5;
  /// distance_sweet_spot with hertz or flexible: the positions of that table over the position
  /// range (the map uses its own grid's), in [3, 401].
  int normal_table_positions = 41;

  /// True when every field is in range; otherwise the refusal ("distance.coarse_positions =
  /// 1: must be in [2, 201]").
  bool Validate(Refusal* refusal) const;
};

/// Options of EvaluateScene.
struct SceneOptions {
  /// Exit-speed model for max/zone/curve: kAuto = free_bat (rigid_pivot for a paper bat);
  /// ResolveExitModel says which and why.
  CollisionModel model = CollisionModel::kAuto;
  SweetSpotMethod method = SweetSpotMethod::kClosedForm;  ///< Closed form or NLopt.
  ScalarSearchOptions nlopt;  ///< The NLopt search (algorithm, tolerances, budget).
  /// Sweet-zone tolerance in `sweet_zone_unit`: [0, 1000] m/s or [0, 100] percent.
  double sweet_zone_tolerance = 1.0;
  ToleranceUnit sweet_zone_unit = ToleranceUnit::kMetersPerSecond;  ///< m/s or percent.
  int curve_samples = 41;  ///< Evenly spaced curve samples from knob to tip (2..max_curve_points).
  std::vector<double> curve_positions_from_knob_m;  ///< Explicit curve positions, m (overrides
                                                    ///< curve_samples; at most max_curve_points).
  /// The most curve points (curve_samples or explicit positions) a scene may
  /// ask for (>= 2); the api sets it from its configured max_curve_samples.
  int max_curve_points = 10000;
  HertzOptions hertz;        ///< Contact-model settings (model = kHertz).
  FlexibleOptions flexible;  ///< Flexible-beam settings (vibration_node, flexible, sting).
  BarrelOptions barrel;      ///< Barrel-model settings (barrel, bbcor).
  DistanceOptions distance;  ///< distance_sweet_spot and carry_map settings.
  /// True (the default): the result's timings and solve_time_s are measured. False: the
  /// closed forms and the mass properties read no clock (their timings are 0 s; the models
  /// and calls are still listed): /v1/explore's sweeps, whose rows report no timings.
  bool time_models = true;
  /// A cancel flag polled between the points of an exit-speed curve (null: never
  /// cancelled); once set, the evaluation stops with termination failure, "cancelled". Not a
  /// value of the scene: the server sets it when a client leaves or a time budget ends.
  const Progress* progress = nullptr;

  /// True when every field is in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
};

}  // namespace sweetspot::core
