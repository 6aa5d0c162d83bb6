// Mass properties of 3-, 16- and 64-knot bats, with and without gradients.
// Run: build/bench/sweetspot_bench_core --benchmark_filter=MassProperties
#include <benchmark/benchmark.h>

#include <cmath>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"
#include "core/optimize/shape_fit.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace bench_core_mass_properties {
namespace {

// A smooth, bat-like profile with n knots (deterministic).
Bat BenchBat(int n, bool hollow) {
  Bat bat;
  const double length = 0.86;
  for (int i = 0; i < n; ++i) {
    const double x = length * i / (n - 1);
    const double s = x / length;
    bat.knots.push_back({x, 0.012 + 0.021 / (1.0 + std::exp(-14.0 * (s - 0.55)))});
  }
  bat.material = *FindMaterial(hollow ? "aluminium-7050" : "ash");
  if (hollow) bat.wall_thickness_m = 0.0028;
  return bat;
}

void BM_MassProperties(benchmark::State& state) {
  const Bat bat = BenchBat(static_cast<int>(state.range(0)), state.range(1) != 0);
  for (auto _ : state) {
    MassProperties p = ComputeMassProperties(bat, InertiaModel::kRigidBody);
    benchmark::DoNotOptimize(p);
  }
}
BENCHMARK(BM_MassProperties)->ArgsProduct({{3, 16, 64}, {0, 1}})->ArgNames({"knots", "hollow"});

void BM_MassPropertiesWithGradient(benchmark::State& state) {
  const Bat bat = BenchBat(static_cast<int>(state.range(0)), state.range(1) != 0);
  for (auto _ : state) {
    MassPropertiesWithGradient g = ComputeMassPropertiesWithGradient(bat);
    benchmark::DoNotOptimize(g);
  }
}
BENCHMARK(BM_MassPropertiesWithGradient)
    ->ArgsProduct({{3, 16, 64}, {0, 1}})
    ->ArgNames({"knots", "hollow"});

void BM_ShapeFitTable2(benchmark::State& state) {
  ShapeFitProblem problem;
  problem.shape = PaperThreeSegmentShape();
  problem.material = *FindMaterial("paper-wood");
  problem.unknowns = {{DesignVariableKind::kTaperStart, 0.0, 0.855},
                      {DesignVariableKind::kTaperEnd, 0.0, 0.855}};
  problem.targets.mass_kg = 0.885;
  problem.targets.balance_point_m = 0.564;
  for (auto _ : state) {
    ShapeFitResult r = FitShape(problem);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_ShapeFitTable2)->Unit(benchmark::kMicrosecond);

// An attainable fit: the taper of the paper's bat from M* = 0.95 kg, C* = 0.6 m (the api's
// golden fit_taper request), met to round-off.
void BM_ShapeFitTaper(benchmark::State& state) {
  ShapeFitProblem problem;
  problem.shape = PaperThreeSegmentShape();
  problem.material = *FindMaterial("paper-wood");
  problem.unknowns = {{DesignVariableKind::kTaperStart, 0.0, 0.855},
                      {DesignVariableKind::kTaperEnd, 0.0, 0.855}};
  problem.targets.mass_kg = 0.95;
  problem.targets.balance_point_m = 0.6;
  for (auto _ : state) {
    ShapeFitResult r = FitShape(problem);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_ShapeFitTaper)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace bench_core_mass_properties
}  // namespace sweetspot::core
