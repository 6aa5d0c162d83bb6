// JSON <-> core::flight (POST /v1/flight): the launch, the environment and the aero model as a
// request writes them (SI fields and their trade twins: exit_speed_mps|_mph, height_m|_ft|_in,
// temperature_c|_f, elevation_m|_ft, pressure_hpa|_inhg, wind.speed_mps|_mph), and a flight's
// answer. The readers are shared so that a scene's `environment` and `aero` (issue 34, parts 2-3)
// read the same way.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

#include "api/json_reader.hpp"
#include "api/limits.hpp"
#include "core/flight/flight.hpp"

namespace sweetspot::api {

/// Where a request gave a number that core validates: core's field name ("exit_speed_mps",
/// "pressure_pa"), the request path as written ("launch.exit_speed_mph") and the value written,
/// so that a core refusal names the field the request used.
struct GivenField {
  std::string core_field;  ///< Core's name within its struct ("wind.speed_mps").
  std::string path;        ///< The request's path of the field given.
  double written = 0.0;    ///< The value as written (in the unit of `path`).
};

/// Reads a launch object (at `path`: "launch", "launches[3]") into *launch; the numbers' ranges
/// are core's (Launch::Validate), checked here and reported under the written names.
bool ReadLaunch(const nlohmann::json& value, const std::string& path, core::flight::Launch* launch,
                ApiError* error);
/// Reads an optional `environment` object of `reader` (defaults: 70 °F, sea level, 50 %,
/// 29.92 inHg, calm) and validates it (Environment::Validate).
bool ReadEnvironment(ObjectReader& reader, core::flight::Environment* environment);
/// Reads an optional `aero` object of `reader` ({"model": "nathan-2016"} by default; the custom
/// coefficients only with "model": "custom", spin_decay_s with nathan-2016 or custom) and
/// validates it (AeroOptions::Validate).
bool ReadAero(ObjectReader& reader, core::flight::AeroOptions* aero);

/// The most trajectory samples one /v1/flight answer may carry, over all its launches.
inline constexpr double kMaxTrajectorySamples = 100000;

/// A parsed /v1/flight request.
struct FlightRequest {
  std::vector<core::flight::Launch> launches;     ///< One or many.
  bool many = false;                              ///< Given as `launches` (answer: `flights`).
  core::flight::Environment environment;          ///< The air.
  core::flight::AeroOptions aero;                 ///< The model.
  core::flight::FlightOptions options;            ///< The integrator's settings.
  bool trajectory = false;                        ///< outputs: ["trajectory"].
};

/// Parses a /v1/flight body: `launch` (an object) or `launches` (an array of at most
/// limits.max_launches), `environment`, `aero`, `outputs`, `options`
/// {relative_tolerance, absolute_tolerance_m, max_flight_time_s, trajectory_interval_s}.
std::optional<FlightRequest> ParseFlight(const nlohmann::json& body, const ApiLimits& limits,
                                         ApiError* error);

/// One flight's answer: distance_m, hang_time_s, apex_m, landing {x_m, y_m}, bearing_deg,
/// air_density_kg_m3, classification, spin_source, backspin_rpm, sidespin_rpm, the landing's
/// speed and angle, `numerics` {method, termination, error_estimate_m, steps, ...} and, when
/// asked, `trajectory` [{t_s, x_m, y_m, z_m, speed_mps}]. A flight that did not land carries
/// its termination and message instead of the numbers.
nlohmann::json FlightToJson(const core::flight::FlightResult& result,
                            const core::flight::AeroOptions& aero,
                            const std::vector<core::flight::TrajectoryPoint>* trajectory);

/// The message of a flight that did not land ("still in the air at max_flight_time_s = 30 s").
std::string NotLandedMessage(const core::flight::FlightResult& result,
                             const core::flight::FlightOptions& options);

}  // namespace sweetspot::api
