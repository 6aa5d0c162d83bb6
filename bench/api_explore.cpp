// Throughput of /v1/explore with the rigid model (issue 7's target: at least a
// million designs per minute per core, i.e. >= 16,667 designs/s), per answer format
// (json, ndjson, csv with two columns: issue 17), and of one /v1/sweet-spot request
// through the handler (no network).
#include <benchmark/benchmark.h>

#include <string>

#include "api/router.hpp"

namespace {

using sweetspot::api::Context;
using sweetspot::api::Dispatch;

std::string Sweep(int designs, const char* outputs) {
  return std::string(R"({"bat": {"preset": "paper-wood",
      "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}},
      "parameters": [{"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": )") +
         std::to_string(designs) + R"(}], "outputs": )" + outputs + "}";
}

void BM_ExploreRigid(benchmark::State& state, const char* outputs) {
  const int designs = static_cast<int>(state.range(0));
  const std::string body = Sweep(designs, outputs);
  const Context context;
  for (auto _ : state) {
    auto response = Dispatch({"POST", "/v1/explore", body}, context);
    if (response.status != 200) state.SkipWithError("explore failed");
    benchmark::DoNotOptimize(response);
  }
  state.SetItemsProcessed(state.iterations() * designs);
}
BENCHMARK_CAPTURE(BM_ExploreRigid, max_exit_speed, R"(["max_exit_speed"])")->Arg(1000);
BENCHMARK_CAPTURE(BM_ExploreRigid, max_and_properties, R"(["max_exit_speed", "properties"])")
    ->Arg(1000);

// One answer format of the same 1000-design rigid sweep (max_exit_speed), as the bytes a
// client gets: the full json rows (the body dumped, as the server and the CLI do), the full
// ndjson lines (streamed; collected here as the CLI and jobs do), csv with two columns, and
// ndjson with the same two columns. Items are designs: items/s compares the formats per design.
void BM_ExploreFormat(benchmark::State& state, const char* format, const char* columns) {
  const int designs = static_cast<int>(state.range(0));
  std::string body = Sweep(designs, R"(["max_exit_speed"])");
  body.pop_back();  // the closing brace
  body += std::string(R"(, "format": ")") + format + "\"" + columns + "}";
  const Context context;
  std::size_t bytes = 0;
  for (auto _ : state) {
    auto response = Dispatch({"POST", "/v1/explore", body}, context);
    if (response.status != 200) state.SkipWithError("explore failed");
    const std::string text = response.content_type.empty() ? response.body.dump() : response.text;
    bytes = text.size();
    benchmark::DoNotOptimize(text);
  }
  state.counters["bytes_per_design"] = static_cast<double>(bytes) / designs;
  state.SetItemsProcessed(state.iterations() * designs);
}
BENCHMARK_CAPTURE(BM_ExploreFormat, json, "json", "")->Arg(1000);
BENCHMARK_CAPTURE(BM_ExploreFormat, ndjson, "ndjson", "")->Arg(1000);
BENCHMARK_CAPTURE(BM_ExploreFormat, csv_2_columns, "csv",
                  R"(, "columns": ["parameters.fill.depth_m", "max_exit_speed.exit_speed_mps"])")
    ->Arg(1000);
BENCHMARK_CAPTURE(BM_ExploreFormat, ndjson_2_columns, "ndjson",
                  R"(, "columns": ["parameters.fill.depth_m", "max_exit_speed.exit_speed_mps"])")
    ->Arg(1000);

void BM_SweetSpotRequest(benchmark::State& state) {
  const std::string body = R"({"bat": {"preset": "paper-wood"},
      "outputs": ["max_exit_speed", "center_of_percussion", "sweet_zone"]})";
  const Context context;
  for (auto _ : state) {
    auto response = Dispatch({"POST", "/v1/sweet-spot", body}, context);
    benchmark::DoNotOptimize(response);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SweetSpotRequest);

}  // namespace
