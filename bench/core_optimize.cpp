// Design optimisation (core/optimize): a 16-knot profile design (target <= 100 ms per solve),
// limited-memory vs exact Hessian, Ipopt vs NLopt SLSQP, the model's evaluation costs, and a
// min_sting design (NLopt COBYLA over the flexible beam).
// Run: build/bench/sweetspot_bench_core --benchmark_filter=Optimize
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace bench_core_optimize {
namespace {

// A 16-knot solid ash bat, 0.86 m: handle 0.0125 m, a smooth taper to a 0.0325 m barrel.
Bat SixteenKnotBat() {
  Bat bat;
  const int n = 16;
  const double length = 0.86;
  for (int i = 0; i < n; ++i) {
    const double x = length * i / (n - 1);
    const double s = x / length;
    bat.knots.push_back({x, 0.0125 + 0.020 / (1.0 + std::exp(-14.0 * (s - 0.55)))});
  }
  bat.material = *FindMaterial("ash");
  return bat;
}

// Max exit speed over the radii of knots 1..14 (the knob knot and the tip fixed), at the base
// mass, with the balance point at most 0.60 m, a 2.61-in barrel limit, a 0.9-in handle
// minimum and a non-decreasing taper.
DesignProblem SixteenKnotProblem() {
  DesignProblem p;
  p.bat = SixteenKnotBat();
  for (int i = 1; i <= 14; ++i) {
    p.variables.push_back({"profile.knots[" + std::to_string(i) + "].radius_m", 0.0110, 0.0332});
  }
  p.constraints.mass_kg = DesignRange::Equal(ComputeMassProperties(p.bat).mass_kg);
  p.constraints.balance_point_m = DesignRange::AtMost(0.60);
  p.constraints.max_barrel_diameter_m = InchesToMetres(2.61);
  p.constraints.min_handle_diameter_m = InchesToMetres(0.9);
  p.constraints.taper = TaperRule::kNonDecreasing;
  return p;
}

DesignProblem ThreeSegmentProblem() {
  DesignProblem p;
  p.three_segment = ThreeSegmentShape{0.8636, 0.0125, 0.033, 0.30, 0.55};
  p.bat.material = *FindMaterial("ash");
  p.variables = {{"three_segment.taper_start_m", 0.1, 0.5},
                 {"three_segment.taper_end_m", 0.3, 0.8},
                 {"three_segment.barrel_radius_m", 0.028, 0.0331}};
  p.constraints.mass_kg = DesignRange::Equal(0.88);
  p.constraints.balance_point_m = DesignRange::Between(0.56, 0.60);
  p.constraints.rules = {RuleSet::kMlbWood};
  return p;
}

void Report(benchmark::State& state, const DesignResult& r) {
  state.counters["iterations"] = r.summary.iterations;
  state.counters["evaluations"] = r.summary.evaluations;
  state.counters["objective_mps"] = r.objective_value;
  state.counters["converged"] = r.summary.termination == Termination::kConverged ? 1 : 0;
}

void BM_OptimizeSixteenKnots(benchmark::State& state) {
  const DesignProblem p = SixteenKnotProblem();
  DesignOptions o;
  o.hessian = state.range(0) != 0 ? HessianMode::kExact : HessianMode::kLimitedMemory;
  DesignResult r;
  for (auto _ : state) {
    r = OptimizeDesign(p, o);
    benchmark::DoNotOptimize(r);
  }
  Report(state, r);
  state.SetLabel(o.hessian == HessianMode::kExact ? "exact hessian" : "limited-memory");
}
BENCHMARK(BM_OptimizeSixteenKnots)->Arg(0)->Arg(1)->ArgName("exact")->Unit(benchmark::kMillisecond);

void BM_OptimizeSixteenKnotsNlopt(benchmark::State& state) {
  const DesignProblem p = SixteenKnotProblem();
  DesignOptions o;
  o.backend = DesignBackend::kNloptSlsqp;
  DesignResult r;
  for (auto _ : state) {
    r = OptimizeDesign(p, o);
    benchmark::DoNotOptimize(r);
  }
  Report(state, r);
}
BENCHMARK(BM_OptimizeSixteenKnotsNlopt)->Unit(benchmark::kMillisecond);

// The 16-knot problem generalised to n knots (knots 1..n-2 free; bench/scipy_peers.py's
// `design --knots n`), for the scaling table of issue 36 (bench/optimize_scaling.sh).
DesignProblem KnotProblem(int n) {
  DesignProblem p;
  const double length = 0.86;
  for (int i = 0; i < n; ++i) {
    const double x = length * i / (n - 1);
    const double s = x / length;
    p.bat.knots.push_back({x, 0.0125 + 0.020 / (1.0 + std::exp(-14.0 * (s - 0.55)))});
  }
  p.bat.material = *FindMaterial("ash");
  for (int i = 1; i <= n - 2; ++i) {
    p.variables.push_back({"profile.knots[" + std::to_string(i) + "].radius_m", 0.0110, 0.0332});
  }
  p.constraints.mass_kg = DesignRange::Equal(ComputeMassProperties(p.bat).mass_kg);
  p.constraints.balance_point_m = DesignRange::AtMost(0.60);
  p.constraints.max_barrel_diameter_m = InchesToMetres(2.61);
  p.constraints.min_handle_diameter_m = InchesToMetres(0.9);
  p.constraints.taper = TaperRule::kNonDecreasing;
  return p;
}

// backend: 3 the default request (the optimiser chooses: DesignOptions::choose_backend), 4 the
// same without the taper's steps as variables (DesignOptions::taper_steps false), 0 Ipopt
// exact Hessian, 1 Ipopt limited memory (both lifted when the problem qualifies, as here), 2
// NLopt SLSQP. A problem the service refuses (SLSQP over 32 variables) reports refused = 1 and
// no time of a solve.
void BM_OptimizeKnots(benchmark::State& state) {
  const DesignProblem p = KnotProblem(static_cast<int>(state.range(0)));
  DesignOptions o;
  o.backend = state.range(1) == 2 ? DesignBackend::kNloptSlsqp : DesignBackend::kIpopt;
  o.hessian = state.range(1) == 0 ? HessianMode::kExact : HessianMode::kLimitedMemory;
  o.choose_backend = state.range(1) >= 3;  // the api's default request
  o.taper_steps = state.range(1) != 4;     // 4: the same over the radii (tapered_nlp.hpp)
  o.max_variables = 100000;  // the service's cap is --max-design-variables; measure past it
  DesignResult r;
  for (auto _ : state) {
    r = OptimizeDesign(p, o);
    benchmark::DoNotOptimize(r);
  }
  Report(state, r);
  state.counters["refused"] = r.summary.termination == Termination::kInvalidInput ? 1 : 0;
  const auto& used = r.summary.models_used;
  const bool lifted = std::find(used.begin(), used.end(), "lifted_integrals") != used.end();
  state.SetLabel(r.summary.termination == Termination::kInvalidInput
                     ? r.summary.message
                     : r.summary.backend + (lifted ? " lifted" : ""));
}
BENCHMARK(BM_OptimizeKnots)
    ->ArgsProduct({{16, 32, 64, 128, 256}, {3, 4, 0, 1, 2}})
    ->ArgNames({"knots", "backend"})
    ->Unit(benchmark::kMillisecond);

void BM_OptimizeThreeSegment(benchmark::State& state) {
  const DesignProblem p = ThreeSegmentProblem();
  DesignOptions o;
  o.hessian = state.range(0) != 0 ? HessianMode::kExact : HessianMode::kLimitedMemory;
  DesignResult r;
  for (auto _ : state) {
    r = OptimizeDesign(p, o);
    benchmark::DoNotOptimize(r);
  }
  Report(state, r);
}
BENCHMARK(BM_OptimizeThreeSegment)->Arg(0)->Arg(1)->ArgName("exact")->Unit(benchmark::kMillisecond);

// The model alone: one evaluation with gradients, and one exact Hessian (16 knots, 14 variables).
void BM_OptimizeModelEvaluate(benchmark::State& state) {
  DesignModel model;
  Refusal why;
  DesignModel::Build(SixteenKnotProblem(), DesignOptions{}, &model, &why);
  const std::vector<double> x = model.BaseX();
  DesignPoint point;
  const bool hessian = state.range(0) != 0;
  std::vector<double> weights(static_cast<std::size_t>(model.m()), 1.0);
  Eigen::MatrixXd h;
  for (auto _ : state) {
    if (hessian) {
      model.Hessian(x.data(), 1.0, weights.data(), &h);
      benchmark::DoNotOptimize(h.data());
    } else {
      model.Evaluate(x.data(), true, &point);
      benchmark::DoNotOptimize(point);
    }
  }
  state.SetLabel(hessian ? "hessian" : "values+gradients");
}
BENCHMARK(BM_OptimizeModelEvaluate)->Arg(0)->Arg(1)->ArgName("hessian");

// min_sting on the contract's three-segment ash bat: the taper's end in [0.45, 0.75] m with the
// mass at most 1.05 kg (variables = 1), and also the barrel radius in [0.029, 0.033] m
// (variables = 2). Each COBYLA evaluation is the rigid sweet spot in closed form and one flexible
// impact there (12 modes to 1e-3, one Dopri5 run); the answer's impact is recomputed with the
// error checks.
void BM_OptimizeMinSting(benchmark::State& state) {
  DesignProblem p;
  p.three_segment = ThreeSegmentShape{0.8636, 0.0125, 0.033, 0.30, 0.55};
  p.bat.material = *FindMaterial("ash");
  p.cor = 0.5;
  p.objective = DesignObjective::kMinSting;
  p.variables = {{"three_segment.taper_end_m", 0.45, 0.75}};
  if (state.range(0) == 2) p.variables.push_back({"three_segment.barrel_radius_m", 0.029, 0.033});
  p.constraints.mass_kg = DesignRange::Between(0.90, 1.05);
  DesignOptions o;
  o.backend = DesignBackend::kNloptCobyla;
  DesignResult r;
  for (auto _ : state) {
    r = OptimizeDesign(p, o);
    benchmark::DoNotOptimize(r);
  }
  state.counters["evaluations"] = r.summary.evaluations;
  state.counters["objective_j"] = r.objective_value;
  state.counters["converged"] = r.summary.termination == Termination::kConverged ? 1 : 0;
}
BENCHMARK(BM_OptimizeMinSting)->Arg(1)->Arg(2)->ArgName("variables")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bench_core_optimize
}  // namespace sweetspot::core
