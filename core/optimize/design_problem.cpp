// Names, parsing and validation of the design problem's public types.
#include "core/optimize/design_problem.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <utility>
#include <string>

#include "core/geometry_format.hpp"
#include "core/optimize/design_model.hpp"
#include "core/refusal.hpp"

namespace sweetspot::core {
namespace {

struct FixedPath {
  DesignVariableKind kind;
  const char* path;
};

constexpr FixedPath kFixedPaths[] = {
    {DesignVariableKind::kLength, "three_segment.length_m"},
    {DesignVariableKind::kHandleRadius, "three_segment.handle_radius_m"},
    {DesignVariableKind::kBarrelRadius, "three_segment.barrel_radius_m"},
    {DesignVariableKind::kTaperStart, "three_segment.taper_start_m"},
    {DesignVariableKind::kTaperEnd, "three_segment.taper_end_m"},
    {DesignVariableKind::kDensity, "material.density_kg_m3"},
    {DesignVariableKind::kWallThickness, "wall_thickness_m"},
    {DesignVariableKind::kFillDiameter, "fill.diameter_m"},
    {DesignVariableKind::kFillDepth, "fill.depth_m"},
    {DesignVariableKind::kFillDensity, "fill.material.density_kg_m3"},
};

struct ObjectiveName {
  DesignObjective objective;
  const char* name;
};

constexpr ObjectiveName kObjectiveNames[] = {
    {DesignObjective::kMaxExitSpeed, "max_exit_speed"},
    {DesignObjective::kMaxExitSpeedSwingWeight, "max_exit_speed_swing_weight"},
    {DesignObjective::kWidestSweetZone, "widest_sweet_zone"},
    {DesignObjective::kMinMoi, "min_moi"},
    {DesignObjective::kMinSting, "min_sting"},
    {DesignObjective::kMaxDistance, "max_distance"},
};

}  // namespace

std::optional<DesignVariableRef> ParseDesignVariablePath(std::string_view path) {
  for (const FixedPath& f : kFixedPaths) {
    if (path == f.path) return DesignVariableRef{f.kind, -1};
  }
  constexpr std::string_view kPrefix = "profile.knots[";
  if (path.substr(0, kPrefix.size()) != kPrefix) return std::nullopt;
  std::string_view rest = path.substr(kPrefix.size());
  const std::size_t close = rest.find(']');
  if (close == std::string_view::npos || close == 0 || close > 6) return std::nullopt;
  const std::string_view digits = rest.substr(0, close);
  for (char c : digits) {
    if (c < '0' || c > '9') return std::nullopt;
  }
  if (digits.size() > 1 && digits[0] == '0') return std::nullopt;  // one spelling per index
  int index = 0;
  std::from_chars(digits.data(), digits.data() + digits.size(), index);
  const std::string_view member = rest.substr(close + 1);
  if (member == ".radius_m") return DesignVariableRef{DesignVariableKind::kKnotRadius, index};
  if (member == ".x_m") return DesignVariableRef{DesignVariableKind::kKnotPosition, index};
  return std::nullopt;
}

std::string DesignVariablePath(const DesignVariableRef& ref) {
  if (ref.kind == DesignVariableKind::kKnotRadius) {
    return "profile.knots[" + std::to_string(ref.knot) + "].radius_m";
  }
  if (ref.kind == DesignVariableKind::kKnotPosition) {
    return "profile.knots[" + std::to_string(ref.knot) + "].x_m";
  }
  for (const FixedPath& f : kFixedPaths) {
    if (f.kind == ref.kind) return f.path;
  }
  return "";
}

const char* DesignObjectiveName(DesignObjective objective) {
  // The shape fit's objective: a name, not one ParseDesignObjective accepts from a request.
  if (objective == DesignObjective::kLeastSquares) return "least_squares";
  for (const auto& o : kObjectiveNames) {
    if (o.objective == objective) return o.name;
  }
  return "unknown";
}

std::optional<DesignObjective> ParseDesignObjective(std::string_view name) {
  for (const auto& o : kObjectiveNames) {
    if (name == o.name) return o.objective;
  }
  return std::nullopt;
}

bool DesignProblem::Validate(Refusal* refusal) const {
  DesignModel built;  // not "model": that is the problem's exit-speed model
  return DesignModel::Build(*this, DesignOptions{}, &built, refusal);
}

bool DesignOptions::Validate(Refusal* why) const {
  if (max_iterations < 1 || max_iterations > 100000) {
    return Refuse(why, "max_iterations", max_iterations, "must be between 1 and 100000");
  }
  if (!std::isfinite(max_time_s) || !(max_time_s > 0.0)) {
    return Refuse(why, "max_time_s", max_time_s, "must be finite and positive");
  }
  if (!std::isfinite(max_cpu_time_s) || max_cpu_time_s < 0.0) {
    return Refuse(why, "max_cpu_time_s", max_cpu_time_s, "must be finite and >= 0 (0 = not set)");
  }
  if (!std::isfinite(tolerance) || !(tolerance > 0.0) || !(tolerance < 1.0)) {
    return Refuse(why, "tolerance", tolerance, "must be in (0, 1)");
  }
  if (!std::isfinite(constraint_tolerance) || !(constraint_tolerance > 0.0) ||
      !(constraint_tolerance < 1.0)) {
    return Refuse(why, "constraint_tolerance", constraint_tolerance, "must be in (0, 1)");
  }
  if (!std::isfinite(feasibility_tolerance) || !(feasibility_tolerance > 0.0) ||
      !(feasibility_tolerance <= 0.01)) {
    return Refuse(why, "feasibility_tolerance", feasibility_tolerance, "must be in (0, 0.01]");
  }
  const std::pair<const char*, double> certificate[] = {
      {"stationarity_tolerance", stationarity_tolerance},
      {"complementarity_tolerance", complementarity_tolerance}};
  for (const auto& [name, value] : certificate) {
    if (!std::isfinite(value) || !(value > 0.0) || !(value < 1.0)) {
      return Refuse(why, name, value, "must be in (0, 1)");
    }
  }
  if (starts < 1 || starts > 64) return Refuse(why, "starts", starts, "must be between 1 and 64");
  for (std::size_t i = 0; i < start_points.size(); ++i) {
    for (double v : start_points[i]) {
      if (!std::isfinite(v)) {
        return Refuse(why, "start_points[" + std::to_string(i) + "]", v, "must be finite");
      }
    }
  }
  if (!std::isfinite(min_knot_gap_m) || !(min_knot_gap_m > 0.0) || min_knot_gap_m > 0.1) {
    return Refuse(why, "min_knot_gap_m", min_knot_gap_m, "must be in (0, 0.1]");
  }
  if (max_variables < 1) return Refuse(why, "max_variables", max_variables, "must be >= 1");
  if (derivative_check == DerivativeCheck::kSecondOrder && hessian != HessianMode::kExact) {
    return Refuse(
        why, Refusal{"derivative_check", std::numeric_limits<double>::quiet_NaN(), "second-order",
                     "needs hessian = exact (the limited-memory approximation has no "
                     "second derivatives to check)"});
  }
  if (derivative_check != DerivativeCheck::kNone && backend != DesignBackend::kIpopt) {
    return Refuse(why, TextRefusal("derivative_check", "Ipopt's checker needs backend = ipopt"));
  }
  return true;
}

}  // namespace sweetspot::core
