// The flight's stepper, shared by flight.cpp (Fly, FlyMany's scalar lanes) and
// flight_soa.cpp (FlyMany's vector lanes): the model's constants and right-hand side, the
// Dormand–Prince 5(4) tableau and dense output, a flight in progress (Lane) and one step of it
// (Attempt, then ErrorOf and Conclude). Internal to core/flight: not part of its interface.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

#include "core/flight/flight.hpp"
#include "core/flight/flight_control.hpp"
#include "core/numerics/limits.hpp"
#include "core/units.hpp"

namespace sweetspot::core::flight::stepper {

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

inline bool Finite(double v) { return std::isfinite(v); }

// The state: position (m) and velocity (m/s).
struct State {
  double x, y, z, vx, vy, vz;
};

// Everything a right-hand side needs, computed once per flight.
struct Model {
  double k_per_m = 0.0;           // ½ρA/m, 1/m.
  double radius_m = 0.0;          // ball radius, m.
  double omega_rad_s = 0.0;       // initial spin, rad/s.
  double ux = 0, uy = 0, uz = 0;  // spin axis (unit; ω/|ω|), fixed (the calculator's).
  double spin_krpm = 0.0;         // total spin / 1000 rpm (the spin drag term).
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
inline double SawickiDrag(double v) {
  constexpr double kCdLow = 0.5, kCdHigh = 0.2, kCentreMps = 30.0, kScaleMps = 2.0;
  return kCdHigh + (kCdLow - kCdHigh) / (1.0 + std::exp((v - kCentreMps) / kScaleMps));
}

inline double SawickiLift(double s) { return s < 0.1 ? 1.5 * s : 0.09 + 0.6 * s; }

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
constexpr double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920, e5 = -17253.0 / 339200,
                 e6 = 22.0 / 525, e7 = -1.0 / 40;
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

// The θ in [0, 1] where component `i` of the dense output crosses zero, given its signs at
// the ends differ: Newton's method on the dense polynomial from an inverse cubic Hermite guess
// (two or three iterations, θ to about 1e-15), and if it leaves [0, 1] or does not settle, an
// Illinois regula falsi to 1e-11 in θ (1e-10 m on a step of tens of metres). FlyMany's kernel
// runs the same Newton iterations lane by lane (SoaRoot, flight_soa.cpp): a change here is a
// change there.
inline double RootOf(const Dense& dense, int i, double f0, double f1) {
  // The first guess: the inverse cubic Hermite interpolant of θ against the component (its
  // values and slopes at the ends: a step's θ as a function of z near the ground, or of vz near
  // the apex, is nearly cubic), or the secant's where the component is not monotone at the ends.
  // From it Newton's method takes two iterations instead of three or four.
  const double secant = f0 / (f0 - f1);
  const double span = f1 - f0;
  const double slope0 = dense.r2[i] + dense.r3[i];                 // df/dθ at θ = 0
  const double slope1 = dense.r2[i] - dense.r3[i] - dense.r4[i];  // df/dθ at θ = 1
  const double m0 = span / slope0, m1 = span / slope1;            // dθ/ds at the ends
  double theta = secant;
  if (m0 > 0.0 && m1 > 0.0) {
    const double s = secant, u = 1.0 - s;
    const double hermite = s * u * u * m0 + s * s * (3.0 - 2.0 * s) - s * s * u * m1;
    if (hermite >= 0.0 && hermite <= 1.0) theta = hermite;
  }
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
    // Converging quadratically: θ's error after a step δ is about |f''/2f'|·δ², 1e-15 here
    // (|f''/2f'| is about h/6 for z at the landing, less for vz at the apex).
    if (std::abs(step) < 1e-7) return theta;
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

inline double GroundSpeed(const State& s) {
  return std::sqrt(s.vx * s.vx + s.vy * s.vy + s.vz * s.vz);
}

inline TrajectoryPoint Sample(double t, const State& s) {
  return {t, s.x, s.y, s.z, GroundSpeed(s)};
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
  // Where the last attempt's landing θ is known already (FlyMany's kernel: RootOf's, lane by
  // lane), else negative (Conclude finds it).
  double landing_theta = -1.0;
};

// The stage derivative k[j] at (t, s): the positions' derivatives are the velocities.
template <Kind K>
[[gnu::always_inline]] inline void Evaluate(Lane<K>& a, int j, double t, const double* s) {
  a.k[j][0] = s[3];
  a.k[j][1] = s[4];
  a.k[j][2] = s[5];
  Derivative<K>(a.m, t, s, a.k[j]);
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
      a.s[i] =
          a.y[i] + a.h * (a51 * a.k[0][i] + a52 * a.k[1][i] + a53 * a.k[2][i] + a54 * a.k[3][i]);
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
  // From the above: √(err2/6), and the local position and velocity errors √position_err2 (m)
  // and √velocity_err2 (m/s); with `controlled`, the controller's steps too (ControlOf:
  // FlyMany's vector lanes compute them for every lane).
  Control<double> control{};
  double position_error = 0.0, velocity_error = 0.0;
  bool controlled = false;
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
    const double e = h * (e1 * k[0][i] + e3 * k[2][i] + e4 * k[3][i] + e5 * k[4][i] + e6 * k[5][i] +
                          e7 * k[6][i]);
    const double yn = y_new[i];
    out.finite = out.finite && Finite(yn) && Finite(e);
    const double scale = i < 6 ? atol + rtol * std::max(std::abs(y[i]), std::abs(yn)) : rtol;
    out.err2 += (e / scale) * (e / scale);
    if (i < 3) {
      out.position_err2 += e * e;
    } else if (i < 6) {
      out.velocity_err2 += e * e;
    }
  }
  out.control.err = std::sqrt(out.err2 / 6.0);
  out.position_error = std::sqrt(out.position_err2);
  out.velocity_error = std::sqrt(out.velocity_err2);
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
  if (!se.finite) {
    if (h > 1e-9) {  // a too-long step can overflow: retry shorter before giving up
      a.h *= 0.1;
      ++r.rejected_steps;
      return Outcome::kRejected;
    }
    r.termination = FlightTermination::kNonFinite;
    return Outcome::kEnded;
  }
  const double err = se.control.err;
  const double log_err = se.controlled ? 0.0 : LogErrorOf(err);
  if (err > 1.0) {
    a.h = se.controlled ? se.control.h_rejected : RejectedStep(h, log_err);
    ++r.rejected_steps;
    return Outcome::kRejected;
  }

  // Accepted.
  ++r.steps;
  a.error_sum += se.position_error;
  const double velocity_error = se.velocity_error;
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
      dense.r5[i] = h * (d1 * k[0][i] + d3 * k[2][i] + d4 * k[3][i] + d5 * k[4][i] + d6 * k[5][i] +
                         d7 * k[6][i]);
    }
    if (apex) {
      const double theta = RootOf(dense, 5, y[5], y_new[5]);
      const double z = dense.Component(2, theta);
      if (z > r.apex_m) {
        r.apex_m = z;
        r.apex_time_s = t + theta * h;
      }
    }
    const double theta_land = !lands                    ? 1.0
                              : a.landing_theta >= 0.0 ? a.landing_theta
                                                       : RootOf(dense, 2, y[2], y_new[2]);
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
      // √(x² + y²) rather than std::hypot (its care for overflow costs a call; a landing is
      // within a few hundred metres).
      r.distance_m = std::sqrt(landed.x * landed.x + landed.y * landed.y);
      r.bearing_deg = std::atan2(landed.x, landed.y) / kDegToRad;
      r.landing_speed_mps = GroundSpeed(landed);
      r.landing_angle_deg =
          std::atan2(-landed.vz, std::sqrt(landed.vx * landed.vx + landed.vy * landed.vy)) /
          kDegToRad;
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
      const double dx = d[0] - landed.vx * shift, dy = d[1] - landed.vy * shift;
      const double interpolation_error = std::sqrt(dx * dx + dy * dy);
      r.error_estimate_m = a.error_sum + t_end * a.velocity_error_sum - a.velocity_error_time_sum +
                           interpolation_error;
      return Outcome::kEnded;
    }
  }
  a.t = t + h;
  // Step-size control (ControlOf: Hairer's DOPRI5's PI control).
  if (se.controlled) {
    a.log_previous_error_ratio = se.control.log_memory;
    a.h = se.control.h_accepted;
  } else {
    a.h = AcceptedStep(h, log_err, a.log_previous_error_ratio);
    a.log_previous_error_ratio = MemoryOf(log_err);
  }
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
}  // namespace sweetspot::core::flight::stepper
