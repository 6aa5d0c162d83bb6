// Batted-ball flight (core/flight/flight.hpp): the equations of Nathan's calculator in SI,
// integrated by a hand-written Dormand–Prince 5(4) with its 4th-order dense output, the landing
// and the apex found as events on that output. No allocation unless a trajectory is asked for.
// One stepper flies one flight (Fly) or several side by side (FlyMany): docs/flight.md, "Where a
// flight's time goes".
#include "core/flight/flight.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

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


// Everything a right-hand side needs, computed once per flight.
struct Model {
  double k_per_m = 0.0;      // ½ρA/m, 1/m.
  double radius_m = 0.0;     // ball radius, m.
  double omega_rad_s = 0.0;  // initial spin, rad/s.
  double ux = 0, uy = 0, uz = 0;  // spin axis (unit; ω/|ω|), fixed (the calculator's).
  double spin_krpm = 0.0;    // total spin / 1000 rpm (the spin drag term).
  double cd0 = 0.0, cd_spin = 0.0;
  double decay_rate_per_m = 0.0;  // 1/(τ·44.704): exponent = −t·v_rel·rate.
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

// Which right-hand side a flight uses: fixed by the aero model, so uniform over a batch
// (FlyMany shares one AeroOptions), and a template parameter so that the stages carry no
// branch on it.
enum class Kind {
  kVacuum,      // gravity only
  kSawicki,     // Sawicki's drag and lift, no spin decay
  kSaturating,  // nathan-2016, or custom with the saturating lift law: spin decay
  kLinear,      // custom with the linear lift law: spin decay
};

// The state's components: position (m) 0-2, velocity (m/s) 3-5, and with spin decay the decay
// factor D = exp(−t·|v_rel|/(τ·44.704 m/s)) as component 6 (see Derivative).
template <Kind K>
constexpr int kComponents = (K == Kind::kSaturating || K == Kind::kLinear) ? 7 : 6;
constexpr int kDecayComponent = 6;

// The right-hand side at time t of state s (its velocity and decay part: the positions'
// derivatives are the velocities, which the stepper copies). Inlined into the stepper: called
// 6 times a step, it is most of a flight's time, and its cost is the latency of one chain.
//
// The spin decay D = exp(−t·v·rate) (the calculator's form: v the speed relative to the air,
// rate = 1/(τ·44.704 m/s)) is carried as a state instead of evaluated: an `exp` per evaluation
// was a quarter of a flight. It follows dD/dt = −rate·D·(v + t·dv/dt), and dv/dt needs no new
// quantity: the Magnus force is normal to v_rel and does no work, so
// dv/dt = (v_rel·a)/v = −k·CD·v² − g·v_rel,z/v. The state then integrates the same function
// (D(0) = 1), with its local error controlled as the other components' (FlyLanes).
//
// Nathan's lift k·CL·v with CL = cl2·S/(cl0 + cl1·S), S = Rω·D/v, is written with one
// division: k·cl2·Rω·D·v / (cl0·v + cl1·Rω·D) (the same number to rounding); the constants
// are folded once per flight (Model::Prepare).
template <Kind K>
[[gnu::always_inline]] inline void Derivative(const Model& m, double t, const double* s,
                                              double* d) {
  d[3] = 0.0;
  d[4] = 0.0;
  d[5] = -kGravityMps2;
  if constexpr (K == Kind::kVacuum) return;
  const double rx = s[3] - m.wind_x, ry = s[4] - m.wind_y, rz = s[5];
  const double v = std::sqrt(rx * rx + ry * ry + rz * rz);
  double drag = 0.0, lift = 0.0;  // drag: −k·CD·v; lift: k·CL·v (1/s)
  if constexpr (K == Kind::kSawicki) {
    const double spin_factor = v > 0.0 ? m.spin_speed_mps / v : 0.0;
    drag = -m.k_per_m * SawickiDrag(v) * v;
    lift = m.k_per_m * SawickiLift(spin_factor) * v;
  } else {
    const double decay = s[kDecayComponent];
    drag = -(m.k_cd0 + m.k_cd_spin * decay) * v;
    if constexpr (K == Kind::kLinear) {
      lift = m.k_slope_spin * decay;  // k·slope·S·v: v cancels
    } else {
      lift = v > 0.0 ? m.k_cl2_spin * decay * v / (m.cl0 * v + m.cl1_spin * decay) : 0.0;
    }
    // dv/dt (at v = 0, where the speed has a kink, taken as drag only).
    const double dv_dt = drag * v - (v > 0.0 ? kGravityMps2 * rz / v : 0.0);
    d[kDecayComponent] = -m.decay_rate_per_m * decay * (v + t * dv_dt);
  }
  // Magnus: k·CL·v·(û × v_rel), û the (fixed) spin axis, as the calculator writes it.
  d[3] += drag * rx + lift * (m.uy * rz - m.uz * ry);
  d[4] += drag * ry + lift * (m.uz * rx - m.ux * rz);
  d[5] += drag * rz + lift * (m.ux * ry - m.uy * rx);
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


// One flight in progress on the stepper: its model and the integrator's state between steps.
// Default-initialised to zeros, so that an idle lane computes on finite numbers.
template <Kind K>
struct Lane {
  static constexpr int N = kComponents<K>;
  Model m;
  FlightResult* r = nullptr;  // the flight's answer; null: the lane is idle
  std::vector<TrajectoryPoint>* trajectory = nullptr;
  double t = 0.0, h = 0.0;
  double y[N] = {}, y_new[N] = {}, s[N] = {};
  double k[7][N] = {};  // the stages' derivatives; k[0] = f(t, y) (first same as last)
  // The error estimate: the local position errors, plus each step's local velocity error
  // carried to the landing (δv · (T − t_i), T the hang time): Σ|δx_i| + T·Σ|δv_i| − Σ|δv_i|·t_i.
  double error_sum = 0.0, velocity_error_sum = 0.0, velocity_error_time_sum = 0.0;
  // PI controller memory (Hairer's DOPRI5 "facold", 1e-4 at first), kept as its logarithm: the
  // controller's err^0.17 · facold^−0.04 is one exp of logarithms (two pow calls cost more).
  double log_previous_error_ratio = kLogMinErrorMemory;
  long long next_sample = 1;  // the next sample is at next_sample · trajectory_interval_s
};

// The stage derivative k[j] at (t, s): the positions' derivatives are the velocities.
template <Kind K>
[[gnu::always_inline]] inline void Evaluate(Lane<K>& a, int j, double t, const double* s) {
  a.k[j][0] = s[3];
  a.k[j][1] = s[4];
  a.k[j][2] = s[5];
  Derivative<K>(a.m, t, s, a.k[j]);
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
  const double sth = std::sin(th), cth = std::cos(th), sph = std::sin(ph), cph = std::cos(ph);
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
  m.spin_krpm = std::hypot(wb, ws) / 1000.0;
  m.radius_m = aero.ball_circumference_m / (2.0 * kPi);
  const double area_m2 = kPi * m.radius_m * m.radius_m;
  const double rho = r->air_density_kg_m3;
  switch (aero.model) {
    case AeroModel::kNathan2016:
      m.k_per_m = kNathanC0PerDensity * rho * (kNathanMassKg / aero.ball_mass_kg) *
                  std::pow(aero.ball_circumference_m / kNathanCircumferenceM, 2);
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
  m.wind_x = environment.wind.speed_mps * std::sin(wind_dir);
  m.wind_y = environment.wind.speed_mps * std::cos(wind_dir);

  const double v0 = launch.exit_speed_mps;
  const double start[6] = {launch.start_x_m, launch.start_y_m, launch.height_m,
                           v0 * cth * sph,   v0 * cth * cph,   v0 * sth};
  std::copy(start, start + 6, y0);
  return true;
}

// Puts a flight on `lane` (false, with `r` final, when an input is refused).
template <Kind K>
bool Start(const Launch& launch, const Environment& environment, const AeroOptions& aero,
           const FlightOptions& options, FlightResult* r,
           std::vector<TrajectoryPoint>* trajectory, Lane<K>* lane, bool checked = false,
           const double* density = nullptr) {
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
  a.h = std::min(0.5, std::pow(options.relative_tolerance, 0.2) * 5.0);
  Evaluate<K>(a, 0, 0.0, a.y);
  r->evaluations = 1;
  a.error_sum = a.velocity_error_sum = a.velocity_error_time_sum = 0.0;
  a.log_previous_error_ratio = kLogMinErrorMemory;
  a.next_sample = 1;
  if (trajectory != nullptr) {
    trajectory->push_back(Sample(0.0, {a.y[0], a.y[1], a.y[2], a.y[3], a.y[4], a.y[5]}));
  }
  return true;
}

// Before a step: ends the flight (true) at its step or time limit, else bounds the step by
// the time limit.
template <Kind K>
bool AtLimit(Lane<K>& a, const FlightOptions& options) {
  FlightResult& r = *a.r;
  // Rejected steps count too: a step size shrinking forever must end as well.
  const bool step_limit = r.steps + r.rejected_steps >= options.max_steps;
  if (step_limit || a.t >= options.max_flight_time_s) {
    r.termination = step_limit ? FlightTermination::kStepLimit : FlightTermination::kTimeLimit;
    r.error_estimate_m =  // of the flight so far
        a.error_sum + a.t * a.velocity_error_sum - a.velocity_error_time_sum;
    return true;
  }
  a.h = std::min(a.h, options.max_flight_time_s - a.t);
  return false;
}

// One Dormand–Prince step attempt on each of the L lanes, stage by stage across the lanes: the
// lanes' chains are independent, so the processor overlaps them (one flight's stages wait on
// each other's square root and division). The positions are not formed at the inner stages:
// the right-hand side does not read them.
template <Kind K, int L>
void Attempt(Lane<K>* lanes) {
  constexpr int N = Lane<K>::N;
  for (int l = 0; l < L; ++l) {
    Lane<K>& a = lanes[l];
    for (int i = 3; i < N; ++i) a.s[i] = a.y[i] + a.h * a21 * a.k[0][i];
  }
  for (int l = 0; l < L; ++l) Evaluate<K>(lanes[l], 1, lanes[l].t + c2 * lanes[l].h, lanes[l].s);
  for (int l = 0; l < L; ++l) {
    Lane<K>& a = lanes[l];
    for (int i = 3; i < N; ++i) a.s[i] = a.y[i] + a.h * (a31 * a.k[0][i] + a32 * a.k[1][i]);
  }
  for (int l = 0; l < L; ++l) Evaluate<K>(lanes[l], 2, lanes[l].t + c3 * lanes[l].h, lanes[l].s);
  for (int l = 0; l < L; ++l) {
    Lane<K>& a = lanes[l];
    for (int i = 3; i < N; ++i) {
      a.s[i] = a.y[i] + a.h * (a41 * a.k[0][i] + a42 * a.k[1][i] + a43 * a.k[2][i]);
    }
  }
  for (int l = 0; l < L; ++l) Evaluate<K>(lanes[l], 3, lanes[l].t + c4 * lanes[l].h, lanes[l].s);
  for (int l = 0; l < L; ++l) {
    Lane<K>& a = lanes[l];
    for (int i = 3; i < N; ++i) {
      a.s[i] = a.y[i] + a.h * (a51 * a.k[0][i] + a52 * a.k[1][i] + a53 * a.k[2][i] +
                               a54 * a.k[3][i]);
    }
  }
  for (int l = 0; l < L; ++l) Evaluate<K>(lanes[l], 4, lanes[l].t + c5 * lanes[l].h, lanes[l].s);
  for (int l = 0; l < L; ++l) {
    Lane<K>& a = lanes[l];
    for (int i = 3; i < N; ++i) {
      a.s[i] = a.y[i] + a.h * (a61 * a.k[0][i] + a62 * a.k[1][i] + a63 * a.k[2][i] +
                               a64 * a.k[3][i] + a65 * a.k[4][i]);
    }
  }
  for (int l = 0; l < L; ++l) Evaluate<K>(lanes[l], 5, lanes[l].t + lanes[l].h, lanes[l].s);
  for (int l = 0; l < L; ++l) {
    Lane<K>& a = lanes[l];
    for (int i = 0; i < N; ++i) {
      a.y_new[i] = a.y[i] + a.h * (a71 * a.k[0][i] + a73 * a.k[2][i] + a74 * a.k[3][i] +
                                   a75 * a.k[4][i] + a76 * a.k[5][i]);
    }
  }
  for (int l = 0; l < L; ++l) Evaluate<K>(lanes[l], 6, lanes[l].t + lanes[l].h, lanes[l].y_new);
}

// The local error of an attempt (5th − 4th order), scaled per component: the sum of squares of
// the scaled errors (err2), of the position's errors in m² and the velocity's in (m/s)², and
// whether the new state and its error are finite. The decay factor D (of order 1) is scaled by
// rtol alone.
struct StepError {
  double err2 = 0.0, position_err2 = 0.0, velocity_err2 = 0.0;
  bool finite = true;
};

// What Conclude decided about an attempt.
enum class Outcome {
  kEnded,     // the flight ended (landed, or not finite): its answer is final
  kRejected,  // a shorter h (a.h) for a new attempt from the same state
  kAccepted,  // the caller moves y_new to y and k[6] to k[0]; a.t and a.h are the next step's
};

template <Kind K>
StepError ErrorOf(const Lane<K>& a, const FlightOptions& options) {
  constexpr int N = Lane<K>::N;
  const double h = a.h;
  const double* y = a.y;
  const double* y_new = a.y_new;
  const auto& k = a.k;
  const double rtol = options.relative_tolerance, atol = options.absolute_tolerance_m;
  StepError out;
  for (int i = 0; i < N; ++i) {
    const double e = h * (e1 * k[0][i] + e3 * k[2][i] + e4 * k[3][i] + e5 * k[4][i] +
                          e6 * k[5][i] + e7 * k[6][i]);
    const double yn = y_new[i];
    out.finite = out.finite && Finite(yn) && Finite(e);
    const double scale =
        i < 6 ? atol + rtol * std::max(std::abs(y[i]), std::abs(yn)) : rtol;
    out.err2 += (e / scale) * (e / scale);
    if (i < 3) {
      out.position_err2 += e * e;
    } else if (i < 6) {
      out.velocity_err2 += e * e;
    }
  }
  return out;
}

// After an attempt whose error is `se`: rejects it (a shorter h) or accepts it (the events on
// its dense output and the next h). Reads a.y, a.y_new and a.k only when the step has an
// event (an apex or a landing: y[5], y_new[5] and y_new[2] decide) or a trajectory.
template <Kind K>
Outcome Conclude(Lane<K>& a, const FlightOptions& options, const StepError& se) {
  FlightResult& r = *a.r;
  const double h = a.h, t = a.t;
  const double* y = a.y;
  const double* y_new = a.y_new;
  const auto& k = a.k;
  r.evaluations += 6;
  const double err2 = se.err2, position_err2 = se.position_err2,
               velocity_err2 = se.velocity_err2;
  if (!se.finite) {
    if (h > 1e-9) {  // a too-long step can overflow: retry shorter before giving up
      a.h *= 0.1;
      ++r.rejected_steps;
      return Outcome::kRejected;
    }
    r.termination = FlightTermination::kNonFinite;
    return Outcome::kEnded;
  }
  const double err = std::sqrt(err2 / 6.0);
  const double log_err = std::log(err);  // −inf for a zero error: the clamps below hold
  if (err > 1.0) {
    a.h *= std::max(0.2, 0.9 * std::exp(-0.2 * log_err));
    ++r.rejected_steps;
    return Outcome::kRejected;
  }

  // Accepted.
  ++r.steps;
  a.error_sum += std::sqrt(position_err2);
  const double velocity_error = std::sqrt(velocity_err2);
  a.velocity_error_sum += velocity_error;
  a.velocity_error_time_sum += velocity_error * (t + h);
  const bool apex = y[5] > 0.0 && y_new[5] <= 0.0;  // vz crosses zero going down
  const bool lands = y_new[2] <= 0.0 && y_new[5] < 0.0;
  if (apex || lands || a.trajectory != nullptr) {
    // The dense output of [t, t + h] (Hairer's contd5), formed only when it is read.
    Dense dense;
    for (int i = 0; i < 6; ++i) {
      const double diff = y_new[i] - y[i];
      const double bspl = h * k[0][i] - diff;
      dense.r1[i] = y[i];
      dense.r2[i] = diff;
      dense.r3[i] = bspl;
      dense.r4[i] = diff - h * k[6][i] - bspl;
      dense.r5[i] = h * (d1 * k[0][i] + d3 * k[2][i] + d4 * k[3][i] + d5 * k[4][i] +
                         d6 * k[5][i] + d7 * k[6][i]);
    }
    if (apex) {
      const double theta = RootOf(dense, 5, y[5], y_new[5]);
      const double z = dense.Component(2, theta);
      if (z > r.apex_m) {
        r.apex_m = z;
        r.apex_time_s = t + theta * h;
      }
    }
    const double theta_land = lands ? RootOf(dense, 2, y[2], y_new[2]) : 1.0;
    const double t_end = t + theta_land * h;
    if (a.trajectory != nullptr) {
      for (double ts = a.next_sample * options.trajectory_interval_s; ts < t_end;
           ts = ++a.next_sample * options.trajectory_interval_s) {
        a.trajectory->push_back(Sample(ts, dense.At((ts - t) / h)));
      }
    }
    if (lands) {
      State landed = dense.At(theta_land);
      landed.z = 0.0;
      if (a.trajectory != nullptr) a.trajectory->push_back(Sample(t_end, landed));
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
        const double cubic = h00 * y[i] + h10 * h * k[0][i] + h01 * y_new[i] + h11 * h * k[6][i];
        d[i] = cubic - dense.Component(i, u);
      }
      const double shift = landed.vz < 0.0 ? d[2] / landed.vz : 0.0;
      const double interpolation_error =
          std::hypot(d[0] - landed.vx * shift, d[1] - landed.vy * shift);
      r.error_estimate_m = a.error_sum + t_end * a.velocity_error_sum -
                           a.velocity_error_time_sum + interpolation_error;
      return Outcome::kEnded;
    }
  }
  a.t = t + h;
  // Step-size control (Hairer's DOPRI5: PI control with β = 0.04).
  // fac = max(err, 1e-10)^0.17 · facold^−0.04, facold = max(err, 1e-4) of the last step.
  const double fac = std::exp((0.2 - 0.04 * 0.75) * std::max(log_err, kLogMinError) -
                              0.04 * a.log_previous_error_ratio);
  a.log_previous_error_ratio = std::max(log_err, kLogMinErrorMemory);
  a.h = h * std::clamp(0.9 / fac, 0.2, 10.0);
  return Outcome::kAccepted;
}

// After an attempt on a lane of scalar lanes: true when the flight ended.
template <Kind K>
bool Finish(Lane<K>& a, const FlightOptions& options) {
  const Outcome outcome = Conclude(a, options, ErrorOf(a, options));
  if (outcome == Outcome::kAccepted) {
    for (int i = 0; i < Lane<K>::N; ++i) {
      a.y[i] = a.y_new[i];
      a.k[0][i] = a.k[6][i];  // first same as last
    }
  }
  return outcome == Outcome::kEnded;
}

// FlyMany's lanes as a structure of arrays (the decay kinds, nathan-2016 and custom): each
// component of 4 lanes' states, stages and models is one vector of GCC's vector extension, so a
// right-hand side, a stage sum and the error norm are one vector operation per term across the
// lanes (one AVX2 instruction: the kernel is compiled for AVX2 and used where the processor has
// it; elsewhere FlyMany keeps the scalar lanes, FlyLanes). FlyMany's 8 lanes are two such
// vectors (SoaLanes groups) taken in turn in each stage: two independent chains, so the
// processor overlaps one's square root and divisions with the other's (one vector of 8 made GCC
// move its elements through memory). A lane's operations are Fly's, in Fly's order, each
// IEEE-rounded (division and square root included), and neither target enables FMA, so nothing
// is contracted: the answers are Fly's to the bit (FlightTest.FlyManyGivesFlysAnswers). The
// step's bookkeeping (the controller's log and exp, the events, the refill) stays per lane on
// the scalar Lane; an idle lane computes on its last numbers, its results unread (masked).
// The vectors never cross a call's boundary (the kernels take them in SoaLanes): GCC's note on
// the ABI of 32-byte vectors without AVX does not apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
typedef double Vec __attribute__((vector_size(32)));
typedef long long VecMask __attribute__((vector_size(32)));
constexpr int kSoaLanes = 4;  // a vector's lanes
constexpr int kSoaGroups = kFlyManyLanes / kSoaLanes;  // vectors side by side (2: two chains)
static_assert(kSoaGroups * kSoaLanes == kFlyManyLanes, "FlyMany's lanes are whole vectors");

[[gnu::always_inline]] inline Vec Splat(double x) { return Vec{x, x, x, x}; }

[[gnu::always_inline]] inline Vec Abs(Vec x) {
  return reinterpret_cast<Vec>(reinterpret_cast<VecMask>(x) &
                               (VecMask{} + 0x7fffffffffffffffLL));
}

// The correctly rounded square root of each lane (as std::sqrt's).
[[gnu::always_inline]] inline Vec Sqrt(Vec x) {
#if defined(__SSE2__)
  typedef double Half __attribute__((vector_size(16)));
  const Half lo = __builtin_ia32_sqrtpd(Half{x[0], x[1]});
  const Half hi = __builtin_ia32_sqrtpd(Half{x[2], x[3]});
  return Vec{lo[0], lo[1], hi[0], hi[1]};
#else
  return Vec{std::sqrt(x[0]), std::sqrt(x[1]), std::sqrt(x[2]), std::sqrt(x[3])};
#endif
}

template <Kind K>
struct SoaLanes {
  static constexpr int N = kComponents<K>;
  Vec y[N] = {}, y_new[N] = {}, s[N] = {};
  Vec k[7][N] = {};
  // Model's fields that Derivative reads, per lane.
  Vec k_cd0 = {}, k_cd_spin = {}, k_slope_spin = {}, k_cl2_spin = {}, cl0 = {}, cl1_spin = {},
      decay_rate_per_m = {}, ux = {}, uy = {}, uz = {}, wind_x = {}, wind_y = {};
  Vec t = {}, h = {};  // the lanes' times and steps for the next attempt (s)
};

// The vector error norm of an attempt, per lane (StepError's fields).
struct SoaError {
  Vec err2, position_err2, velocity_err2;
  VecMask finite;
};

// Derivative<K> (its kinds with spin decay) on 4 lanes: the same expressions, term by term.
template <Kind K>
[[gnu::always_inline]] inline void SoaEvaluate(SoaLanes<K>& m, int j, Vec t, const Vec* s) {
  static_assert(K == Kind::kSaturating || K == Kind::kLinear, "the decay kinds");
  Vec* d = m.k[j];
  const Vec zero = {};
  d[0] = s[3];
  d[1] = s[4];
  d[2] = s[5];
  d[3] = zero;
  d[4] = zero;
  d[5] = Splat(-kGravityMps2);
  const Vec rx = s[3] - m.wind_x, ry = s[4] - m.wind_y, rz = s[5];
  const Vec v = Sqrt(rx * rx + ry * ry + rz * rz);
  const VecMask positive = v > zero;
  const Vec decay = s[kDecayComponent];
  const Vec drag = -(m.k_cd0 + m.k_cd_spin * decay) * v;
  Vec lift;
  if constexpr (K == Kind::kLinear) {
    lift = m.k_slope_spin * decay;
  } else {
    lift = positive ? m.k_cl2_spin * decay * v / (m.cl0 * v + m.cl1_spin * decay) : zero;
  }
  const Vec dv_dt = drag * v - (positive ? kGravityMps2 * rz / v : zero);
  d[kDecayComponent] = -m.decay_rate_per_m * decay * (v + t * dv_dt);
  d[3] += drag * rx + lift * (m.uy * rz - m.uz * ry);
  d[4] += drag * ry + lift * (m.uz * rx - m.ux * rz);
  d[5] += drag * rz + lift * (m.ux * ry - m.uy * rx);
}

// Attempt<K, L> and ErrorOf<K> on the 4 lanes at once.
template <Kind K>
[[gnu::always_inline]] inline void SoaAttempt(SoaLanes<K>* groups, double rtol, double atol,
                                              SoaError* outs) {
  constexpr int N = SoaLanes<K>::N;
#define SWEETSPOT_GROUPS for (int g = 0; g < kSoaGroups; ++g)
#define SWEETSPOT_GROUP \
  SoaLanes<K>& a = groups[g]; \
  const Vec t = a.t, h = a.h; \
  const auto& k = a.k; \
  (void)t; \
  (void)k
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    for (int i = 3; i < N; ++i) a.s[i] = a.y[i] + h * a21 * k[0][i];
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    SoaEvaluate<K>(a, 1, t + c2 * h, a.s);
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    for (int i = 3; i < N; ++i) a.s[i] = a.y[i] + h * (a31 * k[0][i] + a32 * k[1][i]);
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    SoaEvaluate<K>(a, 2, t + c3 * h, a.s);
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    for (int i = 3; i < N; ++i) {
      a.s[i] = a.y[i] + h * (a41 * k[0][i] + a42 * k[1][i] + a43 * k[2][i]);
    }
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    SoaEvaluate<K>(a, 3, t + c4 * h, a.s);
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    for (int i = 3; i < N; ++i) {
      a.s[i] = a.y[i] + h * (a51 * k[0][i] + a52 * k[1][i] + a53 * k[2][i] + a54 * k[3][i]);
    }
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    SoaEvaluate<K>(a, 4, t + c5 * h, a.s);
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    for (int i = 3; i < N; ++i) {
      a.s[i] = a.y[i] + h * (a61 * k[0][i] + a62 * k[1][i] + a63 * k[2][i] + a64 * k[3][i] +
                             a65 * k[4][i]);
    }
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    SoaEvaluate<K>(a, 5, t + h, a.s);
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    for (int i = 0; i < N; ++i) {
      a.y_new[i] = a.y[i] + h * (a71 * k[0][i] + a73 * k[2][i] + a74 * k[3][i] +
                                 a75 * k[4][i] + a76 * k[5][i]);
    }
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    SoaEvaluate<K>(a, 6, t + h, a.y_new);
  }
  const Vec zero = {};
  const Vec largest = Splat(std::numeric_limits<double>::max());
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    SoaError* out = &outs[g];
    out->err2 = out->position_err2 = out->velocity_err2 = zero;
    out->finite = VecMask{} - 1;
    for (int i = 0; i < N; ++i) {
      const Vec e = h * (e1 * k[0][i] + e3 * k[2][i] + e4 * k[3][i] + e5 * k[4][i] +
                         e6 * k[5][i] + e7 * k[6][i]);
      const Vec yn = a.y_new[i];
      out->finite &= (Abs(yn) <= largest) & (Abs(e) <= largest);
      Vec scale;
      if (i < 6) {
        const Vec ay = Abs(a.y[i]), ayn = Abs(yn);
        scale = atol + rtol * (ay < ayn ? ayn : ay);  // std::max(|y|, |y_new|)
      } else {
        scale = Splat(rtol);
      }
      out->err2 += (e / scale) * (e / scale);
      if (i < 3) {
        out->position_err2 += e * e;
      } else if (i < 6) {
        out->velocity_err2 += e * e;
      }
    }
  }
#undef SWEETSPOT_GROUPS
#undef SWEETSPOT_GROUP
}

// The kernels, compiled for AVX2 (without FMA), one non-template function per kind. Only run
// where the processor has AVX2 (SoaLanesPay): compiled for the baseline's SSE2 (two instructions
// per vector) the same stepper measured 0.81 µs per flight against the scalar lanes' 0.75–0.77
// (it gave the same answers to the bit).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define SWEETSPOT_FLIGHT_AVX2 __attribute__((target("avx2")))
bool SoaLanesPay() { return __builtin_cpu_supports("avx2"); }
#else
#define SWEETSPOT_FLIGHT_AVX2
bool SoaLanesPay() { return false; }
#endif
SWEETSPOT_FLIGHT_AVX2 void SoaAttemptSaturating(SoaLanes<Kind::kSaturating>* a, double rtol,
                                                double atol, SoaError* out) {
  SoaAttempt<Kind::kSaturating>(a, rtol, atol, out);
}
SWEETSPOT_FLIGHT_AVX2 void SoaAttemptLinear(SoaLanes<Kind::kLinear>* a, double rtol,
                                            double atol, SoaError* out) {
  SoaAttempt<Kind::kLinear>(a, rtol, atol, out);
}
#undef SWEETSPOT_FLIGHT_AVX2

template <Kind K>
void SoaAttemptOf(SoaLanes<K>* a, double rtol, double atol, SoaError* out) {
  if constexpr (K == Kind::kSaturating) {
    SoaAttemptSaturating(a, rtol, atol, out);
  } else {
    SoaAttemptLinear(a, rtol, atol, out);
  }
}

// Lane l of `v` takes the flight just started on `lane` (its state, its first stage, its model).
template <Kind K>
void SoaLoad(const Lane<K>& lane, int l, SoaLanes<K>* v) {
  for (int i = 0; i < Lane<K>::N; ++i) {
    v->y[i][l] = lane.y[i];
    v->k[0][i][l] = lane.k[0][i];
  }
  const Model& m = lane.m;
  v->k_cd0[l] = m.k_cd0;
  v->k_cd_spin[l] = m.k_cd_spin;
  v->k_slope_spin[l] = m.k_slope_spin;
  v->k_cl2_spin[l] = m.k_cl2_spin;
  v->cl0[l] = m.cl0;
  v->cl1_spin[l] = m.cl1_spin;
  v->decay_rate_per_m[l] = m.decay_rate_per_m;
  v->ux[l] = m.ux;
  v->uy[l] = m.uy;
  v->uz[l] = m.uz;
  v->wind_x[l] = m.wind_x;
  v->wind_y[l] = m.wind_y;
}

// FlyLanes<K, 4> with the stepper's arithmetic on SoaLanes: the same flights in the same lanes,
// the same answers.
template <Kind K, class StartFlight>
void FlyLanesSoa(std::size_t count, const FlightOptions& options, const StartFlight& start) {
  constexpr int N = Lane<K>::N;
  constexpr int L = kFlyManyLanes;
  Lane<K> lanes[L];
  SoaLanes<K> v[kSoaGroups];
  std::size_t next = 0;
  auto refill = [&](int l) {
    lanes[l].r = nullptr;
    while (next < count) {
      if (start(next++, &lanes[l])) {
        SoaLoad(lanes[l], l % kSoaLanes, &v[l / kSoaLanes]);
        return;
      }
    }
  };
  for (int l = 0; l < L; ++l) refill(l);
  const double rtol = options.relative_tolerance, atol = options.absolute_tolerance_m;
  while (true) {
    int active = 0;
    for (int l = 0; l < L; ++l) {
      while (lanes[l].r != nullptr && AtLimit(lanes[l], options)) refill(l);
      active += lanes[l].r != nullptr ? 1 : 0;
    }
    if (active == 0) return;
    for (int g = 0; g < kSoaGroups; ++g) {
      const Lane<K>* q = lanes + g * kSoaLanes;
      v[g].t = Vec{q[0].t, q[1].t, q[2].t, q[3].t};
      v[g].h = Vec{q[0].h, q[1].h, q[2].h, q[3].h};
    }
    SoaError errors[kSoaGroups];
    SoaAttemptOf<K>(v, rtol, atol, errors);
    VecMask advance[kSoaGroups] = {};
    for (int l = 0; l < L; ++l) {
      Lane<K>& a = lanes[l];
      if (a.r == nullptr) continue;
      const SoaLanes<K>& w = v[l / kSoaLanes];
      const SoaError& se = errors[l / kSoaLanes];
      const int m = l % kSoaLanes;
      // What Conclude reads of the state: the event tests always, everything on an event.
      a.y[5] = w.y[5][m];
      a.y_new[2] = w.y_new[2][m];
      a.y_new[5] = w.y_new[5][m];
      if ((a.y[5] > 0.0 && a.y_new[5] <= 0.0) || (a.y_new[2] <= 0.0 && a.y_new[5] < 0.0)) {
        for (int i = 0; i < N; ++i) {
          a.y[i] = w.y[i][m];
          a.y_new[i] = w.y_new[i][m];
          for (int j = 0; j < 7; ++j) a.k[j][i] = w.k[j][i][m];
        }
      }
      const StepError error{se.err2[m], se.position_err2[m], se.velocity_err2[m],
                            se.finite[m] != 0};
      const Outcome outcome = Conclude(a, options, error);
      if (outcome == Outcome::kAccepted) advance[l / kSoaLanes][m] = -1;
      if (outcome == Outcome::kEnded) refill(l);
    }
    for (int g = 0; g < kSoaGroups; ++g) {
      for (int i = 0; i < N; ++i) {
        v[g].y[i] = advance[g] ? v[g].y_new[i] : v[g].y[i];
        v[g].k[0][i] = advance[g] ? v[g].k[6][i] : v[g].k[0][i];  // first same as last
      }
    }
  }
}
#pragma GCC diagnostic pop

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
    case AeroModel::kVacuum: return Kind::kVacuum;
    case AeroModel::kSawicki2003: return Kind::kSawicki;
    case AeroModel::kCustom:
      return aero.lift_law == LiftLaw::kLinear ? Kind::kLinear : Kind::kSaturating;
    case AeroModel::kNathan2016: break;
  }
  return Kind::kSaturating;
}

// Calls f(std::integral_constant<Kind, kind>()): the stepper compiled for each kind.
template <class F>
void WithKind(Kind kind, const F& f) {
  switch (kind) {
    case Kind::kVacuum: f(std::integral_constant<Kind, Kind::kVacuum>()); return;
    case Kind::kSawicki: f(std::integral_constant<Kind, Kind::kSawicki>()); return;
    case Kind::kSaturating: f(std::integral_constant<Kind, Kind::kSaturating>()); return;
    case Kind::kLinear: f(std::integral_constant<Kind, Kind::kLinear>()); return;
  }
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
  WithKind(KindOf(aero), [&](auto kind) {
    constexpr Kind K = decltype(kind)::value;
    FlyLanes<K, 1>(1, options, [&](std::size_t, Lane<K>* lane) {
      return Start<K>(launch, environment, aero, options, &r, trajectory, lane);
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
  WithKind(KindOf(aero), [&](auto kind) {
    constexpr Kind K = decltype(kind)::value;
    auto start = [&](std::size_t i, Lane<K>* lane) {
      results[i] = FlightResult();
      const Environment& environment = environments[shared_environment ? 0 : i];
      bool checked = shared_valid;
      if (checked && !shared_environment) checked = environment.Validate(nullptr);
      return Start<K>(launches[i], environment, aero, options, &results[i], nullptr, lane,
                      checked, shared_valid && shared_environment ? &density : nullptr);
    };
    if constexpr (K == Kind::kSaturating || K == Kind::kLinear) {
      if (SoaLanesPay()) {
        FlyLanesSoa<K>(count, options, start);
        return;
      }
    }
    FlyLanes<K, kFlyManyLanes>(count, options, start);
  });
}

}  // namespace sweetspot::core::flight
