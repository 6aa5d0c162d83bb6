// Speed against error of one batted-ball flight (core/flight), Nathan's model, 100 mph at 28°
// with the Statcast spin relation:
//   sweetspot_bench_core --benchmark_filter=Flight
// Target (issue 34): one flight to 0.1 ft (3.05 cm) of distance in ≤ 5 µs of CPU.
// Counters: distance_ft; err_ft = |distance − a 1e-12 run's| in feet; est_ft = the flight's own
// error estimate in feet; steps = accepted steps; evals = right-hand-side evaluations.
#include <benchmark/benchmark.h>

#include <cmath>

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
