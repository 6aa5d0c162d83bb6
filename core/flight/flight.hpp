// Batted-ball flight: from launch conditions to the landing point, as A. M. Nathan's trajectory
// calculator computes it (parameters fitted to 2015 Statcast batted balls, "Going Deep on Goin'
// Deep", The Hardball Times, 6 Apr 2016; the 3-D spreadsheet TrajectoryCalculator-new-3D.xlsx,
// 2018, a public copy in github.com/dtkaplan/Zcalc, inst/raw_data/Fly_ball/). SI inside.
//
// Frame: the origin at home plate on the ground; y toward centre field, x toward right field,
// z up. A flight is one call, Fly(launch, environment, aero, options, trajectory): no
// allocation unless a trajectory is asked for, no exception, no global state (re-entrant).
// The equations, the aero models and their sources: docs/flight.md.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "core/refusal.hpp"

namespace sweetspot::core::flight {

/// The batter's side, which sets the sign of the estimated sidespin.
enum class BatterHand {
  kRight,  ///< A right-handed batter (the calculator's default).
  kLeft,   ///< A left-handed batter.
};

/// "right" or "left".
const char* BatterHandName(BatterHand hand);

/// The ball as it leaves the bat.
struct Launch {
  /// Speed off the bat, m/s (Statcast's launch_speed); required, in (0, 90].
  double exit_speed_mps = 0.0;
  /// Vertical angle above the horizontal, degrees, in [-90, 90].
  double launch_angle_deg = 0.0;
  /// Horizontal angle, degrees, 0 = toward centre field, + toward right field; in [-90, 90].
  double spray_angle_deg = 0.0;
  /// Backspin, rpm (+ = backspin, lifting; − = topspin); |value| ≤ 10,000. Unset = estimated
  /// with the sidespin from the Statcast relation (EstimateSpin).
  std::optional<double> backspin_rpm;
  /// Sidespin, rpm, in Nathan's sign (spin axis tilted up for +: the ball curves toward left
  /// field; − toward right field); |value| ≤ 10,000. Unset = estimated with the backspin
  /// (both must be given, or neither).
  std::optional<double> sidespin_rpm;
  /// Height of the ball above the ground at launch, m; the calculator's 3 ft. In [0, 5].
  double height_m = 0.9144;
  /// Where the flight starts toward right field, m (the calculator's 0). In [-5, 5].
  double start_x_m = 0.0;
  /// Where the flight starts toward centre field, m: the calculator's 2 ft in front of the
  /// plate. In [-5, 5].
  double start_y_m = 0.6096;
  /// The batter's side (used only to estimate spin).
  BatterHand batter_hand = BatterHand::kRight;

  /// Refuses a field out of its range or not finite (field names as above).
  bool Validate(Refusal* why) const;
};

/// The wind, uniform over the field and the flight.
struct Wind {
  /// Wind speed, m/s, in [0, 50] (50 m/s ≈ 112 mph: no game is played in more).
  double speed_mps = 0.0;
  /// Where the wind blows to, degrees: 0 = out to centre field, 90 = toward right field
  /// (out along +x), 180 = in from centre field. In [-360, 360].
  double direction_deg = 0.0;
};

/// The air the ball flies through.
struct Environment {
  /// Air temperature, °C; 21.11 °C = 70 °F. In [-40, 60].
  double temperature_c = (70.0 - 32.0) * 5.0 / 9.0;
  /// Field elevation above sea level, m. In [-500, 5000].
  double elevation_m = 0.0;
  /// Relative humidity, percent, in [0, 100].
  double relative_humidity_pct = 50.0;
  /// Barometric pressure corrected to sea level (as weather reports give it), Pa;
  /// 29.92 inHg = 101,320.75 Pa. In [80,000, 110,000].
  double sea_level_pressure_pa = 29.92 * 3386.389;
  /// The wind (calm by default).
  Wind wind;

  /// Refuses a field out of its range or not finite ("temperature_c", "wind.speed_mps", ...).
  bool Validate(Refusal* why) const;
};

/// Air density, kg/m³, by the calculator's formula (after the CRC Handbook's moist-air
/// density): ρ = 1.2929 · 273/(T+273) · (P·exp(−β·elev) − 0.3783·RH·SVP/100) / 760, with P the
/// sea-level barometer in mmHg, β = 1.217e-4 per metre, the saturation vapour pressure
/// SVP = 4.5841·exp((18.687 − T/234.5)·T/(257.14 + T)) mmHg (Buck 1981), T in °C.
double AirDensityKgM3(const Environment& environment);
/// Saturation vapour pressure of water over water at `temperature_c`, Pa (Buck 1981, the
/// calculator's form in mmHg converted at 133.322 Pa/mmHg).
double SaturationVapourPressurePa(double temperature_c);
/// Station pressure at `elevation_m` from the sea-level-corrected `sea_level_pressure_pa`, Pa:
/// P·exp(−1.217e-4 · elevation_m) (the calculator's isothermal scale height, 8.2 km).
double StationPressurePa(double sea_level_pressure_pa, double elevation_m);

/// The aerodynamic model of a flight.
enum class AeroModel {
  /// Nathan's calculator (2016, 3-D sheet 2018): CD = 0.3008 + 0.0292·(rpm/1000)·decay,
  /// CL = 1.120·S/(0.583 + 2.333·S), spin decay τ = 30 s (at 100 mph).
  kNathan2016,
  /// Sawicki, Hubbard & Stronge, Am. J. Phys. 71, 1152 (2003): CL = 1.5·S (S < 0.1),
  /// 0.09 + 0.6·S above; a drag coefficient falling with speed through the drag crisis
  /// (docs/flight.md says which breakpoints are used and that they were not read from the
  /// paper's figure in this work); no spin decay.
  kSawicki2003,
  /// No air: gravity only, the closed-form check (Fly still integrates it).
  kVacuum,
  /// The user's: CD = cd0 + cd_spin·(rpm/1000)·decay, lift by `lift_law`, decay τ.
  kCustom,
};

/// "nathan-2016", "sawicki-2003", "vacuum", "custom".
const char* AeroModelName(AeroModel model);

/// How a custom model's lift coefficient follows the spin parameter S = Rω/v.
enum class LiftLaw {
  kSaturating,  ///< CL = cl2·S/(cl0 + cl1·S) (Nathan's form).
  kLinear,      ///< CL = cl_per_spin_factor·S.
};

/// "saturating", "linear".
const char* LiftLawName(LiftLaw law);

/// The aerodynamic model and the ball. Defaults: Nathan 2016 and the calculator's ball.
struct AeroOptions {
  AeroModel model = AeroModel::kNathan2016;  ///< Which model.
  /// Drag coefficient without spin (custom; nathan-2016 fixes 0.3008). In [0, 2].
  double cd0 = 0.3008;
  /// Drag added per 1000 rpm of spin (custom; nathan-2016 fixes 0.0292). In [0, 1].
  double cd_spin_per_krpm = 0.0292;
  /// Custom lift law.
  LiftLaw lift_law = LiftLaw::kSaturating;
  /// Saturating law's numerator, cl2 (Nathan: 1.120). In [0, 10].
  double cl2 = 1.120;
  /// Saturating law's constant, cl0 (Nathan: 0.583). In (0, 10].
  double cl0 = 0.583;
  /// Saturating law's slope, cl1 (Nathan: 2.333). In [0, 10].
  double cl1 = 2.333;
  /// Linear law's slope dCL/dS. In [0, 10].
  double cl_per_spin_factor = 1.0;
  /// Spin decay time constant at 100 mph, s: the spin factor and the spin drag fall as
  /// exp(−t·v/(τ·44.704 m/s)) (the calculator's form). nathan-2016: 30 s by default and may
  /// be overridden (the sheet's other case uses 10,000 s, no decay); custom: as given;
  /// sawicki-2003: not used (the paper keeps the spin). In [0.1, 1e6].
  double spin_decay_s = 30.0;
  /// Ball mass, kg: the calculator's 5.125 oz. In [0.1, 0.2].
  double ball_mass_kg = 5.125 * 0.028349523125;
  /// Ball circumference, m: the calculator's 9.125 in. In [0.2, 0.26].
  double ball_circumference_m = 9.125 * 0.0254;

  /// Refuses a field out of its range or not finite ("cd0", "spin_decay_s", ...).
  bool Validate(Refusal* why) const;
};

/// The integrator's settings (an adaptive Dormand–Prince 5(4) with dense output; the first step
/// min(0.5 s, 5·relative_tolerance^0.2 s), then PI step control).
struct FlightOptions {
  /// Relative tolerance of a step's local error. The default keeps the distance within
  /// 0.1 ft (3 cm) of a converged answer (docs/speed-vs-error.md). In [1e-13, 1e-2].
  double relative_tolerance = 1e-5;
  /// Absolute tolerance of a step's local error in position, m (velocity: per second).
  /// In [1e-12, 1].
  double absolute_tolerance_m = 1e-3;
  /// The flight's time limit, s (simulated): a ball still up then is reported as
  /// kTimeLimit, not integrated on. In (0, 600].
  double max_flight_time_s = 30.0;
  /// Step limit, accepted and rejected steps together (a bound on the work of one flight).
  /// In [10, 1e6].
  int max_steps = 20000;
  /// Sampling interval of a requested trajectory, s. In [1e-3, 10].
  double trajectory_interval_s = 0.05;

  /// Refuses a setting out of its range ("relative_tolerance", ...).
  bool Validate(Refusal* why) const;
};

/// Where the spin of a flight came from.
enum class SpinSource {
  kGiven,           ///< Both spins were given.
  kStatcastRelation,  ///< Estimated from the launch (EstimateSpin).
};

/// "given", "statcast_relation".
const char* SpinSourceName(SpinSource source);

/// Backspin and sidespin, rpm.
struct Spin {
  double backspin_rpm = 0.0;  ///< + lifts.
  double sidespin_rpm = 0.0;  ///< Nathan's sign (+ curves toward left field).
};

/// The spin of a batted ball estimated from its launch by the relation in Nathan's 3-D sheet
/// (a fit to 2015-17 Statcast/TrackMan batted balls): backspin = −763 + 120·LA + 21·φ·s,
/// sidespin = −849·s − 94·φ (rpm; LA the launch angle and φ the spray angle in degrees;
/// s = +1 for a right-handed batter, −1 for a left-handed one).
Spin EstimateSpin(double launch_angle_deg, double spray_angle_deg, BatterHand hand);

/// Statcast's labels of a batted ball (MLB glossary; baseballr's code_barrel for the barrel).
struct Classification {
  /// Barrel: exit speed ≥ 98 mph, LA ≤ 50°, 1.5·EV − LA ≥ 117 and EV + LA ≥ 124 (mph, °):
  /// 26–30° at 98 mph, the window widening with speed to 8–50° at 116 mph.
  bool barrel = false;
  /// Hard-hit: exit speed ≥ 95 mph.
  bool hard_hit = false;
  /// Sweet-spot launch angle: 8° ≤ LA ≤ 32°.
  bool sweet_spot_launch = false;
};

/// Statcast's labels of an exit speed (m/s) and a launch angle (degrees).
Classification Classify(double exit_speed_mps, double launch_angle_deg);

/// How a flight ended.
enum class FlightTermination {
  kLanded,        ///< The ball reached the ground: the result is usable.
  kTimeLimit,     ///< Still in the air at max_flight_time_s: no landing.
  kStepLimit,     ///< max_steps (accepted + rejected) taken before landing: no landing.
  kNonFinite,     ///< The equations gave a NaN or an infinity: no landing.
  kInvalidInput,  ///< Refused before flying: see `refusal`.
};

/// "landed", "time_limit", "step_limit", "non_finite", "invalid_input".
const char* FlightTerminationName(FlightTermination termination);

/// One sample of a trajectory.
struct TrajectoryPoint {
  double t_s = 0.0;    ///< Time since launch, s.
  double x_m = 0.0;    ///< Toward right field, m.
  double y_m = 0.0;    ///< Toward centre field, m.
  double z_m = 0.0;    ///< Height above the ground, m.
  double speed_mps = 0.0;  ///< Speed over the ground, m/s.
};

/// What a flight returns, whatever happened (numbers NaN when not computed).
struct FlightResult {
  FlightTermination termination = FlightTermination::kInvalidInput;  ///< How it ended.
  std::optional<Refusal> refusal;  ///< Why the input was refused (kInvalidInput only).
  double distance_m = 0.0;   ///< Horizontal distance from home plate to the landing point, m.
  double hang_time_s = 0.0;  ///< Time from launch to landing, s.
  double apex_m = 0.0;       ///< Highest point above the ground, m.
  double apex_time_s = 0.0;  ///< When it was reached, s.
  double landing_x_m = 0.0;  ///< Landing point toward right field, m.
  double landing_y_m = 0.0;  ///< Landing point toward centre field, m.
  /// Direction of the landing point from home plate, degrees (0 = centre field, + right).
  double bearing_deg = 0.0;
  double landing_speed_mps = 0.0;  ///< Speed at landing (over the ground), m/s.
  double landing_angle_deg = 0.0;  ///< Descent angle at landing below the horizontal, degrees.
  double air_density_kg_m3 = 0.0;  ///< The air density used, kg/m³.
  Spin spin;                       ///< The spin flown (given or estimated), rpm.
  SpinSource spin_source = SpinSource::kGiven;  ///< Where the spin came from.
  Classification classification;                ///< Statcast's labels of the launch.
  /// Estimated error of distance_m, m: the embedded 4th-order pair's local position errors
  /// summed over the accepted steps, plus each step's local velocity error carried to the
  /// landing, plus the landing interpolant's error (a cubic Hermite against the 4th-order dense
  /// output). An estimate, not a bound: measured over a grid of launches the error was at most
  /// 1.6 times it (nathan-2016, custom; tests/core/flight_test.cpp); sawicki-2003's lift law
  /// has a kink it cannot see.
  double error_estimate_m = 0.0;
  int steps = 0;           ///< Accepted steps.
  int rejected_steps = 0;  ///< Rejected steps.
  int evaluations = 0;     ///< Right-hand-side evaluations.

  /// True when the ball landed (the numbers are usable).
  bool Landed() const { return termination == FlightTermination::kLanded; }
};

/// The closed-form flight without air (the vacuum model's check): launch speed v, angle θ from
/// height h: hang time (v sinθ + √(v² sin²θ + 2gh))/g, apex h + v² sin²θ/(2g), and the
/// distance from home plate of the landing point (x0 + v cosθ sinφ t, y0 + v cosθ cosφ t).
FlightResult VacuumFlight(const Launch& launch);

/// Standard gravity, m/s² (the calculator's 32.174 ft/s²).
inline constexpr double kGravityMps2 = 9.80665;
/// Metres per second in one mph (exact).
inline constexpr double kMpsPerMph = 0.44704;
/// Metres per foot (exact).
inline constexpr double kMetresPerFoot = 0.3048;

/// Flies `launch` through `environment` with `aero`: the landing found as an event on the
/// integrator's dense output (z = 0 going down), the apex as the event vz = 0. Validates
/// every input first (kInvalidInput with the refusal; fields prefixed "launch.",
/// "environment.", "aero.", "options."). With `trajectory` non-null, it is cleared and filled
/// with samples every options.trajectory_interval_s and the landing point.
FlightResult Fly(const Launch& launch, const Environment& environment = {},
                 const AeroOptions& aero = {}, const FlightOptions& options = {},
                 std::vector<TrajectoryPoint>* trajectory = nullptr);

/// How many flights FlyMany flies side by side (the stepper's lanes).
inline constexpr int kFlyManyLanes = 8;

/// Flies `count` launches, results[i] = Fly(launches[i], environments[shared_environment ? 0 :
/// i], aero, options) to the bit (no trajectories), several side by side: one flight's stages
/// wait on each other's square root and division, the lanes' do not, so a batch costs less
/// per flight than single flights (docs/flight.md, "Where a flight's time goes"). `results`
/// holds `count` elements; no allocation beyond a refusal's message; re-entrant.
void FlyMany(std::size_t count, const Launch* launches, const Environment* environments,
             bool shared_environment, const AeroOptions& aero, const FlightOptions& options,
             FlightResult* results);

}  // namespace sweetspot::core::flight
