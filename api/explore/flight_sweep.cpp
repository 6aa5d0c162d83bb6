#include "api/explore/flight_sweep.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <thread>
#include <utility>

#include "api/error_code.hpp"
#include "api/explore/flight_sweep_internal.hpp"
#include "api/flight_json.hpp"
#include "api/json_reader.hpp"
#include "api/thread_budget.hpp"
#include "core/explore/sampling.hpp"
#include "core/flight/flight.hpp"
#include "core/progress.hpp"

namespace sweetspot::api {
namespace flight_sweep {
namespace {

using Json = nlohmann::json;
namespace flight = core::flight;

void Apply(const PathSpec& spec, double written, flight::Launch* launch,
           flight::Environment* environment) {
  const double si = written * spec.scale + spec.offset;
  switch (spec.target) {
    case Target::kExitSpeed:
      launch->exit_speed_mps = si;
      break;
    case Target::kLaunchAngle:
      launch->launch_angle_deg = si;
      break;
    case Target::kSprayAngle:
      launch->spray_angle_deg = si;
      break;
    case Target::kBackspin:
      launch->backspin_rpm = si;
      break;
    case Target::kSidespin:
      launch->sidespin_rpm = si;
      break;
    case Target::kHeight:
      launch->height_m = si;
      break;
    case Target::kTemperature:
      environment->temperature_c = si;
      break;
    case Target::kElevation:
      environment->elevation_m = si;
      break;
    case Target::kHumidity:
      environment->relative_humidity_pct = si;
      break;
    case Target::kPressure:
      environment->sea_level_pressure_pa = si;
      break;
    case Target::kWindSpeed:
      environment->wind.speed_mps = si;
      break;
    case Target::kWindDirection:
      environment->wind.direction_deg = si;
      break;
  }
}

// The integrator steps one block of kBlock launches may take (accepted and rejected): ~1000 a
// launch, against ~10 for an ordinary flight at the default tolerance and a few hundred at
// 1e-13, so that launches that never come down (a custom lift holding them up runs each to the
// 20,000-step limit, ~6 ms) cost a block at most ~0.3 s. A block's launches fly in order on one
// thread, so the budget gives the same rows on any number of threads. Once it is spent, each
// later launch of the block flies with the smallest step limit (10).
constexpr std::uint64_t kBlock = 1024;  // launches a block (one thread's turn)
constexpr long long kBlockStepBudget = static_cast<long long>(kBlock) * 1000;
constexpr int kMinSteps = 10;  // FlightOptions::max_steps's lower bound

// One launch's flight and the step limit it flew with.
struct Flown {
  flight::FlightResult result;
  int max_steps = 0;
};

// Design `index`'s launch and environment (its swept values in `point`; a list's launch
// `index`).
void DesignOf(const FlightSweep& sweep, std::uint64_t index, const std::vector<double>& point,
              flight::Launch* launch, flight::Environment* environment) {
  *launch = sweep.base.launches[sweep.list ? index : 0];
  *environment = sweep.base.environment;
  for (std::size_t d = 0; d < sweep.specs.size(); ++d) {
    Apply(*sweep.specs[d], point[d], launch, environment);
  }
}

// Flies designs [first, last) of a block in order within the block's budget, their swept
// values to points[i − first] and their flights to flown[i − first]. The same flights and step
// limits as one at a time (each launch's limit the least of options.max_steps and what is left
// of the budget, at least kMinSteps), flown side by side by flight::FlyMany while what is left
// is at least the batch's launches times options.max_steps (then no launch of the batch can
// find the budget short: each flies with options.max_steps, as it would alone).
void FlyBlock(const FlightSweep& sweep, std::uint64_t first, std::uint64_t last,
              core::DesignSequence* sequence, std::vector<std::vector<double>>* points,
              std::vector<Flown>* flown) {
  const std::size_t n = static_cast<std::size_t>(last - first);
  points->assign(n, std::vector<double>());
  std::vector<flight::Launch> launches(n);
  std::vector<flight::Environment> environments(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (sequence != nullptr) (*points)[i] = sequence->Design(first + i);
    DesignOf(sweep, first + i, (*points)[i], &launches[i], &environments[i]);
  }
  flown->assign(n, Flown());
  std::vector<flight::FlightResult> results(n);
  const int limit = sweep.base.options.max_steps;
  long long budget = kBlockStepBudget;
  std::size_t i = 0;
  while (i < n) {
    const std::size_t batch =
        budget > 0 && limit > 0
            ? std::min<std::size_t>(n - i, static_cast<std::size_t>(budget / limit))
            : 0;
    if (batch >= 2) {
      flight::FlyMany(batch, &launches[i], &environments[i], false, sweep.base.aero,
                      sweep.base.options, &results[i]);
      for (std::size_t j = i; j < i + batch; ++j) {
        (*flown)[j] = Flown{std::move(results[j]), limit};
        budget -= (*flown)[j].result.steps + (*flown)[j].result.rejected_steps;
      }
      i += batch;
      continue;
    }
    flight::FlightOptions options = sweep.base.options;
    options.max_steps =
        static_cast<int>(std::max<long long>(kMinSteps, std::min<long long>(limit, budget)));
    (*flown)[i] = Flown{flight::Fly(launches[i], environments[i], sweep.base.aero, options),
                        options.max_steps};
    budget -= (*flown)[i].result.steps + (*flown)[i].result.rejected_steps;
    ++i;
  }
}

// Why a launch did not land (NotLandedMessage, and the block's budget when it cut the limit).
std::string Message(const FlightSweep& sweep, const Flown& flown) {
  flight::FlightOptions options = sweep.base.options;
  options.max_steps = flown.max_steps;
  std::string message = NotLandedMessage(flown.result, options);
  if (flown.result.termination == flight::FlightTermination::kStepLimit &&
      flown.max_steps < sweep.base.options.max_steps) {
    message += " (the sweep's budget of " + std::to_string(kBlockStepBudget) +
               " integrator steps per block of " + std::to_string(kBlock) +
               " launches was spent by the block's launches before it)";
  }
  return message;
}

// Shortest round-trip text of a finite number ("" for a non-finite one: never written).
void AppendNumber(double value, std::string* out) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  if (result.ec == std::errc()) out->append(buffer, result.ptr);
}

void AppendQuoted(const std::string& text, std::string* out) {
  out->push_back('"');
  for (char c : text) {
    if (c == '"') out->push_back('"');
    out->push_back(c);
  }
  out->push_back('"');
}

constexpr const char* kCsvColumns =
    "termination,distance_m,hang_time_s,apex_m,landing_x_m,landing_y_m,bearing_deg,"
    "landing_speed_mps,landing_angle_deg,backspin_rpm,sidespin_rpm,spin_source,barrel,hard_hit,"
    "sweet_spot_launch,error_estimate_m,steps,message";

std::string CsvHeader(const FlightSweep& sweep) {
  std::string header = "index";
  for (const std::string& path : sweep.paths) header += ",parameters." + path;
  header += ",";
  header += kCsvColumns;
  header += "\n";
  return header;
}

void AppendCsvRow(const FlightSweep& sweep, std::uint64_t index, const std::vector<double>& point,
                  const Flown& flown, std::string* out) {
  const flight::FlightResult& r = flown.result;
  AppendNumber(static_cast<double>(index), out);
  for (double value : point) {
    out->push_back(',');
    AppendNumber(value, out);
  }
  out->push_back(',');
  out->append(flight::FlightTerminationName(r.termination));
  const bool landed = r.Landed();
  for (double value : {r.distance_m, r.hang_time_s, r.apex_m, r.landing_x_m, r.landing_y_m,
                       r.bearing_deg, r.landing_speed_mps, r.landing_angle_deg}) {
    out->push_back(',');
    if (landed) AppendNumber(value, out);
  }
  const bool ran = r.termination != flight::FlightTermination::kInvalidInput;
  out->push_back(',');
  if (ran) AppendNumber(r.spin.backspin_rpm, out);
  out->push_back(',');
  if (ran) AppendNumber(r.spin.sidespin_rpm, out);
  out->push_back(',');
  if (ran) out->append(flight::SpinSourceName(r.spin_source));
  for (bool label :
       {r.classification.barrel, r.classification.hard_hit, r.classification.sweet_spot_launch}) {
    out->push_back(',');
    if (ran) out->append(label ? "true" : "false");
  }
  out->push_back(',');
  if (landed) AppendNumber(r.error_estimate_m, out);
  out->push_back(',');
  AppendNumber(r.steps, out);
  out->push_back(',');
  if (!landed) AppendQuoted(Message(sweep, flown), out);
  out->push_back('\n');
}

Json JsonRow(const FlightSweep& sweep, std::uint64_t index, const std::vector<double>& point,
             const Flown& flown) {
  const flight::FlightResult& r = flown.result;
  Json out = FlightToJson(r, sweep.base.aero, nullptr);
  if (!r.Landed()) out["message"] = Message(sweep, flown);
  if (sweep.list) return {{"index", index}, {"flight", std::move(out)}};
  Json parameters = Json::object();
  for (std::size_t d = 0; d < sweep.paths.size(); ++d) parameters[sweep.paths[d]] = point[d];
  return {{"index", index}, {"parameters", std::move(parameters)}, {"flight", std::move(out)}};
}

// Runs the sweep's designs in waves of one block per thread (blocks of kBlock designs), hands
// the blocks to `consume` in design order; false when cancelled, when `consume` refused, or
// when a block threw (*out_of_memory: std::bad_alloc is all a block can throw).
// `make(first, last, sequence)` evaluates designs [first, last) into a block. Threads that
// cannot be started leave their block to the calling thread (nothing throws).

template <class Block, class Make, class Consume>
bool RunWaves(const FlightSweep& sweep, Make make, Consume consume, int* lanes_used,
              bool* out_of_memory) {
  *out_of_memory = false;
  int extra = std::max(0, sweep.threads - 1);
  if (extra > 0 && sweep.budget != nullptr) extra = sweep.budget->TryTake(extra);
  struct GiveBack {
    ThreadBudget* budget;
    int threads;
    ~GiveBack() {
      if (budget != nullptr && threads > 0) budget->Give(threads);
    }
  } give_back{sweep.budget, sweep.budget != nullptr ? extra : 0};
  const int lanes = 1 + extra;
  *lanes_used = lanes;
  std::vector<core::DesignSequence> sequences;  // none for a list
  if (!sweep.list) {
    sequences.assign(static_cast<std::size_t>(lanes), core::DesignSequence(sweep.plan));
  }
  const auto sequence = [&](int k) { return sequences.empty() ? nullptr : &sequences[k]; };
  std::vector<Block> blocks(static_cast<std::size_t>(lanes));
  // A block that throws (out of memory) fails the sweep; nothing escapes a thread.
  std::atomic<bool> failed{false};
  const auto run = [&](int k, std::uint64_t lo, std::uint64_t hi) noexcept {
    try {
      blocks[k] = make(lo, hi, sequence(k));
    } catch (...) {
      failed.store(true);
    }
  };
  for (std::uint64_t first = 0; first < sweep.total; first += kBlock * lanes) {
    if (core::IsCancelled(sweep.progress)) return false;
    std::vector<std::thread> workers;
    for (int k = 1; k < lanes; ++k) {
      const std::uint64_t lo = first + kBlock * k;
      if (lo >= sweep.total) break;
      const std::uint64_t hi = std::min(lo + kBlock, sweep.total);
      try {
        workers.emplace_back(run, k, lo, hi);
      } catch (...) {
        run(k, lo, hi);  // no thread: this one does it
      }
    }
    run(0, first, std::min(first + kBlock, sweep.total));
    for (std::thread& worker : workers) worker.join();
    if (failed.load()) {
      *out_of_memory = true;
      return false;
    }
    for (int k = 0; k < lanes && first + kBlock * k < sweep.total; ++k) {
      if (!consume(std::move(blocks[k]))) return false;
    }
    if (sweep.progress != nullptr) {
      sweep.progress->Report(static_cast<double>(std::min(first + kBlock * lanes, sweep.total)) /
                             static_cast<double>(sweep.total));
    }
  }
  return true;
}

}  // namespace
}  // namespace flight_sweep

bool IsFlightSweep(const nlohmann::json& body) {
  return body.is_object() && body.contains("flight");
}

std::vector<std::string> FlightSweepPaths() {
  std::vector<std::string> paths;
  for (const flight_sweep::PathSpec& spec : flight_sweep::kPaths) paths.emplace_back(spec.path);
  return paths;
}

Response HandleFlightSweep(const nlohmann::json& body, const Context& context) {
  using flight_sweep::FlightSweep;
  const auto start = std::chrono::steady_clock::now();
  ApiError error;
  std::string format;
  std::optional<FlightSweep> parsed = flight_sweep::Parse(body, context, &format, &error);
  if (!parsed) return ToResponse(error);
  if (context.validate_only) return {200, nlohmann::json{{"valid", true}}};
  auto sweep = std::make_shared<FlightSweep>(std::move(*parsed));
  sweep->start = start;
  if (format == "csv") {
    Response streamed = Response::Text(200, std::string(), "text/csv");
    streamed.stream = [sweep](const ChunkSink& sink) {
      if (!sink(flight_sweep::CsvHeader(*sweep))) return false;
      int lanes = 1;
      bool out_of_memory = false;  // a cut CSV: the stream ends early
      return flight_sweep::RunWaves<std::string>(
          *sweep,
          [&](std::uint64_t first, std::uint64_t last, core::DesignSequence* sequence) {
            std::string text;
            text.reserve(static_cast<std::size_t>(last - first) * 256);
            std::vector<std::vector<double>> points;
            std::vector<flight_sweep::Flown> flown;
            flight_sweep::FlyBlock(*sweep, first, last, sequence, &points, &flown);
            for (std::uint64_t i = first; i < last; ++i) {
              flight_sweep::AppendCsvRow(*sweep, i, points[i - first], flown[i - first], &text);
            }
            return text;
          },
          [&](std::string&& text) { return sink(text); }, &lanes, &out_of_memory);
    };
    return streamed;
  }
  nlohmann::json rows = nlohmann::json::array();
  std::uint64_t landed = 0;
  int lanes = 1;
  bool out_of_memory = false;
  const bool complete = flight_sweep::RunWaves<std::vector<nlohmann::json>>(
      *sweep,
      [&](std::uint64_t first, std::uint64_t last, core::DesignSequence* sequence) {
        std::vector<nlohmann::json> block;
        block.reserve(static_cast<std::size_t>(last - first));
        std::vector<std::vector<double>> points;
        std::vector<flight_sweep::Flown> flown;
        flight_sweep::FlyBlock(*sweep, first, last, sequence, &points, &flown);
        for (std::uint64_t i = first; i < last; ++i) {
          block.push_back(flight_sweep::JsonRow(*sweep, i, points[i - first], flown[i - first]));
        }
        return block;
      },
      [&](std::vector<nlohmann::json>&& block) {
        for (nlohmann::json& row : block) {
          if (row["flight"].contains("distance_m")) ++landed;
          rows.push_back(std::move(row));
        }
        return true;
      },
      &lanes, &out_of_memory);
  if (out_of_memory) {
    rows = nlohmann::json();
    return ErrorResponse(503, ErrorCode::kUnavailable,
                         "the flight sweep ran out of memory; retry later, or ask for "
                         "\"format\": \"csv\" (streamed)");
  }
  if (!complete) {
    return ErrorResponse(409, ErrorCode::kCancelled, "the flight sweep was cancelled");
  }
  const double timing_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json summary = {
      {"designs", sweep->total},
      {"landed", landed},
      {"threads", lanes},
      {"timing_s", timing_s},
      {"models_used",
       {std::string("flight:") + core::flight::AeroModelName(sweep->base.aero.model)}}};
  return {200, {{"rows", std::move(rows)}, {"summary", std::move(summary)}}};
}

}  // namespace sweetspot::api
