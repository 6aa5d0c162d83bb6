// /v1/explore over batted-ball launches (issue 34): a request with a "flight" template instead of
// a bat sweeps the launch and the air of POST /v1/flight through the explore's samplings (grid,
// lhs, sobol; core/explore/sampling.hpp), one flight per design, on the sweep's threads, and
// answers its rows as JSON or streams them as CSV, in design order:
//
//   {"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28}, "environment": {...},
//               "aero": {...}, "options": {...}},
//    "parameters": [{"path": "launch.exit_speed_mph", "min": 60, "max": 120, "count": 1000},
//                   {"path": "launch.launch_angle_deg", "min": -10, "max": 60, "count": 1000}],
//    "sampling": "grid", "format": "csv"}
//
// The swept paths are the launch's and the environment's numbers (FlightSweepPaths), in the
// units /v1/flight takes them. A design whose values core refuses, or whose ball does not land,
// is a row with its message, never fatal to the sweep. Kept apart from the bat sweep's engine
// (api/explore/engine.*): a flight needs no bat, no scene and no JSON per design.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "api/response.hpp"
#include "api/router.hpp"

namespace sweetspot::api {

/// True when `body` is a flight sweep (an object with a "flight" member).
bool IsFlightSweep(const nlohmann::json& body);

/// The paths a flight sweep may sweep, as written in "parameters[i].path".
std::vector<std::string> FlightSweepPaths();

/// Answers a flight sweep: 4xx naming the field for a bad request; "format": "json" (the
/// default, as a bat sweep's) answers {"rows": [...], "summary"}; "csv" streams a header and a
/// row per design.
/// Designs are limited to limits.max_samples (max_batch_samples for a batch: a job, the CLI).
/// Runs on context.explore_threads threads (the extra ones taken from context.thread_budget
/// without waiting); stops at a cancel (context.progress) or when the receiver is gone.
Response HandleFlightSweep(const nlohmann::json& body, const Context& context);

}  // namespace sweetspot::api
