// The exit-speed closed forms templated on the scalar type (core/collision/exit_speed_algebra.hpp):
// the double path against the closed forms as they were written before the templates (a copy
// kept here as the reference), and the jet path's derivatives against finite differences.
#include "core/collision/exit_speed_algebra.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "core/collision/exit_speed_profile.hpp"
#include "core/collision/rigid_pivot.hpp"
#include "core/numerics/jet.hpp"

namespace sweetspot::core {
namespace {

// The reference: ExitSpeedProfile::Maximum and ::ZoneAround as written before the templates
// (exit_speed_profile.cpp at c2384e5), for a rigid pivot (w = u >= 0, omega > 0).
struct ExitSpeedAlgebraOld {
  double x, exit, lo, hi;
};
ExitSpeedAlgebraOld ExitSpeedAlgebraReference(const ExitSpeedProfile& p, double delta) {
  const double j = p.inertia_kg_m2, m = p.ball_mass_kg, w = p.approach_mps;
  const double omega = p.angular_speed_rad_s;
  const double s = std::hypot(w, omega * std::sqrt(j / m));
  const double ws = w + s;
  ExitSpeedAlgebraOld out{};
  out.x = omega * j / (m * ws);
  out.exit = -p.ball_speed_mps + p.gain_kg_m2 * ws / (2.0 * j);
  const double cg = out.exit + p.ball_speed_mps;
  const double a = m * (cg - delta);
  const double b = cg * m * out.x;
  const double c0 = cg * m * out.x * out.x - delta * j;
  const double disc = m * delta * (cg * (j + m * out.x * out.x) - delta * j);
  const double q = b + std::sqrt(disc);
  EXPECT_GT(a, 0.0);  // the cases below: tolerance below the peak
  out.lo = std::min(q / a, c0 / q);
  out.hi = std::max(q / a, c0 / q);
  return out;
}

std::vector<RigidPivotInputs> ExitSpeedAlgebraCases() {
  std::vector<RigidPivotInputs> cases;
  for (double j : {0.05, 0.2, 0.6}) {
    for (double omega : {5.0, 17.288, 60.0}) {
      for (double u : {0.0, 27.7, 45.0}) {
        RigidPivotInputs in;
        in.moi_pivot_kg_m2 = j;
        in.angular_speed_rad_s = omega;
        in.ball_speed_mps = u;
        in.cor = 0.5;
        cases.push_back(in);
      }
    }
  }
  return cases;
}

// The maximum (x*, f(x*)) is the same sequence of operations as before: bit for bit. The zone
// now takes c G from the maximum directly instead of (-u + c G) + u, which differs by at most
// 2 ulp of u + c G (two roundings); the zone's ends move by that relative change times their
// sensitivity to c G (order one here), so 1e-12 m (about 4500 ulp of a 1 m position) is ample.
TEST(ExitSpeedAlgebraTest, DoublePathMatchesTheClosedFormsItReplaced) {
  for (const RigidPivotInputs& in : ExitSpeedAlgebraCases()) {
    const ExitSpeedProfile p = RigidPivotProfile(in);
    const double delta = 1.0;
    const ExitSpeedAlgebraOld old = ExitSpeedAlgebraReference(p, delta);
    const ProfileMaximum mx = p.Maximum();
    EXPECT_EQ(mx.x_m, old.x);
    EXPECT_EQ(mx.exit_speed_mps, old.exit);
    const ProfileInterval zone = p.ZoneAround(delta);
    EXPECT_NEAR(zone.lo_m, old.lo, 1e-12);
    EXPECT_NEAR(zone.hi_m, old.hi, 1e-12);
    // f(x) itself: the same expression as before, bit for bit.
    const double x = 0.6;
    const double den = p.inertia_kg_m2 + p.ball_mass_kg * x * x;
    EXPECT_EQ(
        p.ExitSpeedMps(x),
        -p.ball_speed_mps + p.gain_kg_m2 * (p.approach_mps + p.angular_speed_rad_s * x) / den);
  }
}

using ExitSpeedAlgebraJet = jet::Jet<2, true>;  // variables: J (kg m^2), omega (rad/s)

// The peak, the sweet spot and the zone's width as functions of (J, omega), in any scalar.
template <typename T>
std::array<T, 3> ExitSpeedAlgebraOutputs(const T& j, const T& omega, double u) {
  const exit_speed::Form<T> form = exit_speed::RigidPivotForm(j, 0.145, u, omega, 0.5);
  const exit_speed::Maximum<T> mx = exit_speed::MaximumOf(form);
  const exit_speed::Zone<T> zone = exit_speed::ZoneAround(form, mx, T(1.0));
  return {mx.peak_mps - u, mx.x_m, zone.hi_m - zone.lo_m};
}

// Jet gradients and Hessians against central differences of the double path. With relative
// steps h = 1e-5 the truncation error is ~h^2 |f'''| ~ 1e-10 relative and the rounding error
// ~eps / h ~ 2e-11 relative (1e-6 for the second differences of gradients: eps / h^2 on values,
// here differences of exact jet gradients, so ~eps / h); 1e-7 relative covers both with margin.
TEST(ExitSpeedAlgebraTest, JetDerivativesMatchFiniteDifferences) {
  for (double u : {0.0, 27.7}) {
    for (double j0 : {0.05, 0.2, 0.6}) {
      for (double omega0 : {5.0, 17.288, 60.0}) {
        const auto out = ExitSpeedAlgebraOutputs(ExitSpeedAlgebraJet::Variable(j0, 0),
                                                 ExitSpeedAlgebraJet::Variable(omega0, 1), u);
        const double base[2] = {j0, omega0};
        for (int k = 0; k < 3; ++k) {
          const auto value = ExitSpeedAlgebraOutputs(j0, omega0, u);
          // The jet's value follows the double path, except that a Jet divides by multiplying
          // with the reciprocal (one more rounding per quotient): about ten operations, so at
          // most ~20 ulp (4.4e-15) relative; 1e-14 relative.
          EXPECT_NEAR(out[k].v, value[k], 1e-14 * std::abs(value[k])) << k;
          for (int i = 0; i < 2; ++i) {
            const double h = 1e-5 * base[i];
            double plus[2] = {j0, omega0}, minus[2] = {j0, omega0};
            plus[i] += h;
            minus[i] -= h;
            const double fd = (ExitSpeedAlgebraOutputs(plus[0], plus[1], u)[k] -
                               ExitSpeedAlgebraOutputs(minus[0], minus[1], u)[k]) /
                              (2.0 * h);
            const double g = out[k].g[i];
            EXPECT_NEAR(g, fd, 1e-7 * std::max(1.0, std::abs(g)) * std::max(1.0, 1.0 / base[i]))
                << "output " << k << " variable " << i;
            // Second derivatives: differences of the jet gradient along variable i.
            const auto gp = ExitSpeedAlgebraOutputs(ExitSpeedAlgebraJet::Variable(plus[0], 0),
                                                    ExitSpeedAlgebraJet::Variable(plus[1], 1), u);
            const auto gm = ExitSpeedAlgebraOutputs(ExitSpeedAlgebraJet::Variable(minus[0], 0),
                                                    ExitSpeedAlgebraJet::Variable(minus[1], 1), u);
            for (int l = 0; l < 2; ++l) {
              const double fd2 = (gp[k].g[l] - gm[k].g[l]) / (2.0 * h);
              const double hess = out[k].h[l * 2 + i];
              EXPECT_NEAR(
                  hess, fd2,
                  1e-6 * std::max(1.0, std::abs(hess)) * std::max(1.0, 1.0 / (base[i] * base[i])))
                  << "output " << k << " d2/d" << l << " d" << i;
            }
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace sweetspot::core
