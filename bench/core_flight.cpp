// Speed against error of one batted-ball flight (core/flight), Nathan's model, 100 mph at 28°
// with the Statcast spin relation:
//   sweetspot_bench_core --benchmark_filter=Flight
// Target (issue 34): one flight to 0.1 ft (3.05 cm) of distance in ≤ 5 µs of CPU.
// Counters: distance_ft; err_ft = |distance − a 1e-12 run's| in feet; est_ft = the flight's own
// error estimate in feet; steps = accepted steps; evals = right-hand-side evaluations;
// us_per_flight = CPU µs per flight of a batch (FlyMany, and the grid one at a time).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "core/flight/flight.hpp"

namespace sweetspot::core::flight {
// In a namespace of its own: the benchmark programs are unity builds (cmake/BuildSpeed.cmake).
namespace bench_core_flight {
namespace {

template <class T>
void Keep(const T& value) {
  benchmark::DoNotOptimize(value);
}

Launch Reference() {
  Launch launch;
  launch.exit_speed_mps = 100.0 * kMpsPerMph;
  launch.launch_angle_deg = 28.0;
  return launch;
}

double ReferenceDistanceM() {
  FlightOptions tight;
  tight.relative_tolerance = 1e-12;
  tight.absolute_tolerance_m = 1e-12;
  return Fly(Reference(), {}, {}, tight).distance_m;
}

// Arg: −log10 of the relative tolerance (5 = the default, 1e-5, with absolute 1e-3 m).
void BM_FlightNathan(benchmark::State& state) {
  FlightOptions options;
  if (state.range(0) != 5) {
    options.relative_tolerance = std::pow(10.0, -static_cast<double>(state.range(0)));
    options.absolute_tolerance_m = options.relative_tolerance * 100.0;  // as the default
  }
  const Launch launch = Reference();
  const Environment environment;
  const AeroOptions aero;
  FlightResult r;
  for (auto _ : state) {
    Keep(launch);
    r = Fly(launch, environment, aero, options);
    Keep(r.distance_m);
  }
  const double reference = ReferenceDistanceM();
  state.counters["distance_ft"] = r.distance_m / kMetresPerFoot;
  state.counters["err_ft"] = std::abs(r.distance_m - reference) / kMetresPerFoot;
  state.counters["est_ft"] = r.error_estimate_m / kMetresPerFoot;
  state.counters["steps"] = r.steps;
  state.counters["evals"] = r.evaluations;
}
BENCHMARK(BM_FlightNathan)->Arg(4)->Arg(5)->Arg(6)->Arg(8)->Arg(10)->Arg(12);

// The same flight 1024 times through FlyMany (kFlyManyLanes side by side): the batched
// figure per flight (us_per_flight), the workload of BM_FlightNathan/5 repeated; the answers
// are Fly's to the bit (FlightTest.FlyManyGivesFlysAnswers).
void BM_FlyManyNathan(benchmark::State& state) {
  const std::vector<Launch> launches(1024, Reference());
  const Environment environment;
  std::vector<FlightResult> results(launches.size());
  for (auto _ : state) {
    Keep(launches.front());
    FlyMany(launches.size(), launches.data(), &environment, true, {}, {}, results.data());
    Keep(results.back().distance_m);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(launches.size()));
  state.counters["us_per_flight"] = benchmark::Counter(
      static_cast<double>(launches.size()) * 1e-6,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["err_ft"] =
      std::abs(results.back().distance_m - ReferenceDistanceM()) / kMetresPerFoot;
}
BENCHMARK(BM_FlyManyNathan);

// A varied workload: 456 launches (25-55 m/s, −5° to 85°, calm and 10-20 m/s winds out and
// across: FlightTest's grid), one at a time (Arg 0) or through FlyMany (Arg 1).
void BM_FlightGrid(benchmark::State& state) {
  std::vector<Launch> launches;
  std::vector<Environment> environments;
  for (double v : {25.0, 35.0, 45.0, 55.0}) {
    for (double la = -5.0; la <= 85.0; la += 5.0) {
      for (double wind : {0.0, 10.0, 20.0}) {
        for (double direction : {0.0, 135.0}) {
          Launch launch;
          launch.exit_speed_mps = v;
          launch.launch_angle_deg = la;
          launches.push_back(launch);
          Environment environment;
          environment.wind.speed_mps = wind;
          environment.wind.direction_deg = direction;
          environments.push_back(environment);
        }
      }
    }
  }
  std::vector<FlightResult> results(launches.size());
  for (auto _ : state) {
    Keep(launches.front());
    if (state.range(0) == 0) {
      for (std::size_t i = 0; i < launches.size(); ++i) {
        results[i] = Fly(launches[i], environments[i]);
      }
    } else {
      FlyMany(launches.size(), launches.data(), environments.data(), false, {}, {},
              results.data());
    }
    Keep(results.back().distance_m);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(launches.size()));
  state.counters["us_per_flight"] = benchmark::Counter(
      static_cast<double>(launches.size()) * 1e-6,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_FlightGrid)->Arg(0)->Arg(1);

void BM_FlightWithTrajectory(benchmark::State& state) {
  std::vector<TrajectoryPoint> path;
  path.reserve(256);
  for (auto _ : state) {
    const FlightResult r = Fly(Reference(), {}, {}, {}, &path);
    Keep(r.distance_m);
  }
  state.counters["points"] = static_cast<double>(path.size());
}
BENCHMARK(BM_FlightWithTrajectory);

void BM_FlightSawicki(benchmark::State& state) {
  AeroOptions aero;
  aero.model = AeroModel::kSawicki2003;
  for (auto _ : state) {
    const FlightResult r = Fly(Reference(), {}, aero);
    Keep(r.distance_m);
  }
}
BENCHMARK(BM_FlightSawicki);

}  // namespace
}  // namespace bench_core_flight
}  // namespace sweetspot::core::flight
