// FlyMany's vector lanes: the stepper's stage and error arithmetic on 4 lanes at once
// (flight_soa.hpp; docs/flight.md, "Where a flight's time goes").
#include "core/flight/flight_soa.hpp"

#include <cmath>

namespace sweetspot::core::flight::stepper {

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

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
#define SWEETSPOT_GROUP       \
  SoaLanes<K>& a = groups[g]; \
  const Vec t = a.t, h = a.h; \
  const auto& k = a.k;        \
  (void)t;                    \
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
  const Vec zero = {};
  const Vec largest = Splat(std::numeric_limits<double>::max());
  SWEETSPOT_GROUPS {
    SWEETSPOT_GROUP;
    SoaError* out = &outs[g];
    out->err2 = out->position_err2 = out->velocity_err2 = zero;
    out->finite = VecMask{} - 1;
    for (int i = 0; i < N; ++i) {
      const Vec e = h * (e1 * k[0][i] + e3 * k[2][i] + e4 * k[3][i] + e5 * k[4][i] + e6 * k[5][i] +
                         e7 * k[6][i]);
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
bool SoaLanesPay() { return __builtin_cpu_supports("avx2"); }
#else
bool SoaLanesPay() { return false; }
#endif
SWEETSPOT_FLIGHT_AVX2 void SoaAttemptSaturating(SoaLanes<Kind::kSaturating>* a, double rtol,
                                                double atol, SoaError* out) {
  SoaAttempt<Kind::kSaturating>(a, rtol, atol, out);
}
SWEETSPOT_FLIGHT_AVX2 void SoaAttemptLinear(SoaLanes<Kind::kLinear>* a, double rtol, double atol,
                                            SoaError* out) {
  SoaAttempt<Kind::kLinear>(a, rtol, atol, out);
}

#pragma GCC diagnostic pop

}  // namespace sweetspot::core::flight::stepper
