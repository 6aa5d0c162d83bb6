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
// step's bookkeeping (the controller's log and exp, the events, the refill) stays per lane on
// the scalar Lane; an idle lane computes on its last numbers, its results unread (masked).
// The vectors never cross a call's boundary (the kernels take them in SoaLanes): GCC's note on
// the ABI of 32-byte vectors without AVX does not apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
typedef double Vec __attribute__((vector_size(32)));
typedef long long VecMask __attribute__((vector_size(32)));
constexpr int kSoaLanes = 4;                           // a vector's lanes
constexpr int kSoaGroups = kFlyManyLanes / kSoaLanes;  // vectors side by side (2: two chains)
static_assert(kSoaGroups * kSoaLanes == kFlyManyLanes, "FlyMany's lanes are whole vectors");

[[gnu::always_inline]] inline Vec Splat(double x) { return Vec{x, x, x, x}; }

[[gnu::always_inline]] inline Vec Abs(Vec x) {
  return reinterpret_cast<Vec>(reinterpret_cast<VecMask>(x) & (VecMask{} + 0x7fffffffffffffffLL));
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

// The kernels, compiled for AVX2 (without FMA), one non-template function per kind
// (flight_soa.cpp); SoaLanesPay: whether this processor runs them (it has AVX2).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define SWEETSPOT_FLIGHT_AVX2 __attribute__((target("avx2")))
#else
#define SWEETSPOT_FLIGHT_AVX2
#endif
bool SoaLanesPay();
SWEETSPOT_FLIGHT_AVX2 void SoaAttemptSaturating(SoaLanes<Kind::kSaturating>* a, double rtol,
                                                double atol, SoaError* out);
SWEETSPOT_FLIGHT_AVX2 void SoaAttemptLinear(SoaLanes<Kind::kLinear>* a, double rtol, double atol,
                                            SoaError* out);

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

}  // namespace sweetspot::core::flight::stepper
