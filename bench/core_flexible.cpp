// Speed against error for the flexible bat (core/flexible/*).
//   sweetspot_bench_core --benchmark_filter='Flexible|Modes'
// Counters: elements, err_rel = largest relative frequency error of the first 4 modes against
// a 1e-9-tolerance reference, est_rel = the error the solver reports, err_mps = exit-speed
// difference to a 40-mode, 1e-11-tolerance reference, modes = bending modes used.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/bat/presets.hpp"
#include "core/collision/bbcor_scan.hpp"
#include "core/collision/flexible_impact.hpp"
#include "core/collision/hertz_contact.hpp"
#include "core/flexible/modes.hpp"
#include "core/flexible/modes_cache.hpp"
#include "core/scene/collide.hpp"
#include "core/scene/evaluate_scene.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace bench_core_flexible {
namespace {

// See bench/core_collision.cpp: the const overload of DoNotOptimize is input-only.
template <class T>
void Keep(const T& value) {
  benchmark::DoNotOptimize(value);
}

const Bat& PaperBat() {
  static const Bat bat = FindPreset("paper-wood")->bat;
  return bat;
}

// The first 4 frequencies to 1e-9 (round-off limited near 1e-8 for Euler-Bernoulli: the
// reference's own error estimate is reported as ref_est_rel).
const BatModes& Reference(BeamTheory theory) {
  static const BatModes eb = [] {
    BeamModesOptions o;
    o.theory = BeamTheory::kEulerBernoulli;
    o.relative_tolerance = 1e-9;
    return ComputeBatModes(PaperBat(), o);
  }();
  static const BatModes ti = [] {
    BeamModesOptions o;
    o.theory = BeamTheory::kTimoshenko;
    o.relative_tolerance = 1e-9;
    return ComputeBatModes(PaperBat(), o);
  }();
  return theory == BeamTheory::kEulerBernoulli ? eb : ti;
}

double WorstError(const BatModes& m, const BatModes& ref) {
  double worst = 0.0;
  for (std::size_t k = 0; k < 4 && k < m.modes.size(); ++k) {
    worst = std::max(worst, std::abs(m.modes[k].frequency_hz / ref.modes[k].frequency_hz - 1.0));
  }
  return worst;
}

// One fixed mesh (initial = max elements: a single solve, no refinement).
void BM_ModesFixedMesh(benchmark::State& state, BeamTheory theory) {
  BeamModesOptions o;
  o.theory = theory;
  o.initial_elements = static_cast<int>(state.range(0));
  o.max_elements = 4 * static_cast<int>(state.range(0));  // the first mesh may add knot splits
  o.relative_tolerance = 0.1;                             // stop after the second mesh
  BatModes m;
  for (auto _ : state) {
    m = ComputeBatModes(PaperBat(), o);
    Keep(m.modes.front().frequency_hz);
  }
  state.counters["elements"] = m.Elements();
  state.counters["err_rel"] = WorstError(m, Reference(theory));
  state.counters["ref_est_rel"] = Reference(theory).max_relative_error;
}
BENCHMARK_CAPTURE(BM_ModesFixedMesh, EulerBernoulli, BeamTheory::kEulerBernoulli)
    ->Arg(4)
    ->Arg(8)
    ->Arg(16)
    ->Arg(32)
    ->Arg(64)
    ->Arg(128)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ModesFixedMesh, Timoshenko, BeamTheory::kTimoshenko)
    ->Arg(4)
    ->Arg(8)
    ->Arg(16)
    ->Arg(32)
    ->Arg(64)
    ->Arg(128)
    ->Unit(benchmark::kMicrosecond);

// The adaptive solve to a tolerance (arg: -log10 tolerance), 4 modes: the target is
// 1e-4 in <= 5 ms.
void BM_ModesToTolerance(benchmark::State& state, BeamTheory theory) {
  BeamModesOptions o;
  o.theory = theory;
  o.relative_tolerance = std::pow(10.0, -static_cast<double>(state.range(0)));
  BatModes m;
  for (auto _ : state) {
    m = ComputeBatModes(PaperBat(), o);
    Keep(m.modes.front().frequency_hz);
  }
  state.counters["elements"] = m.Elements();
  state.counters["err_rel"] = WorstError(m, Reference(theory));
  state.counters["est_rel"] = m.max_relative_error;
  state.SetLabel(TerminationName(m.summary.termination));
}
BENCHMARK_CAPTURE(BM_ModesToTolerance, EulerBernoulli, BeamTheory::kEulerBernoulli)
    ->Arg(3)
    ->Arg(4)
    ->Arg(6)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ModesToTolerance, Timoshenko, BeamTheory::kTimoshenko)
    ->Arg(3)
    ->Arg(4)
    ->Arg(6)
    ->Unit(benchmark::kMicrosecond);

// The impact's default mode set: 12 modes to 1e-3 (what Collide(kFlexible) computes once).
void BM_ModesForImpacts(benchmark::State& state) {
  BeamModesOptions o;
  o.num_modes = 12;
  o.relative_tolerance = 1e-3;
  BatModes m;
  for (auto _ : state) {
    m = ComputeBatModes(PaperBat(), o);
    Keep(m.modes.front().frequency_hz);
  }
  state.counters["elements"] = m.Elements();
}
BENCHMARK(BM_ModesForImpacts)->Unit(benchmark::kMicrosecond);

FlexibleImpactInputs Inputs(double s) {
  FlexibleImpactInputs in;
  in.impact_from_knob_m = s;
  in.approach_speed_mps = 27.7 + 17.288 * s;
  in.surface_stiffness =
      BatSurfaceHertzStiffness(PaperBat().material.youngs_modulus_pa,
                               PaperBat().material.poissons_ratio, 0.0366, PaperBat().RadiusAtM(s));
  return in;
}

double ReferenceExit(double s) {
  static const BatModes many = [] {
    BeamModesOptions o;
    o.num_modes = 40;
    return ComputeBatModes(PaperBat(), o);
  }();
  FlexibleImpactOptions o;
  o.cutoff_factor = 1000.0;
  o.relative_tolerance = 1e-11;
  o.refine_check = false;
  return SolveFlexibleImpact(PaperBat(), many, Inputs(s), o).exit_speed_mps;
}

// One impact at 0.7 m with a given number of bending modes (arg), refinement off; with and
// without the static correction.
void BM_FlexibleImpactModes(benchmark::State& state, bool correction) {
  BeamModesOptions mo;
  mo.num_modes = static_cast<int>(state.range(0));
  mo.relative_tolerance = 1e-4;
  const BatModes modes = ComputeBatModes(PaperBat(), mo);
  FlexibleImpactOptions o;
  o.cutoff_factor = 1000.0;
  o.static_correction = correction;
  o.refine_check = false;
  FlexibleImpactResult r;
  for (auto _ : state) {
    r = SolveFlexibleImpact(PaperBat(), modes, Inputs(0.7), o);
    Keep(r.exit_speed_mps);
  }
  static const double reference = ReferenceExit(0.7);
  state.counters["modes"] = r.modes_used;
  state.counters["steps"] = r.steps;
  state.counters["err_mps"] = std::abs(r.exit_speed_mps - reference);
}
BENCHMARK_CAPTURE(BM_FlexibleImpactModes, corrected, true)
    ->Arg(2)
    ->Arg(4)
    ->Arg(8)
    ->Arg(12)
    ->Arg(16)
    ->Arg(24)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_FlexibleImpactModes, uncorrected, false)
    ->Arg(4)
    ->Arg(12)
    ->Arg(24)
    ->Unit(benchmark::kMicrosecond);

// The BBCOR scan (bbcor_scan.hpp) of a preset with the scene's default options: 9 flexible
// impacts at 136 mph, 4 to 8 in from the tip, on modes computed once outside the loop (the
// refinement check on: each point is run three times). Counters: the maximum, its location
// from the tip (in) and the fixed-point rigid value beside it.
void BM_BbcorScan(benchmark::State& state, const char* preset) {
  const Bat bat = FindPreset(preset)->bat;
  const FlexibleOptions fo;
  const BatModes modes = ComputeBatModes(bat, fo.ImpactModes());
  BbcorScan scan;
  for (auto _ : state) {
    scan = ComputeBbcorScan(bat, modes, {}, fo.impact);
    Keep(scan.max_value);
  }
  state.counters["max"] = scan.max_value;
  state.counters["max_from_tip_in"] = scan.max_from_tip_m / 0.0254;
  state.counters["fixed_point"] = scan.fixed_point_value;
  state.counters["steps"] = scan.steps;
}
BENCHMARK_CAPTURE(BM_BbcorScan, wood_34_ash, "wood-34-ash")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BbcorScan, paper_wood, "paper-wood")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BbcorScan, bbcor_33_aluminium, "bbcor-33-aluminium")
    ->Unit(benchmark::kMillisecond);

// Collide(kFlexible) as /v1/collision runs it: modes (12 to 1e-3) + impact with the refinement
// runs; "cached" reuses the modes through a ModesCache.
void BM_CollideFlexible(benchmark::State& state, bool cached) {
  Scene scene;
  scene.bat = PaperBat();
  ModesCache cache;
  CollisionOptions o;
  if (cached) o.flexible.modes_cache = &cache;
  CollisionResult r;
  for (auto _ : state) {
    r = Collide(scene, 0.7, CollisionModel::kFlexible, o);
    Keep(r.exit_speed_mps);
  }
  state.counters["err_est_mps"] = r.error_estimate_mps;
  state.counters["err_mps"] = std::abs(r.exit_speed_mps - ReferenceExit(0.7));
}
BENCHMARK_CAPTURE(BM_CollideFlexible, fresh, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_CollideFlexible, cached, true)->Unit(benchmark::kMicrosecond);

// vibration_node (2 modes to 1e-4) and least_sting_zone (41 impacts + refinement) via
// EvaluateScene.
void BM_SceneFlexible(benchmark::State& state, SceneOutput output) {
  Scene scene;
  scene.bat = PaperBat();
  scene.outputs = {output};
  SceneResult r;
  for (auto _ : state) {
    r = EvaluateScene(scene, {});
    Keep(r.summary.solve_time_s);
  }
  state.SetLabel(TerminationName(r.summary.termination));
}
BENCHMARK_CAPTURE(BM_SceneFlexible, vibration_node, SceneOutput::kVibrationNode)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SceneFlexible, least_sting_zone, SceneOutput::kLeastStingZone)
    ->Unit(benchmark::kMillisecond);

// The flexible max-exit-speed sweet spot of wood-34-ash (issue 17), through EvaluateScene:
// "paper" = the scene's default speeds (ball 27.7 m/s, 17.288 rad/s), "game" = a 40 m/s pitch
// and a 45 rad/s swing (~32 m/s bat speed at 0.7 m). `nlopt` = SweetSpotMethod::kNlopt, the
// NLopt search (LN_BOBYQA, every impact with the refinement check); `default` = the default
// method. Fresh: no modes cache (the modes are computed in every iteration); cached: a
// ModesCache warmed before the loop. Counters: evals = impacts of the search (summary
// evaluations), pos_err_m = |position - reference| (the reference: a tight run, see
// SweetSpotReference), est_m = the reported position error estimate.
Scene AshScene(bool game, std::vector<SceneOutput> outputs) {
  Scene scene;
  scene.bat = FindPreset("wood-34-ash")->bat;
  scene.outputs = std::move(outputs);
  if (game) {
    scene.ball.speed_mps = 40.0;
    scene.swing.angular_speed_rad_s = 45.0;
  }
  return scene;
}

// The converged sweet spot: the NLopt search to 1e-12 m on impacts with 1e-11 integration
// tolerance (the default modes and cutoff: the model the answer is an answer of).
double TightSweetSpot(bool game) {
  SceneOptions o;
  o.model = CollisionModel::kFlexible;
  o.method = SweetSpotMethod::kNlopt;
  o.flexible.impact.relative_tolerance = 1e-11;
  o.flexible.impact.refine_check = false;
  const SceneResult r = EvaluateScene(AshScene(game, {SceneOutput::kMaxExitSpeed}), o);
  return r.max_exit_speed ? r.max_exit_speed->position_from_knob_m : std::nan("");
}
double SweetSpotReference(bool game) {
  static const double paper = TightSweetSpot(false);
  static const double fast = TightSweetSpot(true);
  return game ? fast : paper;
}

void BM_FlexibleSweetSpot(benchmark::State& state, bool game, bool nlopt, bool cached) {
  const Scene scene = AshScene(game, {SceneOutput::kMaxExitSpeed});
  ModesCache cache;
  SceneOptions o;
  o.model = CollisionModel::kFlexible;
  if (nlopt) o.method = SweetSpotMethod::kNlopt;
  if (cached) {
    o.flexible.modes_cache = &cache;
    Keep(EvaluateScene(scene, o).summary.solve_time_s);
  }
  SceneResult r;
  for (auto _ : state) {
    r = EvaluateScene(scene, o);
    Keep(r.summary.solve_time_s);
  }
  state.SetLabel(TerminationName(r.summary.termination));
  if (!r.max_exit_speed) return;
  state.counters["evals"] = r.max_exit_speed->summary.evaluations;
  state.counters["pos_err_m"] =
      std::abs(r.max_exit_speed->position_from_knob_m - SweetSpotReference(game));
  state.counters["est_m"] = r.max_exit_speed->error_estimate_m;
}
BENCHMARK_CAPTURE(BM_FlexibleSweetSpot, paper_nlopt_fresh, false, true, false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FlexibleSweetSpot, paper_nlopt_cached, false, true, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FlexibleSweetSpot, paper_default_fresh, false, false, false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FlexibleSweetSpot, paper_default_cached, false, false, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FlexibleSweetSpot, game_nlopt_cached, true, true, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FlexibleSweetSpot, game_default_fresh, true, false, false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FlexibleSweetSpot, game_default_cached, true, false, true)
    ->Unit(benchmark::kMillisecond);

// least_sting_zone of wood-34-ash per design (default speeds), fresh and cached modes.
void BM_LeastStingZone(benchmark::State& state, bool cached) {
  const Scene scene = AshScene(false, {SceneOutput::kLeastStingZone});
  ModesCache cache;
  SceneOptions o;
  if (cached) {
    o.flexible.modes_cache = &cache;
    Keep(EvaluateScene(scene, o).summary.solve_time_s);
  }
  SceneResult r;
  for (auto _ : state) {
    r = EvaluateScene(scene, o);
    Keep(r.summary.solve_time_s);
  }
  state.SetLabel(TerminationName(r.summary.termination));
  if (!r.least_sting_zone) return;
  state.counters["min_m"] = r.least_sting_zone->min_position_from_knob_m;
  state.counters["from_m"] = r.least_sting_zone->from_knob_m;
  state.counters["to_m"] = r.least_sting_zone->to_knob_m;
  state.counters["est_m"] = r.least_sting_zone->error_estimate_m;
  for (const auto& t : r.timings) {
    if (t.model == "flexible") state.counters["impacts"] = t.calls;
  }
}
BENCHMARK_CAPTURE(BM_LeastStingZone, fresh, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LeastStingZone, cached, true)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bench_core_flexible
}  // namespace sweetspot::core
