// One design of a /v1/explore sweep: its row (the outputs asked for, or the error the
// single endpoint would answer for that design) and the time its models took.
#pragma once

#include <nlohmann/json.hpp>

#include <vector>

#include "api/limits.hpp"
#include "core/scene/evaluate_scene.hpp"
#include "core/scene/timing_book.hpp"

namespace sweetspot::api {

/// What a row reports besides its parameters.
struct RowOutputs {
  bool properties = false;            ///< The bat's mass properties ("properties").
  bool collision_efficiency = false;  ///< q at the sweet spot (rigid pivot; needs max_exit_speed).
  std::vector<core::SceneOutput> scene;  ///< The scene outputs.
};

/// A design's row and what computing it took.
struct DesignRow {
  nlohmann::json row;  ///< {"feasible": true, outputs...} or {"feasible": false, "error": {...}}.
  std::vector<core::ModelTiming> timings;  ///< Per model over the scene and the collision.
};

/// Evaluates `design` (a bat and scene fields, as a request writes them): the mass properties
/// are computed once per design, whatever the outputs. Never throws.
DesignRow EvaluateDesign(const nlohmann::json& design, const RowOutputs& outputs,
                         const core::SceneOptions& options, const ApiLimits& limits);

}  // namespace sweetspot::api
