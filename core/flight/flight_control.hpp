// The flight's step controller (internal to core/flight): Hairer's DOPRI5 PI control written
// without libm, once for a double (Fly) and once for a vector of 4 lanes (FlyMany's kernel), so
// that both take the same step sizes to the bit. Included by flight_stepper.hpp.
#pragma once

#include <bit>
#include <type_traits>

namespace sweetspot::core::flight::stepper {

// The step controller (Hairer's DOPRI5: PI control with β = 0.04) without libm, so that FlyMany's
// vector kernel runs it on 4 lanes at once and Fly runs the same arithmetic on one: the
// controller's err^0.17 · facold^−0.04 and err^−0.2 as an exp of logarithms, with the log and
// exp below (a few additions and multiplications, no call). Written once for a double and for a
// vector of 4 (Vec), so that Fly's and FlyMany's step sizes are the same to the bit.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
typedef double Vec __attribute__((vector_size(32)));
typedef long long VecMask __attribute__((vector_size(32)));
typedef unsigned long long VecBits __attribute__((vector_size(32)));
#pragma GCC diagnostic pop

[[gnu::always_inline]] inline unsigned long long Bits(double x) {
  return std::bit_cast<unsigned long long>(x);
}
[[gnu::always_inline]] inline double FromBits(unsigned long long b) {
  return std::bit_cast<double>(b);
}
[[gnu::always_inline]] inline VecBits Bits(Vec x) { return reinterpret_cast<VecBits>(x); }
[[gnu::always_inline]] inline Vec FromBits(VecBits b) { return reinterpret_cast<Vec>(b); }
template <class T>
[[gnu::always_inline]] inline T Broadcast(double x) {
  if constexpr (std::is_same_v<T, double>) {
    return x;
  } else {
    return T{x, x, x, x};
  }
}
// std::max's and std::clamp's order of comparison (a lane's NaN goes the same way).
template <class T>
[[gnu::always_inline]] inline T Max(T a, T b) {
  return a < b ? b : a;
}
template <class T>
[[gnu::always_inline]] inline T Clamp(T v, T lo, T hi) {
  return v < lo ? lo : (hi < v ? hi : v);
}

// ln x for a positive finite x (the controller's: x ≥ 1e-10). x = 2^k·z with z in [0.707, 1.414)
// (musl's reduction), ln z = 2·atanh(s), s = (z − 1)/(z + 1), |s| ≤ 0.1716, by its series to s¹³
// (truncation below 5e-13): a step size's factor to 1e-12 relative, where 1e-3 would do.
template <class T>
[[gnu::always_inline]] inline T ControllerLog(T x) {
  constexpr unsigned long long kOff = 0x3fe6a09e667f3bcdULL;  // bits of √½
  const auto ix = Bits(x);
  const auto tmp = ix - kOff;
  // The exponent k + 2048 by a logical shift (AVX2 has no 64-bit arithmetic one), made a double
  // exactly through the bits of 2^52 + (k + 2048).
  const auto biased = (tmp + 0x8000000000000000ULL) >> 52;
  const T k = FromBits(biased | 0x4330000000000000ULL) - (4503599627370496.0 + 2048.0);
  const T z = FromBits(ix - (tmp & 0xfff0000000000000ULL));
  const T f = z - 1.0;
  const T s = f / (2.0 + f);
  const T w = s * s;
  // w·(1/3 + w/5 + … + w⁵/13) by Estrin's scheme (a shorter chain than Horner's).
  const T w2 = w * w;
  const T r = w * ((1.0 / 3 + w * (1.0 / 5)) +
                   w2 * ((1.0 / 7 + w * (1.0 / 9)) + w2 * (1.0 / 11 + w * (1.0 / 13))));
  return k * 0.69314718055994530942 + (2.0 * s + 2.0 * s * r);
}

// exp y for y in [−4, 1] (the controller's: 0.17·ln err − 0.04·ln facold is in [−3.92, 0.37]
// for an accepted step, −0.2·ln err is bounded to [−3, 0] for a rejected one): y = n·ln 2 + r, |r| ≤ 0.347, e^r by its Taylor
// series to r¹⁰ (truncation below 3e-13), 2^n from the bits of the rounding's magic number.
template <class T>
[[gnu::always_inline]] inline T ControllerExp(T y) {
  constexpr double kMagic = 6755399441055744.0;  // 1.5·2^52: t − kMagic is y/ln 2 rounded
  const T t = y * 1.4426950408889634074 + kMagic;
  const T n = t - kMagic;
  const T r = (y - n * 6.93147180369123816490e-01) - n * 1.90821492927058770002e-10;
  // Σ r^j/j! by Estrin's scheme (a shorter chain than Horner's).
  const T r2 = r * r, r4 = r2 * r2;
  const T p = ((1.0 + r) + r2 * (1.0 / 2 + r * (1.0 / 6))) +
              r4 * (((1.0 / 24 + r * (1.0 / 120)) + r2 * (1.0 / 720 + r * (1.0 / 5040))) +
                    r4 * ((1.0 / 40320 + r * (1.0 / 362880)) + r2 * (1.0 / 3628800)));
  // The low bits of t hold n; (n + 1023) << 52 is 2^n's bits.
  return p * FromBits((Bits(t) + 1023) << 52);
}

// The controller's floors: err is taken as at least 1e-10, and the memory of the last step's
// err as at least 1e-4 (Hairer's DOPRI5), the latter as its logarithm.
constexpr double kMinError = 1e-10;
constexpr double kLogMinErrorMemory = -9.210340371976182;  // ln 1e-4

// What the controller makes of an attempt with step h and error norm err = √(err2/6) (err2 the
// sum of the scaled components' squares, ErrorOf): if rejected (err > 1) the next attempt's
// h·max(0.2, 0.9·err^−0.2); if accepted the next step's h·clamp(0.9/fac, 0.2, 10) with
// fac = max(err, 1e-10)^0.17 · facold^−0.04 (facold = max(err, 1e-4) of the last accepted step,
// `log_memory` its logarithm, updated to this step's). A lane's numbers are unread where its
// decision does not use them (a rejected lane's accepted step, say).
template <class T>
struct Control {
  T err, h_rejected, h_accepted, log_memory;
};
template <class T>
[[gnu::always_inline]] inline T LogErrorOf(T err) {
  return ControllerLog(Max(err, Broadcast<T>(kMinError)));
}
template <class T>
[[gnu::always_inline]] inline T RejectedStep(T h, T log_err) {
  // Below −3 the factor 0.9·e^y is under the 0.2 floor: the argument is bounded there.
  return h * Max(Broadcast<T>(0.2), 0.9 * ControllerExp(Max(-0.2 * log_err, Broadcast<T>(-3.0))));
}
template <class T>
[[gnu::always_inline]] inline T AcceptedStep(T h, T log_err, T log_memory) {
  const T fac = ControllerExp((0.2 - 0.04 * 0.75) * log_err - 0.04 * log_memory);
  return h * Clamp(0.9 / fac, Broadcast<T>(0.2), Broadcast<T>(10.0));
}
template <class T>
[[gnu::always_inline]] inline T MemoryOf(T log_err) {
  return Max(log_err, Broadcast<T>(kLogMinErrorMemory));
}
// All of it, for FlyMany's vector lanes (Fly's Conclude computes only the part its decision
// reads, with the same functions).
template <class T>
[[gnu::always_inline]] inline Control<T> ControlOf(T err, T h, T log_memory) {
  const T log_err = LogErrorOf(err);
  return {err, RejectedStep(h, log_err), AcceptedStep(h, log_err, log_memory), MemoryOf(log_err)};
}

}  // namespace sweetspot::core::flight::stepper
