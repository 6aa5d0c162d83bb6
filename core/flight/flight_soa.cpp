// FlyMany's vector lanes: the stepper's stage and error arithmetic on 4 lanes at once
// (flight_soa.hpp; docs/flight.md, "Where a flight's time goes").
#include "core/flight/flight_soa.hpp"

#include <cmath>

namespace sweetspot::core::flight::stepper {

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

// The correctly rounded square root of each lane (as std::sqrt's): one AVX instruction.
SWEETSPOT_FLIGHT_AVX2 [[gnu::always_inline]] inline Vec Sqrt(Vec x) {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
  return __builtin_ia32_sqrtpd256(x);
#else
  return Vec{std::sqrt(x[0]), std::sqrt(x[1]), std::sqrt(x[2]), std::sqrt(x[3])};
#endif
}

// Derivative<K> (its kinds with spin decay) on 4 lanes: the same expressions, term by term.
template <Kind K>
SWEETSPOT_FLIGHT_AVX2 [[gnu::always_inline]] inline void SoaEvaluate(SoaLanes<K>& m, int j, Vec t, const Vec* s) {
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

// Hairer's contd5 coefficients of component i of the lanes' last attempt, as Conclude forms them.
template <Kind K>
SWEETSPOT_FLIGHT_AVX2 [[gnu::always_inline]] inline void SoaDense(const SoaLanes<K>& a, int i,
                                                                  Vec* r) {
  const Vec h = a.h;
  const auto& k = a.k;
  const Vec diff = a.y_new[i] - a.y[i];
  const Vec bspl = h * k[0][i] - diff;
  r[0] = a.y[i];
  r[1] = diff;
  r[2] = bspl;
  r[3] = diff - h * k[6][i] - bspl;
  r[4] = h * (d1 * k[0][i] + d3 * k[2][i] + d4 * k[3][i] + d5 * k[4][i] + d6 * k[5][i] +
              d7 * k[6][i]);
}

// RootOf on the lanes `lanes` of a vector (dense coefficients r, ends f0 and f1 of opposite
// signs): its first guess, Newton's iterations with its stopping rules, in its order of
// operations, lane by lane (a lane that stops is masked). Returns the lanes whose iterations
// fail (leave [0, 1], meet a zero derivative, or do not settle in 8): for those RootOf's regula
// falsi decides, on the scalar Lane (Conclude, from the start), so a lane's θ stays Fly's.
SWEETSPOT_FLIGHT_AVX2 [[gnu::always_inline]] inline VecMask SoaRoot(const Vec* r, Vec f0, Vec f1,
                                                                    VecMask lanes, Vec* root) {
  const Vec zero = {};
  const Vec secant = f0 / (f0 - f1);
  const Vec span = f1 - f0;
  const Vec slope0 = r[1] + r[2];
  const Vec slope1 = r[1] - r[2] - r[3];
  const Vec m0 = span / slope0, m1 = span / slope1;
  const Vec s = secant, u0 = 1.0 - s;
  const Vec hermite = s * u0 * u0 * m0 + s * s * (3.0 - 2.0 * s) - s * s * u0 * m1;
  const VecMask use_hermite =
      (m0 > zero) & (m1 > zero) & (hermite >= zero) & (hermite <= Splat(1.0));
  Vec theta = use_hermite ? hermite : secant;
  VecMask live = lanes, failed = VecMask{};
  for (int iter = 0; iter < 8; ++iter) {
    bool any = false;
    for (int m = 0; m < kSoaLanes; ++m) any = any || live[m] != 0;
    if (!any) break;
    const Vec u = 1.0 - theta;
    const Vec inner = r[3] + u * r[4];
    const Vec p = r[2] + theta * inner;
    const Vec q = r[1] + u * p;
    const Vec dp = inner - theta * r[4];
    const Vec dq = -p + u * dp;
    const Vec f = r[0] + theta * q;
    const Vec df = q + theta * dq;
    live &= ~(f == zero);  // a root: θ as it is
    const VecMask flat = live & ~(df != zero);  // RootOf's break: the fallback
    failed |= flat;
    live &= ~flat;
    const Vec step = f / df;
    const Vec next = theta - step;
    theta = live ? next : theta;
    const VecMask out = live & ~((next >= zero) & (next <= Splat(1.0)));
    failed |= out;
    live &= ~out;
    live &= ~(Abs(step) < Splat(1e-7));  // converged
  }
  *root = theta;
  return failed | live;  // not settled in 8 iterations: the fallback
}

// Dense::Component of coefficients r at θ.
SWEETSPOT_FLIGHT_AVX2 [[gnu::always_inline]] inline Vec SoaComponent(const Vec* r, Vec theta) {
  const Vec u = 1.0 - theta;
  return r[0] + theta * (r[1] + u * (r[2] + theta * (r[3] + u * r[4])));
}

// Conclude's apex on the lanes `lanes` of an accepted step (vz crosses zero going down): the
// root of vz (SoaRoot), z there, and the apex update. Returns the lanes left to Conclude.
template <Kind K>
SWEETSPOT_FLIGHT_AVX2 [[gnu::always_inline]] inline VecMask SoaApex(SoaLanes<K>& a,
                                                                    VecMask lanes) {
  Vec v[5], z[5], theta;
  SoaDense(a, 5, v);
  const VecMask failed = SoaRoot(v, a.y[5], a.y_new[5], lanes, &theta);
  SoaDense(a, 2, z);
  const Vec height = SoaComponent(z, theta);
  const VecMask higher = lanes & ~failed & (height > a.apex_m);
  a.apex_m = higher ? height : a.apex_m;
  a.apex_time_s = higher ? a.t + theta * a.h : a.apex_time_s;
  return failed;
}

#define SWEETSPOT_GROUPS for (int g = 0; g < kSoaGroups; ++g)
#define SWEETSPOT_GROUP       \
  SoaLanes<K>& a = groups[g]; \
  const Vec t = a.t, h = a.h; \
  const auto& k = a.k;        \
  (void)t;                    \
  (void)h;                    \
  (void)k

// Start's first evaluation (Evaluate at t) for the lanes of each group whose flight has just
// started, here for 4 lanes at once, through k[6], which the attempt overwrites.
template <Kind K>
SWEETSPOT_FLIGHT_AVX2 [[gnu::always_inline]] inline void SoaFirstStage(SoaLanes<K>* groups) {
  constexpr int N = SoaLanes<K>::N;
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    bool any_fresh = false;
    for (int m = 0; m < kSoaLanes; ++m) any_fresh = any_fresh || a.fresh[m] != 0;
    if (any_fresh) {
      SoaEvaluate<K>(a, 6, t, a.y);
      for (int i = 0; i < N; ++i) a.k[0][i] = a.fresh ? a.k[6][i] : a.k[0][i];
      a.fresh = VecMask{};
    }
  }
}

// Attempt<K, L> on every group: the stages and y_new, each stage across the groups in turn
// (their chains independent, so the processor overlaps them).
template <Kind K>
SWEETSPOT_FLIGHT_AVX2 [[gnu::always_inline]] inline void SoaAttempt(SoaLanes<K>* groups) {
  constexpr int N = SoaLanes<K>::N;
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
      a.s[i] = a.y[i] +
               h * (a61 * k[0][i] + a62 * k[1][i] + a63 * k[2][i] + a64 * k[3][i] + a65 * k[4][i]);
    }
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    SoaEvaluate<K>(a, 5, t + h, a.s);
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    for (int i = 0; i < N; ++i) {
      a.y_new[i] = a.y[i] + h * (a71 * k[0][i] + a73 * k[2][i] + a74 * k[3][i] + a75 * k[4][i] +
                                 a76 * k[5][i]);
    }
  }
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    SoaEvaluate<K>(a, 6, t + h, a.y_new);
  }
}

#undef SWEETSPOT_GROUPS
#undef SWEETSPOT_GROUP

// ErrorOf<K> on group `g`'s 4 lanes, and on those whose attempt is accepted without an event
// Conclude<K> and AtLimit<K>; the others are marked in *special for the scalar code.
template <Kind K>
SWEETSPOT_FLIGHT_AVX2 [[gnu::always_inline]] inline void SoaConcludeGroup(
    SoaLanes<K>& a, int g, const SoaSettings& settings, SoaSpecial* special) {
  constexpr int N = SoaLanes<K>::N;
  const double rtol = settings.rtol, atol = settings.atol;
  const Vec t = a.t, h = a.h;
  const auto& k = a.k;
  const Vec zero = {};
  const Vec largest = Splat(std::numeric_limits<double>::max());
  Vec err2 = zero, position_err2 = zero, velocity_err2 = zero;
  VecMask finite = VecMask{} - 1;
  for (int i = 0; i < N; ++i) {
    const Vec e = h * (e1 * k[0][i] + e3 * k[2][i] + e4 * k[3][i] + e5 * k[4][i] + e6 * k[5][i] +
                       e7 * k[6][i]);
    const Vec yn = a.y_new[i];
    finite &= (Abs(yn) <= largest) & (Abs(e) <= largest);
    Vec scale;
    if (i < 6) {
      const Vec ay = Abs(a.y[i]), ayn = Abs(yn);
      scale = atol + rtol * (ay < ayn ? ayn : ay);  // std::max(|y|, |y_new|)
    } else {
      scale = Splat(rtol);
    }
    err2 += (e / scale) * (e / scale);
    if (i < 3) {
      position_err2 += e * e;
    } else if (i < 6) {
      velocity_err2 += e * e;
    }
  }
  a.finite = finite;
  a.control = ControlOf(Sqrt(err2 / 6.0), h, a.log_memory);
  a.position_error = Sqrt(position_err2);
  a.velocity_error = Sqrt(velocity_err2);
  // Conclude's cases: not finite, rejected (err > 1) or a landing in the step (its tests on y
  // and y_new), left to the scalar code; the rest accepted here, an apex in the step included
  // (SoaApex) unless its root needs the scalar fallback.
  const VecMask apex = (a.y[5] > zero) & (a.y_new[5] <= zero);
  const VecMask lands = (a.y_new[2] <= zero) & (a.y_new[5] < zero);
  const VecMask accepted = a.active & finite & ~(a.control.err > 1.0) & ~lands;
  VecMask plain = accepted;
  const VecMask apex_lanes = accepted & apex;
  bool any_apex = false;
  for (int m = 0; m < kSoaLanes; ++m) any_apex = any_apex || apex_lanes[m] != 0;
  if (any_apex) plain &= ~SoaApex(a, apex_lanes);
  // The landing's root for Conclude (which finishes a landing on the scalar Lane): z's.
  const VecMask landing_lanes = a.active & finite & ~(a.control.err > 1.0) & lands;
  bool any_landing = false;
  for (int m = 0; m < kSoaLanes; ++m) any_landing = any_landing || landing_lanes[m] != 0;
  a.landing_known = VecMask{};
  if (any_landing) {
    Vec z[5];
    SoaDense(a, 2, z);
    a.landing_known =
        landing_lanes & ~SoaRoot(z, a.y[2], a.y_new[2], landing_lanes, &a.landing_theta);
  }
  // Conclude on an accepted step without an event, in its order.
  a.evaluations = plain ? a.evaluations + 6.0 : a.evaluations;
  a.steps = plain ? a.steps + 1.0 : a.steps;
  a.error_sum = plain ? a.error_sum + a.position_error : a.error_sum;
  a.velocity_error_sum = plain ? a.velocity_error_sum + a.velocity_error : a.velocity_error_sum;
  a.velocity_error_time_sum = plain ? a.velocity_error_time_sum + a.velocity_error * (t + h)
                                    : a.velocity_error_time_sum;
  const Vec t_new = plain ? t + h : t;
  a.t = t_new;
  a.log_memory = plain ? a.control.log_memory : a.log_memory;
  const Vec h_new = plain ? a.control.h_accepted : h;
  for (int i = 0; i < N; ++i) {
    a.y[i] = plain ? a.y_new[i] : a.y[i];
    a.k[0][i] = plain ? a.k[6][i] : a.k[0][i];  // first same as last
  }
  // AtLimit before the next attempt: the lanes at a limit are left to the scalar code, the
  // others' steps bounded by the time left.
  const VecMask limit = plain & ((a.steps + a.rejected_steps >= settings.max_steps) |
                                 (t_new >= settings.max_flight_time_s));
  const Vec left = settings.max_flight_time_s - t_new;
  a.h = plain & ~limit & (left < h_new) ? left : h_new;  // std::min(h, left)
  const VecMask conclude = a.active & ~plain;
  for (int m = 0; m < kSoaLanes; ++m) {
    special->conclude |= (conclude[m] != 0 ? 1U : 0U) << (g * kSoaLanes + m);
    special->limit |= (limit[m] != 0 ? 1U : 0U) << (g * kSoaLanes + m);
  }
}

// Attempt<K, L>, ErrorOf<K> and, on the lanes whose attempt is accepted without an event,
// Conclude<K> and AtLimit<K> on the 4 lanes of each group at once.
template <Kind K>
SWEETSPOT_FLIGHT_AVX2 [[gnu::always_inline]] inline SoaSpecial SoaStep(
    SoaLanes<K>* groups, const SoaSettings& settings) {
  SoaFirstStage<K>(groups);
  SoaAttempt<K>(groups);
  SoaSpecial special;
  for (int g = 0; g < kSoaGroups; ++g) SoaConcludeGroup<K>(groups[g], g, settings, &special);
  return special;
}

// The kernels, compiled for AVX2 (without FMA), one non-template function per kind. Only run
// where the processor has AVX2 (SoaLanesPay): compiled for the baseline's SSE2 (two instructions
// per vector) the same stepper measured 0.81 µs per flight against the scalar lanes' 0.75–0.77
// (it gave the same answers to the bit).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
bool SoaLanesPay() { return __builtin_cpu_supports("avx2"); }
#else
bool SoaLanesPay() { return false; }
#endif
SWEETSPOT_FLIGHT_AVX2 SoaSpecial SoaStepSaturating(SoaLanes<Kind::kSaturating>* a,
                                                   const SoaSettings& settings) {
  return SoaStep<Kind::kSaturating>(a, settings);
}
SWEETSPOT_FLIGHT_AVX2 SoaSpecial SoaStepLinear(SoaLanes<Kind::kLinear>* a,
                                               const SoaSettings& settings) {
  return SoaStep<Kind::kLinear>(a, settings);
}

#pragma GCC diagnostic pop

}  // namespace sweetspot::core::flight::stepper
