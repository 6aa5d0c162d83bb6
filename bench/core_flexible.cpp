// Speed against error for the flexible bat (core/flexible/*).
//   sweetspot_bench_core --benchmark_filter='Flexible|Modes'
// Counters: elements, err_rel = largest relative frequency error of the first 4 modes against
// a 1e-9-tolerance reference, est_rel = the error the solver reports, err_mps = exit-speed
// difference to a 40-mode, 1e-11-tolerance reference, modes = bending modes used.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/collision/collide.hpp"
#include "core/collision/flexible_impact.hpp"
#include "core/collision/hertz_contact.hpp"
#include "core/flexible/modes.hpp"
#include "core/presets.hpp"
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

}  // namespace
}  // namespace bench_core_flexible
}  // namespace sweetspot::core
