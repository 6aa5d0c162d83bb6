// oblique_impact: the head-on reduction to the normal models, the undercut's spin, the
// conservation laws, the limits of the tangential law, the published statements it reproduces
// and the refusals. Pinned numbers come from an independent script (the slip after impact
// evaluated from both bodies' velocities and solved for J_t: docs/validation.md, "Oblique
// impact").
#include "core/collision/oblique_impact.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/bat/presets.hpp"
#include "core/collision/free_bat.hpp"
#include "core/collision/hertz_contact.hpp"
#include "core/collision/rigid_pivot.hpp"
#include "core/geometry_format.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace oblique_impact_test {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The paper-shape bat of the other collision tests (paper-notes.md), free, struck at 0.75 m.
FreeBatInputs PaperFreeBat() {
  FreeBatInputs in;
  in.bat_mass_kg = 1.0078;
  in.balance_point_m = 0.6090;
  in.moi_centroid_kg_m2 = 0.4122 - 1.0078 * 0.6090 * 0.6090;
  in.pivot_from_knob_m = 0.0;
  in.ball_speed_mps = 40.2336;
  in.angular_speed_rad_s = 45.0;
  in.cor = 0.5;
  return in;
}

double FreeBatNormalMass(const FreeBatInputs& in, double impact_from_knob_m) {
  const double b = impact_from_knob_m - in.balance_point_m;
  return 1.0 / (1.0 / in.bat_mass_kg + b * b / in.moi_centroid_kg_m2);
}

// The issue's case: 90 mph pitch descending 6 degrees with 2200 rpm of backspin, 70 mph bat
// rising 10 degrees, a normal effective mass of 0.5 kg and e = 0.5 (the default I_roll, 4e-4).
ObliqueImpactInputs IssueCase(double undercut_m) {
  ObliqueImpactInputs in;
  in.ball_speed_mps = 40.2336;
  in.descent_angle_deg = 6.0;
  in.ball_backspin_rad_s = RpmToRadPerSecond(2200.0);
  in.bat_speed_mps = 31.2928;
  in.attack_angle_deg = 10.0;
  in.undercut_m = undercut_m;
  in.normal.bat_effective_mass_kg = 0.5;
  in.normal.cor = 0.5;
  return in;
}

ObliqueImpactResult Solve(const ObliqueImpactInputs& in) {
  ObliqueImpactResult r = SolveObliqueImpact(in);
  EXPECT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  return r;
}

// Collinear paths (attack angle = descent angle), no undercut, no spin.
ObliqueImpactInputs HeadOn(const FreeBatInputs& bat, double impact_from_knob_m, double angle_deg) {
  ObliqueImpactInputs in;
  in.ball_speed_mps = bat.ball_speed_mps;
  in.descent_angle_deg = angle_deg;
  in.attack_angle_deg = angle_deg;
  in.bat_speed_mps = bat.angular_speed_rad_s * (impact_from_knob_m - bat.pivot_from_knob_m);
  in.undercut_m = 0.0;
  in.ball_backspin_rad_s = 0.0;
  in.ball_mass_kg = bat.ball_mass_kg;
  in.normal.bat_effective_mass_kg = FreeBatNormalMass(bat, impact_from_knob_m);
  in.normal.cor = bat.cor;
  return in;
}

TEST(ObliqueImpact, HeadOnIsTheFreeBatImpactAlongTheBatPath) {
  const FreeBatInputs bat = PaperFreeBat();
  for (double s : {0.55, 0.70, 0.80}) {
    for (double angle : {0.0, 8.0, -5.0}) {
      const FreeBatImpact ref = FreeBatImpactAt(bat, s);
      const ObliqueImpactResult r = Solve(HeadOn(bat, s, angle));
      // Two algebraic forms of the same closed form: rounding only (1e-13 relative of ~40 m/s).
      EXPECT_NEAR(r.exit_speed_mps, ref.exit_speed_mps, 1e-12) << s << " " << angle;
      EXPECT_NEAR(r.normal_impulse_n_s, ref.ball_impulse_n_s, 1e-13);
      EXPECT_NEAR(r.launch_angle_deg, angle, 1e-12);
      EXPECT_EQ(r.tangential_impulse_n_s, 0.0);
      EXPECT_EQ(r.backspin_rpm, 0.0);
      EXPECT_EQ(r.regime, TangentialRegime::kNoSlip);
      EXPECT_NEAR(r.normal_cor, bat.cor, 1e-14);
    }
  }
}

TEST(ObliqueImpact, HeadOnIsTheRigidPivotImpact) {
  RigidPivotInputs pivot;
  pivot.bat_mass_kg = 1.0078;
  pivot.balance_point_m = 0.6090;
  pivot.moi_pivot_kg_m2 = 0.4122;
  const double s = 0.7;
  const RigidPivotImpact ref = RigidPivotImpactAt(pivot, s);
  ObliqueImpactInputs in;
  in.ball_speed_mps = pivot.ball_speed_mps;
  in.bat_speed_mps = pivot.angular_speed_rad_s * s;
  in.descent_angle_deg = in.attack_angle_deg = 3.0;
  in.normal.bat_effective_mass_kg = pivot.moi_pivot_kg_m2 / (s * s);  // J / z^2
  in.normal.cor = pivot.cor;
  const ObliqueImpactResult r = Solve(in);
  EXPECT_NEAR(r.exit_speed_mps, ref.exit_speed_mps, 1e-12);
  EXPECT_NEAR(r.launch_angle_deg, 3.0, 1e-12);
  EXPECT_EQ(r.backspin_rpm, 0.0);
}

TEST(ObliqueImpact, AModelsOwnNormalImpulseIsUsedAtTheNormalApproachSpeed) {
  // The normal law as a model's answer: the free bat fired at v_n with the bat at rest at the
  // impact point (how the scene wires hertz and flexible). Identical to the (M_n, e) pair.
  const FreeBatInputs bat = PaperFreeBat();
  const double s = 0.72;
  ObliqueImpactInputs pair = IssueCase(0.02);
  pair.normal.bat_effective_mass_kg = FreeBatNormalMass(bat, s);
  ObliqueImpactInputs law = pair;
  int calls = 0;
  law.normal.ball_normal_impulse_n_s = [&](double v_n) {
    ++calls;
    FreeBatInputs at_rest = bat;
    at_rest.ball_speed_mps = v_n;
    at_rest.angular_speed_rad_s = 0.0;
    return FreeBatImpactAt(at_rest, s).ball_impulse_n_s;
  };
  const ObliqueImpactResult a = Solve(pair);
  const ObliqueImpactResult b = Solve(law);
  EXPECT_EQ(calls, 1);
  EXPECT_NEAR(b.normal_impulse_n_s, a.normal_impulse_n_s, 1e-13);
  EXPECT_NEAR(b.exit_speed_mps, a.exit_speed_mps, 1e-12);
  EXPECT_NEAR(b.backspin_rpm, a.backspin_rpm, 1e-9);
  // A speed-dependent COR (a ball law): the normal COR reported is the law's at v_n.
  law.normal.ball_normal_impulse_n_s = [&](double v_n) {
    const double e = 0.6 - 0.001 * v_n;
    return (1.0 + e) * v_n / (1.0 / law.ball_mass_kg + 1.0 / law.normal.bat_effective_mass_kg);
  };
  const ObliqueImpactResult c = Solve(law);
  EXPECT_NEAR(c.normal_cor, 0.6 - 0.001 * c.normal_approach_speed_mps, 1e-13);
}

// The normal part from an ODE model: the contact model (soft ball's power law, free bat) fired
// at v_n with the bat at rest at the impact point, as the scene would wire hertz (flexible alike).
HertzProblem FreeBatContact(double bat_mass_kg, double normal_mass_kg) {
  HertzProblem p;
  p.law = ContactLaw::kBallPowerLaw;
  p.ball_mass_kg = 0.145;
  p.c11_per_kg = 1.0 / 0.145 + 1.0 / normal_mass_kg;
  p.c12_per_kg = 1.0 / bat_mass_kg;
  p.c22_per_kg = 1.0 / bat_mass_kg;
  p.ball_stiffness = 4.0e7;
  p.ball_exponent = 1.5;
  p.surface_stiffness = 0.0;
  p.cor = 0.5;
  p.hands_stiffness_n_m = 0.0;  // free bat
  return p;
}

TEST(ObliqueImpact, TheContactModelFeedsTheNormalPart) {
  const FreeBatInputs bat = PaperFreeBat();
  const double s = 0.72;
  const double mn = FreeBatNormalMass(bat, s);
  const HertzProblem contact = FreeBatContact(bat.bat_mass_kg, mn);
  HertzSolverOptions options;
  options.refine_check = false;
  int calls = 0;
  auto law = [&](double v_n) {
    ++calls;
    HertzProblem at = contact;
    at.approach_speed_mps = v_n;
    at.ball_speed_mps = v_n;  // the bat at rest at the impact point
    const HertzImpact r = SolveHertzImpact(at, options);
    EXPECT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
    return r.ball_impulse_n_s;
  };
  // Head-on: the contact model's own exit speed at u + V (the same integration, so equal to
  // rounding in the final -u + J/m).
  ObliqueImpactInputs in = HeadOn(bat, s, 4.0);
  in.normal.ball_normal_impulse_n_s = law;
  const ObliqueImpactResult head_on = Solve(in);
  HertzProblem direct = contact;
  direct.approach_speed_mps = in.ball_speed_mps + in.bat_speed_mps;
  direct.ball_speed_mps = in.ball_speed_mps;
  const HertzImpact reference = SolveHertzImpact(direct, options);
  EXPECT_NEAR(head_on.exit_speed_mps, reference.exit_speed_mps, 1e-12);
  EXPECT_EQ(head_on.backspin_rpm, 0.0);
  EXPECT_NEAR(head_on.launch_angle_deg, 4.0, 1e-12);
  // Its unloading returns e^2 of the work, so the two-body COR is e: the pair (M_n, e) agrees to
  // the integration tolerance (1e-8 relative; 1e-6 allowed).
  ObliqueImpactInputs pair = HeadOn(bat, s, 4.0);
  EXPECT_NEAR(head_on.exit_speed_mps, Solve(pair).exit_speed_mps, 1e-6 * head_on.exit_speed_mps);
  // Oblique: the model sees v_n = |w| cos psi, and the normal COR it implies is e again.
  in.undercut_m = InchesToMetres(1.0);
  pair.undercut_m = in.undercut_m;
  const ObliqueImpactResult oblique = Solve(in);
  EXPECT_NEAR(oblique.normal_cor, 0.5, 1e-6);
  EXPECT_NEAR(oblique.backspin_rpm, Solve(pair).backspin_rpm, 1e-6 * oblique.backspin_rpm);
  EXPECT_EQ(calls, 2);
}

TEST(ObliqueImpact, IssueCaseAgainstTheIndependentScript) {
  // Pinned from the independent script (1e-6 relative: its own rounding is 1e-15; the margin
  // only absorbs printing to 6 decimals).
  struct Row {
    double undercut_in, speed, launch, rpm;
  };
  const std::vector<Row> rows = {
      {0.0, 42.934820, 5.633152, -364.214801},  {0.25, 42.840208, 12.811155, 1047.578214},
      {0.5, 42.438203, 20.040770, 2459.371228}, {0.75, 41.715829, 27.416133, 3871.164243},
      {1.0, 40.651449, 35.048023, 5282.957258}, {1.5, 37.346763, 51.713272, 8106.543287},
  };
  for (const Row& row : rows) {
    const ObliqueImpactResult r = Solve(IssueCase(InchesToMetres(row.undercut_in)));
    EXPECT_NEAR(r.exit_speed_mps, row.speed, 2e-6) << row.undercut_in;
    EXPECT_NEAR(r.launch_angle_deg, row.launch, 2e-6) << row.undercut_in;
    EXPECT_NEAR(r.backspin_rpm, row.rpm, 2e-6 * 1e3) << row.undercut_in;
    EXPECT_EQ(r.regime, TangentialRegime::kGripped);
  }
}

TEST(ObliqueImpact, SpinGrowsWithTheUndercut) {
  // Monotone while the ball grips (with the defaults: up to 0.8 (R + r), psi = 53 degrees).
  for (double spin_rpm : {2200.0, 0.0, -1500.0}) {
    ObliqueImpactInputs in = IssueCase(0.0);
    in.ball_backspin_rad_s = RpmToRadPerSecond(spin_rpm);
    const double reach = MaxUndercutM(in);
    double last_spin = -kInf;
    double last_launch = -kInf;
    for (int i = -80; i <= 80; ++i) {
      in.undercut_m = 0.01 * i * reach;
      const ObliqueImpactResult r = Solve(in);
      EXPECT_TRUE(r.regime == TangentialRegime::kGripped ||
                  r.regime == TangentialRegime::kNoSlip)
          << in.undercut_m;
      EXPECT_GT(r.backspin_rpm, last_spin) << in.undercut_m;
      EXPECT_GT(r.launch_angle_deg, last_launch) << in.undercut_m;
      last_spin = r.backspin_rpm;
      last_launch = r.launch_angle_deg;
    }
  }
}

TEST(ObliqueImpact, BackspinForAnUndercutTopspinForAnOvercut) {
  // No incoming spin, collinear paths: the impact is mirror-symmetric about the common path,
  // so spin(-D) = -spin(D) and the launch angle mirrors about the path (rounding only).
  ObliqueImpactInputs in = IssueCase(0.0);
  in.ball_backspin_rad_s = 0.0;
  in.attack_angle_deg = in.descent_angle_deg = 7.0;
  for (double d_in : {0.1, 0.5, 1.0, 2.0}) {
    in.undercut_m = InchesToMetres(d_in);
    const ObliqueImpactResult under = Solve(in);
    in.undercut_m = -InchesToMetres(d_in);
    const ObliqueImpactResult over = Solve(in);
    EXPECT_GT(under.backspin_rpm, 0.0);
    EXPECT_LT(over.backspin_rpm, 0.0);
    EXPECT_NEAR(under.backspin_rpm, -over.backspin_rpm, 1e-9 * std::abs(under.backspin_rpm));
    EXPECT_NEAR(under.launch_angle_deg - 7.0, 7.0 - over.launch_angle_deg, 1e-11);
    EXPECT_NEAR(under.exit_speed_mps, over.exit_speed_mps, 1e-12);
  }
}

// A grid over the law's parameters, the bat's masses, the undercut and the incoming spin.
std::vector<ObliqueImpactInputs> Grid() {
  std::vector<ObliqueImpactInputs> grid;
  for (double d_frac : {-0.9, -0.4, 0.0, 0.3, 0.7, 0.95}) {
    for (double spin_rpm : {-2500.0, 0.0, 2500.0}) {
      for (double e_x : {0.0, 0.4, 1.0}) {
        for (double mu : {0.0, 0.2, 0.5, kInf}) {
          for (double mass : {0.3, 0.7, kInf}) {
            for (double e : {0.0, 0.5, 1.0}) {
              ObliqueImpactInputs in = IssueCase(0.0);
              in.undercut_m = d_frac * MaxUndercutM(in);
              in.ball_backspin_rad_s = RpmToRadPerSecond(spin_rpm);
              in.tangential.tangential_cor = e_x;
              in.tangential.friction_coefficient = mu;
              in.normal.bat_effective_mass_kg = mass;
              in.normal.cor = e;
              in.bat_roll_moi_kg_m2 = mass == kInf ? kInf : 6e-4;
              grid.push_back(in);
            }
          }
        }
      }
    }
  }
  return grid;
}

TEST(ObliqueImpact, NoEnergyIsCreatedBatIncluded) {
  for (const ObliqueImpactInputs& in : Grid()) {
    const ObliqueImpactResult r = Solve(in);
    // Rounding of energies of ~120 J (ball) and ~1e3 J (the bat's term): 1e-10 J.
    EXPECT_GE(r.energy_lost_j, -1e-10)
        << in.undercut_m << " " << in.tangential.tangential_cor << " "
        << in.tangential.friction_coefficient << " " << in.normal.cor;
    // Elastic and frictionless: nothing is lost (to rounding).
    if (in.normal.cor == 1.0 && in.tangential.friction_coefficient == 0.0) {
      EXPECT_NEAR(r.energy_lost_j, 0.0, 1e-10);
    }
  }
}

TEST(ObliqueImpact, MomentumIsConservedWithTheBatsRecoil) {
  for (const ObliqueImpactInputs& in : Grid()) {
    if (in.normal.bat_effective_mass_kg == kInf) continue;
    const ObliqueImpactResult r = Solve(in);
    const double m = in.ball_mass_kg;
    const double delta = in.descent_angle_deg * kPi / 180.0;
    const double dvx = r.velocity_x_mps + in.ball_speed_mps * std::cos(delta);
    const double dvy = r.velocity_y_mps + in.ball_speed_mps * std::sin(delta);
    const double mn = in.normal.bat_effective_mass_kg;
    // Along x and y: the ball's gain and the bat's (effective) loss cancel (rounding: 1e-14 of
    // impulses of ~10 N s).
    EXPECT_NEAR(m * dvx + mn * r.bat_velocity_change_x_mps, 0.0, 1e-12);
    EXPECT_NEAR(m * dvy + mn * r.bat_velocity_change_y_mps, 0.0, 1e-12);
    // The impulses reproduce the ball's change (the directions n and t are a rotation).
    EXPECT_NEAR(std::hypot(dvx, dvy) * m,
                std::hypot(r.normal_impulse_n_s, r.tangential_impulse_n_s), 1e-12);
    // The bat's roll takes the tangential impulse's moment about its axis.
    EXPECT_NEAR(in.bat_roll_moi_kg_m2 * r.bat_roll_rate_change_rad_s,
                -in.bat_radius_m * r.tangential_impulse_n_s, 1e-15);
    // The ball's angular momentum about the contact point, I omega + m R v_t, is conserved:
    // I d(omega) = -R J_t.
    const double inertia = in.ball_gyration_ratio * m * in.ball_radius_m * in.ball_radius_m;
    EXPECT_NEAR(inertia * (r.backspin_rad_s + in.ball_backspin_rad_s),
                -in.ball_radius_m * r.tangential_impulse_n_s, 1e-14);
  }
}

TEST(ObliqueImpact, FrictionlessLeavesSpinAndTangentialVelocityUnchanged) {
  for (double d_in : {-1.0, 0.4, 1.2}) {
    ObliqueImpactInputs in = IssueCase(InchesToMetres(d_in));
    in.tangential.friction_coefficient = 0.0;
    const ObliqueImpactResult r = Solve(in);
    EXPECT_EQ(r.tangential_impulse_n_s, 0.0);
    // The pitch's backspin leaves as the same rotation: topspin of the batted ball.
    EXPECT_EQ(r.backspin_rad_s, -in.ball_backspin_rad_s);
    EXPECT_EQ(r.slip_after_mps, r.slip_before_mps);
    EXPECT_EQ(r.regime, TangentialRegime::kSlidThroughout);
    // The ball's velocity along t is unchanged: the change is along n only.
    const double delta = in.descent_angle_deg * kPi / 180.0;
    const double dvx = r.velocity_x_mps + in.ball_speed_mps * std::cos(delta);
    const double dvy = r.velocity_y_mps + in.ball_speed_mps * std::sin(delta);
    EXPECT_NEAR(std::hypot(dvx, dvy), r.normal_impulse_n_s / in.ball_mass_kg, 1e-12);
  }
}

TEST(ObliqueImpact, FullGripRollsAtSeparation) {
  // e_x = 0, no friction bound: the ball's contact point leaves with the bat's surface point,
  // checked from the bodies' velocities after impact (not from the law's own slip).
  for (double d_in : {-1.0, 0.3, 0.8, 1.5}) {
    for (double spin_rpm : {-2000.0, 0.0, 2200.0}) {
      ObliqueImpactInputs in = IssueCase(InchesToMetres(d_in));
      in.ball_backspin_rad_s = RpmToRadPerSecond(spin_rpm);
      in.tangential.tangential_cor = 0.0;
      in.tangential.friction_coefficient = kInf;
      const ObliqueImpactResult r = Solve(in);
      EXPECT_EQ(r.regime, TangentialRegime::kGripped);
      // t from the impulses: the tangential part of the ball's velocity change.
      const double delta = in.descent_angle_deg * kPi / 180.0;
      const double attack = in.attack_angle_deg * kPi / 180.0;
      const double dvx = r.velocity_x_mps + in.ball_speed_mps * std::cos(delta);
      const double dvy = r.velocity_y_mps + in.ball_speed_mps * std::sin(delta);
      const double jn = r.normal_impulse_n_s, jt = r.tangential_impulse_n_s;
      const double m = in.ball_mass_kg;
      // Solve (jn n + jt t) = m dv with t = n turned +90 degrees for n.
      const double nx = (jn * dvx + jt * dvy) * m / (jn * jn + jt * jt);
      const double ny = (jn * dvy - jt * dvx) * m / (jn * jn + jt * jt);
      const double tx = -ny, ty = nx;
      const double ball_contact =
          r.velocity_x_mps * tx + r.velocity_y_mps * ty - in.ball_radius_m * r.backspin_rad_s;
      const double bat_contact =
          (in.bat_speed_mps * std::cos(attack) + r.bat_velocity_change_x_mps) * tx +
          (in.bat_speed_mps * std::sin(attack) + r.bat_velocity_change_y_mps) * ty +
          in.bat_radius_m * r.bat_roll_rate_change_rad_s;
      // Rounding of velocities of ~40 m/s through the reconstruction: 1e-11 m/s.
      EXPECT_NEAR(ball_contact, bat_contact, 1e-11) << d_in << " " << spin_rpm;
      EXPECT_NEAR(r.slip_after_mps, 0.0, 1e-12);
    }
  }
}

TEST(ObliqueImpact, TheFrictionBoundSlidesThroughoutOrStopsAtTheBound) {
  ObliqueImpactInputs in = IssueCase(InchesToMetres(1.0));
  in.tangential.friction_coefficient = 0.02;
  const ObliqueImpactResult slid = Solve(in);
  EXPECT_EQ(slid.regime, TangentialRegime::kSlidThroughout);
  EXPECT_TRUE(slid.slid_throughout);
  EXPECT_NEAR(slid.tangential_impulse_n_s, -0.02 * slid.normal_impulse_n_s, 1e-15);
  EXPECT_GT(slid.slip_after_mps, 0.0);
  // Between: the grip needs (1 + e_x) mu_t s, the slip stops at mu_t s.
  const double gripped = Solve(IssueCase(InchesToMetres(1.0))).tangential_impulse_n_s;
  in.tangential.friction_coefficient = 0.9 * std::abs(gripped) / slid.normal_impulse_n_s;
  const ObliqueImpactResult limited = Solve(in);
  EXPECT_EQ(limited.regime, TangentialRegime::kFrictionLimited);
  EXPECT_LT(limited.slip_after_mps, 0.0);
}

// Nathan, Cantakos, Kesman, Mathew, Lukash (2012), abstract: on a 3-in wood cylinder fixed to a
// wall, balls fired horizontally at up to 120 mph; "for a given angle of incidence, the
// scattered spin is nearly independent of the incident spin" and "considerably larger than
// expected for a model whereby the ball rolls".
ObliqueImpactInputs FixedCylinder(double undercut_in, double spin_rpm) {
  ObliqueImpactInputs in;
  in.ball_speed_mps = 120.0 * 0.44704;
  in.descent_angle_deg = 0.0;
  in.bat_speed_mps = 0.0;
  in.attack_angle_deg = 0.0;
  in.bat_radius_m = InchesToMetres(1.5);
  in.undercut_m = InchesToMetres(undercut_in);
  in.ball_backspin_rad_s = RpmToRadPerSecond(spin_rpm);
  in.normal.bat_effective_mass_kg = kInf;
  in.bat_roll_moi_kg_m2 = kInf;
  return in;
}

TEST(ObliqueImpact, FixedCylinderScatteredSpinDoesNotDependOnTheIncidentSpin) {
  // With e_x = alpha the incident spin drops out exactly: d(omega')/d(omega) = (alpha - e_x) /
  // (1 + alpha) = 0 (rounding of ~1e4 rpm: 1e-9).
  for (double d_in : {0.5, 1.0, 1.5}) {
    const double base = Solve(FixedCylinder(d_in, 0.0)).backspin_rpm;
    for (double spin : {-2000.0, 1500.0, 2500.0}) {
      EXPECT_NEAR(Solve(FixedCylinder(d_in, spin)).backspin_rpm, base, 1e-9) << d_in << spin;
    }
    // Rolling (e_x = 0) keeps alpha / (1 + alpha) = 2/7 of it (with the sign of a rotation:
    // the pitch's backspin is the batted ball's topspin).
    ObliqueImpactInputs rolling = FixedCylinder(d_in, 2000.0);
    rolling.tangential.tangential_cor = 0.0;
    ObliqueImpactInputs rolling0 = FixedCylinder(d_in, 0.0);
    rolling0.tangential.tangential_cor = 0.0;
    EXPECT_NEAR(Solve(rolling).backspin_rpm - Solve(rolling0).backspin_rpm, -2000.0 * 2.0 / 7.0,
                1e-9);
  }
}

TEST(ObliqueImpact, ImmovableSurfaceFollowsCrossesRelation) {
  // A ball (I = alpha m R^2) on an immovable surface with tangential COR e_x (Cross 2002; the
  // relation quoted in flight-notes.md): omega' = [(alpha - e_x) omega + (1 + e_x) v_t / R] /
  // (1 + alpha), v_t the tangential speed of the ball's centre over the surface (= u sin psi
  // here), omega in the same sense (the pitch's backspin counts negative in this view).
  for (double e_x : {0.0, 0.25, 0.4, 1.0}) {
    for (double spin_rpm : {-1800.0, 0.0, 2400.0}) {
      ObliqueImpactInputs in = FixedCylinder(1.0, spin_rpm);
      in.tangential.tangential_cor = e_x;
      in.tangential.friction_coefficient = kInf;
      const ObliqueImpactResult r = Solve(in);
      const double alpha = in.ball_gyration_ratio;
      const double v_t = in.ball_speed_mps * in.undercut_m / MaxUndercutM(in);
      const double omega = -in.ball_backspin_rad_s;
      const double expected =
          ((alpha - e_x) * omega + (1.0 + e_x) * v_t / in.ball_radius_m) / (1.0 + alpha);
      // Rounding of terms of ~2e3 rad/s: 1e-10 rad/s.
      EXPECT_NEAR(r.backspin_rad_s, expected, 1e-10) << e_x << " " << spin_rpm;
    }
  }
}

TEST(ObliqueImpact, ASpinlessBallSpinsOnePlusExTimesRolling) {
  // Kensrud, Nathan, Smith (2017), abstract: "a spin that was up to 40% greater than would be
  // obtained by rolling contact": for a spinless ball the law gives (1 + e_x) times rolling,
  // whatever the bat's masses.
  for (double mass : {0.5, kInf}) {
    ObliqueImpactInputs in = FixedCylinder(1.0, 0.0);
    in.normal.bat_effective_mass_kg = mass;
    in.bat_roll_moi_kg_m2 = mass == kInf ? kInf : 6e-4;
    in.tangential.friction_coefficient = kInf;
    const double with_ex = Solve(in).backspin_rpm;
    in.tangential.tangential_cor = 0.0;
    const double rolling = Solve(in).backspin_rpm;
    EXPECT_NEAR(with_ex / rolling, 1.4, 1e-13);
    if (mass == kInf) {
      // Rolling on an immovable cylinder: omega = (5/7) v_t / R, v_t = u sin psi.
      const double sin_psi = in.undercut_m / MaxUndercutM(in);
      EXPECT_NEAR(RpmToRadPerSecond(rolling),
                  5.0 / 7.0 * in.ball_speed_mps * sin_psi / in.ball_radius_m, 1e-10);
    }
  }
}

TEST(ObliqueImpact, ACurveballGetsMoreBackspinThanAFastballByLessThanRolling) {
  // Cross & Nathan (2006), abstract: "a curveball can be hit with greater backspin than a
  // fastball, but by an amount that is less than would be the case in the absence of tangential
  // compliance". Same speeds here, only the incoming spin differs.
  ObliqueImpactInputs fastball = IssueCase(InchesToMetres(0.75));
  ObliqueImpactInputs curveball = fastball;
  curveball.ball_backspin_rad_s = RpmToRadPerSecond(-1500.0);  // topspin
  const double gain = Solve(curveball).backspin_rpm - Solve(fastball).backspin_rpm;
  fastball.tangential.tangential_cor = curveball.tangential.tangential_cor = 0.0;
  const double gain_rolling = Solve(curveball).backspin_rpm - Solve(fastball).backspin_rpm;
  EXPECT_GT(gain, 0.0);
  EXPECT_LT(gain, gain_rolling);
  // For this bat (M_n = 0.5 kg; the independent script): 3700 rpm of difference in the pitch
  // leaves 613 rpm batted with e_x = 0.4, 1495 rpm with rolling.
  EXPECT_NEAR(gain, 612.543074, 1e-3);
  EXPECT_NEAR(gain_rolling, 1494.673624, 1e-3);
}

TEST(ObliqueImpact, GameImpactsDoNotDependOnTheFrictionCoefficient) {
  // Sawicki, Hubbard, Stronge (2003), abstract: "post-impact conditions are found to be
  // independent of the ball-bat coefficient of friction". Here for mu_f >= 0.3 and undercuts up
  // to 1.5 in: the ball grips and mu_f does not enter.
  for (double d_in : {0.0, 0.5, 1.0, 1.5}) {
    ObliqueImpactInputs in = IssueCase(InchesToMetres(d_in));
    in.tangential.friction_coefficient = kInf;
    const ObliqueImpactResult ref = Solve(in);
    for (double mu : {0.3, 0.5, 1.0}) {
      in.tangential.friction_coefficient = mu;
      const ObliqueImpactResult r = Solve(in);
      EXPECT_EQ(r.backspin_rpm, ref.backspin_rpm) << d_in << " " << mu;
      EXPECT_EQ(r.exit_speed_mps, ref.exit_speed_mps);
    }
  }
}

TEST(ObliqueImpact, DefaultsAreValidAndEachRuleRefuses) {
  EXPECT_TRUE(ObliqueImpactInputs{}.Validate(nullptr));
  EXPECT_TRUE(TangentialLaw{}.Validate(nullptr));
  EXPECT_TRUE(NormalImpactLaw{}.Validate(nullptr));
  const std::string reach = FormatNumber(0.0366 + 0.0334);
  const std::string undercut_rule = "must be in (-" + reach + ", " + reach +
                                    "): beyond the ball radius + the bat radius the ball misses "
                                    "the bat";
  struct Case {
    void (*set)(ObliqueImpactInputs*);
    std::string message;
  };
  const Case cases[] = {
      {[](ObliqueImpactInputs* in) { in->undercut_m = 0.0700; },
       "undercut_m = 0.07: " + undercut_rule},
      {[](ObliqueImpactInputs* in) { in->undercut_m = -0.08; },
       "undercut_m = -0.08: " + undercut_rule},
      {[](ObliqueImpactInputs* in) { in->undercut_m = std::nan(""); },
       "undercut_m = nan: " + undercut_rule},
      {[](ObliqueImpactInputs* in) { in->descent_angle_deg = 120.0; },
       "descent_angle_deg = 120: must be in [-89, 89]"},
      {[](ObliqueImpactInputs* in) { in->ball_backspin_rad_s = 1e6; },
       "ball_backspin_rad_s = " + FormatNumber(1e6) + ": " + RangeRule(-1e4, 1e4)},
      {[](ObliqueImpactInputs* in) { in->ball_gyration_ratio = 0.0; },
       "ball_gyration_ratio = 0: " + RangeRule(0.0, 2.0 / 3.0, true) +
           " (0.4 = a uniform sphere, 2/3 = a thin shell)"},
      {[](ObliqueImpactInputs* in) { in->tangential.tangential_cor = 1.5; },
       "tangential.tangential_cor = 1.5: must be in [0, 1]"},
      {[](ObliqueImpactInputs* in) { in->tangential.friction_coefficient = -1.0; },
       "tangential.friction_coefficient = -1: must be non-negative (inf = the grip is never "
       "limited)"},
      {[](ObliqueImpactInputs* in) { in->normal.cor = 2.0; }, "normal.cor = 2: must be in [0, 1]"},
      {[](ObliqueImpactInputs* in) { in->normal.bat_effective_mass_kg = 0.0; },
       "normal.bat_effective_mass_kg = 0: must be positive (inf = an immovable bat)"},
      {[](ObliqueImpactInputs* in) {
         in->ball_speed_mps = 0.0;
         in->bat_speed_mps = 0.0;
       },
       "ball_speed_mps: the ball and the bat are both at rest: no impact"},
  };
  for (const Case& c : cases) {
    ObliqueImpactInputs in;
    in.bat_radius_m = 0.0334;
    in.ball_radius_m = 0.0366;
    c.set(&in);
    const ObliqueImpactResult r = SolveObliqueImpact(in);
    EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
    ASSERT_TRUE(r.summary.refusal.has_value());
    EXPECT_EQ(r.summary.message, c.message);
  }
}

TEST(ObliqueImpact, ANormalLawOutOfRangeOrThrowingIsAFailureNotAThrow) {
  ObliqueImpactInputs in = IssueCase(0.01);
  in.normal.ball_normal_impulse_n_s = [](double v_n) { return 10.0 * v_n; };  // e >> 1
  const ObliqueImpactResult over = SolveObliqueImpact(in);
  EXPECT_EQ(over.summary.termination, Termination::kFailure);
  EXPECT_NE(over.summary.message.find("the normal law answered"), std::string::npos);
  in.normal.ball_normal_impulse_n_s = [](double) -> double { throw std::runtime_error("boom"); };
  const ObliqueImpactResult thrown = SolveObliqueImpact(in);
  EXPECT_EQ(thrown.summary.termination, Termination::kFailure);
  EXPECT_EQ(thrown.summary.message, "internal error: boom");
}

TEST(ObliqueImpact, RollMomentOfInertiaOfCylindersAndPresets) {
  Bat bat;
  bat.knots = {{0.0, 0.03}, {0.8, 0.03}};
  bat.material.density_kg_m3 = 650.0;
  const double mass = 650.0 * kPi * 0.03 * 0.03 * 0.8;
  // Exact polynomial integrals: rounding only.
  EXPECT_NEAR(BatRollMoiKgM2(bat), 0.5 * mass * 0.03 * 0.03, 1e-17);
  bat.wall_thickness_m = 0.002;  // a tube: (1/2) M (r_o^2 + r_i^2)
  const double tube = 650.0 * kPi * (0.03 * 0.03 - 0.028 * 0.028) * 0.8;
  EXPECT_NEAR(BatRollMoiKgM2(bat), 0.5 * tube * (0.03 * 0.03 + 0.028 * 0.028), 1e-17);
  // A taper (a cone frustum): rho pi L (r_a^4 + r_a^3 r_b + ... + r_b^4) / 10.
  bat.wall_thickness_m = 0.0;
  bat.knots = {{0.0, 0.01}, {0.5, 0.03}};
  const double a = 0.01, b = 0.03;
  EXPECT_NEAR(BatRollMoiKgM2(bat),
              650.0 * kPi * 0.5 *
                  (a * a * a * a + a * a * a * b + a * a * b * b + a * b * b * b + b * b * b * b) /
                  10.0,
              1e-17);
  // The presets (docs/models.md quotes them): the default 4.0e-4 kg m^2 lies between them.
  for (const char* name : {"wood-34-ash", "paper-wood"}) {
    const double moi = BatRollMoiKgM2(FindPreset(name)->bat);
    std::printf("roll MOI of %s: %.6g kg m^2\n", name, moi);
    EXPECT_GT(moi, 2e-4) << name;
    EXPECT_LT(moi, 1e-3) << name;
  }
}

TEST(ObliqueImpact, RegimeNamesAreStable) {
  EXPECT_STREQ(TangentialRegimeName(TangentialRegime::kNoSlip), "no_slip");
  EXPECT_STREQ(TangentialRegimeName(TangentialRegime::kGripped), "gripped");
  EXPECT_STREQ(TangentialRegimeName(TangentialRegime::kFrictionLimited), "friction_limited");
  EXPECT_STREQ(TangentialRegimeName(TangentialRegime::kSlidThroughout), "slid_throughout");
}

}  // namespace
}  // namespace oblique_impact_test
}  // namespace sweetspot::core
