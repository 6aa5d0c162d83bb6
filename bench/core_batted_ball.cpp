// The batted-ball scene outputs (core/scene/batted_ball.hpp): distance_sweet_spot and carry_map
// through EvaluateScene, wood-34-ash, a 90 mph pitch descending 6°, a 70 mph swing rising 10°:
//   sweetspot_bench_core --benchmark_filter='DistanceSweetSpot|CarryMap|BattedBall'
// Targets (issue 34): distance_sweet_spot with the free bat <= 5 ms; a 41 x 21 carry_map with
// the flexible bat <= 1 s. Counters: distance_m, evals (carries computed), impacts (the normal
// model's ODE impacts: the table's), table_err_m (distance_sweet_spot: the exact law's carry at
// the optimum minus the table's).
#include <benchmark/benchmark.h>

#include <memory>

#include "core/bat/presets.hpp"
#include "core/flexible/modes_cache.hpp"
#include "core/scene/evaluate_scene.hpp"

namespace sweetspot::core {
// In a namespace of its own: the benchmark programs are unity builds (cmake/BuildSpeed.cmake).
namespace bench_core_batted_ball {
namespace {

Scene GameScene(SceneOutput output) {
  Scene s;
  s.bat = FindPreset("wood-34-ash")->bat;
  s.ball.speed_mps = 90.0 * 0.44704;
  s.ball.descent_angle_deg = 6.0;
  s.swing.bat_speed_mps = 70.0 * 0.44704;
  s.swing.attack_angle_deg = 10.0;
  s.outputs = {output};
  return s;
}

const ModelTiming* TimingOf(const SceneResult& r, const char* model) {
  for (const auto& t : r.timings) {
    if (t.model == model) return &t;
  }
  return nullptr;
}

// Arg 0: the collision model (CollisionModel's value).
void BM_DistanceSweetSpot(benchmark::State& state) {
  const Scene scene = GameScene(SceneOutput::kDistanceSweetSpot);
  SceneOptions options;
  options.model = static_cast<CollisionModel>(state.range(0));
  options.time_models = false;
  ModesCache cache;  // flexible: the modes from a cache, as the server's
  options.flexible.modes_cache = &cache;
  SceneEvaluator evaluator(options);
  SceneResult r;
  for (auto _ : state) {
    evaluator.Evaluate(scene, &r);
    benchmark::DoNotOptimize(r);
  }
  if (!r.distance_sweet_spot) {
    state.SkipWithError(r.summary.message.c_str());
    return;
  }
  state.SetLabel(CollisionModelName(options.model));
  state.counters["distance_m"] = r.distance_sweet_spot->distance_m;
  state.counters["evals"] = r.distance_sweet_spot->evaluations;
  state.counters["table_err_m"] = r.distance_sweet_spot->normal_table_error_m;
  const ModelTiming* impacts = TimingOf(r, CollisionModelName(options.model));
  state.counters["impacts"] = impacts != nullptr ? impacts->calls : 0;
}
BENCHMARK(BM_DistanceSweetSpot)
    ->Arg(static_cast<int>(CollisionModel::kFreeBat))
    ->Arg(static_cast<int>(CollisionModel::kRigidPivot))
    ->Arg(static_cast<int>(CollisionModel::kHertz))
    ->Arg(static_cast<int>(CollisionModel::kFlexible))
    ->Unit(benchmark::kMillisecond);

// Arg 0: the collision model; the modes (flexible) from a cache shared across iterations
// (as the server's), so that the figure is the map's own.
void BM_CarryMap(benchmark::State& state) {
  const Scene scene = GameScene(SceneOutput::kCarryMap);
  SceneOptions options;
  options.model = static_cast<CollisionModel>(state.range(0));
  options.time_models = false;
  ModesCache cache;
  options.flexible.modes_cache = &cache;
  SceneEvaluator evaluator(options);
  SceneResult r;
  for (auto _ : state) {
    evaluator.Evaluate(scene, &r);
    benchmark::DoNotOptimize(r);
  }
  if (!r.carry_map) {
    state.SkipWithError(r.summary.message.c_str());
    return;
  }
  state.SetLabel(CollisionModelName(options.model));
  state.counters["best_m"] = r.carry_map->best_distance_m;
  const ModelTiming* impacts = TimingOf(r, CollisionModelName(options.model));
  state.counters["impacts"] = impacts != nullptr ? impacts->calls : 0;
}
BENCHMARK(BM_CarryMap)
    ->Arg(static_cast<int>(CollisionModel::kFreeBat))
    ->Arg(static_cast<int>(CollisionModel::kFlexible))
    ->Unit(benchmark::kMillisecond);

// The flexible map with its modes computed fresh every time (no cache).
void BM_CarryMapFlexibleFresh(benchmark::State& state) {
  const Scene scene = GameScene(SceneOutput::kCarryMap);
  SceneOptions options;
  options.model = CollisionModel::kFlexible;
  options.time_models = false;
  SceneEvaluator evaluator(options);
  SceneResult r;
  for (auto _ : state) {
    evaluator.Evaluate(scene, &r);
    benchmark::DoNotOptimize(r);
  }
  if (!r.carry_map) state.SkipWithError(r.summary.message.c_str());
}
BENCHMARK(BM_CarryMapFlexibleFresh)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bench_core_batted_ball
}  // namespace sweetspot::core
