// POST /v1/flight: batted-ball flight (core/flight) from launch conditions to the landing point,
// for one launch (`launch`: the flight's fields at the top level) or many (`launches`: a
// `flights` array in the request's order).
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "api/flight_json.hpp"
#include "api/handlers/endpoint.hpp"
#include "api/handlers/handlers.hpp"

namespace sweetspot::api {
namespace {

namespace flight = core::flight;

// The integrator steps (accepted and rejected) one request may take over all its launches:
// about 0.6 s of CPU at ~0.3 µs a step. A flight takes ~10 steps at the default tolerance and
// a few hundred at 1e-13, so 4096 ordinary launches use under 5 % of it; but a ball that never
// comes down (a custom lift that holds it up) runs to the 20,000-step limit, ~6 ms, and 4096 of
// them would take ~25 s. Once the budget is spent, each later launch still flies with the
// smallest step limit (10 steps: enough for a short flight), so the request answers in bounded
// time and every row says what happened to it.
constexpr long long kMaxStepsPerRequest = 2'000'000;
constexpr int kMinStepsPerFlight = 10;  // FlightOptions::max_steps's lower bound

// The flights of a request, in its order, with their trajectories when asked for, and the step
// limit each flew with (options.max_steps, lower when the request's budget ran short).
struct FlightRun {
  std::vector<flight::FlightResult> results;
  std::vector<std::vector<flight::TrajectoryPoint>> trajectories;
  std::vector<int> max_steps;
};

FlightRun RunFlights(const FlightRequest& request, const Context&) {
  FlightRun run;
  run.results.reserve(request.launches.size());
  run.max_steps.reserve(request.launches.size());
  if (request.trajectory) run.trajectories.resize(request.launches.size());
  long long remaining = kMaxStepsPerRequest;
  const std::size_t n = request.launches.size();
  const int limit = request.options.max_steps;
  std::size_t i = 0;
  while (i < n) {
    // Without trajectories, launches fly side by side (flight::FlyMany) while what is left of
    // the budget is at least their number times their step limit: none of them can then find
    // it short, so each flies as it would alone (the same answers, to the bit).
    const std::size_t batch =
        request.trajectory || remaining <= 0 || limit <= 0
            ? 0
            : std::min<std::size_t>(n - i, static_cast<std::size_t>(remaining / limit));
    if (batch >= 2) {
      run.results.resize(i + batch);
      flight::FlyMany(batch, &request.launches[i], &request.environment, true, request.aero,
                      request.options, &run.results[i]);
      for (std::size_t j = i; j < i + batch; ++j) {
        run.max_steps.push_back(limit);
        remaining -= run.results[j].steps + run.results[j].rejected_steps;
      }
      i += batch;
      continue;
    }
    flight::FlightOptions options = request.options;
    options.max_steps = static_cast<int>(std::max<long long>(
        kMinStepsPerFlight, std::min<long long>(options.max_steps, remaining)));
    run.results.push_back(flight::Fly(request.launches[i], request.environment, request.aero,
                                      options,
                                      request.trajectory ? &run.trajectories[i] : nullptr));
    run.max_steps.push_back(options.max_steps);
    remaining -= run.results.back().steps + run.results.back().rejected_steps;
    ++i;
  }
  return run;
}

// Why flight i did not land, in words (NotLandedMessage, plus the request's budget when it was
// what cut the flight's step limit).
std::string NotLanded(const FlightRequest& request, const FlightRun& run, std::size_t i) {
  flight::FlightOptions options = request.options;
  options.max_steps = run.max_steps[i];
  std::string message = NotLandedMessage(run.results[i], options);
  if (run.results[i].termination == flight::FlightTermination::kStepLimit &&
      run.max_steps[i] < request.options.max_steps) {
    message += " (the request's budget of " + std::to_string(kMaxStepsPerRequest) +
               " integrator steps over all its launches was spent by the launches before it)";
  }
  return message;
}

const Endpoint<FlightRequest, FlightRun>& FlightEndpoint() {
  static const auto endpoint = [] {
    Endpoint<FlightRequest, FlightRun> e;
    e.parse = [](const nlohmann::json& body, const Context& context, ApiError* error) {
      return ParseFlight(body, context.limits, error);
    };
    e.run = RunFlights;
    // One launch that did not land is a 422 naming the limit; in a batch, its row says so.
    e.failure = [](const FlightRequest& request,
                   const FlightRun& run) -> std::optional<Response> {
      if (request.many || run.results.front().Landed()) return std::nullopt;
      const flight::FlightResult& r = run.results.front();
      const char* field = r.termination == flight::FlightTermination::kStepLimit
                              ? "options.relative_tolerance"
                              : "options.max_flight_time_s";
      const ApiError error{ErrorCodeStatus(ErrorCode::kModelFailed), ErrorCode::kModelFailed,
                           "launch: " + NotLanded(request, run, 0), field};
      return ToResponse(error);
    };
    e.render = [](const FlightRequest& request, const FlightRun& run) {
      auto one = [&](std::size_t i) {
        nlohmann::json out = FlightToJson(run.results[i], request.aero,
                                          request.trajectory ? &run.trajectories[i] : nullptr);
        if (!run.results[i].Landed()) {
          out["message"] = NotLanded(request, run, i);
        }
        return out;
      };
      nlohmann::json out;
      if (request.many) {
        nlohmann::json flights = nlohmann::json::array();
        for (std::size_t i = 0; i < run.results.size(); ++i) flights.push_back(one(i));
        out["flights"] = std::move(flights);
      } else {
        out = one(0);
      }
      out["models_used"] = {std::string("flight:") + flight::AeroModelName(request.aero.model)};
      return out;
    };
    e.provenance = [](const FlightRequest&, const nlohmann::json& body) {
      return BodyOptions(body);
    };
    return e;
  }();
  return endpoint;
}

}  // namespace

Response HandleFlight(const Request& request, const Context& context) {
  return ServeEndpoint(FlightEndpoint(), request, context);
}

}  // namespace sweetspot::api
