// Hard cases of the collision models and sweet spots (core/collision/*, core/sweet_spot.*,
// core/numerics/nlopt_search.*, core/scene.*): extreme masses, speeds and CORs against long double
// closed forms, stiff and soft contacts against the exact power-law contact, and every NLopt
// algorithm on a flat objective.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/bat/presets.hpp"
#include "core/collision/free_bat.hpp"
#include "core/collision/hertz_contact.hpp"
#include "core/collision/oblique_impact.hpp"
#include "core/collision/rigid_pivot.hpp"
#include "core/numerics/nlopt_search.hpp"
#include "core/scene/collide.hpp"
#include "core/scene/evaluate_scene.hpp"
#include "core/sweet_spot/sweet_spot.hpp"
#include "tests/hard_cases/hard_case.hpp"
#include "tests/hard_cases/reference.hpp"

namespace sweetspot::hard_cases {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace core_collision_test {
namespace {

// ------------------------------------------------------------------ rigid pivot, closed form

// The paper's scene (paper-notes.md section 3): M = 1.0078 kg, C = 0.609 m, J about the knob
// 0.4122 kg m^2, ball 0.145 kg at 27.7 m/s, omega 17.288 rad/s, e = 0.5, pivot at the knob.
struct PivotScene {
  double j = 0.4122, m = 0.145, u = 27.7, w = 17.288, e = 0.5;
};

core::RigidPivotInputs Inputs(const PivotScene& s) {
  core::RigidPivotInputs in;
  in.bat_mass_kg = 1.0078;
  in.balance_point_m = 0.609;
  in.moi_pivot_kg_m2 = s.j;
  in.ball_mass_kg = s.m;
  in.ball_speed_mps = s.u;
  in.angular_speed_rad_s = s.w;
  in.cor = s.e;
  return in;
}

// The closed-form maximiser x* (m from the pivot) or maximum v2max (m/s), with its long double
// reference. x* = w J / (m (u + S)) and ((1+e) S - (1-e) u)/2 are a few roundings each and
// never subtract nearly equal numbers: 8 eps relative (the textbook (S - u)/w loses 4e-4 at
// w = 1e-5 and fails these rows).
CoreCase SweetSpotRow(std::string name, PivotScene s, bool position) {
  return {std::move(name),
          [s, position] {
            const core::ProfileMaximum mx = core::RigidPivotProfile(Inputs(s)).Maximum();
            return Value(position ? mx.x_m : mx.exit_speed_mps);
          },
          Reference(
              [s, position] {
                const ReferenceSweetSpot r = RigidPivotSweetSpot(s.j, s.m, s.u, s.w, s.e);
                return position ? r.x_from_pivot_m : r.exit_speed_mps;
              },
              8 * kEps)};
}

PivotScene Scene(double m, double u, double w, double e) {
  PivotScene s;
  s.m = m;
  s.u = u;
  s.w = w;
  s.e = e;
  return s;
}

std::vector<CoreCase> RigidPivotCases() {
  const PivotScene paper;
  std::vector<CoreCase> rows = {
      SweetSpotRow("PaperSceneSweetSpot", paper, true),
      SweetSpotRow("PaperSceneMaxExitSpeed", paper, false),
      SweetSpotRow("CorZeroMaxExitSpeed", Scene(0.145, 27.7, 17.288, 0.0), false),
      SweetSpotRow("CorOneMaxExitSpeed", Scene(0.145, 27.7, 17.288, 1.0), false),
      SweetSpotRow("CorZeroSweetSpotEqualsCorOne", Scene(0.145, 27.7, 17.288, 0.0), true),
      SweetSpotRow("SwingOf1e-5RadPerSecondSweetSpot", Scene(0.145, 27.7, 1e-5, 0.5), true),
      SweetSpotRow("SwingOf1e4RadPerSecondSweetSpot", Scene(0.145, 27.7, 1e4, 0.5), true),
      SweetSpotRow("SwingOf1e4RadPerSecondMaxExitSpeed", Scene(0.145, 27.7, 1e4, 0.5), false),
      SweetSpotRow("BallAtRestSweetSpot", Scene(0.145, 0.0, 17.288, 0.5), true),
      SweetSpotRow("BallAt1e6MetresPerSecondMaxExitSpeed", Scene(0.145, 1e6, 17.288, 0.5), false),
      // Ball mass >> bat mass (1000 kg) and << (1e-6 kg: x* = 640 m, far beyond the tip).
      SweetSpotRow("BallOf1000KgSweetSpot", Scene(1000.0, 27.7, 17.288, 0.5), true),
      SweetSpotRow("BallOf1000KgMaxExitSpeed", Scene(1000.0, 27.7, 17.288, 0.5), false),
      SweetSpotRow("BallOf1e-6KgSweetSpot", Scene(1e-6, 27.7, 17.288, 0.5), true),
      SweetSpotRow("BallOf1e-6KgMaxExitSpeed", Scene(1e-6, 27.7, 17.288, 0.5), false),
  };
  // No swing: x* = 0 (the pivot) and v2max = e u exactly (S = u; 2 roundings of 27.7).
  rows.push_back(
      {"NoSwingSweetSpotAtThePivot",
       [] {
         return Value(core::RigidPivotProfile(Inputs(Scene(0.145, 27.7, 0.0, 0.5))).Maximum().x_m);
       },
       Exactly(0, 0)});
  rows.push_back({"NoSwingMaxExitSpeedIsCorTimesBallSpeed",
                  [] {
                    return Value(core::RigidPivotProfile(Inputs(Scene(0.145, 27.7, 0.0, 0.5)))
                                     .Maximum()
                                     .exit_speed_mps);
                  },
                  Exactly(0.5L * 27.7L, 4 * kEps * 27.7)});
  // No swing, no ball: the profile is flat (0 everywhere) and says so.
  rows.push_back({"NoSwingNoBallIsFlatZero",
                  [] {
                    const core::ProfileMaximum mx =
                        core::RigidPivotProfile(Inputs(Scene(0.145, 0.0, 0.0, 0.5))).Maximum();
                    return Value(mx.flat ? mx.exit_speed_mps : kNaN);
                  },
                  Exactly(0, 0)});
  // The deficit v2max - v2(x) 1 mm from the maximum (~1e-5 m/s) in closed form: its relative
  // error is a few eps, where the subtraction of two ~23 m/s speeds in double would lose
  // 23 eps / 1e-5 = 5e-10. Reference: the subtraction in long double (error 2e-13 relative).
  rows.push_back({"DeficitAMillimetreFromTheMaximum",
                  [] {
                    const core::ExitSpeedProfile p = core::RigidPivotProfile(Inputs({}));
                    return Value(p.DeficitMps(p.Maximum().x_m + 1e-3));
                  },
                  Reference(
                      [] {
                        const PivotScene s;
                        const core::ExitSpeedProfile p = core::RigidPivotProfile(Inputs(s));
                        const long double x = p.Maximum().x_m + 1e-3;
                        return RigidPivotSweetSpot(s.j, s.m, s.u, s.w, s.e).exit_speed_mps -
                               RigidPivotExitSpeed(s.j, s.m, s.u, s.w, s.e, x);
                      },
                      1e-12)});
  return rows;
}

class HardCaseRigidPivot : public testing::TestWithParam<CoreCase> {};
TEST_P(HardCaseRigidPivot, Holds) { CheckCoreCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Core, HardCaseRigidPivot, testing::ValuesIn(RigidPivotCases()),
                         RowName<CoreCase>);

// ------------------------------------------------------------------------- oblique impact

// The oblique impact's spin (rpm) in long double for a gripping ball (mu_f = inf), the closed
// form of oblique_impact.hpp evaluated in extended precision.
long double ObliqueSpinRpm(const core::ObliqueImpactInputs& in) {
  using L = long double;
  const L pi = 3.141592653589793238462643383279502884L;
  const L d = L(in.descent_angle_deg) * pi / 180, a = L(in.attack_angle_deg) * pi / 180;
  const L wx = -L(in.ball_speed_mps) * std::cos(d) - L(in.bat_speed_mps) * std::cos(a);
  const L wy = -L(in.ball_speed_mps) * std::sin(d) - L(in.bat_speed_mps) * std::sin(a);
  const L speed = std::sqrt(wx * wx + wy * wy);
  const L m = in.ball_mass_kg, big_r = in.ball_radius_m, r = in.bat_radius_m;
  const L alpha = in.ball_gyration_ratio;
  const L sin_psi = L(in.undercut_m) / (big_r + r);
  const L cos_psi = std::sqrt(1 - sin_psi * sin_psi);
  const L inv_mn = 1 / L(in.normal.bat_effective_mass_kg);
  const L j_n = (1 + L(in.normal.cor)) * speed * cos_psi / (1 / m + inv_mn);
  (void)j_n;
  const L inv_mu = (1 + alpha) / (alpha * m) + inv_mn + r * r / L(in.bat_roll_moi_kg_m2);
  const L omega = -L(in.ball_backspin_rad_s);
  const L slip = speed * sin_psi - big_r * omega;
  const L j_t = -(1 + L(in.tangential.tangential_cor)) * slip / inv_mu;
  return (omega - j_t / (alpha * m * big_r)) * 60 / (2 * pi);
}

core::ObliqueImpactInputs ObliqueInputs(double undercut_fraction) {
  core::ObliqueImpactInputs in;
  in.ball_backspin_rad_s = core::RpmToRadPerSecond(2200.0);
  in.normal.bat_effective_mass_kg = 0.6;
  in.tangential.friction_coefficient = std::numeric_limits<double>::infinity();
  in.undercut_m = undercut_fraction * core::MaxUndercutM(in);
  return in;
}

// Against the long double form: a few dozen roundings of terms of size |w| / R (~2e3 rad/s,
// ~2e4 rpm), so 64 eps of 2e4 rpm; the grazing rows (cos psi from (1 - s)(1 + s)) stay there.
CoreCase ObliqueSpinRow(std::string name, core::ObliqueImpactInputs in) {
  return {std::move(name),
          [in] {
            const core::ObliqueImpactResult r = core::SolveObliqueImpact(in);
            return FromSummary(r.summary, r.backspin_rpm);
          },
          Reference([in] { return ObliqueSpinRpm(in); }, 0, 64 * kEps * 2e4)};
}

CoreCase ObliqueRefusalRow(std::string name, void (*set)(core::ObliqueImpactInputs*),
                           std::string phrase) {
  return {std::move(name),
          [set] {
            core::ObliqueImpactInputs in = ObliqueInputs(0.2);
            set(&in);
            const core::ObliqueImpactResult r = core::SolveObliqueImpact(in);
            return FromSummary(r.summary, r.backspin_rpm);
          },
          Refused("invalid_input", std::move(phrase))};
}

std::vector<CoreCase> ObliqueImpactCases() {
  std::vector<CoreCase> rows = {
      ObliqueSpinRow("UndercutOfAFifthOfTheReach", ObliqueInputs(0.2)),
      ObliqueSpinRow("GrazingUndercut", ObliqueInputs(1.0 - 1e-12)),
      ObliqueSpinRow("GrazingOvercut", ObliqueInputs(-1.0 + 1e-12)),
      ObliqueSpinRow("TinyUndercut", ObliqueInputs(1e-300)),
  };
  {
    core::ObliqueImpactInputs slow = ObliqueInputs(0.3);
    slow.ball_speed_mps = 1e-9;
    slow.bat_speed_mps = 0.0;
    slow.ball_backspin_rad_s = 0.0;
    rows.push_back(ObliqueSpinRow("BallAtOneNanometrePerSecond", slow));
  }
  // Elastic, frictionless, immovable bat at rest: the ball leaves at its own speed (a mirror),
  // to a few roundings.
  rows.push_back({"ElasticFrictionlessMirrorKeepsTheSpeed",
                  [] {
                    core::ObliqueImpactInputs in = ObliqueInputs(0.7);
                    in.bat_speed_mps = 0.0;
                    in.normal.cor = 1.0;
                    in.normal.bat_effective_mass_kg = std::numeric_limits<double>::infinity();
                    in.tangential.friction_coefficient = 0.0;
                    const core::ObliqueImpactResult r = core::SolveObliqueImpact(in);
                    return FromSummary(r.summary, r.exit_speed_mps);
                  },
                  Exactly(40.2336, 16 * kEps * 40.2336)});
  rows.push_back(ObliqueRefusalRow(
      "NaNDescentAngleIsRefused",
      [](core::ObliqueImpactInputs* in) { in->descent_angle_deg = std::nan(""); },
      "descent_angle_deg = nan: must be in [-89, 89]"));
  rows.push_back(ObliqueRefusalRow(
      "InfiniteBallSpeedIsRefused",
      [](core::ObliqueImpactInputs* in) {
        in->ball_speed_mps = std::numeric_limits<double>::infinity();
      },
      "ball_speed_mps = inf: must be in [0, 500]"));
  rows.push_back(ObliqueRefusalRow(
      "UndercutAtTheReachIsRefused",
      [](core::ObliqueImpactInputs* in) { in->undercut_m = core::MaxUndercutM(*in); },
      "the ball misses the bat"));
  rows.push_back(ObliqueRefusalRow(
      "SpinOfAMillionRpmIsRefused",
      [](core::ObliqueImpactInputs* in) {
        in->ball_backspin_rad_s = core::RpmToRadPerSecond(1e6);
      },
      "ball_backspin_rad_s = "));
  rows.push_back(ObliqueRefusalRow(
      "NegativeBatRadiusIsRefused", [](core::ObliqueImpactInputs* in) { in->bat_radius_m = -0.01; },
      "bat_radius_m = -0.01: must be in (0, 1]"));
  rows.push_back({"NormalLawAnsweringNaNFails",
                  [] {
                    core::ObliqueImpactInputs in = ObliqueInputs(0.2);
                    in.normal.ball_normal_impulse_n_s = [](double) { return std::nan(""); };
                    const core::ObliqueImpactResult r = core::SolveObliqueImpact(in);
                    return FromSummary(r.summary, r.backspin_rpm);
                  },
                  Refused("failure", "the normal law answered J_n = nan")});
  return rows;
}

class HardCaseObliqueImpact : public testing::TestWithParam<CoreCase> {};
TEST_P(HardCaseObliqueImpact, Holds) { CheckCoreCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Core, HardCaseObliqueImpact, testing::ValuesIn(ObliqueImpactCases()),
                         RowName<CoreCase>);

// ------------------------------------------------------------------------------- free bat

core::FreeBatInputs FreeInputs(double ball_mass, double cor) {
  core::FreeBatInputs in;
  in.bat_mass_kg = 1.0078;
  in.balance_point_m = 0.609;
  in.moi_centroid_kg_m2 = 0.0387;
  in.ball_mass_kg = ball_mass;
  in.cor = cor;
  return in;
}

// The exit speed at 0.7 m against q u + (1 + q) v_bat in long double. Core evaluates
// -u + (1+e)(u + v_bat)/(1 + r): a few roundings of numbers of size u + v_bat, so the bound is
// absolute, 8 eps (u + v_bat).
CoreCase FreeBatRow(std::string name, double ball_mass, double cor) {
  return {std::move(name),
          [ball_mass, cor] {
            return Value(core::FreeBatImpactAt(FreeInputs(ball_mass, cor), 0.7).exit_speed_mps);
          },
          Reference(
              [ball_mass, cor] {
                return FreeBatExitSpeed(1.0078L, 0.0387L, 0.7L - 0.609L, ball_mass, 27.7L,
                                        17.288L * 0.7L, cor);
              },
              0, 8 * kEps * (27.7 + 17.288 * 0.7))};
}

std::vector<CoreCase> FreeBatCases() {
  return {
      FreeBatRow("PaperSceneExitSpeed", 0.145, 0.5),
      FreeBatRow("CorZeroExitSpeed", 0.145, 0.0),
      FreeBatRow("CorOneExitSpeed", 0.145, 1.0),
      FreeBatRow("BallOf1000KgExitSpeed", 1000.0, 0.5),
      FreeBatRow("BallOf1e-6KgExitSpeed", 1e-6, 0.5),
      // BBCOR recovered as e_A (1 + r6) + r6 = e: with a 1000 kg ball r6 = 1205, and the sum
      // (e - r6) + r6 loses log2(r6) bits: |error| <= 4 eps r6 (2.7e-13); exact for r6 < 1.
      {"BbcorRecoveredWithABallOf1000Kg",
       [] { return Value(core::FreeBatImpactAt(FreeInputs(1000.0, 0.5), 0.7).bbcor.bbcor); },
       Exactly(0.5, 4 * kEps * 1206)},
      {"BbcorRecoveredWithTheStandardBall",
       [] { return Value(core::FreeBatImpactAt(FreeInputs(0.145, 0.5), 0.7).bbcor.bbcor); },
       Exactly(0.5, 4 * kEps)},
  };
}

class HardCaseFreeBat : public testing::TestWithParam<CoreCase> {};
TEST_P(HardCaseFreeBat, Holds) { CheckCoreCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Core, HardCaseFreeBat, testing::ValuesIn(FreeBatCases()),
                         RowName<CoreCase>);

// ----------------------------------------------------------------------------------- hertz

// A free two-body contact (no hands, rigid bat surface): for e = 1 the power law is elastic
// and the contact time and compression have closed forms; for any e the impulse is
// (1 + e) v0 / c11 exactly (the unloading returns e^2 of the loading work).
core::HertzProblem FreeContact(double stiffness, double exponent, double cor) {
  core::HertzProblem p;
  p.law = core::ContactLaw::kBallPowerLaw;
  p.approach_speed_mps = 39.8;
  p.ball_speed_mps = 27.7;
  p.ball_mass_kg = 0.145;
  // paper-wood-like: M = 1.0078 kg, I_cm = 0.0387 kg m^2, the impact b = 0.091 m beyond the
  // centroid, the hands b_h = -0.4566 m before it.
  p.c11_per_kg = 1.0 / 0.145 + 1.0 / 1.0078 + 0.091 * 0.091 / 0.0387;
  p.c12_per_kg = 1.0 / 1.0078 - 0.091 * 0.4566 / 0.0387;
  p.c22_per_kg = 1.0 / 1.0078 + 0.4566 * 0.4566 / 0.0387;
  p.ball_stiffness = stiffness;
  p.ball_exponent = exponent;
  p.surface_stiffness = 0.0;
  p.cor = cor;
  p.hands_stiffness_n_m = 0.0;
  return p;
}

enum class HertzOutput { kExitSpeed, kContactTime, kMaxCompression, kApparentCor };

core::HertzSolverOptions Solver(double tolerance) {
  core::HertzSolverOptions o;
  o.relative_tolerance = tolerance;
  return o;
}

Outcome SolveFor(const core::HertzProblem& p, const core::HertzSolverOptions& o, HertzOutput q) {
  const core::HertzImpact r = core::SolveHertzImpact(p, o);
  switch (q) {
    case HertzOutput::kExitSpeed:
      return FromSummary(r.summary, r.exit_speed_mps);
    case HertzOutput::kContactTime:
      return FromSummary(r.summary, r.contact_time_s);
    case HertzOutput::kMaxCompression:
      return FromSummary(r.summary, r.max_compression_m);
    default:
      return FromSummary(r.summary, r.apparent_cor);
  }
}

// Exit speed -u + (1 + e) v0 / (c11 m).
long double TwoBodyExitSpeed(const core::HertzProblem& p) {
  return -static_cast<long double>(p.ball_speed_mps) +
         (1 + static_cast<long double>(p.cor)) * p.approach_speed_mps /
             (static_cast<long double>(p.c11_per_kg) * p.ball_mass_kg);
}

CoreCase HertzExitRow(std::string name, core::HertzProblem p, double tolerance,
                      long double rel_bound) {
  return {std::move(name),
          [p, tolerance] { return SolveFor(p, Solver(tolerance), HertzOutput::kExitSpeed); },
          Reference([p] { return TwoBodyExitSpeed(p); }, rel_bound)};
}

CoreCase HertzElasticRow(std::string name, double stiffness, double exponent, HertzOutput q,
                         long double rel_bound) {
  const core::HertzProblem p = FreeContact(stiffness, exponent, 1.0);
  return {std::move(name), [p, q] { return SolveFor(p, Solver(1e-10), q); },
          Reference(
              [p, q] {
                return q == HertzOutput::kContactTime
                           ? ElasticContactTime(p.c11_per_kg, p.ball_stiffness, p.ball_exponent,
                                                p.approach_speed_mps)
                           : ElasticMaxCompression(p.c11_per_kg, p.ball_stiffness, p.ball_exponent,
                                                   p.approach_speed_mps);
              },
              rel_bound)};
}

std::vector<CoreCase> HertzCases() {
  // Dopri5 on the scaled state: the exit speed is good to ~the relative tolerance (measured
  // 1e-10 to 2e-9 at tol 1e-8, see docs/models.md), so the bound is 10 x the tolerance, and
  // 1e-11 (round-off of the impulse integral) at tolerance 1e-12.
  std::vector<CoreCase> rows = {
      // e = 1 unloads along the loading curve F ~ d^(3/2), whose derivatives are singular at
      // separation, so Dopri5 loses order there: measured 2.4e-7 relative at tol 1e-8 (the
      // solver's own refinement estimate says 2.1e-7); bound 1e-6.
      HertzExitRow("CorOneExitSpeed", FreeContact(4e7, 1.5, 1.0), 1e-8, 1e-6),
      HertzExitRow("DefaultBallExitSpeed", FreeContact(4e7, 1.5, 0.5), 1e-8, 1e-7),
      HertzExitRow("StiffBall1e12ExitSpeed", FreeContact(1e12, 1.5, 0.5), 1e-8, 1e-7),
      HertzExitRow("StiffBall1e15LinearExitSpeed", FreeContact(1e15, 1.0, 0.5), 1e-8, 1e-7),
      HertzExitRow("SoftBall1e3ExitSpeed", FreeContact(1e3, 1.5, 0.5), 1e-8, 1e-7),
      HertzExitRow("SoftBallCubicLawExitSpeed", FreeContact(1.0, 3.0, 0.5), 1e-8, 1e-7),
      HertzExitRow("Tolerance1e-12ExitSpeed", FreeContact(4e7, 1.5, 0.5), 1e-12, 1e-11),
      // e = 0 ends at maximum compression: the impulse v0 / c11 is reached exactly there.
      HertzExitRow("CorZeroExitSpeed", FreeContact(4e7, 1.5, 0.0), 1e-8, 1e-7),
      {"CorZeroApparentCorIsZero",
       [] { return SolveFor(FreeContact(4e7, 1.5, 0.0), Solver(1e-8), HertzOutput::kApparentCor); },
       Exactly(0, 0)},
      // Elastic contact (e = 1) against the closed forms at tolerance 1e-10: the event
      // location and the scaled integration give ~1e-10; bound 1e-8.
      HertzElasticRow("ElasticContactTimeDefaultBall", 4e7, 1.5, HertzOutput::kContactTime, 1e-8),
      HertzElasticRow("ElasticContactTimeStiffBall1e12", 1e12, 1.5, HertzOutput::kContactTime,
                      1e-8),
      HertzElasticRow("ElasticContactTimeSoftBall1e3", 1e3, 1.5, HertzOutput::kContactTime, 1e-8),
      HertzElasticRow("ElasticContactTimeLinearSpring", 4e7, 1.0, HertzOutput::kContactTime, 1e-8),
      HertzElasticRow("ElasticContactTimeCubicLaw", 4e7, 3.0, HertzOutput::kContactTime, 1e-8),
      HertzElasticRow("ElasticMaxCompressionStiffBall1e12", 1e12, 1.5, HertzOutput::kMaxCompression,
                      1e-8),
      HertzElasticRow("ElasticMaxCompressionSoftBall1e3", 1e3, 1.5, HertzOutput::kMaxCompression,
                      1e-8),
  };
  // Approach speeds from 1e-6 to 1e3 m/s: the scaled state makes them the same problem.
  for (const auto& [name, v0] : {std::pair{"ApproachAt1e-6MetresPerSecondExitSpeed", 1e-6},
                                 std::pair{"ApproachAt1e3MetresPerSecondExitSpeed", 1e3}}) {
    core::HertzProblem p = FreeContact(4e7, 1.5, 0.5);
    p.approach_speed_mps = v0;
    p.ball_speed_mps = v0;
    rows.push_back(HertzExitRow(name, p, 1e-8, 1e-7));
  }
  // Hands 1e12 N/m: their period (~2.5 us) is 300 times shorter than the contact, so the bat
  // is pinned at the hands. Bounded against that limit: exit = -u + (1+e) v0 / (m c11'), c11'
  // = c11 - c12^2 / c22 = 1/m + z^2 / I_h for an impact z from the hands; the spring's residual
  // vibration and the finite stiffness leave it within 1e-3 relative.
  rows.push_back({"StiffHands1e12PinTheBat",
                  [] {
                    core::HertzProblem p = FreeContact(4e7, 1.5, 0.5);
                    p.hands_stiffness_n_m = 1e12;
                    return SolveFor(p, Solver(1e-8), HertzOutput::kExitSpeed);
                  },
                  Reference(
                      [] {
                        // The impact 0.091 m beyond C, the hands 0.4566 m before it.
                        const long double ih = 0.0387L + 1.0078L * 0.4566L * 0.4566L;
                        const long double z = 0.091L + 0.4566L;
                        const long double c11 = 1 / 0.145L + z * z / ih;
                        return -27.7L + 1.5L * 39.8L / (0.145L * c11);
                      },
                      1e-3)});
  // A contact too stiff for the explicit integrator's step bound is a named failure.
  rows.push_back({"StepBoundIsANamedFailure",
                  [] {
                    core::HertzSolverOptions o = Solver(1e-8);
                    o.max_steps = 10;
                    return SolveFor(FreeContact(4e7, 1.5, 0.5), o, HertzOutput::kExitSpeed);
                  },
                  Refused("failure", "the contact did not end within max_steps = 10")});
  rows.push_back({"ZeroApproachSpeedIsRefused",
                  [] {
                    core::HertzProblem p = FreeContact(4e7, 1.5, 0.5);
                    p.approach_speed_mps = 0.0;
                    return SolveFor(p, Solver(1e-8), HertzOutput::kExitSpeed);
                  },
                  Refused("invalid_input", "approach_speed_mps = 0: must be finite and > 0")});
  rows.push_back(
      {"ToleranceBelow1e-13IsRefused",
       [] { return SolveFor(FreeContact(4e7, 1.5, 0.5), Solver(1e-14), HertzOutput::kExitSpeed); },
       Refused("invalid_input", "relative_tolerance = 1e-14")});
  return rows;
}

class HardCaseHertz : public testing::TestWithParam<CoreCase> {};
TEST_P(HardCaseHertz, Holds) { CheckCoreCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Core, HardCaseHertz, testing::ValuesIn(HertzCases()), RowName<CoreCase>);

// ------------------------------------------------------------------- scenes and sweet zones

core::Scene PaperWood() {
  core::Scene s;
  s.bat = core::FindPreset("paper-wood")->bat;
  s.paper_bat = true;  // as the api marks the paper's preset: model auto is the paper's rigid_pivot
  return s;
}

std::vector<CoreCase> SceneCases() {
  return {
      // Zone tolerance 0: the zone is the maximiser itself. At a double root the ends move by
      // sqrt(2 rounding / |f''|) ~ 1e-7 m: the width is in [0, 2e-7] m.
      {"SweetZoneOfZeroToleranceIsAPoint",
       [] {
         core::Scene s = PaperWood();
         s.outputs = {core::SceneOutput::kSweetZone};
         core::SceneOptions o;
         o.sweet_zone_tolerance = 0.0;
         const core::SceneResult r = core::EvaluateScene(s, o);
         return FromSummary(
             r.summary, r.sweet_zone ? r.sweet_zone->to_knob_m - r.sweet_zone->from_knob_m : kNaN);
       },
       Within(0, 2e-7)},
      // A tolerance above the whole curve's range: the zone is the bat, ends exactly 0 and L.
      {"SweetZoneOfHugeToleranceIsTheWholeBat",
       [] {
         core::Scene s = PaperWood();
         s.outputs = {core::SceneOutput::kSweetZone};
         core::SceneOptions o;
         o.sweet_zone_tolerance = 1e3;
         const core::SceneResult r = core::EvaluateScene(s, o);
         return FromSummary(
             r.summary, r.sweet_zone ? r.sweet_zone->to_knob_m - r.sweet_zone->from_knob_m : kNaN);
       },
       Exactly(0.855, 0)},
      // A pivot 100 m beyond the knob swinging at 1e4 rad/s: the maximiser is clamped to the
      // tip, which must be reported as the tip exactly (not L + rounding of 100 + (L - 100)).
      {"ClampedSweetSpotIsExactlyTheTip",
       [] {
         core::Scene s = PaperWood();
         s.swing.pivot_from_knob_m = 100.0;
         s.swing.angular_speed_rad_s = 1e4;
         const core::SceneResult r = core::EvaluateScene(s, {});
         return FromSummary(r.summary,
                            r.max_exit_speed ? r.max_exit_speed->position_from_knob_m : kNaN);
       },
       Exactly(0.855, 0)},
      {"ClampedSweetZoneEndsWithinTheBat",
       [] {
         core::Scene s = PaperWood();
         s.swing.pivot_from_knob_m = 100.0;
         s.swing.angular_speed_rad_s = 1e4;
         s.outputs = {core::SceneOutput::kSweetZone};
         const core::SceneResult r = core::EvaluateScene(s, {});
         return FromSummary(r.summary, r.sweet_zone ? r.sweet_zone->to_knob_m : kNaN);
       },
       Within(0, 0.855)},
      {"HertzRefusesNoMotion",
       [] {
         core::Scene s = PaperWood();
         s.swing.angular_speed_rad_s = 0.0;
         s.ball.speed_mps = 0.0;
         return FromSummary(core::Collide(s, 0.7, core::CollisionModel::kHertz).summary, kNaN);
       },
       Refused("invalid_input", "hertz.approach_speed_mps = 0")},
      {"ImpactBeyondTheTipIsRefused",
       [] {
         return FromSummary(
             core::Collide(PaperWood(), 0.855 + 1e-12, core::CollisionModel::kFreeBat).summary,
             kNaN);
       },
       Refused("invalid_input", "must be within the bat [0, 0.85499999999999998]")},
      {"SubnormalBallMassIsRefused",
       [] {
         core::Scene s = PaperWood();
         s.ball.mass_kg = 5e-324;
         return FromSummary(core::Collide(s, 0.7, core::CollisionModel::kFreeBat).summary, kNaN);
       },
       Refused("invalid_input",
               "ball.mass_kg = 4.9406564584124654e-324: must be in [1e-06, 1000]")},
      {"ZeroBallRadiusIsRefused",
       [] {
         core::Scene s = PaperWood();
         s.ball.radius_m = 0.0;
         return FromSummary(core::Collide(s, 0.7, core::CollisionModel::kHertz).summary, kNaN);
       },
       Refused("invalid_input", "ball.radius_m = 0: must be in [1e-06, 10]")},
  };
}

class HardCaseScene : public testing::TestWithParam<CoreCase> {};
TEST_P(HardCaseScene, Holds) { CheckCoreCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Core, HardCaseScene, testing::ValuesIn(SceneCases()), RowName<CoreCase>);

// ------------------------------------------------------------ NLopt on a flat objective

// Every offered NLopt algorithm through EvaluateScene (method nlopt, rigid pivot) on two flat
// objectives:
//  - no swing and no ball (u = 0, omega = 0): the exit speed is 0 at every impact position, so
//    any point of the bat is a maximiser: the answer is exactly 0 at a point of the bat,
//    usable (converged, or no_convergence when the first-order check cannot certify a flat
//    function);
//  - e = 0, no swing (u = 27.7): v2 = -u m x^2 / (J + m x^2) <= 0, flat (f' = f'' ... = 0 up to
//    x^2) at the pivot, the knob: the maximum 0 at x = 0. Within x_tol the value is below 0 by
//    u m x^2 / J: with x <= 1e-4 m that is <= 1e-7 m/s.
// The value is NaN (the row fails) when the reported position is outside the bat.
Outcome FlatSearch(core::NloptAlgorithm algorithm, bool ball_at_rest) {
  core::Scene s = PaperWood();
  s.swing.angular_speed_rad_s = 0.0;
  if (ball_at_rest) {
    s.ball.speed_mps = 0.0;
  } else {
    s.cor = 0.0;
  }
  core::SceneOptions o;
  o.method = core::SweetSpotMethod::kNlopt;
  o.nlopt.algorithm = algorithm;
  const core::SceneResult r = core::EvaluateScene(s, o);
  if (!r.max_exit_speed) return FromSummary(r.summary, kNaN);
  const double x = r.max_exit_speed->position_from_knob_m;
  const bool on_bat = x >= 0.0 && x <= 0.855;
  return FromSummary(r.max_exit_speed->summary, on_bat ? r.max_exit_speed->exit_speed_mps : kNaN);
}

std::vector<CoreCase> FlatObjectiveCases() {
  std::vector<CoreCase> rows;
  for (const core::NloptAlgorithm a : core::OfferedNloptAlgorithms()) {
    const std::string name = core::NloptAlgorithmName(a);
    std::string camel;  // "LD_SLSQP" -> "LdSlsqp"
    bool upper = true;
    for (const char ch : name) {
      if (ch == '_') {
        upper = true;
        continue;
      }
      camel += upper ? ch : static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
      upper = false;
    }
    rows.push_back({camel + "NoSwingNoBall", [a] { return FlatSearch(a, true); },
                    Exactly(0, 0).With("usable")});
    rows.push_back({camel + "CorZeroNoSwing", [a] { return FlatSearch(a, false); },
                    Within(-1e-7, 0).With("usable")});
  }
  return rows;
}

class HardCaseNloptFlat : public testing::TestWithParam<CoreCase> {};
TEST_P(HardCaseNloptFlat, Holds) { CheckCoreCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Core, HardCaseNloptFlat, testing::ValuesIn(FlatObjectiveCases()),
                         RowName<CoreCase>);

}  // namespace
}  // namespace core_collision_test
}  // namespace sweetspot::hard_cases
