// The flexible impact between contacts: the exact free motion of the modes, the hands' loads
// along it and the search for a further contact (flexible_modal_system.hpp).
#include <algorithm>
#include <cmath>
#include <exception>
#include <vector>

#include <boost/math/tools/roots.hpp>

#include "core/collision/flexible_modal_system.hpp"
#include "core/geometry_format.hpp"
#include "core/units.hpp"

namespace sweetspot::core::flexible_detail {
namespace {

constexpr double kTwoPi = 2.0 * kPi;
// The longest free flight scanned for a further contact when the bat's rigid recoil does not
// bound it, s.
constexpr double kMaxFreeFlightS = 0.05;
// A gap below this (scaled by the compression scale) counts as touching.
constexpr double kTouch = 1e-12;

}  // namespace

// Exact free motion over dtau (scaled): ballistic ball, rigid modes linear, flexible harmonic.
void FreeAdvance(const Rhs& rhs, double dtau, State* y) {
  State& s = *y;
  s[0] += s[1] * dtau;
  for (int k = 0; k < rhs.model->n; ++k) {
    const std::size_t i = static_cast<std::size_t>(rhs.Q(k));
    const std::size_t j = static_cast<std::size_t>(rhs.QD(k));
    const double om = rhs.model->omega_hat[static_cast<std::size_t>(k)];
    if (om == 0.0) {
      s[i] += s[j] * dtau;
    } else {
      const double c = std::cos(om * dtau), sn = std::sin(om * dtau);
      const double q = s[i], qd = s[j];
      s[i] = q * c + qd / om * sn;
      s[j] = -q * om * sn + qd * c;
    }
  }
}

// Samples the hands' loads along free motion from y over [0, window] (scaled) and updates the
// peaks (rotation recurrences: no trigonometry per sample).
void FreeHandsPeaks(const Rhs& rhs, const State& y, double window, double dtau, RawRun* run) {
  const Model& md = *rhs.model;
  const int n = md.n;
  if (!(window > 0.0) || !(dtau > 0.0)) return;
  // Clamp in double before the cast (no overflow for any ratio).
  const long samples = static_cast<long>(std::min(std::ceil(window / dtau), 2e6));
  // In free motion q_k = q0 cos(om t) + qd0 / om sin(om t) and the hands' loads are sums of
  // -scale om^2 q_k weighted by S_k and T_k: per flexible mode, shear = a_k c_k + b_k s_k and
  // moment = am_k c_k + bm_k s_k with (c_k, s_k) = (cos, sin)(om_k t) by rotation recurrences
  // (the rigid modes do not accelerate in free motion and are left out).
  const double scale = rhs.delta_s * std::sqrt(rhs.m) / (rhs.t_s * rhs.t_s);
  std::vector<double> c, s, cd, sd, a, b, am, bm;
  for (int k = 0; k < n; ++k) {
    const std::size_t ks = static_cast<std::size_t>(k);
    const double om = md.omega_hat[ks];
    if (om == 0.0) continue;
    const double q0 = y[static_cast<std::size_t>(rhs.Q(k))];
    const double qd0 = y[static_cast<std::size_t>(rhs.QD(k))];
    const double acc_c = -scale * om * om * q0, acc_s = -scale * om * qd0;
    c.push_back(1.0);
    s.push_back(0.0);
    cd.push_back(std::cos(om * dtau));
    sd.push_back(std::sin(om * dtau));
    a.push_back(md.shear[ks] * acc_c);
    b.push_back(md.shear[ks] * acc_s);
    am.push_back(md.moment[ks] * acc_c);
    bm.push_back(md.moment[ks] * acc_s);
  }
  const std::size_t nf = c.size();
  double peak_v = run->peak_shear_n, peak_mo = run->peak_moment_n_m;
  for (long i = 1; i <= samples; ++i) {
    double v = 0.0, mo = 0.0;
    for (std::size_t k = 0; k < nf; ++k) {
      const double cn = c[k] * cd[k] - s[k] * sd[k];
      const double sn = s[k] * cd[k] + c[k] * sd[k];
      c[k] = cn;
      s[k] = sn;
      v += a[k] * cn + b[k] * sn;
      mo += am[k] * cn + bm[k] * sn;
    }
    peak_v = std::max(peak_v, std::abs(v));
    peak_mo = std::max(peak_mo, std::abs(mo));
  }
  run->peak_shear_n = peak_v;
  run->peak_moment_n_m = peak_mo;
}

// The first time (scaled, > 0) the free motion from y closes the gap again, or a negative value.
double FindRecontact(const Rhs& rhs, const State& y, std::vector<std::string>* warnings) {
  const Model& md = *rhs.model;
  double v_rigid = y[1], amplitude = 0.0, om_max = 0.0;
  for (int k = 0; k < md.n; ++k) {
    const std::size_t ks = static_cast<std::size_t>(k);
    const double om = md.omega_hat[ks];
    const double q = y[static_cast<std::size_t>(rhs.Q(k))];
    const double qd = y[static_cast<std::size_t>(rhs.QD(k))];
    if (om == 0.0) {
      v_rigid -= md.phi_hat[ks] * qd;
    } else {
      amplitude += std::abs(md.phi_hat[ks]) * std::hypot(q, qd / om);
      om_max = std::max(om_max, om);
    }
  }
  const double d0 = rhs.Delta(y);
  // delta(tau) <= d0 + v_rigid tau + 2 A: no contact once that is negative.
  double horizon = kMaxFreeFlightS / rhs.t_s;
  if (v_rigid < 0.0) {
    horizon = std::min(horizon, (std::max(d0, 0.0) + 2.0 * amplitude) / -v_rigid);
  } else {
    warnings->push_back(
        "after a separation the ball does not move away from the bat's rigid-body recoil (a "
        "soft, far-from-the-centre impact); a later contact was looked for during " +
        FormatNumber17(kMaxFreeFlightS) +
        " s only, beyond which the swing's rotation would matter");
  }
  if (!(horizon > 0.0)) return -1.0;
  const double dtau = om_max > 0.0 ? kTwoPi / (kSamplesPerPeriod * om_max) : horizon;
  const double wanted_samples = std::ceil(horizon / dtau);
  const long samples = static_cast<long>(std::min(wanted_samples, 2e6));
  if (wanted_samples > 2e6) {
    warnings->push_back("the search for a further contact was cut at 2e6 samples");
  }
  State work = y;
  auto gap = [&](double tau) {
    work = y;
    FreeAdvance(rhs, tau, &work);
    return rhs.Delta(work);
  };
  // The scan by rotation recurrences (no trigonometry per sample, as FreeHandsPeaks): the
  // gap is d0 + v_ball t - sum_k phi_k q_k(t); a sample that looks open is confirmed with the
  // exact motion (gap), which also brackets the root.
  const int n = md.n;
  std::vector<double> c(static_cast<std::size_t>(n), 1.0), sn(static_cast<std::size_t>(n), 0.0),
      cd(static_cast<std::size_t>(n)), sd(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double om = md.omega_hat[static_cast<std::size_t>(k)];
    cd[static_cast<std::size_t>(k)] = std::cos(om * dtau);
    sd[static_cast<std::size_t>(k)] = std::sin(om * dtau);
  }
  auto scan_gap = [&](double t) {
    double w = 0.0;
    for (int k = 0; k < n; ++k) {
      const std::size_t ks = static_cast<std::size_t>(k);
      const double cn = c[ks] * cd[ks] - sn[ks] * sd[ks];
      const double snn = sn[ks] * cd[ks] + c[ks] * sd[ks];
      c[ks] = cn;
      sn[ks] = snn;
      const double om = md.omega_hat[ks];
      const double q0 = y[static_cast<std::size_t>(rhs.Q(k))];
      const double qd0 = y[static_cast<std::size_t>(rhs.QD(k))];
      w += md.phi_hat[ks] * (om == 0.0 ? q0 + qd0 * t : q0 * cn + qd0 / om * snn);
    }
    return y[0] + y[1] * t - w;
  };
  double t_prev = 0.0, g_prev = d0;
  for (long i = 1; i <= std::min(samples, 2000000L); ++i) {
    const double t = std::min(horizon, i * dtau);
    const double g_scan = scan_gap(i * dtau);
    const double g = g_scan > 0.5 * kTouch ? gap(t) : g_scan;
    if (g > kTouch) {
      g_prev = gap(t_prev);
      boost::uintmax_t iters = 100;
      try {
        const auto r =
            boost::math::tools::toms748_solve(gap, t_prev, t, std::min(g_prev, 0.0), g,
                                              boost::math::tools::eps_tolerance<double>(52), iters);
        return r.second;
      } catch (const std::exception&) {
        return t;
      }
    }
    t_prev = t;
    g_prev = g;
  }
  return -1.0;
}

}  // namespace sweetspot::core::flexible_detail
