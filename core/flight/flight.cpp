// Batted-ball flight (core/flight/flight.hpp): the equations of Nathan's calculator in SI,
// integrated by a hand-written Dormand–Prince 5(4) with its 4th-order dense output, the landing
// and the apex found as events on that output. No allocation unless a trajectory is asked for.
#include "core/flight/flight.hpp"

#include <algorithm>
#include <cmath>

#include "core/numerics/limits.hpp"
#include "core/units.hpp"

namespace sweetspot::core::flight {
namespace {

constexpr double kDegToRad = kPi / 180.0;
constexpr double kRpmToRadS = kPi / 30.0;
// The calculator's spin-decay reference speed: τ is quoted at 146.7 ft/s = 100 mph.
constexpr double kDecayReferenceSpeedMps = 100.0 * kMpsPerMph;

// The calculator's c0 = ½ρA/m per foot for the standard ball is 0.07182·ρ[lb/ft³] with
// ρ[lb/ft³] = 0.06261·ρ[kg/m³]; per metre that is 0.07182·0.06261/0.3048 per kg/m³. It is
// 0.3 % above ½ρA/m of the nominal ball (0.06261 is 0.3 % above the exact 0.062428 lb/ft³ per
// kg/m³); nathan-2016 keeps the sheet's constant so that its worked cases reproduce.
constexpr double kNathanC0PerDensity = 0.07182 * 0.06261 / kMetresPerFoot;
constexpr double kNathanMassKg = 5.125 * kKilogramsPerOunce;
constexpr double kNathanCircumferenceM = 9.125 * kMetresPerInch;

bool Finite(double v) { return std::isfinite(v); }

// The state: position (m) and velocity (m/s).
struct State {
  double x, y, z, vx, vy, vz;
};

State Axpy(const State& a, double h, const State& k) {
  return {a.x + h * k.x,   a.y + h * k.y,   a.z + h * k.z,
          a.vx + h * k.vx, a.vy + h * k.vy, a.vz + h * k.vz};
}

// Everything a right-hand side needs, computed once per flight.
struct Model {
  bool air = true;           // false: vacuum.
  double k_per_m = 0.0;      // ½ρA/m, 1/m.
  double radius_m = 0.0;     // ball radius, m.
  double omega_rad_s = 0.0;  // initial spin, rad/s.
  double ux = 0, uy = 0, uz = 0;  // spin axis (unit; ω/|ω|), fixed (the calculator's).
  double spin_krpm = 0.0;    // total spin / 1000 rpm (the spin drag term).
  double cd0 = 0.0, cd_spin = 0.0;
  bool decay = true;
  double decay_rate_per_m = 0.0;  // 1/(τ·44.704): exponent = −t·v_rel·rate.
  AeroModel model = AeroModel::kNathan2016;
  LiftLaw lift = LiftLaw::kSaturating;
  double cl0 = 0, cl1 = 0, cl2 = 0, cl_slope = 0;
  double wind_x = 0, wind_y = 0;  // wind velocity, m/s.
  // Products of the above, computed once per flight (Prepare) so that a right-hand side needs
  // one division: k·cd0, k·cd_spin·spin_krpm (1/m), Rω (m/s), k·cl2·Rω and k·slope·Rω (1/s),
  // cl1·Rω (m/s).
  double k_cd0 = 0, k_cd_spin = 0, spin_speed_mps = 0, k_cl2_spin = 0, k_slope_spin = 0,
         cl1_spin = 0;

  void Prepare() {
    k_cd0 = k_per_m * cd0;
    k_cd_spin = k_per_m * cd_spin * spin_krpm;
    spin_speed_mps = radius_m * omega_rad_s;
    k_cl2_spin = k_per_m * cl2 * spin_speed_mps;
    k_slope_spin = k_per_m * cl_slope * spin_speed_mps;
    cl1_spin = cl1 * spin_speed_mps;
  }
};

// Sawicki et al. (2003)'s drag coefficient against air speed, as this file approximates it: 0.5
// below the drag crisis, 0.2 above, a smooth (logistic) fall centred at 30 m/s with a 2 m/s
// scale (0.48 at 25 m/s, 0.22 at 35 m/s). Smooth so that the integrator's error estimate holds
// (a kink in the right-hand side defeats it). The shape is this file's reading of the paper's
// description of a baseball's crisis (about 55 to 80 mph), not values read from its figure:
// docs/flight.md and docs/validation.md say so.
double SawickiDrag(double v) {
  constexpr double kCdLow = 0.5, kCdHigh = 0.2, kCentreMps = 30.0, kScaleMps = 2.0;
  return kCdHigh + (kCdLow - kCdHigh) / (1.0 + std::exp((v - kCentreMps) / kScaleMps));
}

double SawickiLift(double s) { return s < 0.1 ? 1.5 * s : 0.09 + 0.6 * s; }

// Inlined into the stepper: called 6 times a step, it is most of a flight's time. Its cost is
// the latency of one chain (sqrt, exp, one division), so the constants are folded (Model::
// Prepare) and Nathan's lift k·CL·v with CL = cl2·S/(cl0 + cl1·S), S = Rω·decay/v, is written
// with one division: k·cl2·Rω·decay·v / (cl0·v + cl1·Rω·decay) (the same number to rounding).
[[gnu::always_inline]] inline State Derivative(const Model& m, double t, const State& s) {
  State d{s.vx, s.vy, s.vz, 0.0, 0.0, -kGravityMps2};
  if (!m.air) return d;
  const double rx = s.vx - m.wind_x, ry = s.vy - m.wind_y, rz = s.vz;
  const double v = std::sqrt(rx * rx + ry * ry + rz * rz);
  double drag = 0.0, lift = 0.0;  // drag: −k·CD·v; lift: k·CL·v (1/s)
  if (m.model == AeroModel::kSawicki2003) {
    const double spin_factor = v > 0.0 ? m.spin_speed_mps / v : 0.0;
    drag = -m.k_per_m * SawickiDrag(v) * v;
    lift = m.k_per_m * SawickiLift(spin_factor) * v;
  } else {
    const double decay = m.decay ? std::exp(-t * v * m.decay_rate_per_m) : 1.0;
    drag = -(m.k_cd0 + m.k_cd_spin * decay) * v;
    if (m.lift == LiftLaw::kLinear) {
      lift = m.k_slope_spin * decay;  // k·slope·S·v: v cancels
    } else if (v > 0.0) {
      lift = m.k_cl2_spin * decay * v / (m.cl0 * v + m.cl1_spin * decay);
    }
  }
  // Magnus: k·CL·v·(û × v_rel), û the (fixed) spin axis, as the calculator writes it.
  d.vx += drag * rx + lift * (m.uy * rz - m.uz * ry);
  d.vy += drag * ry + lift * (m.uz * rx - m.ux * rz);
  d.vz += drag * rz + lift * (m.ux * ry - m.uy * rx);
  return d;
}

// Dormand–Prince 5(4) tableau (Dormand & Prince 1980; Hairer, Nørsett & Wanner, Solving ODEs I,
// Table 5.2) and the dense output of Hairer's DOPRI5 (contd5).
constexpr double c2 = 1.0 / 5, c3 = 3.0 / 10, c4 = 4.0 / 5, c5 = 8.0 / 9;
constexpr double a21 = 1.0 / 5;
constexpr double a31 = 3.0 / 40, a32 = 9.0 / 40;
constexpr double a41 = 44.0 / 45, a42 = -56.0 / 15, a43 = 32.0 / 9;
constexpr double a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561,
                 a54 = -212.0 / 729;
constexpr double a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247, a64 = 49.0 / 176,
                 a65 = -5103.0 / 18656;
constexpr double a71 = 35.0 / 384, a73 = 500.0 / 1113, a74 = 125.0 / 192, a75 = -2187.0 / 6784,
                 a76 = 11.0 / 84;
constexpr double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920,
                 e5 = -17253.0 / 339200, e6 = 22.0 / 525, e7 = -1.0 / 40;
constexpr double d1 = -12715105075.0 / 11282082432.0, d3 = 87487479700.0 / 32700410799.0,
                 d4 = -10690763975.0 / 1880347072.0, d5 = 701980252875.0 / 199316789632.0,
                 d6 = -1453857185.0 / 822651844.0, d7 = 69997945.0 / 29380423.0;

// The dense output of one step: y(t0 + θh) = r1 + θ(r2 + (1−θ)(r3 + θ(r4 + (1−θ)r5))).
struct Dense {
  double r1[6], r2[6], r3[6], r4[6], r5[6];
  double Component(int i, double theta) const {
    const double u = 1.0 - theta;
    return r1[i] + theta * (r2[i] + u * (r3[i] + theta * (r4[i] + u * r5[i])));
  }
  State At(double theta) const {
    return {Component(0, theta), Component(1, theta), Component(2, theta),
            Component(3, theta), Component(4, theta), Component(5, theta)};
  }
};

const double* Array(const State& s) { return &s.x; }

// The step controller's floors, as logarithms: err is taken as at least 1e-10, and the memory
// of the last step's err as at least 1e-4 (Hairer's DOPRI5).
constexpr double kLogMinError = -23.025850929940457;       // ln 1e-10
constexpr double kLogMinErrorMemory = -9.210340371976182;  // ln 1e-4

// The θ in [0, 1] where component `i` of the dense output crosses zero, given its signs at
// the ends differ: Newton's method on the dense polynomial from the secant's guess (three or
// four iterations to 1e-13 in θ), and if it leaves [0, 1] or does not settle, an Illinois
// regula falsi to 1e-11 in θ (1e-10 m on a step of tens of metres).
double RootOf(const Dense& dense, int i, double f0, double f1) {
  double theta = f0 / (f0 - f1);
  for (int iter = 0; iter < 8; ++iter) {
    // y = r1 + θ·Q, Q = r2 + u·P, P = r3 + θ·(r4 + u·r5), u = 1 − θ; dy/dθ by the product rule.
    const double u = 1.0 - theta;
    const double inner = dense.r4[i] + u * dense.r5[i];
    const double p = dense.r3[i] + theta * inner;
    const double q = dense.r2[i] + u * p;
    const double dp = inner - theta * dense.r5[i];
    const double dq = -p + u * dp;
    const double f = dense.r1[i] + theta * q;
    const double df = q + theta * dq;
    if (f == 0.0) return theta;
    if (!(df != 0.0)) break;
    const double step = f / df;
    theta -= step;
    if (!(theta >= 0.0 && theta <= 1.0)) break;
    if (std::abs(step) < 1e-13) return theta;
  }
  double a = 0.0, b = 1.0, fa = f0, fb = f1;
  int side = 0;
  for (int iter = 0; iter < 60 && b - a > 1e-11; ++iter) {
    theta = (a * fb - b * fa) / (fb - fa);
    const double f = dense.Component(i, theta);
    if (f == 0.0) return theta;
    if ((f > 0.0) == (fa > 0.0)) {
      a = theta;
      fa = f;
      if (side == -1) fb *= 0.5;
      side = -1;
    } else {
      b = theta;
      fb = f;
      if (side == 1) fa *= 0.5;
      side = 1;
    }
  }
  return (a * fb - b * fa) / (fb - fa);
}

double GroundSpeed(const State& s) { return std::sqrt(s.vx * s.vx + s.vy * s.vy + s.vz * s.vz); }

TrajectoryPoint Sample(double t, const State& s) {
  return {t, s.x, s.y, s.z, GroundSpeed(s)};
}

bool PrefixOnFailure(Refusal* why, const char* prefix, bool ok) {
  if (!ok && why != nullptr) *why = core::Prefixed(prefix, std::move(*why));
  return ok;
}

}  // namespace

const char* BatterHandName(BatterHand hand) {
  return hand == BatterHand::kLeft ? "left" : "right";
}

const char* AeroModelName(AeroModel model) {
  switch (model) {
    case AeroModel::kNathan2016: return "nathan-2016";
    case AeroModel::kSawicki2003: return "sawicki-2003";
    case AeroModel::kVacuum: return "vacuum";
    case AeroModel::kCustom: return "custom";
  }
  return "nathan-2016";
}

const char* LiftLawName(LiftLaw law) {
  return law == LiftLaw::kLinear ? "linear" : "saturating";
}

const char* SpinSourceName(SpinSource source) {
  return source == SpinSource::kStatcastRelation ? "statcast_relation" : "given";
}

const char* FlightTerminationName(FlightTermination termination) {
  switch (termination) {
    case FlightTermination::kLanded: return "landed";
    case FlightTermination::kTimeLimit: return "time_limit";
    case FlightTermination::kStepLimit: return "step_limit";
    case FlightTermination::kNonFinite: return "non_finite";
    case FlightTermination::kInvalidInput: return "invalid_input";
  }
  return "invalid_input";
}

bool Launch::Validate(Refusal* why) const {
  if (!CheckInRange(why, "exit_speed_mps", exit_speed_mps, 0.0, 90.0, /*lo_open=*/true)) {
    return false;
  }
  if (!CheckInRange(why, "launch_angle_deg", launch_angle_deg, -90.0, 90.0)) return false;
  if (!CheckInRange(why, "spray_angle_deg", spray_angle_deg, -90.0, 90.0)) return false;
  if (backspin_rpm.has_value() != sidespin_rpm.has_value()) {
    return Refuse(why, TextRefusal(backspin_rpm ? "sidespin_rpm" : "backspin_rpm",
                                   "give both spins or neither (neither: estimated from the "
                                   "launch angle)"));
  }
  if (backspin_rpm && !CheckInRange(why, "backspin_rpm", *backspin_rpm, -10000.0, 10000.0)) {
    return false;
  }
  if (sidespin_rpm && !CheckInRange(why, "sidespin_rpm", *sidespin_rpm, -10000.0, 10000.0)) {
    return false;
  }
  if (!CheckInRange(why, "height_m", height_m, 0.0, 5.0)) return false;
  if (!CheckInRange(why, "start_x_m", start_x_m, -5.0, 5.0)) return false;
  return CheckInRange(why, "start_y_m", start_y_m, -5.0, 5.0);
}

bool Environment::Validate(Refusal* why) const {
  return CheckInRange(why, "temperature_c", temperature_c, -40.0, 60.0) &&
         CheckInRange(why, "elevation_m", elevation_m, -500.0, 5000.0) &&
         CheckInRange(why, "relative_humidity_pct", relative_humidity_pct, 0.0, 100.0) &&
         CheckInRange(why, "sea_level_pressure_pa", sea_level_pressure_pa, 80000.0, 110000.0) &&
         CheckInRange(why, "wind.speed_mps", wind.speed_mps, 0.0, 50.0) &&
         CheckInRange(why, "wind.direction_deg", wind.direction_deg, -360.0, 360.0);
}

bool AeroOptions::Validate(Refusal* why) const {
  return CheckInRange(why, "cd0", cd0, 0.0, 2.0) &&
         CheckInRange(why, "cd_spin_per_krpm", cd_spin_per_krpm, 0.0, 1.0) &&
         CheckInRange(why, "cl2", cl2, 0.0, 10.0) &&
         CheckInRange(why, "cl0", cl0, 0.0, 10.0, /*lo_open=*/true) &&
         CheckInRange(why, "cl1", cl1, 0.0, 10.0) &&
         CheckInRange(why, "cl_per_spin_factor", cl_per_spin_factor, 0.0, 10.0) &&
         CheckInRange(why, "spin_decay_s", spin_decay_s, 0.1, 1e6) &&
         CheckInRange(why, "ball_mass_kg", ball_mass_kg, 0.1, 0.2) &&
         CheckInRange(why, "ball_circumference_m", ball_circumference_m, 0.2, 0.26);
}

bool FlightOptions::Validate(Refusal* why) const {
  return CheckInRange(why, "relative_tolerance", relative_tolerance, 1e-13, 1e-2) &&
         CheckInRange(why, "absolute_tolerance_m", absolute_tolerance_m, 1e-12, 1.0) &&
         CheckInRange(why, "max_flight_time_s", max_flight_time_s, 0.0, 600.0, true) &&
         CheckIntegerInRange(why, "max_steps", max_steps, 10, 1000000) &&
         CheckInRange(why, "trajectory_interval_s", trajectory_interval_s, 1e-3, 10.0);
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
  {
    Refusal why;
    Refusal* out = &why;
    if (!PrefixOnFailure(out, "launch.", launch.Validate(out)) ||
        !PrefixOnFailure(out, "environment.", environment.Validate(out)) ||
        !PrefixOnFailure(out, "aero.", aero.Validate(out)) ||
        !PrefixOnFailure(out, "options.", options.Validate(out))) {
      r.termination = FlightTermination::kInvalidInput;
      r.refusal = std::move(why);
      return r;
    }
  }

  // The spin and its axis (the calculator's cells D10-D12, gyrospin 0).
  if (launch.backspin_rpm) {
    r.spin = {*launch.backspin_rpm, *launch.sidespin_rpm};
    r.spin_source = SpinSource::kGiven;
  } else {
    r.spin = EstimateSpin(launch.launch_angle_deg, launch.spray_angle_deg, launch.batter_hand);
    r.spin_source = SpinSource::kStatcastRelation;
  }
  r.classification = Classify(launch.exit_speed_mps, launch.launch_angle_deg);
  r.air_density_kg_m3 = aero.model == AeroModel::kVacuum ? 0.0 : AirDensityKgM3(environment);

  const double th = launch.launch_angle_deg * kDegToRad, ph = launch.spray_angle_deg * kDegToRad;
  const double sth = std::sin(th), cth = std::cos(th), sph = std::sin(ph), cph = std::cos(ph);
  Model m;
  m.air = aero.model != AeroModel::kVacuum;
  m.model = aero.model;
  const double wb = r.spin.backspin_rpm, ws = r.spin.sidespin_rpm;
  const double wx = (wb * cph - ws * sth * sph) * kRpmToRadS;
  const double wy = (-wb * sph - ws * sth * cph) * kRpmToRadS;
  const double wz = ws * cth * kRpmToRadS;
  m.omega_rad_s = std::sqrt(wx * wx + wy * wy + wz * wz);
  if (m.omega_rad_s > 0.0) {
    m.ux = wx / m.omega_rad_s;
    m.uy = wy / m.omega_rad_s;
    m.uz = wz / m.omega_rad_s;
  }
  m.spin_krpm = std::hypot(wb, ws) / 1000.0;
  m.radius_m = aero.ball_circumference_m / (2.0 * kPi);
  const double area_m2 = kPi * m.radius_m * m.radius_m;
  const double rho = r.air_density_kg_m3;
  switch (aero.model) {
    case AeroModel::kNathan2016:
      m.k_per_m = kNathanC0PerDensity * rho * (kNathanMassKg / aero.ball_mass_kg) *
                  std::pow(aero.ball_circumference_m / kNathanCircumferenceM, 2);
      m.cd0 = 0.3008;
      m.cd_spin = 0.0292;
      m.lift = LiftLaw::kSaturating;
      m.cl0 = 0.583;
      m.cl1 = 2.333;
      m.cl2 = 1.120;
      m.decay = true;
      break;
    case AeroModel::kCustom:
      m.k_per_m = 0.5 * rho * area_m2 / aero.ball_mass_kg;
      m.cd0 = aero.cd0;
      m.cd_spin = aero.cd_spin_per_krpm;
      m.lift = aero.lift_law;
      m.cl0 = aero.cl0;
      m.cl1 = aero.cl1;
      m.cl2 = aero.cl2;
      m.cl_slope = aero.cl_per_spin_factor;
      m.decay = true;
      break;
    case AeroModel::kSawicki2003:
      m.k_per_m = 0.5 * rho * area_m2 / aero.ball_mass_kg;
      m.decay = false;
      break;
    case AeroModel::kVacuum:
      m.decay = false;
      break;
  }
  m.decay_rate_per_m = 1.0 / (aero.spin_decay_s * kDecayReferenceSpeedMps);
  m.Prepare();
  const double wind_dir = environment.wind.direction_deg * kDegToRad;
  m.wind_x = environment.wind.speed_mps * std::sin(wind_dir);
  m.wind_y = environment.wind.speed_mps * std::cos(wind_dir);

  const double v0 = launch.exit_speed_mps;
  State y{launch.start_x_m, launch.start_y_m, launch.height_m,
          v0 * cth * sph,   v0 * cth * cph,   v0 * sth};
  double t = 0.0;
  r.apex_m = y.z;
  r.apex_time_s = 0.0;

  const double rtol = options.relative_tolerance, atol = options.absolute_tolerance_m;
  // The first step: about 1/100 of a flight's scale, refined by the controller.
  double h = std::min(0.05, std::pow(rtol, 0.2) * 0.5);
  State k1 = Derivative(m, t, y);
  r.evaluations = 1;
  long long next_sample = 1;  // the next sample is at next_sample · trajectory_interval_s
  if (trajectory != nullptr) trajectory->push_back(Sample(0.0, y));
  // The error estimate: the local position errors, plus each step's local velocity error
  // carried to the landing (δv · (T − t_i), T the hang time): Σ|δx_i| + T·Σ|δv_i| − Σ|δv_i|·t_i.
  double error_sum = 0.0, velocity_error_sum = 0.0, velocity_error_time_sum = 0.0;
  // PI controller memory (Hairer's DOPRI5 "facold", 1e-4 at first), kept as its logarithm: the
  // controller's err^0.17 · facold^−0.04 is one exp of logarithms (two pow calls cost more).
  double log_previous_error_ratio = std::log(1e-4);

  while (true) {
    // Rejected steps count too: a step size shrinking forever must end as well.
    const bool step_limit = r.steps + r.rejected_steps >= options.max_steps;
    if (step_limit || t >= options.max_flight_time_s) {
      r.termination = step_limit ? FlightTermination::kStepLimit : FlightTermination::kTimeLimit;
      r.error_estimate_m =  // of the flight so far
          error_sum + t * velocity_error_sum - velocity_error_time_sum;
      return r;
    }
    h = std::min(h, options.max_flight_time_s - t);
    const State k2 = Derivative(m, t + c2 * h, Axpy(y, h * a21, k1));
    State s3 = y;
    {
      const double* a = Array(y);
      const double* p1 = Array(k1);
      const double* p2 = Array(k2);
      double* o = &s3.x;
      for (int i = 0; i < 6; ++i) o[i] = a[i] + h * (a31 * p1[i] + a32 * p2[i]);
    }
    const State k3 = Derivative(m, t + c3 * h, s3);
    State s4 = y, s5 = y, s6 = y, y_new = y;
    const double* a = Array(y);
    const double* p1 = Array(k1);
    const double* p2 = Array(k2);
    const double* p3 = Array(k3);
    for (int i = 0; i < 6; ++i) (&s4.x)[i] = a[i] + h * (a41 * p1[i] + a42 * p2[i] + a43 * p3[i]);
    const State k4 = Derivative(m, t + c4 * h, s4);
    const double* p4 = Array(k4);
    for (int i = 0; i < 6; ++i) {
      (&s5.x)[i] = a[i] + h * (a51 * p1[i] + a52 * p2[i] + a53 * p3[i] + a54 * p4[i]);
    }
    const State k5 = Derivative(m, t + c5 * h, s5);
    const double* p5 = Array(k5);
    for (int i = 0; i < 6; ++i) {
      (&s6.x)[i] =
          a[i] + h * (a61 * p1[i] + a62 * p2[i] + a63 * p3[i] + a64 * p4[i] + a65 * p5[i]);
    }
    const State k6 = Derivative(m, t + h, s6);
    const double* p6 = Array(k6);
    for (int i = 0; i < 6; ++i) {
      (&y_new.x)[i] =
          a[i] + h * (a71 * p1[i] + a73 * p3[i] + a74 * p4[i] + a75 * p5[i] + a76 * p6[i]);
    }
    const State k7 = Derivative(m, t + h, y_new);
    const double* p7 = Array(k7);
    r.evaluations += 6;

    // The local error (5th − 4th order), scaled per component; position's error kept in m.
    double err2 = 0.0, position_err2 = 0.0, velocity_err2 = 0.0;
    bool finite = true;
    for (int i = 0; i < 6; ++i) {
      const double e = h * (e1 * p1[i] + e3 * p3[i] + e4 * p4[i] + e5 * p5[i] + e6 * p6[i] +
                            e7 * p7[i]);
      const double yn = (&y_new.x)[i];
      finite = finite && Finite(yn) && Finite(e);
      const double scale = atol + rtol * std::max(std::abs(a[i]), std::abs(yn));
      err2 += (e / scale) * (e / scale);
      (i < 3 ? position_err2 : velocity_err2) += e * e;
    }
    if (!finite) {
      if (h > 1e-9) {  // a too-long step can overflow: retry shorter before giving up
        h *= 0.1;
        ++r.rejected_steps;
        continue;
      }
      r.termination = FlightTermination::kNonFinite;
      return r;
    }
    const double err = std::sqrt(err2 / 6.0);
    const double log_err = std::log(err);  // −inf for a zero error: the clamps below hold
    if (err > 1.0) {
      h *= std::max(0.2, 0.9 * std::exp(-0.2 * log_err));
      ++r.rejected_steps;
      continue;
    }

    // Accepted: the dense output of [t, t + h].
    ++r.steps;
    error_sum += std::sqrt(position_err2);
    const double velocity_error = std::sqrt(velocity_err2);
    velocity_error_sum += velocity_error;
    velocity_error_time_sum += velocity_error * (t + h);
    Dense dense;
    for (int i = 0; i < 6; ++i) {
      const double diff = (&y_new.x)[i] - a[i];
      const double bspl = h * p1[i] - diff;
      dense.r1[i] = a[i];
      dense.r2[i] = diff;
      dense.r3[i] = bspl;
      dense.r4[i] = diff - h * p7[i] - bspl;
      dense.r5[i] = h * (d1 * p1[i] + d3 * p3[i] + d4 * p4[i] + d5 * p5[i] + d6 * p6[i] +
                         d7 * p7[i]);
    }
    // The apex: vz crosses zero going down.
    if (y.vz > 0.0 && y_new.vz <= 0.0) {
      const double theta = RootOf(dense, 5, y.vz, y_new.vz);
      const double z = dense.Component(2, theta);
      if (z > r.apex_m) {
        r.apex_m = z;
        r.apex_time_s = t + theta * h;
      }
    }
    const bool lands = y_new.z <= 0.0 && y_new.vz < 0.0;
    const double theta_land = lands ? RootOf(dense, 2, y.z, y_new.z) : 1.0;
    const double t_end = t + theta_land * h;
    if (trajectory != nullptr) {
      for (double ts = next_sample * options.trajectory_interval_s; ts < t_end;
           ts = ++next_sample * options.trajectory_interval_s) {
        trajectory->push_back(Sample(ts, dense.At((ts - t) / h)));
      }
    }
    if (lands) {
      State landed = dense.At(theta_land);
      landed.z = 0.0;
      if (trajectory != nullptr) trajectory->push_back(Sample(t_end, landed));
      r.termination = FlightTermination::kLanded;
      r.hang_time_s = t_end;
      r.landing_x_m = landed.x;
      r.landing_y_m = landed.y;
      r.distance_m = std::hypot(landed.x, landed.y);
      r.bearing_deg = std::atan2(landed.x, landed.y) / kDegToRad;
      r.landing_speed_mps = GroundSpeed(landed);
      r.landing_angle_deg =
          std::atan2(-landed.vz, std::hypot(landed.vx, landed.vy)) / kDegToRad;
      // The landing is read from the step's 4th-order interpolant: its error is estimated by
      // the cubic Hermite interpolant's difference from it at the landing, moved onto the
      // ground along the path (a height error dz shifts the landing by v_h·dz/v_z).
      const double u = theta_land, u2 = u * u, u3 = u2 * u;
      const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u;
      const double h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
      double d[3];
      for (int i = 0; i < 3; ++i) {
        const double cubic = h00 * a[i] + h10 * h * p1[i] + h01 * (&y_new.x)[i] + h11 * h * p7[i];
        d[i] = cubic - dense.Component(i, u);
      }
      const double shift = landed.vz < 0.0 ? d[2] / landed.vz : 0.0;
      const double interpolation_error =
          std::hypot(d[0] - landed.vx * shift, d[1] - landed.vy * shift);
      r.error_estimate_m = error_sum + t_end * velocity_error_sum - velocity_error_time_sum +
                           interpolation_error;
      return r;
    }
    y = y_new;
    k1 = k7;  // first same as last
    t += h;
    // Step-size control (Hairer's DOPRI5: PI control with β = 0.04).
    // fac = max(err, 1e-10)^0.17 · facold^−0.04, facold = max(err, 1e-4) of the last step.
    const double fac = std::exp((0.2 - 0.04 * 0.75) * std::max(log_err, kLogMinError) -
                                0.04 * log_previous_error_ratio);
    log_previous_error_ratio = std::max(log_err, kLogMinErrorMemory);
    h = h * std::clamp(0.9 / fac, 0.2, 10.0);
  }
}

}  // namespace sweetspot::core::flight
