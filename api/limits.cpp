#include "api/limits.hpp"

#include <cmath>

#include "core/geometry_format.hpp"
#include "core/refusal.hpp"

namespace sweetspot::api {

bool ApiLimits::Validate(core::Refusal* refusal) const {
  using core::IntegerRefusal;
  using core::Refuse;
  if (max_json_depth < 2 || max_json_depth > 512) {
    return Refuse(refusal, IntegerRefusal("max_json_depth", max_json_depth, "must be in [2, 512]"));
  }
  const std::pair<const char*, std::size_t> sizes[] = {
      {"max_array_length", max_array_length},
      {"max_string_length", max_string_length},
      {"max_knots", max_knots},
      {"max_variants", max_variants},
      {"max_launches", max_launches},
      {"max_frontier_values", max_frontier_values},
      {"max_curve_samples", max_curve_samples},
      {"max_samples", max_samples},
      {"max_batch_samples", max_batch_samples},
      {"max_design_variables", max_design_variables},
      {"max_jobs_page", max_jobs_page},
      {"max_response_bytes", max_response_bytes},
      {"max_job_result_bytes", max_job_result_bytes}};
  for (const auto& [name, value] : sizes) {
    if (value < 1) return Refuse(refusal, IntegerRefusal(name, 0, "must be at least 1"));
  }
  if (max_curve_samples < 2) {
    return Refuse(refusal,
                  IntegerRefusal("max_curve_samples", static_cast<long long>(max_curve_samples),
                                 "must be at least 2 (a curve has two ends)"));
  }
  if (max_knots < 2) {
    return Refuse(refusal, IntegerRefusal("max_knots", static_cast<long long>(max_knots),
                                          "must be at least 2"));
  }
  if (max_iterations < 1) {
    return Refuse(refusal, IntegerRefusal("max_iterations", max_iterations, "must be at least 1"));
  }
  if (max_integration_steps < 10) {
    return Refuse(refusal, IntegerRefusal("max_integration_steps", max_integration_steps,
                                          "must be at least 10"));
  }
  if (!std::isfinite(max_time_s) || max_time_s <= 0) {
    return Refuse(refusal, core::NumberRefusal("max_time_s", max_time_s, "must be > 0"));
  }
  const std::pair<const char*, double> seconds[] = {{"max_job_cpu_s", max_job_cpu_s},
                                                    {"max_job_time_s", max_job_time_s}};
  for (const auto& [name, value] : seconds) {
    if (!std::isfinite(value) || value <= 0) {
      return Refuse(refusal, core::NumberRefusal(name, value, "must be > 0"));
    }
  }
  return true;
}

}  // namespace sweetspot::api
