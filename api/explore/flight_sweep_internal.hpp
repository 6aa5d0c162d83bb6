// The parts of a flight sweep (flight_sweep.hpp) that its parser (flight_sweep_parse.cpp) and
// its runner (flight_sweep.cpp) share: the swept paths and the parsed sweep. Internal to
// api/explore.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "api/flight_json.hpp"
#include "api/json_reader.hpp"
#include "api/router.hpp"
#include "api/thread_budget.hpp"
#include "core/explore/sampling.hpp"
#include "core/flight/flight.hpp"
#include "core/progress.hpp"

namespace sweetspot::api::flight_sweep {

// What a swept path sets.
enum class Target {
  kExitSpeed,
  kLaunchAngle,
  kSprayAngle,
  kBackspin,
  kSidespin,
  kHeight,
  kTemperature,
  kElevation,
  kHumidity,
  kPressure,
  kWindSpeed,
  kWindDirection,
};

// A path as a request writes it, and its SI value: written * scale + offset (api/flight_json's
// spellings of the same fields).
struct PathSpec {
  const char* path;
  Target target;
  double scale = 1.0;
  double offset = 0.0;
};

inline constexpr double kPaPerInHg = 3386.389;  // as api/flight_json.cpp
inline constexpr PathSpec kPaths[] = {
    {"launch.exit_speed_mps", Target::kExitSpeed},
    {"launch.exit_speed_mph", Target::kExitSpeed, core::flight::kMpsPerMph},
    {"launch.launch_angle_deg", Target::kLaunchAngle},
    {"launch.spray_angle_deg", Target::kSprayAngle},
    {"launch.backspin_rpm", Target::kBackspin},
    {"launch.sidespin_rpm", Target::kSidespin},
    {"launch.height_m", Target::kHeight},
    {"launch.height_ft", Target::kHeight, core::flight::kMetresPerFoot},
    {"environment.temperature_c", Target::kTemperature},
    {"environment.temperature_f", Target::kTemperature, 5.0 / 9.0, -32.0 * 5.0 / 9.0},
    {"environment.elevation_m", Target::kElevation},
    {"environment.elevation_ft", Target::kElevation, core::flight::kMetresPerFoot},
    {"environment.relative_humidity_pct", Target::kHumidity},
    {"environment.pressure_hpa", Target::kPressure, 100.0},
    {"environment.pressure_inhg", Target::kPressure, kPaPerInHg},
    {"environment.wind.speed_mps", Target::kWindSpeed},
    {"environment.wind.speed_mph", Target::kWindSpeed, core::flight::kMpsPerMph},
    {"environment.wind.direction_deg", Target::kWindDirection},
};

inline const PathSpec* FindPath(const std::string& path) {
  for (const PathSpec& spec : kPaths) {
    if (path == spec.path) return &spec;
  }
  return nullptr;
}

// A parsed flight sweep, owned by its (maybe streamed) answer.
struct FlightSweep {
  FlightRequest base;                  // launches[0] is the template, or the list
  bool list = false;                   // fly base.launches as given (no parameters)
  std::vector<std::string> paths;      // as written
  std::vector<const PathSpec*> specs;  // per path
  core::SweepPlan plan;                // dimensions in the order of `paths`
  std::uint64_t total = 0;             // designs
  int threads = 1;                     // wanted (the extra ones from `budget`)
  ThreadBudget* budget = nullptr;      // or none
  core::Progress* progress = nullptr;  // cancel flag (a job's), or none
  std::chrono::steady_clock::time_point start;
};

/// Parses a /v1/explore body with "flight" (flight_sweep_parse.cpp): the sweep, or nullopt
/// with `error` set; `format` is the answer's ("json" or "csv").
std::optional<FlightSweep> Parse(const nlohmann::json& body, const Context& context,
                                 std::string* format, ApiError* error);

}  // namespace sweetspot::api::flight_sweep
