// FlyMany's vector lanes (flight_soa.cpp): the lanes' state as a structure of arrays, the
// kernels' declarations and the driver FlyLanesSoa. Internal to core/flight.
#pragma once

#include <cstddef>

#include "core/flight/flight.hpp"
#include "core/flight/flight_stepper.hpp"

namespace sweetspot::core::flight::stepper {

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
// kernel also does the step's bookkeeping on every lane whose attempt is accepted and does not
// land (the controller, without libm: ControlOf; the error sums; the apex's root: SoaApex);
// the scalar Lane and Conclude take only a rejection, a landing, a limit and the refill; an
// idle lane computes on its last numbers, its results unread (masked).
// The vectors never cross a call's boundary (the kernels take them in SoaLanes): GCC's note on
// the ABI of 32-byte vectors without AVX does not apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
constexpr int kSoaLanes = 4;                           // a vector's lanes
constexpr int kSoaGroups = kFlyManyLanes / kSoaLanes;  // vectors side by side (2: two chains)
static_assert(kSoaGroups * kSoaLanes == kFlyManyLanes, "FlyMany's lanes are whole vectors");

[[gnu::always_inline]] inline Vec Splat(double x) { return Vec{x, x, x, x}; }

[[gnu::always_inline]] inline Vec Abs(Vec x) {
  return reinterpret_cast<Vec>(reinterpret_cast<VecMask>(x) & (VecMask{} + 0x7fffffffffffffffLL));
}

template <Kind K>
struct SoaLanes {
  static constexpr int N = kComponents<K>;
  Vec y[N] = {}, y_new[N] = {}, s[N] = {};
  Vec k[7][N] = {};
  // Model's fields that Derivative reads, per lane.
  Vec k_cd0 = {}, k_cd_spin = {}, k_slope_spin = {}, k_cl2_spin = {}, cl0 = {}, cl1_spin = {},
      decay_rate_per_m = {}, ux = {}, uy = {}, uz = {}, wind_x = {}, wind_y = {};
  // The flights' integrator state between steps (Lane's fields of the same names; here the
  // lanes' own, copied to a Lane only when its step needs Conclude, and back).
  Vec t = {}, h = {};   // times and the next attempts' steps (s)
  Vec log_memory = {};  // Lane::log_previous_error_ratio
  Vec error_sum = {}, velocity_error_sum = {}, velocity_error_time_sum = {};
  Vec steps = {}, rejected_steps = {}, evaluations = {};  // FlightResult's counts, as doubles
  Vec apex_m = {}, apex_time_s = {};  // FlightResult's apex so far
  // The landing's θ in the last attempt (RootOf's), where landing_known.
  Vec landing_theta = {};
  VecMask landing_known = {};
  VecMask active = {};  // all ones where the lane flies a flight
  VecMask fresh = {};   // all ones where its flight has just started: k[0] is not yet f(t, y)
  // The last attempt's error norm and controller (read by Conclude on the lanes it concludes).
  Control<Vec> control = {};
  Vec position_error = {}, velocity_error = {};
  VecMask finite = {};
};

// The shared limits of one FlyMany call, for the kernel.
struct SoaSettings {
  double rtol, atol, max_steps, max_flight_time_s;
};

// What a kernel call leaves to the scalar code, one bit per lane (bit l = lane l of FlyMany's
// kFlyManyLanes): `conclude`, the lanes whose attempt was rejected, not finite, lands, or has an
// apex whose root needs RootOf's fallback — Conclude decides them; `limit`, the lanes whose
// accepted step put them at the time or step limit (AtLimit ends them).
struct SoaSpecial {
  unsigned conclude = 0, limit = 0;
};

// The kernels, compiled for AVX2 (without FMA), one non-template function per kind
// (flight_soa.cpp); SoaLanesPay: whether this processor runs them (it has AVX2). One call: an
// attempt on every lane, its error norm and controller, and for the lanes whose attempt is
// accepted and not landing (most steps) all of Conclude's and AtLimit's bookkeeping, as vector
// operations in Conclude's order (so a lane's numbers are Fly's to the bit).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define SWEETSPOT_FLIGHT_AVX2 __attribute__((target("avx2")))
#else
#define SWEETSPOT_FLIGHT_AVX2
#endif
bool SoaLanesPay();
SWEETSPOT_FLIGHT_AVX2 SoaSpecial SoaStepSaturating(SoaLanes<Kind::kSaturating>* a,
                                                   const SoaSettings& settings);
SWEETSPOT_FLIGHT_AVX2 SoaSpecial SoaStepLinear(SoaLanes<Kind::kLinear>* a,
                                               const SoaSettings& settings);

template <Kind K>
SoaSpecial SoaStepOf(SoaLanes<K>* a, const SoaSettings& settings) {
  if constexpr (K == Kind::kSaturating) {
    return SoaStepSaturating(a, settings);
  } else {
    return SoaStepLinear(a, settings);
  }
}

// Lane l of `v` takes the flight just started on `lane` (its state and its model; the kernel
// evaluates its first stage), or (lane.r null) goes idle.
template <Kind K>
void SoaLoad(const Lane<K>& lane, int l, SoaLanes<K>* v) {
  v->active[l] = lane.r != nullptr ? -1 : 0;
  if (lane.r == nullptr) return;
  v->fresh[l] = -1;  // the kernel evaluates the first stage (Start left it)
  for (int i = 0; i < Lane<K>::N; ++i) v->y[i][l] = lane.y[i];
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

// Lane l's integrator state between steps: from the vectors to the Lane (In) and back (Out).
template <Kind K>
void SoaSyncIn(const SoaLanes<K>& v, int l, Lane<K>* lane) {
  Lane<K>& a = *lane;
  a.t = v.t[l];
  a.h = v.h[l];
  a.log_previous_error_ratio = v.log_memory[l];
  a.error_sum = v.error_sum[l];
  a.velocity_error_sum = v.velocity_error_sum[l];
  a.velocity_error_time_sum = v.velocity_error_time_sum[l];
  a.r->steps = static_cast<int>(v.steps[l]);
  a.r->rejected_steps = static_cast<int>(v.rejected_steps[l]);
  a.r->evaluations = static_cast<int>(v.evaluations[l]);
  a.r->apex_m = v.apex_m[l];
  a.r->apex_time_s = v.apex_time_s[l];
}
template <Kind K>
void SoaSyncOut(const Lane<K>& a, int l, SoaLanes<K>* v) {
  v->t[l] = a.t;
  v->h[l] = a.h;
  v->log_memory[l] = a.log_previous_error_ratio;
  v->error_sum[l] = a.error_sum;
  v->velocity_error_sum[l] = a.velocity_error_sum;
  v->velocity_error_time_sum[l] = a.velocity_error_time_sum;
  v->steps[l] = a.r->steps;
  v->rejected_steps[l] = a.r->rejected_steps;
  v->evaluations[l] = a.r->evaluations;
  v->apex_m[l] = a.r->apex_m;
  v->apex_time_s[l] = a.r->apex_time_s;
}

// FlyLanes<K, kFlyManyLanes> with the stepper's arithmetic on SoaLanes: the same flights in the
// same lanes, each lane's operations in the same order, the same answers. The scalar code runs
// only on a lane's exceptional steps (a rejection, its apex, its landing, a limit) and to start
// a flight.
template <Kind K, class StartFlight>
void FlyLanesSoa(std::size_t count, const FlightOptions& options, const StartFlight& start) {
  constexpr int N = Lane<K>::N;
  constexpr int L = kFlyManyLanes;
  Lane<K> lanes[L];
  SoaLanes<K> v[kSoaGroups];
  std::size_t next = 0;
  int active = 0;
  // Lane l takes the next flight whose input is valid and which is not at its limits (FlyLanes:
  // a flight is checked against its limits before each attempt), or goes idle.
  auto refill = [&](int l) {
    Lane<K>& a = lanes[l];
    if (a.r != nullptr) --active;
    a.r = nullptr;
    while (next < count) {
      if (start(next++, &a) && !AtLimit(a, options)) break;
      a.r = nullptr;
    }
    if (a.r != nullptr) {
      ++active;
      SoaSyncOut(a, l % kSoaLanes, &v[l / kSoaLanes]);
    }
    SoaLoad(a, l % kSoaLanes, &v[l / kSoaLanes]);
  };
  for (int l = 0; l < L; ++l) refill(l);
  const SoaSettings settings{options.relative_tolerance, options.absolute_tolerance_m,
                             static_cast<double>(options.max_steps), options.max_flight_time_s};
  while (active > 0) {
    const SoaSpecial special = SoaStepOf<K>(v, settings);
    for (unsigned bits = special.conclude | special.limit; bits != 0; bits &= bits - 1) {
      const int l = __builtin_ctz(bits);
      Lane<K>& a = lanes[l];
      SoaLanes<K>& w = v[l / kSoaLanes];
      const int m = l % kSoaLanes;
      SoaSyncIn(w, m, &a);
      if ((special.limit >> l) & 1U) {
        if (AtLimit(a, options)) refill(l);  // (it is: the kernel found it there)
        continue;
      }
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
      StepError error;
      error.finite = w.finite[m] != 0;
      error.control = {w.control.err[m], w.control.h_rejected[m], w.control.h_accepted[m],
                       w.control.log_memory[m]};
      error.position_error = w.position_error[m];
      error.velocity_error = w.velocity_error[m];
      error.controlled = true;
      a.landing_theta = w.landing_known[m] != 0 ? w.landing_theta[m] : -1.0;
      const Outcome outcome = Conclude(a, options, error);
      if (outcome == Outcome::kEnded) {
        refill(l);
        continue;
      }
      if (outcome == Outcome::kAccepted) {
        for (int i = 0; i < N; ++i) {
          w.y[i][m] = w.y_new[i][m];
          w.k[0][i][m] = w.k[6][i][m];  // first same as last
        }
      }
      if (AtLimit(a, options)) {
        refill(l);
      } else {
        SoaSyncOut(a, m, &w);
      }
    }
  }
}
#pragma GCC diagnostic pop

}  // namespace sweetspot::core::flight::stepper
