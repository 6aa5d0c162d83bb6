// /v1/optimize's "variables" (and /v1/bat/fit's path unknowns, which become them): each path
// found in the table of fields (api/fields.hpp) in SI or any trade form, its bounds converted
// to SI for core, and the names as written kept for the answer and for core's refusals.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "api/json_reader.hpp"
#include "api/limits.hpp"
#include "core/bat/material.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/refusal.hpp"

namespace sweetspot::api {

/// A variable's field as the request wrote it.
struct WrittenVariable {
  std::string si;       ///< Core's path ("wall_thickness_m").
  std::string written;  ///< The request's ("wall_thickness_in").
  double to_si = 1.0;   ///< SI = written * to_si.
};

/// How the request named its variables: every path (linked and scaled ones too) written in a
/// trade form, and per variable the factor of its bounds (1 for a scale variable).
struct VariableNames {
  std::vector<WrittenVariable> paths;
  std::vector<double> bound_to_si;  ///< Per problem.variables entry.

  /// The path as written, or `si` when it was written in SI.
  const WrittenVariable* Find(const std::string& si) const;
  /// Core's refusal with the variable named and its value given as the request wrote them
  /// ("variables[0].min = 0.02: must be positive for wall_thickness_in", in inches).
  core::Refusal AsWritten(core::Refusal refusal) const;
  /// An answer's "variables" object: each variable under its written path, in its unit.
  nlohmann::json ValuesAsWritten(const std::vector<core::DesignValue>& values) const;
};

/// Reads "variables": continuous design variables into `problem` (SI), a "material" choice into
/// `material_choices`, the written names into `names`.
bool ReadVariables(ObjectReader& reader, const ApiLimits& limits, core::DesignProblem* problem,
                   std::vector<core::Material>* material_choices, VariableNames* names);

}  // namespace sweetspot::api
