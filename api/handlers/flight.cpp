// POST /v1/flight: batted-ball flight (core/flight) from launch conditions to the landing point,
// for one launch (`launch`: the flight's fields at the top level) or many (`launches`: a
// `flights` array in the request's order).
#include <optional>
#include <vector>

#include "api/flight_json.hpp"
#include "api/handlers/endpoint.hpp"
#include "api/handlers/handlers.hpp"

namespace sweetspot::api {
namespace {

namespace flight = core::flight;

// The flights of a request, in its order, with their trajectories when asked for.
struct FlightRun {
  std::vector<flight::FlightResult> results;
  std::vector<std::vector<flight::TrajectoryPoint>> trajectories;
};

FlightRun RunFlights(const FlightRequest& request, const Context&) {
  FlightRun run;
  run.results.reserve(request.launches.size());
  if (request.trajectory) run.trajectories.resize(request.launches.size());
  for (std::size_t i = 0; i < request.launches.size(); ++i) {
    run.results.push_back(flight::Fly(request.launches[i], request.environment, request.aero,
                                      request.options,
                                      request.trajectory ? &run.trajectories[i] : nullptr));
  }
  return run;
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
                           "launch: " + NotLandedMessage(r, request.options), field};
      return ToResponse(error);
    };
    e.render = [](const FlightRequest& request, const FlightRun& run) {
      auto one = [&](std::size_t i) {
        nlohmann::json out = FlightToJson(run.results[i], request.aero,
                                          request.trajectory ? &run.trajectories[i] : nullptr);
        if (!run.results[i].Landed()) {
          out["message"] = NotLandedMessage(run.results[i], request.options);
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
