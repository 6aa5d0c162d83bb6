// Batted-ball flight against published figures beyond Nathan's sheet (docs/validation.md, the
// flight rows): Hit Tracker's worked case of weather and wind, and what published work says of
// the distance-optimal undercut and attack angle (the oblique impact, core/collision, feeding the
// flight). Where the model does not match, the test pins the model's number and the doc says so.
#include <gtest/gtest.h>

#include <cmath>

#include "core/collision/oblique_impact.hpp"
#include "core/flight/flight.hpp"

namespace sweetspot::core::flight {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace flight_checks_test {
namespace {

double Feet(double m) { return m / kMetresPerFoot; }
double CelsiusOf(double fahrenheit) { return (fahrenheit - 32.0) * 5.0 / 9.0; }

// Hit Tracker's case (G. Rybarczyk, quoted by the Boston Globe, 2 May 2006; copy at
// econball.blogspot.com/2006/05/david-ortizs-hr-last-night.html): 120.7 mph at 37.7°, 46 °F,
// a 16 mph wind in from centre field; "impact from wind: −54 feet", "impact from temperature:
// −12 feet (as compared to a 70 degree day)", 460 ft "standard distance" (70 °F, calm), and
// 509 ft with the wind blowing out instead. Hit Tracker does not publish the spin it assumes:
// the checks run at 2000 and 3000 rpm of backspin.
TEST(FlightChecks, HitTrackerWeatherAndWindCase) {
  for (double backspin : {2000.0, 3000.0}) {
    Launch launch;
    launch.exit_speed_mps = 120.7 * kMpsPerMph;
    launch.launch_angle_deg = 37.7;
    launch.backspin_rpm = backspin;
    launch.sidespin_rpm = 0.0;
    Environment standard;  // 70 °F, calm: the defaults
    Environment cold;
    cold.temperature_c = CelsiusOf(46.0);
    Environment cold_wind_in = cold;
    cold_wind_in.wind.speed_mps = 16.0 * kMpsPerMph;
    cold_wind_in.wind.direction_deg = 180.0;
    Environment wind_out;
    wind_out.wind.speed_mps = 16.0 * kMpsPerMph;
    const double d_standard = Feet(Fly(launch, standard).distance_m);
    const double d_cold = Feet(Fly(launch, cold).distance_m);
    const double d_cold_in = Feet(Fly(launch, cold_wind_in).distance_m);
    const double d_out = Feet(Fly(launch, wind_out).distance_m);
    // Standard distance: 483 ft at 2000 rpm, 459 ft at 3000 (Hit Tracker: 460). ±30 ft covers
    // the unknown spin (the two spins differ by 24 ft).
    EXPECT_NEAR(d_standard, 460.0, 30.0) << backspin;
    // Temperature: −12.6 / −13.2 ft (Hit Tracker −12, quoted to the foot; ±2 ft).
    EXPECT_NEAR(d_cold - d_standard, -12.0, 2.0) << backspin;
    // Wind: NOT matched. A uniform 16 mph wind over the whole flight costs this model 108-115 ft
    // in and adds 91-95 ft out, twice Hit Tracker's −54 / +49 ft (whose wind model is not
    // published; Nathan's sheet offers a height below which there is no wind, which would
    // shrink the effect). Pinned: the model's effect is 1.8-2.3 times Hit Tracker's.
    EXPECT_GT((d_cold_in - d_cold) / -54.0, 1.8) << backspin;
    EXPECT_LT((d_cold_in - d_cold) / -54.0, 2.3) << backspin;
    EXPECT_GT((d_out - d_standard) / 49.0, 1.8) << backspin;
    EXPECT_LT((d_out - d_standard) / 49.0, 2.1) << backspin;
  }
}

// The distance-optimal swing: the oblique impact (tangential COR 0.4, the default; M_n 0.5 kg,
// e 0.5, 70 mph bat speed: the case) feeding Nathan's flight, scanned over the attack
// angle (−10° to 50°, 1° steps) and the undercut (0 to 1.6 in, 0.05 in steps), for a 90 mph
// fastball descending 6° with 2200 rpm of backspin and a 78 mph curveball descending 8° with
// 1500 rpm of topspin. Published:
// - Nathan, "Optimizing the Swing", The Hardball Times, 11 Nov 2015: "the fastball beats the
//   curveball, but only by a little bit ... the distances are comparable", and "swinging down
//   on the ball ... does not appear to be a good idea" (quoted by diamondkinetics.com and The
//   Baseball Observer, May-June 2016; his figures' numbers were not reachable in this work);
// - Sawicki, Hubbard & Stronge, Am. J. Phys. 71, 1152 (2003), abstract: "the lift is enhanced
//   by backspin produced by undercutting the ball" and "an optimally hit curve ball will travel
//   farther than an optimally hit fastball" (their optimal undercut and swing angle sit past
//   the stored openings: not reproduced).
struct Optimum {
  double distance_ft = 0.0, undercut_in = 0.0, attack_deg = 0.0;
};

Optimum BestSwing(double pitch_mph, double descent_deg, double pitch_spin_rpm) {
  Optimum best;
  for (int a = -10; a <= 50; ++a) {
    for (int u = 0; u <= 32; ++u) {
      ObliqueImpactInputs in;
      in.ball_speed_mps = pitch_mph * kMpsPerMph;
      in.descent_angle_deg = descent_deg;
      in.ball_backspin_rad_s = RpmToRadPerSecond(pitch_spin_rpm);
      in.bat_speed_mps = 70.0 * kMpsPerMph;
      in.attack_angle_deg = a;
      in.undercut_m = 0.05 * u * 0.0254;
      in.normal.bat_effective_mass_kg = 0.5;
      in.normal.cor = 0.5;
      const ObliqueImpactResult impact = SolveObliqueImpact(in);
      EXPECT_EQ(impact.summary.termination, Termination::kConverged);
      Launch launch;
      launch.exit_speed_mps = impact.exit_speed_mps;
      launch.launch_angle_deg = impact.launch_angle_deg;
      launch.backspin_rpm = impact.backspin_rpm;
      launch.sidespin_rpm = 0.0;
      const FlightResult flight = Fly(launch);
      if (flight.Landed() && Feet(flight.distance_m) > best.distance_ft) {
        best = {Feet(flight.distance_m), 0.05 * u, static_cast<double>(a)};
      }
    }
  }
  return best;
}

TEST(FlightChecks, DistanceOptimalUndercutAndAttackAngle) {
  const Optimum fastball = BestSwing(90.0, 6.0, 2200.0);
  const Optimum curveball = BestSwing(78.0, 8.0, -1500.0);
  // The model's optima (pinned to the scan's grid: ±1 step): fastball 392.1 ft at 0.35 in of
  // undercut and a 29° attack angle (96.0 mph, 31.7°, 1574 rpm off the bat); curveball
  // 388.4 ft at 0.25 in and 26°.
  EXPECT_NEAR(fastball.distance_ft, 392.1, 0.5);
  EXPECT_NEAR(fastball.undercut_in, 0.35, 0.05 + 1e-9);
  EXPECT_NEAR(fastball.attack_deg, 29.0, 1.0);
  EXPECT_NEAR(curveball.distance_ft, 388.4, 0.5);
  EXPECT_NEAR(curveball.undercut_in, 0.25, 0.05 + 1e-9);
  EXPECT_NEAR(curveball.attack_deg, 26.0, 1.0);
  // Published findings: an upward swing (Nathan) and an undercut (Sawicki et al.) carry
  // farthest; the fastball beats the curveball by a little (Nathan: matched, 3.7 ft), not the
  // other way round (Sawicki et al.: not matched).
  EXPECT_GT(fastball.attack_deg, 0.0);
  EXPECT_GT(curveball.attack_deg, 0.0);
  EXPECT_GT(fastball.undercut_in, 0.0);
  EXPECT_GT(curveball.undercut_in, 0.0);
  EXPECT_GT(fastball.distance_ft - curveball.distance_ft, 0.0);
  EXPECT_LT(fastball.distance_ft - curveball.distance_ft, 10.0);
}

}  // namespace
}  // namespace flight_checks_test
}  // namespace sweetspot::core::flight
