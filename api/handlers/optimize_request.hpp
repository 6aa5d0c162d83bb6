// /v1/optimize's parsed request and answer, shared by the single design (optimize.cpp) and the
// frontier (optimize_frontier.cpp: one design per value of a constraint).
#pragma once

#include <nlohmann/json.hpp>
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "api/json_reader.hpp"
#include "api/handlers/optimize_variables.hpp"
#include "api/response.hpp"
#include "api/router.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/optimize/design_cor.hpp"
#include "core/optimize/design_problem.hpp"

namespace sweetspot::api::optimize_detail {

/// A parsed /v1/optimize request: the problem, the solver's options, the materials to choose
/// among (empty = no choice), the objective's name and the bat as written (the answer's bat
/// is given back in its form).
struct OptimizeRequest {
  core::DesignProblem problem;
  std::string model_reason;  ///< Why problem.model (core::ResolveExitModel).
  core::DesignOptions options;
  std::vector<core::Material> material_choices;
  std::string objective;
  nlohmann::json request_bat;
  /// Where the COR comes from (core::ResolveDesignCor): the answer's "cor_source".
  core::DesignCorPolicy cor_policy;
  /// The base bat's mass properties under problem.inertia_model, computed once (ParseBat).
  core::MassProperties base_properties;
  /// The variables' paths as the request wrote them (trade forms): the answer's names, units.
  VariableNames variable_names;
};

/// The request body (without the frontier's own fields) as a design problem; nullopt with
/// *error set on a refusal.
std::optional<OptimizeRequest> ParseOptimize(const nlohmann::json& body, const Context& context,
                                             ApiError* error);

/// `v`, or null when it is not finite (an answer never holds NaN or infinity).
nlohmann::json Finite(double v);

/// A material written out whole, as a request gives one (no source or density range; no null
/// cor).
nlohmann::json MaterialInRequestForm(const core::Material& m);

/// One design's answer: bat in the request's form, variables as written, properties, objective,
/// sweet spot, summary (with active constraints and the multi-start spread).
nlohmann::json ResultToJson(const core::DesignResult& r, const nlohmann::json& request_bat,
                            const VariableNames& names);

/// POST /v1/optimize with "frontier" (optimize_frontier.cpp): `body` is the parsed request,
/// `start` its arrival.
Response HandleFrontier(nlohmann::json body, const Context& context,
                        std::chrono::steady_clock::time_point start);

}  // namespace sweetspot::api::optimize_detail
