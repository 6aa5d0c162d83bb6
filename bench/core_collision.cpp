// Speed against error for the collision models and the sweet-spot search.
//   sweetspot_bench_core --benchmark_filter='Rigid|Hertz|Scene'
// Counters: err_m / err_rel = distance from the closed form (or from a 1e-12 reference run),
// evals = objective evaluations, steps = accepted ODE steps.
#include <benchmark/benchmark.h>

#include <cmath>

#include "core/bat/presets.hpp"
#include "core/collision/free_bat.hpp"
#include "core/collision/hertz_contact.hpp"
#include "core/collision/oblique_impact.hpp"
#include "core/collision/rigid_pivot.hpp"
#include "core/numerics/nlopt_search.hpp"
#include "core/scene/collide.hpp"
#include "core/scene/evaluate_scene.hpp"
#include "core/scene/scene_barrel.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace bench_core_collision {
namespace {

// benchmark 1.7.1's DoNotOptimize(T&) uses a "+m,r" constraint that GCC 12 may satisfy with a
// general-purpose register for a double and write garbage back (seen here: results read as 0).
// The const overload is input-only.
template <class T>
void Keep(const T& value) {
  benchmark::DoNotOptimize(value);
}

RigidPivotInputs PaperBat() {
  RigidPivotInputs in;
  in.bat_mass_kg = 1.0078;
  in.balance_point_m = 0.6090;
  in.moi_pivot_kg_m2 = 0.4122;
  return in;
}

void BM_RigidSweetSpotClosedForm(benchmark::State& state) {
  const ExitSpeedProfile p = RigidPivotProfile(PaperBat());
  double x = 0.0;
  for (auto _ : state) {
    Keep(p);
    const ProfileMaximum m = p.Maximum();
    x = std::min(m.x_m, 0.855);
    Keep(x);
  }
  state.counters["x_m"] = x;
}
BENCHMARK(BM_RigidSweetSpotClosedForm);

void BM_RigidSweetSpotClosedFormFull(benchmark::State& state) {
  // ClosedFormMaxExitSpeed: also evaluates both ends and fills the result/summary.
  const ExitSpeedProfile p = RigidPivotProfile(PaperBat());
  for (auto _ : state) {
    MaxExitSpeedResult r = ClosedFormMaxExitSpeed(p, 0.855);
    Keep(r.position_from_knob_m);
  }
}
BENCHMARK(BM_RigidSweetSpotClosedFormFull);

void BM_RigidSweetSpotNlopt(benchmark::State& state, NloptAlgorithm algorithm) {
  const ExitSpeedProfile p = RigidPivotProfile(PaperBat());
  const double exact = p.Maximum().x_m;
  ScalarSearchOptions o;
  o.algorithm = algorithm;
  o.x_tolerance_m = 1e-10;
  const bool grad = NloptAlgorithmNeedsGradient(algorithm);
  auto f = [&p](double x, double* g) {
    if (g != nullptr) *g = p.DerivativePerS(x);
    return p.ExitSpeedMps(x);
  };
  ScalarSearchResult r;
  for (auto _ : state) {
    r = MaximizeScalar(f, grad || NloptAlgorithmIsGlobal(algorithm), 0.0, 0.855, o);
    Keep(r.x);
  }
  state.counters["err_m"] = std::abs(r.x - exact);
  state.counters["evals"] = r.summary.evaluations;
  state.SetLabel(TerminationName(r.summary.termination));
}
BENCHMARK_CAPTURE(BM_RigidSweetSpotNlopt, LD_SLSQP, NloptAlgorithm::kLdSlsqp);
BENCHMARK_CAPTURE(BM_RigidSweetSpotNlopt, LD_LBFGS, NloptAlgorithm::kLdLbfgs);
BENCHMARK_CAPTURE(BM_RigidSweetSpotNlopt, LD_TNEWTON, NloptAlgorithm::kLdTnewton);
BENCHMARK_CAPTURE(BM_RigidSweetSpotNlopt, LD_MMA, NloptAlgorithm::kLdMma);
BENCHMARK_CAPTURE(BM_RigidSweetSpotNlopt, LD_CCSAQ, NloptAlgorithm::kLdCcsaq);
BENCHMARK_CAPTURE(BM_RigidSweetSpotNlopt, LN_BOBYQA, NloptAlgorithm::kLnBobyqa);
BENCHMARK_CAPTURE(BM_RigidSweetSpotNlopt, LN_COBYLA, NloptAlgorithm::kLnCobyla);
BENCHMARK_CAPTURE(BM_RigidSweetSpotNlopt, LN_SBPLX, NloptAlgorithm::kLnSbplx);
BENCHMARK_CAPTURE(BM_RigidSweetSpotNlopt, LN_NELDERMEAD, NloptAlgorithm::kLnNelderMead);
BENCHMARK_CAPTURE(BM_RigidSweetSpotNlopt, GN_DIRECT_L, NloptAlgorithm::kGnDirectL);
BENCHMARK_CAPTURE(BM_RigidSweetSpotNlopt, GN_AGS, NloptAlgorithm::kGnAgs);
BENCHMARK_CAPTURE(BM_RigidSweetSpotNlopt, GN_CRS2_LM, NloptAlgorithm::kGnCrs2Lm);

HertzProblem DefaultContact() {
  // The default physical contact of the paper-wood bat at 0.72 m (what Collide builds).
  Scene s;
  s.bat = FindPreset("paper-wood")->bat;
  const CollisionResult c = Collide(s, 0.72, CollisionModel::kHertz);
  return c.hertz->problem;
}

void BM_HertzImpact(benchmark::State& state) {
  const double tol = std::pow(10.0, -static_cast<double>(state.range(0)));
  const HertzProblem p = DefaultContact();
  HertzSolverOptions ref_o;
  ref_o.relative_tolerance = 1e-12;
  ref_o.refine_check = false;
  ref_o.max_steps = 200000;
  const HertzImpact ref = SolveHertzImpact(p, ref_o);
  HertzSolverOptions o;
  o.relative_tolerance = tol;
  o.refine_check = false;
  HertzImpact r;
  for (auto _ : state) {
    r = SolveHertzImpact(p, o);
    Keep(r.exit_speed_mps);
  }
  state.counters["err_rel"] = std::abs(r.exit_speed_mps / ref.exit_speed_mps - 1.0);
  state.counters["t_err_rel"] = std::abs(r.contact_time_s / ref.contact_time_s - 1.0);
  state.counters["steps"] = r.steps;
  state.SetLabel(TerminationName(r.summary.termination));
}
BENCHMARK(BM_HertzImpact)->DenseRange(4, 12, 2)->Unit(benchmark::kMicrosecond);

void BM_HertzImpactPaperConstants(benchmark::State& state) {
  HertzProblem p = DefaultContact();
  p.law = ContactLaw::kPaperConstants;
  HertzSolverOptions o;
  o.relative_tolerance = 1e-6;
  o.refine_check = false;
  for (auto _ : state) {
    HertzImpact r = SolveHertzImpact(p, o);
    Keep(r.contact_time_s);
  }
}
BENCHMARK(BM_HertzImpactPaperConstants)->Unit(benchmark::kMicrosecond);

void BM_SceneDefault(benchmark::State& state) {
  // Mass properties (exact integrals) + closed-form sweet spot + zone + CoP.
  Scene s;
  s.bat = FindPreset("paper-wood")->bat;
  s.outputs = {SceneOutput::kMaxExitSpeed, SceneOutput::kSweetZone,
               SceneOutput::kCenterOfPercussion};
  const SceneOptions o;
  for (auto _ : state) {
    SceneResult r = EvaluateScene(s, o);
    Keep(r.max_exit_speed);
  }
}
BENCHMARK(BM_SceneDefault)->Unit(benchmark::kMicrosecond);

void BM_CollideHertzWithRefinement(benchmark::State& state) {
  Scene s;
  s.bat = FindPreset("paper-wood")->bat;
  for (auto _ : state) {
    CollisionResult r = Collide(s, 0.72, CollisionModel::kHertz);
    Keep(r.exit_speed_mps);
  }
}
BENCHMARK(BM_CollideHertzWithRefinement)->Unit(benchmark::kMicrosecond);

// The oblique impact (core/collision/oblique_impact.hpp) next to the normal model it wraps: the
// free bat's impact at one point (FreeBatImpactAt, with its BBCOR-style block) and the oblique
// impact with the pair (M_n, e) and with the normal part as a std::function answering the free
// bat's impulse at v_n (how the scene would wire hertz or flexible; here the cost of the call).
FreeBatInputs ObliqueBenchBat() {
  FreeBatInputs in;
  in.bat_mass_kg = 1.0078;
  in.balance_point_m = 0.6090;
  in.moi_centroid_kg_m2 = 0.4122 - 1.0078 * 0.6090 * 0.6090;
  return in;
}

ObliqueImpactInputs ObliqueBenchInputs() {
  ObliqueImpactInputs in;  // 90 mph pitch, 6 degrees down; 70 mph bat, 10 degrees up
  in.ball_backspin_rad_s = RpmToRadPerSecond(2200.0);
  in.undercut_m = 0.019;
  const FreeBatInputs bat = ObliqueBenchBat();
  const double b = 0.72 - bat.balance_point_m;
  in.normal.bat_effective_mass_kg =
      1.0 / (1.0 / bat.bat_mass_kg + b * b / bat.moi_centroid_kg_m2);
  return in;
}

void BM_FreeBatImpactNormalModel(benchmark::State& state) {
  const FreeBatInputs bat = ObliqueBenchBat();
  for (auto _ : state) {
    Keep(bat);
    const FreeBatImpact r = FreeBatImpactAt(bat, 0.72);
    Keep(r.exit_speed_mps);
  }
}
BENCHMARK(BM_FreeBatImpactNormalModel);

void BM_ObliqueImpact(benchmark::State& state) {
  ObliqueImpactInputs in = ObliqueBenchInputs();
  double rpm = 0.0;
  for (auto _ : state) {
    Keep(in);
    const ObliqueImpactResult r = SolveObliqueImpact(in);
    rpm = r.backspin_rpm;
    Keep(rpm);
  }
  state.counters["backspin_rpm"] = rpm;
}
BENCHMARK(BM_ObliqueImpact);

void BM_ObliqueImpactNormalLawCallable(benchmark::State& state) {
  ObliqueImpactInputs in = ObliqueBenchInputs();
  const FreeBatInputs bat = ObliqueBenchBat();
  in.normal.ball_normal_impulse_n_s = [bat](double v_n) {
    FreeBatInputs at_rest = bat;
    at_rest.ball_speed_mps = v_n;
    at_rest.angular_speed_rad_s = 0.0;
    return FreeBatImpactAt(at_rest, 0.72).ball_impulse_n_s;
  };
  for (auto _ : state) {
    const ObliqueImpactResult r = SolveObliqueImpact(in);
    Keep(r.backspin_rpm);
  }
}
BENCHMARK(BM_ObliqueImpactNormalLawCallable);

// Issue 35: THE BBCOR (the flexible scan's maximum) against its fixed-point estimate, per
// design, for the aluminium preset: the estimate (ComputeBbcor), the certified value with the
// bat's modes computed (ComputeCertifiedBbcor, no cache: what rules: bbcor pays per answer) and
// with the modes given (the scan alone).
//   sweetspot_bench_core --benchmark_filter='Bbcor'
void BM_BbcorEstimate(benchmark::State& state) {
  const Bat bat = FindPreset("bbcor-33-aluminium")->bat;
  for (auto _ : state) {
    const BbcorResult r = ComputeBbcor(bat);
    Keep(r.value);
  }
}
BENCHMARK(BM_BbcorEstimate)->Unit(benchmark::kMicrosecond);

void BM_BbcorCertifiedWithModes(benchmark::State& state) {
  const Bat bat = FindPreset("bbcor-33-aluminium")->bat;
  int impacts = 0;
  for (auto _ : state) {
    BbcorScan scan;
    const BbcorResult r =
        ComputeCertifiedBbcor(bat, FlexibleOptions{}, BarrelOptions{}, nullptr, nullptr, &scan);
    impacts = static_cast<int>(scan.points.size()) + scan.polish_impacts;
    Keep(r.value);
  }
  state.counters["impacts"] = impacts;
}
BENCHMARK(BM_BbcorCertifiedWithModes)->Unit(benchmark::kMillisecond);

void BM_BbcorCertifiedScanOnly(benchmark::State& state) {
  const Bat bat = FindPreset("bbcor-33-aluminium")->bat;
  const BatModes modes = ComputeBatModes(bat, FlexibleOptions{}.ImpactModes());
  for (auto _ : state) {
    const BbcorResult r =
        ComputeCertifiedBbcor(bat, FlexibleOptions{}, BarrelOptions{}, nullptr, &modes);
    Keep(r.value);
  }
}
BENCHMARK(BM_BbcorCertifiedScanOnly)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bench_core_collision
}  // namespace sweetspot::core
