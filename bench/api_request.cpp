// The API side of bench/http_bench.sh's request, without the network: the contract's example
// POST /v1/sweet-spot (max_exit_speed) through the handler and its answer's text (the tree's, and
// written straight to text as the server answers); the two pieces api/json_text.hpp writes (the
// answer's text, the provenance's input hash); and the body read by nlohmann's parser with and
// without its tree, and by ParseBody. The HTTP server's CPU per request is this plus
// the socket, epoll and framing work (bench/cpu_per_request.sh; docs/http-bench.md).
#include <benchmark/benchmark.h>

#include <string>

#include "api/handlers/handlers.hpp"
#include "api/json_reader.hpp"
#include "api/json_text.hpp"
#include "api/router.hpp"

namespace {

using sweetspot::api::Context;
using sweetspot::api::Dispatch;

constexpr const char* kExample =
    R"({"bat": {"preset": "paper-wood"}, "ball": {"mass_kg": 0.145, "radius_m": 0.0366,)"
    R"( "speed_mps": 27.7}, "swing": {"angular_speed_rad_s": 17.288, "pivot_from_knob_m": 0.0,)"
    R"( "hands_from_knob_m": 0.1524}, "cor": 0.5, "outputs": ["max_exit_speed"]})";

// The request read, computed and answered, and the answer's tree written as text (the CLI's
// path, and the server's before the answers were written as text).
void BM_ExampleRequest(benchmark::State& state) {
  const Context context;
  std::string text;
  for (auto _ : state) {
    auto response = Dispatch({"POST", "/v1/sweet-spot", kExample}, context);
    if (response.status != 200) state.SkipWithError("the example failed");
    text.clear();
    sweetspot::api::AppendJson(response.body, &text);
    benchmark::DoNotOptimize(text.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ExampleRequest);

// The same request answered as the server answers it (Context::answer_text): the answer written
// straight to text, without its tree (api/json_writer.hpp).
void BM_ExampleRequestAsText(benchmark::State& state) {
  Context context;
  context.answer_text = true;
  for (auto _ : state) {
    auto response = Dispatch({"POST", "/v1/sweet-spot", kExample}, context);
    if (response.status != 200 || response.json_text.empty()) {
      state.SkipWithError("the example failed");
    }
    benchmark::DoNotOptimize(response.json_text.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ExampleRequestAsText);

// The example's answer (1.8 kB, 28 doubles) written as text.
void BM_ExampleAnswerText(benchmark::State& state) {
  const auto response = Dispatch({"POST", "/v1/sweet-spot", kExample}, Context{});
  std::string text;
  for (auto _ : state) {
    text.clear();
    sweetspot::api::AppendJson(response.body, &text);
    benchmark::DoNotOptimize(text.data());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<long long>(text.size()));
}
BENCHMARK(BM_ExampleAnswerText);

// The example body's input hash (its canonical text's FNV-1a 64).
void BM_ExampleInputHash(benchmark::State& state) {
  const auto body = nlohmann::json::parse(kExample);
  for (auto _ : state) benchmark::DoNotOptimize(sweetspot::api::InputHash(body));
}
BENCHMARK(BM_ExampleInputHash);

// nlohmann's parser over the example body without building anything (json::accept): the
// least any reading of the body with the one JSON library the dependency rules allow costs.
void BM_ExampleBodyAccept(benchmark::State& state) {
  const std::string body = kExample;
  for (auto _ : state) benchmark::DoNotOptimize(nlohmann::json::accept(body));
}
BENCHMARK(BM_ExampleBodyAccept);

// The same body parsed into nlohmann's tree and destroyed.
void BM_ExampleBodyParse(benchmark::State& state) {
  const std::string body = kExample;
  for (auto _ : state) {
    auto tree = nlohmann::json::parse(body);
    benchmark::DoNotOptimize(tree);
  }
}
BENCHMARK(BM_ExampleBodyParse);

// The same body read by ParseBody, as every request's is: ReadPlainBody's tree (the same as
// nlohmann's parser builds) without nlohmann's lexer (api/json_plain_body.cpp).
void BM_ExampleParseBody(benchmark::State& state) {
  const std::string body = kExample;
  const sweetspot::api::ApiLimits limits;
  for (auto _ : state) {
    sweetspot::api::ApiError error;
    auto tree = sweetspot::api::ParseBody(body, limits, &error);
    benchmark::DoNotOptimize(tree);
  }
}
BENCHMARK(BM_ExampleParseBody);

}  // namespace
