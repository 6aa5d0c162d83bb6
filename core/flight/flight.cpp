// Batted-ball flight (core/flight/flight.hpp): the equations of Nathan's calculator in SI,
// integrated by a hand-written Dormand–Prince 5(4) with its 4th-order dense output, the landing
// and the apex found as events on that output. No allocation unless a trajectory is asked for.
// One stepper flies one flight (Fly) or several side by side (FlyMany): docs/flight.md, "Where a
// flight's time goes".
#include "core/flight/flight.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <type_traits>
#include <vector>

#include "core/flight/flight_soa.hpp"
#include "core/flight/flight_stepper.hpp"
#include "core/numerics/limits.hpp"
#include "core/units.hpp"

namespace sweetspot::core::flight {
namespace {

// The stepper's names (flight_stepper.hpp, flight_soa.hpp), as this file's own.
using namespace stepper;  // NOLINT(build/namespaces): internal to core/flight

bool PrefixOnFailure(Refusal* why, const char* prefix, bool ok) {
  if (!ok && why != nullptr) *why = core::Prefixed(prefix, std::move(*why));
  return ok;
}

// sin a and cos a, without libm's call at a = ±0 (no spray, a wind out to centre field): the
// same numbers (sin ±0 = ±0, cos ±0 = 1).
void SinCos(double a, double* sin_a, double* cos_a) {
  if (a == 0.0) {
    *sin_a = a;
    *cos_a = 1.0;
  } else {
    *sin_a = std::sin(a);
    *cos_a = std::cos(a);
  }
}

// The model and the initial state of a flight (Fly's documented inputs), its spin, labels and
// air density written to `r`; false (with `r` final) when an input is refused.
// `checked`: the environment, aero and options are known valid (FlyMany checks shared ones
// once), and `density` (when not null) is the environment's air density.
bool Prepare(const Launch& launch, const Environment& environment, const AeroOptions& aero,
             const FlightOptions& options, FlightResult* r, Model* model, double y0[6],
             bool checked = false, const double* density = nullptr) {
  {
    Refusal why;
    Refusal* out = &why;
    if (!PrefixOnFailure(out, "launch.", launch.Validate(out)) ||
        (!checked && (!PrefixOnFailure(out, "environment.", environment.Validate(out)) ||
                      !PrefixOnFailure(out, "aero.", aero.Validate(out)) ||
                      !PrefixOnFailure(out, "options.", options.Validate(out))))) {
      r->termination = FlightTermination::kInvalidInput;
      r->refusal = std::move(why);
      return false;
    }
  }

  // The spin and its axis (the calculator's cells D10-D12, gyrospin 0).
  if (launch.backspin_rpm) {
    r->spin = {*launch.backspin_rpm, *launch.sidespin_rpm};
    r->spin_source = SpinSource::kGiven;
  } else {
    r->spin = EstimateSpin(launch.launch_angle_deg, launch.spray_angle_deg, launch.batter_hand);
    r->spin_source = SpinSource::kStatcastRelation;
  }
  r->classification = Classify(launch.exit_speed_mps, launch.launch_angle_deg);
  r->air_density_kg_m3 = aero.model == AeroModel::kVacuum ? 0.0
                         : density != nullptr             ? *density
                                                          : AirDensityKgM3(environment);

  const double th = launch.launch_angle_deg * kDegToRad, ph = launch.spray_angle_deg * kDegToRad;
  double sth, cth, sph, cph;
  SinCos(th, &sth, &cth);
  SinCos(ph, &sph, &cph);
  Model& m = *model;
  m = Model();
  const double wb = r->spin.backspin_rpm, ws = r->spin.sidespin_rpm;
  const double wx = (wb * cph - ws * sth * sph) * kRpmToRadS;
  const double wy = (-wb * sph - ws * sth * cph) * kRpmToRadS;
  const double wz = ws * cth * kRpmToRadS;
  m.omega_rad_s = std::sqrt(wx * wx + wy * wy + wz * wz);
  if (m.omega_rad_s > 0.0) {
    m.ux = wx / m.omega_rad_s;
    m.uy = wy / m.omega_rad_s;
    m.uz = wz / m.omega_rad_s;
  }
  m.spin_krpm = std::sqrt(wb * wb + ws * ws) / 1000.0;
  m.radius_m = aero.ball_circumference_m / (2.0 * kPi);
  const double area_m2 = kPi * m.radius_m * m.radius_m;
  const double rho = r->air_density_kg_m3;
  switch (aero.model) {
    case AeroModel::kNathan2016:
      m.k_per_m = kNathanC0PerDensity * rho * (kNathanMassKg / aero.ball_mass_kg) *
                  ((aero.ball_circumference_m / kNathanCircumferenceM) *
                   (aero.ball_circumference_m / kNathanCircumferenceM));
      m.cd0 = 0.3008;
      m.cd_spin = 0.0292;
      m.cl0 = 0.583;
      m.cl1 = 2.333;
      m.cl2 = 1.120;
      break;
    case AeroModel::kCustom:
      m.k_per_m = 0.5 * rho * area_m2 / aero.ball_mass_kg;
      m.cd0 = aero.cd0;
      m.cd_spin = aero.cd_spin_per_krpm;
      m.cl0 = aero.cl0;
      m.cl1 = aero.cl1;
      m.cl2 = aero.cl2;
      m.cl_slope = aero.cl_per_spin_factor;
      break;
    case AeroModel::kSawicki2003:
      m.k_per_m = 0.5 * rho * area_m2 / aero.ball_mass_kg;
      break;
    case AeroModel::kVacuum:
      break;
  }
  m.decay_rate_per_m = 1.0 / (aero.spin_decay_s * kDecayReferenceSpeedMps);
  m.Prepare();
  const double wind_dir = environment.wind.direction_deg * kDegToRad;
  double swind, cwind;
  SinCos(wind_dir, &swind, &cwind);
  m.wind_x = environment.wind.speed_mps * swind;
  m.wind_y = environment.wind.speed_mps * cwind;

  const double v0 = launch.exit_speed_mps;
  const double start[6] = {launch.start_x_m, launch.start_y_m, launch.height_m,
                           v0 * cth * sph,   v0 * cth * cph,   v0 * sth};
  std::copy(start, start + 6, y0);
  return true;
}

// The first step (s): about a tenth of a flight's time scale (0.5 s at the default tolerance),
// refined by the controller (Start).
double FirstStep(const FlightOptions& options) {
  return std::min(0.5, std::pow(options.relative_tolerance, 0.2) * 5.0);
}

// Puts a flight on `lane` (false, with `r` final, when an input is refused).
template <Kind K>
bool Start(const Launch& launch, const Environment& environment, const AeroOptions& aero,
           const FlightOptions& options, FlightResult* r, std::vector<TrajectoryPoint>* trajectory,
           Lane<K>* lane, double first_step_s, bool checked = false,
           const double* density = nullptr, bool first_stage = true) {
  Lane<K>& a = *lane;
  double y0[6];
  if (!Prepare(launch, environment, aero, options, r, &a.m, y0, checked, density)) return false;
  a.r = r;
  a.trajectory = trajectory;
  std::copy(y0, y0 + 6, a.y);
  if constexpr (Lane<K>::N > 6) a.y[kDecayComponent] = 1.0;  // D(0) = exp(0)
  a.t = 0.0;
  r->apex_m = a.y[2];
  r->apex_time_s = 0.0;
  // The first step: about a tenth of a flight's time scale (0.5 s at the default tolerance),
  // refined by the controller. 0.05 s (the earlier choice) let the controller spend two or
  // three steps growing it (errors of 5e-7 and 8e-3 of the tolerance in the first two steps
  // of a 400 ft fly ball): 0.5 s takes 6 steps (37 evaluations) instead of 8 (49), and the
  // grid's worst errors are lower (docs/flight.md, "Where a flight's time goes").
  a.h = first_step_s;  // FirstStep(options), computed once per Fly or FlyMany
  // f(0, y0), the first attempt's first stage (FlyMany's vector kernel evaluates it itself).
  if (first_stage) Evaluate<K>(a, 0, 0.0, a.y);
  r->evaluations = 1;
  a.error_sum = a.velocity_error_sum = a.velocity_error_time_sum = 0.0;
  a.log_previous_error_ratio = kLogMinErrorMemory;
  a.next_sample = 1;
  if (trajectory != nullptr) {
    trajectory->push_back(Sample(0.0, {a.y[0], a.y[1], a.y[2], a.y[3], a.y[4], a.y[5]}));
  }
  return true;
}

// Flies flights 0 … count − 1 on L lanes: `start(i, lane)` puts flight i on a lane (false when
// its input was refused: its answer is then final). A lane whose flight ends takes the next
// flight, so the lanes stay busy until the last flights; each flight's arithmetic is the same
// on any number of lanes (the same answers to the bit as Fly).
template <Kind K, int L, class StartFlight>
void FlyLanes(std::size_t count, const FlightOptions& options, const StartFlight& start) {
  Lane<K> lanes[L];
  std::size_t next = 0;
  auto refill = [&](Lane<K>& lane) {
    lane.r = nullptr;
    while (next < count) {
      if (start(next++, &lane)) return;
    }
  };
  for (Lane<K>& lane : lanes) refill(lane);
  while (true) {
    int active = 0;
    for (Lane<K>& lane : lanes) {
      while (lane.r != nullptr && AtLimit(lane, options)) refill(lane);
      active += lane.r != nullptr ? 1 : 0;
    }
    if (active == 0) return;
    Attempt<K, L>(lanes);
    for (Lane<K>& lane : lanes) {
      if (lane.r != nullptr && Finish(lane, options)) refill(lane);
    }
  }
}

Kind KindOf(const AeroOptions& aero) {
  switch (aero.model) {
    case AeroModel::kVacuum:
      return Kind::kVacuum;
    case AeroModel::kSawicki2003:
      return Kind::kSawicki;
    case AeroModel::kCustom:
      return aero.lift_law == LiftLaw::kLinear ? Kind::kLinear : Kind::kSaturating;
    case AeroModel::kNathan2016:
      break;
  }
  return Kind::kSaturating;
}

// Calls f(std::integral_constant<Kind, kind>()): the stepper compiled for each kind.
template <class F>
void WithKind(Kind kind, const F& f) {
  switch (kind) {
    case Kind::kVacuum:
      f(std::integral_constant<Kind, Kind::kVacuum>());
      return;
    case Kind::kSawicki:
      f(std::integral_constant<Kind, Kind::kSawicki>());
      return;
    case Kind::kSaturating:
      f(std::integral_constant<Kind, Kind::kSaturating>());
      return;
    case Kind::kLinear:
      f(std::integral_constant<Kind, Kind::kLinear>());
      return;
  }
}

}  // namespace

const char* BatterHandName(BatterHand hand) { return hand == BatterHand::kLeft ? "left" : "right"; }

const char* AeroModelName(AeroModel model) {
  switch (model) {
    case AeroModel::kNathan2016:
      return "nathan-2016";
    case AeroModel::kSawicki2003:
      return "sawicki-2003";
    case AeroModel::kVacuum:
      return "vacuum";
    case AeroModel::kCustom:
      return "custom";
  }
  return "nathan-2016";
}

const char* LiftLawName(LiftLaw law) { return law == LiftLaw::kLinear ? "linear" : "saturating"; }

const char* SpinSourceName(SpinSource source) {
  return source == SpinSource::kStatcastRelation ? "statcast_relation" : "given";
}

const char* FlightTerminationName(FlightTermination termination) {
  switch (termination) {
    case FlightTermination::kLanded:
      return "landed";
    case FlightTermination::kTimeLimit:
      return "time_limit";
    case FlightTermination::kStepLimit:
      return "step_limit";
    case FlightTermination::kNonFinite:
      return "non_finite";
    case FlightTermination::kInvalidInput:
      return "invalid_input";
  }
  return "invalid_input";
}

namespace {

// CheckInRange with its test inline: the checks run for every flight (FlyMany: every launch),
// and a call per field was 7 % of a flight's instructions (callgrind). The refusal's text, on
// a failure, is CheckInRange's.
inline bool InRange(Refusal* why, std::string_view field, double value, double lo, double hi,
                    bool lo_open = false) {
  if (std::isfinite(value) && (lo_open ? value > lo : value >= lo) && value <= hi) return true;
  return core::CheckInRange(why, field, value, lo, hi, lo_open);
}

}  // namespace

bool Launch::Validate(Refusal* why) const {
  if (!InRange(why, "exit_speed_mps", exit_speed_mps, 0.0, 90.0, /*lo_open=*/true)) {
    return false;
  }
  if (!InRange(why, "launch_angle_deg", launch_angle_deg, -90.0, 90.0)) return false;
  if (!InRange(why, "spray_angle_deg", spray_angle_deg, -90.0, 90.0)) return false;
  if (backspin_rpm.has_value() != sidespin_rpm.has_value()) {
    return Refuse(why, TextRefusal(backspin_rpm ? "sidespin_rpm" : "backspin_rpm",
                                   "give both spins or neither (neither: estimated from the "
                                   "launch angle)"));
  }
  if (backspin_rpm && !InRange(why, "backspin_rpm", *backspin_rpm, -10000.0, 10000.0)) {
    return false;
  }
  if (sidespin_rpm && !InRange(why, "sidespin_rpm", *sidespin_rpm, -10000.0, 10000.0)) {
    return false;
  }
  if (!InRange(why, "height_m", height_m, 0.0, 5.0)) return false;
  if (!InRange(why, "start_x_m", start_x_m, -5.0, 5.0)) return false;
  return InRange(why, "start_y_m", start_y_m, -5.0, 5.0);
}

bool Environment::Validate(Refusal* why) const {
  return InRange(why, "temperature_c", temperature_c, -40.0, 60.0) &&
         InRange(why, "elevation_m", elevation_m, -500.0, 5000.0) &&
         InRange(why, "relative_humidity_pct", relative_humidity_pct, 0.0, 100.0) &&
         InRange(why, "sea_level_pressure_pa", sea_level_pressure_pa, 80000.0, 110000.0) &&
         InRange(why, "wind.speed_mps", wind.speed_mps, 0.0, 50.0) &&
         InRange(why, "wind.direction_deg", wind.direction_deg, -360.0, 360.0);
}

bool AeroOptions::Validate(Refusal* why) const {
  return InRange(why, "cd0", cd0, 0.0, 2.0) &&
         InRange(why, "cd_spin_per_krpm", cd_spin_per_krpm, 0.0, 1.0) &&
         InRange(why, "cl2", cl2, 0.0, 10.0) &&
         InRange(why, "cl0", cl0, 0.0, 10.0, /*lo_open=*/true) &&
         InRange(why, "cl1", cl1, 0.0, 10.0) &&
         InRange(why, "cl_per_spin_factor", cl_per_spin_factor, 0.0, 10.0) &&
         InRange(why, "spin_decay_s", spin_decay_s, 0.1, 1e6) &&
         InRange(why, "ball_mass_kg", ball_mass_kg, 0.1, 0.2) &&
         InRange(why, "ball_circumference_m", ball_circumference_m, 0.2, 0.26);
}

bool FlightOptions::Validate(Refusal* why) const {
  return InRange(why, "relative_tolerance", relative_tolerance, 1e-13, 1e-2) &&
         InRange(why, "absolute_tolerance_m", absolute_tolerance_m, 1e-12, 1.0) &&
         InRange(why, "max_flight_time_s", max_flight_time_s, 0.0, 600.0, true) &&
         CheckIntegerInRange(why, "max_steps", max_steps, 10, 1000000) &&
         InRange(why, "trajectory_interval_s", trajectory_interval_s, 1e-3, 10.0);
}

FlightResult VacuumFlight(const Launch& launch) {
  FlightResult r;
  const double v = launch.exit_speed_mps;
  const double th = launch.launch_angle_deg * kDegToRad, ph = launch.spray_angle_deg * kDegToRad;
  const double vz = v * std::sin(th), vh = v * std::cos(th);
  const double h = launch.height_m;
  r.termination = FlightTermination::kLanded;
  r.hang_time_s = (vz + std::sqrt(vz * vz + 2.0 * kGravityMps2 * h)) / kGravityMps2;
  r.apex_time_s = std::max(0.0, vz / kGravityMps2);
  r.apex_m = vz > 0.0 ? h + vz * vz / (2.0 * kGravityMps2) : h;
  r.landing_x_m = launch.start_x_m + vh * std::sin(ph) * r.hang_time_s;
  r.landing_y_m = launch.start_y_m + vh * std::cos(ph) * r.hang_time_s;
  r.distance_m = std::hypot(r.landing_x_m, r.landing_y_m);
  r.bearing_deg = std::atan2(r.landing_x_m, r.landing_y_m) / kDegToRad;
  const double vz_land = vz - kGravityMps2 * r.hang_time_s;
  r.landing_speed_mps = std::hypot(vh, vz_land);
  r.landing_angle_deg = std::atan2(-vz_land, vh) / kDegToRad;
  r.classification = Classify(v, launch.launch_angle_deg);
  return r;
}

FlightResult Fly(const Launch& launch, const Environment& environment, const AeroOptions& aero,
                 const FlightOptions& options, std::vector<TrajectoryPoint>* trajectory) {
  FlightResult r;
  if (trajectory != nullptr) trajectory->clear();
  WithKind(KindOf(aero), [&](auto kind) {
    constexpr Kind K = decltype(kind)::value;
    FlyLanes<K, 1>(1, options, [&](std::size_t, Lane<K>* lane) {
      return Start<K>(launch, environment, aero, options, &r, trajectory, lane,
                      FirstStep(options));
    });
  });
  return r;
}

void FlyMany(std::size_t count, const Launch* launches, const Environment* environments,
             bool shared_environment, const AeroOptions& aero, const FlightOptions& options,
             FlightResult* results) {
  // What all the flights share is checked once (and the shared air's density computed once);
  // when it is refused, each flight is checked in full, as Fly would (a launch's own refusal
  // comes first).
  const bool shared_valid = count > 0 && aero.Validate(nullptr) && options.Validate(nullptr) &&
                            (!shared_environment || environments[0].Validate(nullptr));
  double density = 0.0;
  if (shared_valid && shared_environment) density = AirDensityKgM3(environments[0]);
  const double first_step = FirstStep(options);
  WithKind(KindOf(aero), [&](auto kind) {
    constexpr Kind K = decltype(kind)::value;
    bool first_stage = true;  // false: the vector lanes evaluate it (FlyLanesSoa)
    auto start = [&](std::size_t i, Lane<K>* lane) {
      results[i] = FlightResult();
      const Environment& environment = environments[shared_environment ? 0 : i];
      bool checked = shared_valid;
      if (checked && !shared_environment) checked = environment.Validate(nullptr);
      return Start<K>(launches[i], environment, aero, options, &results[i], nullptr, lane,
                      first_step, checked, shared_valid && shared_environment ? &density : nullptr,
                      first_stage);
    };
    if constexpr (K == Kind::kSaturating || K == Kind::kLinear) {
      if (SoaLanesPay()) {
        first_stage = false;
        FlyLanesSoa<K>(count, options, start);
        return;
      }
    }
    FlyLanes<K, kFlyManyLanes>(count, options, start);
  });
}

}  // namespace sweetspot::core::flight
