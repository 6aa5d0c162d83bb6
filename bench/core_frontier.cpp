// The frontier (issue 36, item 3): the best 16-knot bat at each of 20 masses (the base mass
// -2 oz to +2 oz), solved as one frontier (each value from its neighbour's answer, a secant
// predictor, the Newton step on the neighbour's active set) against 20 independent solves of
// the same problems (each from the base design).
// Run: build/bench/sweetspot_bench_core --benchmark_filter=Frontier
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/bat/material.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/optimize/frontier.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace bench_core_frontier {
namespace {

// bench/core_optimize.cpp's 16-knot problem (solid ash, 0.86 m, balance point <= 0.60 m,
// diameters, non-decreasing taper), its mass the frontier's quantity.
DesignProblem SixteenKnotProblem() {
  DesignProblem p;
  const int n = 16;
  const double length = 0.86;
  for (int i = 0; i < n; ++i) {
    const double x = length * i / (n - 1);
    const double s = x / length;
    p.bat.knots.push_back({x, 0.0125 + 0.020 / (1.0 + std::exp(-14.0 * (s - 0.55)))});
  }
  p.bat.material = *FindMaterial("ash");
  for (int i = 1; i <= 14; ++i) {
    p.variables.push_back({"profile.knots[" + std::to_string(i) + "].radius_m", 0.0110, 0.0332});
  }
  p.constraints.balance_point_m = DesignRange::AtMost(0.60);
  p.constraints.max_barrel_diameter_m = InchesToMetres(2.61);
  p.constraints.min_handle_diameter_m = InchesToMetres(0.9);
  p.constraints.taper = TaperRule::kNonDecreasing;
  return p;
}

FrontierSpec TwentyMasses(const DesignProblem& p, bool warm) {
  FrontierSpec spec;
  const double base = ComputeMassProperties(p.bat).mass_kg;
  for (int i = 0; i < 20; ++i) {
    spec.values.push_back(base + OuncesToKilograms(-2.0 + 4.0 * i / 19.0));
  }
  spec.warm_start = warm;
  return spec;
}

void BM_FrontierTwentyMasses(benchmark::State& state) {
  const DesignProblem p = SixteenKnotProblem();
  const FrontierSpec spec = TwentyMasses(p, state.range(0) != 0);
  DesignOptions o;
  o.hessian = state.range(1) != 0 ? HessianMode::kExact : HessianMode::kLimitedMemory;
  // exact = 2: the api's default request (no options.backend: the optimiser chooses).
  o.choose_backend = state.range(1) == 2;
  FrontierSummary s;
  double objective_sum = 0.0;
  std::vector<double> objectives;
  int newton = 0;  // values answered by the Newton step (summary.backend active_set_newton)
  for (auto _ : state) {
    objective_sum = 0.0;
    objectives.clear();
    newton = 0;
    s = OptimizeFrontier(p, spec, o, true, [&](const FrontierPoint& point) {
      objective_sum += point.result.objective_value;
      objectives.push_back(point.result.objective_value);
      newton += point.result.summary.backend == "active_set_newton" ? 1 : 0;
      return true;
    });
    benchmark::DoNotOptimize(s);
  }
  // The same optima: the largest relative difference from the independent solves (outside
  // the timing).
  FrontierSpec independent = spec;
  independent.warm_start = false;
  double worst = 0.0;
  std::size_t k = 0;
  OptimizeFrontier(p, independent, o, true, [&](const FrontierPoint& point) {
    if (k < objectives.size()) {
      worst = std::max(worst, std::abs(objectives[k] - point.result.objective_value) /
                                  std::abs(point.result.objective_value));
    }
    ++k;
    return true;
  });
  state.counters["max_rel_diff"] = worst;
  state.counters["iterations"] = s.summary.iterations;
  state.counters["converged"] = s.converged;
  state.counters["restarts"] = s.restarts;
  state.counters["continued"] = s.continued;
  state.counters["newton"] = newton;
  state.counters["objective_sum"] = objective_sum;
  state.SetLabel(state.range(0) != 0 ? "frontier" : "independent");
}
BENCHMARK(BM_FrontierTwentyMasses)
    ->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1})->Args({0, 2})->Args({1, 2})
    ->ArgNames({"warm", "exact"})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bench_core_frontier
}  // namespace sweetspot::core
