// What a /v1/explore sweep will cost, estimated before its first design: the size of its
// answer (rows x the values and bytes of one row) and its CPU time (designs x the per-design
// cost of the models its outputs need). The synchronous JSON answer, which is built in memory,
// is refused (413) over ApiLimits::max_response_bytes; a job over max_job_cpu_s,
// max_job_time_s or max_job_result_bytes (docs/api.md, "Limits").
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "api/explore/engine.hpp"
#include "api/json_reader.hpp"

namespace sweetspot::api {

/// The estimate of one sweep's answer and work.
struct SweepEstimate {
  std::uint64_t rows = 0;            ///< Rows of the answer: the shard's designs.
  std::uint64_t values_per_row = 0;  ///< Numbers, strings, booleans and nulls in one row.
  std::uint64_t bytes_per_row = 0;   ///< Bytes of one row as written (JSON, NDJSON or CSV line).
  std::uint64_t curve_points = 0;    ///< Points of each row's exit_speed_curve (0: not asked).
  double cpu_s_per_design = 0.0;     ///< Estimated CPU seconds to evaluate one design.
  std::string cost_basis;  ///< What the per-design cost counts, e.g. "flexible max_exit_speed".

  /// Estimated bytes of the whole answer (rows and summary).
  std::uint64_t AnswerBytes() const;
  /// Estimated CPU seconds of the whole sweep.
  double CpuSeconds() const;
};

/// The estimate for `sweep` answered in `format` ("json", "ndjson", "csv") with `columns`
/// (empty: full rows). Pure: evaluates no design.
SweepEstimate EstimateSweep(const Sweep& sweep, const std::string& format,
                            const std::vector<ExploreColumn>& columns);

/// A synchronous answer built in memory (format "json", not a batch): nullopt when its
/// estimate is within limits.max_response_bytes, else the 413 TooBig naming the designs,
/// curve_samples, the estimate and the limit.
std::optional<ApiError> CheckResponseSize(const SweepEstimate& estimate, const Sweep& sweep,
                                          const ApiLimits& limits);

/// A job's sweep at submit: nullopt when its estimated CPU time is within limits.max_job_cpu_s,
/// its wall time on `threads` threads within limits.max_job_time_s and its result within
/// limits.max_job_result_bytes; else the 413 TooBig naming the estimate and the limit.
std::optional<ApiError> CheckJobEstimate(const SweepEstimate& estimate, const Sweep& sweep,
                                         int threads, const ApiLimits& limits);

}  // namespace sweetspot::api
