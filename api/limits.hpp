// Limits on what a request may ask for. Configuration, not constants: the
// server sets them from flags/environment; every limit has a test that hits it.
#pragma once

#include <cstddef>
#include <string>

#include "core/refusal.hpp"

namespace sweetspot::api {

/// Request limits with their defaults.
struct ApiLimits {
  int max_json_depth = 32;                ///< Deepest nesting of arrays/objects in a body.
  std::size_t max_array_length = 4096;    ///< Longest array anywhere in a body (elements).
  std::size_t max_string_length = 256;    ///< Longest string value or key (bytes).
  std::size_t max_knots = 256;            ///< Knots of a profile.
  std::size_t max_variants = 64;          ///< Variants in /v1/compare.
  std::size_t max_launches = 4096;        ///< Launches in one /v1/flight request.
  /// Values of one /v1/optimize frontier (`frontier.values`, or `count`).
  std::size_t max_frontier_values = 1000;
  std::size_t max_curve_samples = 10000;  ///< Points of an exit-speed curve (>= 2).
  std::size_t max_samples = 100000;       ///< Designs in one synchronous /v1/explore request.
  /// Designs in one /v1/explore run as a batch (a job, the CLI: Context::batch), whose rows
  /// go to a job's result or a file. The CLI lifts it (no limit) unless told otherwise.
  std::size_t max_batch_samples = 1000000;
  /// Variables of one /v1/optimize design. The optimiser has its own ceiling
  /// of 1000 (core/optimize, DesignOptions::max_variables): a larger limit lets such requests
  /// reach it.
  std::size_t max_design_variables = 1000;
  int max_iterations = 10000;                  ///< Solver iterations a request may ask for.
  double max_time_s = 60.0;                    ///< Solver wall time a request may ask for, s.
  long long max_integration_steps = 10000000;  ///< ODE steps of one impact (hertz, flexible).
  /// Jobs on one page of GET /v1/jobs (the largest `limit` a client may ask for).
  std::size_t max_jobs_page = 1000;
  /// Estimated bytes of an answer built in memory before it is sent: a synchronous
  /// /v1/explore in JSON (rows x the bytes of a row as written; while it is built the server
  /// holds about 6x that: 2000 rows x 1000 curve points, 160 MB of text, peaked at 0.93 GB).
  /// 413 before the first design beyond it; ndjson and csv answers are streamed, not bounded.
  std::size_t max_response_bytes = 64u << 20;
  /// A job's estimated CPU time at submit, s: designs x the per-design cost of the models its
  /// outputs need (api/explore/estimate.cpp). 413 at POST /v1/jobs beyond it.
  double max_job_cpu_s = 3600.0;
  /// A job's wall time, s. At submit: its estimated CPU time over its threads (413 beyond);
  /// while it runs: enforced by the job runner (server/jobs). The server sets it from its
  /// --job-max-time-s.
  double max_job_time_s = 600.0;
  /// A job's result, bytes. At submit: its estimate (413 beyond); when stored: enforced by the
  /// job runner (server/jobs). The server sets it from its --job-max-result-bytes.
  std::size_t max_job_result_bytes = 268435456;

  /// True when every limit is positive and sane; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(core::Refusal* refusal) const;
};

}  // namespace sweetspot::api
