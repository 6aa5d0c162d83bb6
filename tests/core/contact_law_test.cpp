// The ball's contact law (core/collision/contact_law.hpp) against its closed forms: the
// compression split, the loading work, the unloading exponent, the series spring and the
// contact scales.
#include "core/collision/contact_law.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "core/units.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace contact_law_test {
namespace {

constexpr double kBall = 4.0e7;     // k, N/m^p (the default ball)
constexpr double kSurface = 4.0e9;  // K, N/m^1.5 (about a wooden bat's surface)

TEST(ContactLaw, NewtonSplitMatchesTheQuadraticClosedFormForExponentThree) {
  // p = 3: delta_b + a delta_b^2 = delta with a = (k / K)^{2/3}, whose positive root is
  // 2 delta / (1 + sqrt(1 + 4 a delta)) (the cancellation-free form). The Newton iteration
  // stops when its step is below 1e-15 delta; each residual evaluation rounds at a few ulps:
  // 1e-14 relative is a safe bound.
  const double k = 1.0e9;  // N/m^3
  const BallPowerLaw law(k, 3.0, kSurface);
  const double a = std::cbrt((k / kSurface) * (k / kSurface));
  for (double d : {1e-9, 1e-6, 1e-4, 1e-3, 1e-2, 5e-2}) {
    const double closed = 2.0 * d / (1.0 + std::sqrt(1.0 + 4.0 * a * d));
    EXPECT_NEAR(law.BallShare(d) / closed, 1.0, 1e-14) << d;
    EXPECT_NEAR(law.LoadingForce(d) / (k * closed * closed * closed), 1.0, 4e-14) << d;
  }
}

TEST(ContactLaw, NewtonSplitInvertsTheLoadingCurveForEveryExponent) {
  // LoadingCompression(F) = (F/k)^{1/p} + (F/K)^{2/3} is explicit: the split solved by Newton
  // must reproduce delta from F = LoadingForce(delta). The iteration stops when its step in
  // delta_b is below 1e-15 delta; an error of that size in delta_b moves the total compression
  // by the derivative g' = 1 + a e delta_b^{e-1} (a = (k/K)^{2/3}, e = 2p/3), which exceeds 200
  // when the ball takes a tiny share (p = 1, delta = 1e-8). Bound: 1e-15 g' plus 1e-14 for the
  // roundings of pow and cbrt in the inverse.
  const double a = std::cbrt((kBall / kSurface) * (kBall / kSurface));
  for (double p : {1.0, 1.2, 2.0, 2.5, 3.0}) {
    const BallPowerLaw law(kBall, p, kSurface);
    const double e = 2.0 * p / 3.0;
    for (double d : {1e-8, 1e-5, 1e-3, 8e-3, 3e-2}) {
      const double f = law.LoadingForce(d);
      const double slope = 1.0 + a * e * std::pow(law.BallShare(d), e - 1.0);
      EXPECT_NEAR(law.LoadingCompression(f) / d, 1.0, 1e-15 * slope + 1e-14) << p << " " << d;
      EXPECT_NEAR(law.BallShare(d) / law.BallCompression(f), 1.0, 1e-14) << p << " " << d;
    }
  }
}

TEST(ContactLaw, ThreeHalvesSeriesSpringIsExact) {
  // p = 3/2: two 3/2-power springs in series are one, k_eff = (k^{-2/3} + K^{-2/3})^{-3/2},
  // and the ball's share is delta / (1 + (k/K)^{2/3}). Rounding only: 1e-14.
  const BallPowerLaw law(kBall, 1.5, kSurface);
  const double a = std::cbrt((kBall / kSurface) * (kBall / kSurface));
  const double k_eff =
      std::pow(std::cbrt(1.0 / (kBall * kBall)) + std::cbrt(1.0 / (kSurface * kSurface)), -1.5);
  for (double d : {1e-6, 1e-3, 8e-3}) {
    EXPECT_NEAR(law.BallShare(d) / (d / (1.0 + a)), 1.0, 1e-15) << d;
    EXPECT_NEAR(law.LoadingForce(d) / (k_eff * std::pow(d, 1.5)), 1.0, 1e-14) << d;
    EXPECT_NEAR(law.LoadingForce(d) / (kBall * std::pow(law.BallShare(d), 1.5)), 1.0, 1e-14);
  }
  // A rigid surface: the ball takes the whole compression.
  const BallPowerLaw rigid(kBall, 1.5, 0.0);
  EXPECT_EQ(rigid.BallShare(3e-3), 3e-3);
  EXPECT_NEAR(rigid.LoadingForce(3e-3) / (kBall * std::pow(3e-3, 1.5)), 1.0, 1e-15);
}

TEST(ContactLaw, LoadingWorkIsTheIntegralOfTheLoadingCurve) {
  // Rigid surface: W = k delta^{p+1} / (p + 1) exactly (rounding: 1e-14).
  for (double p : {1.0, 1.5, 2.5}) {
    const BallPowerLaw rigid(kBall, p, 0.0);
    const double d = 7e-3;
    EXPECT_NEAR(
        rigid.LoadingWork(rigid.LoadingForce(d), d) / (kBall * std::pow(d, p + 1.0) / (p + 1.0)),
        1.0, 1e-13)
        << p;
  }
  // In series with the surface: against composite Simpson in u = sqrt(delta) (the substitution
  // makes the integrand 2 u F(u^2), smooth at 0): 4000 intervals give ~1e-12; 1e-10 is safe.
  for (double p : {1.2, 2.0}) {
    const BallPowerLaw law(kBall, p, kSurface);
    const double d = 8e-3;
    const int n = 4000;
    const double umax = std::sqrt(d);
    const double h = umax / n;
    double sum = 0.0;
    for (int i = 0; i <= n; ++i) {
      const double u = i * h;
      const double w = (i == 0 || i == n) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
      sum += w * 2.0 * u * law.LoadingForce(u * u);
    }
    const double simpson = sum * h / 3.0;
    EXPECT_NEAR(law.LoadingWork(law.LoadingForce(d), d) / simpson, 1.0, 1e-10) << p;
  }
}

TEST(ContactLaw, UnloadingReturnsCorSquaredOfTheLoadingWork) {
  // The unloading curve F_max (delta/delta_max)^q returns F_max delta_max / (q + 1), which must
  // be e^2 W_load (algebraic identity: rounding, 1e-14).
  const BallPowerLaw law(kBall, 1.5, kSurface);
  const double d = 8e-3;
  const double f = law.LoadingForce(d);
  for (double e : {0.1, 0.5, 1.0}) {
    ContactBranch branch;
    branch.StartUnloading(law, d, f, e);
    EXPECT_TRUE(branch.unloading);
    const double returned = f * d / (branch.exponent + 1.0);
    EXPECT_NEAR(returned / (e * e * law.LoadingWork(f, d)), 1.0, 1e-14) << e;
    // Below delta_max the unloading curve, at and above it the virgin curve.
    EXPECT_NEAR(branch.Force(law, 0.5 * d), f * std::pow(0.5, branch.exponent), 1e-12 * f);
    EXPECT_EQ(branch.Force(law, 1.5 * d), law.LoadingForce(1.5 * d));
  }
  // e = 1: elastic, the unloading exponent is the loading one for a single power law.
  const BallPowerLaw single(kBall, 1.5, 0.0);
  EXPECT_NEAR(single.UnloadingExponent(single.LoadingForce(d), d, 1.0), 1.5, 1e-13);
}

TEST(ContactLaw, SeriesSpringForceMatchesTheLinearClosedForm) {
  // p = 1 on a rigid surface in series with c: d = F/k + c F, F = d / (1/k + c).
  const double k = 2.0e6;  // N/m
  const BallPowerLaw law(k, 1.0, 0.0);
  const ContactBranch loading;
  const double c = 3.0e-7;  // m/N
  double warm = 0.0;
  for (double d : {1e-6, 1e-3, 1e-2}) {
    // The Newton stop: |g| <= 4 eps d or a step below 1e-14 F: 1e-13 relative is safe.
    EXPECT_NEAR(SeriesContactForce(law, loading, c, d, &warm) / (d / (1.0 / k + c)), 1.0, 1e-13)
        << d;
    EXPECT_GT(warm, 0.0);  // the cache holds the root
  }
  // Nonlinear law, cold and warm starts: the residual compression(F) + c F - d vanishes.
  const BallPowerLaw ball(kBall, 2.0, kSurface);
  for (double start : {0.0, 1e9, 123.0}) {
    double w = start;
    const double d = 5e-3;
    const double f = SeriesContactForce(ball, loading, c, d, &w);
    EXPECT_NEAR((ball.LoadingCompression(f) + c * f) / d, 1.0, 1e-13) << start;
  }
  // No spring: the contact's own force.
  double w = 0.0;
  EXPECT_EQ(SeriesContactForce(ball, loading, 0.0, 5e-3, &w), ball.LoadingForce(5e-3));
}

TEST(ContactLaw, SeriesSpringForceOnBothBranchesOfTheHertzBall) {
  // p = 3/2 on a Hertz surface (the flexible model's law): loading takes the one-spring path
  // (LoadingCompressionThreeHalves), unloading F_max (delta/delta_max)^q; Halley's iteration
  // returns without a last evaluation once its step is below 1e-6 F. The residual
  // compression(F) + c F - d must vanish to round-off whatever the start (1e-14: a few ulps of
  // d from the compression's cbrt or pow and the sum).
  const BallPowerLaw law(kBall, 1.5, kSurface);
  for (double f : {1.0, 2.5e3, 1.7e4}) {
    EXPECT_NEAR(law.LoadingCompressionThreeHalves(f) / law.LoadingCompression(f), 1.0, 1e-15) << f;
  }
  const double c = 3.0e-7;  // m/N
  const double d_max = 6e-3;
  ContactBranch unloading;
  unloading.StartUnloading(law, d_max, law.LoadingForce(d_max), 0.5);
  for (const ContactBranch& branch : {ContactBranch{}, unloading}) {
    for (double start : {0.0, 1e9, 123.0, 4.0e3}) {
      for (double d : {1e-6, 2e-3, 5.9e-3}) {
        double w = start;
        const double f = SeriesContactForce(law, branch, c, d, &w);
        double comp = 0.0, compliance = 0.0, rate = 0.0;
        branch.CompressionAndCompliance(law, f, &comp, &compliance, &rate);
        EXPECT_NEAR((comp + c * f) / d, 1.0, 1e-14) << branch.unloading << " " << start << " " << d;
        EXPECT_EQ(w, f);  // the cache holds the root
      }
    }
  }
}

TEST(ContactLaw, ComplianceAndItsRateMatchDifferences) {
  // d(delta)/dF and d2(delta)/dF2 on both branches against central differences of the
  // compression (step 1e-4 F: truncation ~1e-8 relative, rounding ~1e-12; 1e-7 covers both).
  const BallPowerLaw hertz(kBall, 1.5, kSurface);
  const BallPowerLaw steep(kBall, 2.0, kSurface);  // the two-term path
  for (const BallPowerLaw* law : {&hertz, &steep}) {
    ContactBranch unloading;
    unloading.StartUnloading(*law, 6e-3, law->LoadingForce(6e-3), 0.6);
    for (const ContactBranch& branch : {ContactBranch{}, unloading}) {
      const double f = 0.4 * law->LoadingForce(6e-3), h = 1e-4 * f;
      double d0, c0, r0, dp, cp, rp, dm, cm, rm;
      branch.CompressionAndCompliance(*law, f, &d0, &c0, &r0);
      branch.CompressionAndCompliance(*law, f + h, &dp, &cp, &rp);
      branch.CompressionAndCompliance(*law, f - h, &dm, &cm, &rm);
      EXPECT_NEAR((dp - dm) / (2.0 * h) / c0, 1.0, 1e-7) << branch.unloading;
      EXPECT_NEAR((cp - cm) / (2.0 * h) / r0, 1.0, 1e-7) << branch.unloading;
    }
  }
}

TEST(ContactLaw, ContactScalesOfALinearSpring) {
  // p = 1: a linear spring k against the inverse effective mass c11 is a harmonic oscillator
  // with omega = sqrt(k c11): compression amplitude v0 / omega, contact time pi / omega
  // (half a period). Closed forms through pow and tgamma: 1e-14.
  const double c11 = 8.0, k = 2.0e6, v0 = 40.0;
  const double omega = std::sqrt(k * c11);
  EXPECT_NEAR(ContactCompressionScaleM(c11, k, 1.0, v0) / (v0 / omega), 1.0, 1e-14);
  EXPECT_NEAR(ElasticContactTimeS(c11, k, 1.0, v0) / (kPi / omega), 1.0, 1e-14);
  // p = 3/2: delta_max = (5 v0^2 / (4 c11 k))^{2/5} (the Hertz impact).
  EXPECT_NEAR(ContactCompressionScaleM(c11, kBall, 1.5, v0) /
                  std::pow(5.0 * v0 * v0 / (4.0 * c11 * kBall), 0.4),
              1.0, 1e-14);
}

}  // namespace
}  // namespace contact_law_test
}  // namespace sweetspot::core
