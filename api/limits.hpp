// Limits on what a request may ask for. Configuration, not constants: the
// server sets them from flags/environment; every limit has a test that hits it.
#pragma once

#include <cstddef>
#include <string>

namespace sweetspot::api {

/// Request limits with their defaults.
struct ApiLimits {
  int max_json_depth = 32;                ///< Deepest nesting of arrays/objects in a body.
  std::size_t max_array_length = 4096;    ///< Longest array anywhere in a body (elements).
  std::size_t max_string_length = 256;    ///< Longest string value or key (bytes).
  std::size_t max_knots = 256;            ///< Knots of a profile.
  std::size_t max_variants = 64;          ///< Variants in /v1/compare.
  std::size_t max_curve_samples = 10000;  ///< Points of an exit-speed curve (>= 2).
  std::size_t max_samples = 100000;       ///< Designs in one synchronous /v1/explore request.
  /// Designs in one /v1/explore run as a batch (a job, the CLI: Context::batch), whose rows
  /// go to a job's result or a file. The CLI lifts it (no limit) unless told otherwise.
  std::size_t max_batch_samples = 1000000;
  /// Variables of one /v1/optimize design. The optimiser has its own ceiling
  /// of 200 (core/optimize): a larger limit lets such requests reach it.
  std::size_t max_design_variables = 200;
  int max_iterations = 10000;                  ///< Solver iterations a request may ask for.
  double max_time_s = 60.0;                    ///< Solver wall time a request may ask for, s.
  long long max_integration_steps = 10000000;  ///< ODE steps of one impact (hertz, flexible).
  /// Jobs on one page of GET /v1/jobs (the largest `limit` a client may ask for).
  std::size_t max_jobs_page = 1000;

  /// True when every limit is positive and sane; otherwise "field = value: rule" in *why.
  bool IsValid(std::string* why) const;
};

}  // namespace sweetspot::api
