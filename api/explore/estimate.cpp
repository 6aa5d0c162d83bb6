#include "api/explore/estimate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "api/explore/columns.hpp"
#include "api/explore/design.hpp"
#include "core/geometry_format.hpp"
#include "core/scene/output_registry.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

// Bytes of one number as a row writes it: the shortest form of a double is 17-19 characters
// for the model's results ("0.7992624048392926", "24.213236341146274"), indices and counts
// fewer; 19 over-counts those slightly.
constexpr double kNumberBytes = 19.0;

// CPU seconds per design, from docs/benchmarks.md (measured on this 2-core machine type; the
// estimate is an order of magnitude, not a promise):
// - a full JSON row with the closed forms (rigid_pivot/free_bat) and the mass properties:
//   10.5 us ("Issue 17: explore's answer formats per design", BM_ExploreFormat/json);
constexpr double kClosedFormRowS = 10.5e-6;
// - one Hertz impact at the default relative tolerance 1e-6: 6.1 us (BM_HertzImpact/6); the
//   hertz max_exit_speed of a design: 0.825 ms CPU, measured on 2026-11-27 through the server
//   (--explore-threads 1, 400 designs of paper-wood with a cork fill, fill.depth_m swept, ndjson,
//   the process's CPU ticks from /proc/PID/stat before and after: 0.33 s);
constexpr double kHertzImpactS = 6.1e-6;
constexpr double kHertzSweetSpotS = 0.85e-3;
// - the flexible sweet spot with the design's modes computed fresh: 11.1-11.6 ms ("Issue 17:
//   the flexible sweet spot and least_sting_zone", second round; the same measurement as the
//   hertz one gave 7.75 ms CPU per design for 40 designs, and the 1,000,000 designs took
//   ~85 min of both cores, 10.2 ms: the benchmark's figure, the largest, is kept); one flexible
//   impact with the modes known: 0.22 ms (BM_FlexibleImpactModes/corrected/4);
constexpr double kFlexibleSweetSpotS = 11.6e-3;
constexpr double kFlexibleImpactS = 0.22e-3;
// - the modes of vibration_node (2 modes, Timoshenko, to 1e-6): 2.22 ms (BM_ModesToTolerance);
constexpr double kModesS = 2.22e-3;
// - least_sting_zone with the modes fresh: 24.5 ms (same section as the flexible sweet spot);
constexpr double kLeastStingZoneS = 24.5e-3;
// - bbcor_scan: 9 flexible impacts plus the design's modes (docs/api.md: "~10 ms plus the
//   design's modes"); bbcor and barrel: the trampoline model's closed forms, counted as a row.
constexpr double kBbcorScanS = 10e-3 + kModesS;
// - distance_sweet_spot and carry_map (docs/benchmarks.md, "Issue 34: the batted-ball scene
//   outputs", BM_DistanceSweetSpot, BM_CarryMap, CPU): 0.37 ms for the free bat's search (163
//   carries: 2.3 us each), 1.65 ms for a 41 x 21 free-bat map (1.9 us per carry); hertz and
//   flexible add their table's impacts (positions x speeds: 6.1 us, 0.23 ms each).
constexpr double kSearchCarryS = 2.3e-6;
constexpr double kSearchCarries = 170.0;
constexpr double kMapCarryS = 1.9e-6;

// The elements an array of a row has: the shape holds one of each (RowShape).
std::uint64_t ArrayCount(const std::string& key, const Json& array, const Sweep& sweep,
                         std::uint64_t curve_points) {
  if (key == "exit_speed_curve") return curve_points;
  if (key == "curve") return static_cast<std::uint64_t>(sweep.options.flexible.sting_samples);
  if (key == "effective_cor_curve") return 10;  // 1 to 10 in from the tip (core/scene_barrel)
  if (key == "points") return 9;                // every 0.5 in from 4 to 8 in from the tip
  // carry_map: a row per position, each with a carry per undercut.
  if (key == "positions") return static_cast<std::uint64_t>(sweep.options.distance.map_positions);
  // With report_units "imperial" each list has its twins (api/trade_units.cpp): as long.
  if (key == "undercuts_m" || key == "distance_m" || key == "undercuts_in" ||
      key == "distance_in" || key == "distance_ft") {
    return static_cast<std::uint64_t>(sweep.options.distance.map_undercuts);
  }
  return array.size();
}

struct Size {
  double values = 0.0;
  double bytes = 0.0;
};

// The values and bytes of `value` as a JSON text, its arrays at their counts.
Size Measure(const Json& value, const std::string& key, const Sweep& sweep,
             std::uint64_t curve_points) {
  Size size;
  if (value.is_object()) {
    size.bytes = 2.0 + (value.empty() ? 0.0 : static_cast<double>(value.size()) - 1.0);
    for (const auto& item : value.items()) {
      const Size child = Measure(item.value(), item.key(), sweep, curve_points);
      size.values += child.values;
      size.bytes += static_cast<double>(item.key().size()) + 3.0 + child.bytes;
    }
  } else if (value.is_array()) {
    const double n = static_cast<double>(ArrayCount(key, value, sweep, curve_points));
    size.bytes = 2.0 + std::max(0.0, n - 1.0);
    if (!value.empty()) {
      const Size element = Measure(value.front(), "", sweep, curve_points);
      size.values = n * element.values;
      size.bytes += n * element.bytes;
    }
  } else {
    size.values = 1.0;
    if (value.is_number()) size.bytes = kNumberBytes;
    if (value.is_string())
      size.bytes = static_cast<double>(value.get_ref<const std::string&>().size()) + 2.0;
    if (value.is_boolean()) size.bytes = 5.0;
    if (value.is_null()) size.bytes = 4.0;
  }
  return size;
}

bool Asks(const Sweep& sweep, core::SceneOutput output) {
  return std::find(sweep.outputs.scene.begin(), sweep.outputs.scene.end(), output) !=
         sweep.outputs.scene.end();
}

// "1.2 GB", "310 MB", "12 kB": a size for a message (decimal units; the exact bytes beside it).
std::string Human(double bytes) {
  const char* units[] = {"B", "kB", "MB", "GB", "TB", "PB"};
  int u = 0;
  while (bytes >= 1000.0 && u < 5) {
    bytes /= 1000.0;
    ++u;
  }
  char text[32];
  std::snprintf(text, sizeof text, bytes < 10 ? "%.1f %s" : "%.0f %s", bytes, units[u]);
  return text;
}

std::string Seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, s < 10 ? "%.2g s" : "%.0f s", s);
  return text;
}

// "100000 designs x 10000 curve points (options.curve_samples)" or "100000 designs".
std::string WhatIsAsked(const SweepEstimate& estimate, const Sweep& sweep) {
  std::string text = std::to_string(estimate.rows) + " designs";
  if (sweep.shard.count > 1) text += " (this shard's)";
  if (estimate.curve_points > 0) {
    text += " x " + std::to_string(estimate.curve_points) + " exit_speed_curve points (" +
            (sweep.options.curve_positions_from_knob_m.empty()
                 ? "options.curve_samples = " + std::to_string(sweep.options.curve_samples)
                 : std::string("options.curve_positions_from_knob_m")) +
            ")";
  }
  return text;
}

}  // namespace

std::uint64_t SweepEstimate::AnswerBytes() const {
  const double bytes = static_cast<double>(rows) * static_cast<double>(bytes_per_row + 1) + 1024.0;
  return bytes >= 1.8e19 ? UINT64_MAX : static_cast<std::uint64_t>(bytes);
}

double SweepEstimate::CpuSeconds() const { return static_cast<double>(rows) * cpu_s_per_design; }

SweepEstimate EstimateSweep(const Sweep& sweep, const std::string& format,
                            const std::vector<ExploreColumn>& columns) {
  SweepEstimate estimate;
  const core::Shard& shard = sweep.shard;
  estimate.rows = sweep.total / shard.count + (shard.index < sweep.total % shard.count ? 1 : 0);
  if (Asks(sweep, core::SceneOutput::kExitSpeedCurve)) {
    estimate.curve_points = sweep.options.curve_positions_from_knob_m.empty()
                                ? static_cast<std::uint64_t>(sweep.options.curve_samples)
                                : sweep.options.curve_positions_from_knob_m.size();
  }
  std::vector<std::string> parameter_paths;
  for (const SweepParameter& parameter : sweep.parameters)
    parameter_paths.push_back(parameter.path);
  Json shape = RowShape(parameter_paths, sweep.outputs);
  if (sweep.imperial) AddImperialToRow(&shape, 0.0);
  // A feasible row has no "error" (the shape's is for the failed rows), and a closed form's
  // max_exit_speed no solver "summary" (the shape's probe shows one).
  shape.erase("error");
  if (shape.contains("max_exit_speed") &&
      sweep.options.method == core::SweetSpotMethod::kClosedForm &&
      (sweep.exit_speed_model == "rigid_pivot" || sweep.exit_speed_model == "free_bat")) {
    shape["max_exit_speed"].erase("summary");
  }
  Size row;
  if (columns.empty()) {
    row = Measure(shape, "", sweep, estimate.curve_points);
  } else {
    // A column is one value (an array or object column is written whole: counted as a number
    // each, which under-counts only such columns).
    row.values = static_cast<double>(columns.size());
    row.bytes = static_cast<double>(columns.size()) * (kNumberBytes + 1.0);
    if (format != "csv") {
      for (const ExploreColumn& column : columns) row.bytes += column.path.size() + 3.0;
    }
  }
  estimate.values_per_row = static_cast<std::uint64_t>(row.values);
  estimate.bytes_per_row = static_cast<std::uint64_t>(std::ceil(row.bytes));

  // The per-design CPU: the row, then each model the outputs need.
  double cost = kClosedFormRowS;
  std::string basis = "closed forms";
  // The outputs of the scene's exit-speed model (their declarations' uses_exit_model).
  const bool exit_speed = std::any_of(
      sweep.outputs.scene.begin(), sweep.outputs.scene.end(),
      [](core::SceneOutput o) { return core::SceneOutputDeclaration(o).uses_exit_model; });
  const auto add = [&](double seconds, const std::string& what) {
    cost += seconds;
    basis = basis == "closed forms" ? what : basis + " + " + what;
  };
  const double curve = static_cast<double>(estimate.curve_points);
  if (exit_speed && sweep.exit_speed_model == "hertz") {
    add(kHertzSweetSpotS + curve * kHertzImpactS, "hertz exit speeds");
  } else if (exit_speed && sweep.exit_speed_model == "flexible") {
    add(kFlexibleSweetSpotS + curve * kFlexibleImpactS, "flexible exit speeds");
  }
  if (Asks(sweep, core::SceneOutput::kVibrationNode)) add(kModesS, "vibration_node");
  if (Asks(sweep, core::SceneOutput::kLeastStingZone)) {
    add(kLeastStingZoneS *
            std::max(1.0, sweep.options.flexible.sting_samples / 21.0),  // 21: the benchmark's
        "least_sting_zone");
  }
  if (Asks(sweep, core::SceneOutput::kBbcorScan)) add(kBbcorScanS, "bbcor_scan");
  // The distance outputs: their carries, and the normal law's table for hertz and flexible.
  const double table_impact_s = sweep.exit_speed_model == "hertz"      ? kHertzImpactS
                                : sweep.exit_speed_model == "flexible" ? kFlexibleImpactS
                                                                       : 0.0;
  const core::DistanceOptions& distance = sweep.options.distance;
  if (Asks(sweep, core::SceneOutput::kDistanceSweetSpot)) {
    add(kSearchCarries * kSearchCarryS +
            table_impact_s * distance.normal_table_positions * distance.normal_table_speeds,
        "distance_sweet_spot");
  }
  if (Asks(sweep, core::SceneOutput::kCarryMap)) {
    add(static_cast<double>(distance.map_positions) * distance.map_undercuts * kMapCarryS +
            table_impact_s * distance.map_positions * distance.normal_table_speeds,
        "carry_map");
  }
  estimate.cpu_s_per_design = cost;
  estimate.cost_basis = basis;
  return estimate;
}

std::optional<ApiError> CheckResponseSize(const SweepEstimate& estimate, const Sweep& sweep,
                                          const ApiLimits& limits) {
  const std::uint64_t bytes = estimate.AnswerBytes();
  if (bytes <= limits.max_response_bytes) return std::nullopt;
  ApiError error;
  error.status = 413;
  error.code = ErrorCode::kTooBig;
  error.field = estimate.curve_points > 0 && sweep.options.curve_positions_from_knob_m.empty()
                    ? "options.curve_samples"
                    : "parameters";
  error.message =
      WhatIsAsked(estimate, sweep) + ": a JSON answer of " + std::to_string(estimate.rows) +
      " rows x " + std::to_string(estimate.values_per_row) + " values, estimated at " +
      std::to_string(bytes) + " bytes (" + Human(static_cast<double>(bytes)) +
      "), over the limit max_response_bytes = " + std::to_string(limits.max_response_bytes) +
      " (an answer built in memory); ask for \"format\": \"ndjson\" or \"csv\" "
      "(streamed), fewer designs or curve points, \"columns\", or shards";
  return error;
}

std::optional<ApiError> CheckJobEstimate(const SweepEstimate& estimate, const Sweep& sweep,
                                         int threads, const ApiLimits& limits) {
  const double cpu_s = estimate.CpuSeconds();
  const double wall_s = cpu_s / std::max(1, threads);
  const std::uint64_t bytes = estimate.AnswerBytes();
  std::string over;
  if (cpu_s > limits.max_job_cpu_s) {
    over = "its CPU time is estimated at " + Seconds(cpu_s) + " (" + estimate.cost_basis + ": " +
           Seconds(estimate.cpu_s_per_design) + " per design), over the limit max_job_cpu_s = " +
           core::FormatNumber(limits.max_job_cpu_s);
  } else if (wall_s > limits.max_job_time_s) {
    over = "its run time on " + std::to_string(std::max(1, threads)) + " threads is estimated at " +
           Seconds(wall_s) + " (" + estimate.cost_basis + ": " +
           Seconds(estimate.cpu_s_per_design) +
           " CPU per design), over the limit job_max_time_s = " +
           core::FormatNumber(limits.max_job_time_s);
  } else if (bytes > limits.max_job_result_bytes) {
    over = "its result is estimated at " + std::to_string(bytes) + " bytes (" +
           Human(static_cast<double>(bytes)) + ": " + std::to_string(estimate.values_per_row) +
           " values, " + std::to_string(estimate.bytes_per_row) +
           " bytes per row), over the limit job_max_result_bytes = " +
           std::to_string(limits.max_job_result_bytes);
  } else {
    return std::nullopt;
  }
  ApiError error;
  error.status = 413;
  error.code = ErrorCode::kTooBig;
  error.field = "parameters";
  error.message = "a job of " + WhatIsAsked(estimate, sweep) + ": " + over +
                  "; split it into shards (\"shard\": {\"index\", \"count\"}), fewer designs, or "
                  "outputs that need cheaper models";
  return error;
}

}  // namespace sweetspot::api
