// One design of a /v1/explore sweep: its row (the outputs asked for, or the error the
// single endpoint would answer for that design). A design is
// evaluated in two steps that the sweep engine (api/explore/engine.hpp) shares with the
// JSON path: a scene (parsed from the design's JSON here, or bound from a resolved template
// there), then ComputeDesign and RenderDesignRow.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <vector>

#include "api/json_reader.hpp"
#include "api/limits.hpp"
#include "core/numerics/timing_book.hpp"
#include "core/scene/evaluate_scene.hpp"

namespace sweetspot::api {

/// What a row reports besides its parameters.
struct RowOutputs {
  bool properties = false;            ///< The bat's mass properties ("properties").
  bool collision_efficiency = false;  ///< q at the sweet spot (rigid pivot; needs max_exit_speed).
  std::vector<core::SceneOutput> scene;  ///< The scene outputs.
  /// Each design has its own swing (a bat speed given or swept): rows carry "swing".
  bool swing = false;
};

/// A design's row and what computing it took.
struct DesignRow {
  nlohmann::json row;  ///< {"feasible": true, outputs...} or {"feasible": false, "error": {...}}.
  std::optional<double> length_m;          ///< The design's bat length (feasible rows).
  std::vector<core::ModelTiming> timings;  ///< Per model over the scene and the collision.
};

/// What a design's models computed: the values a row is rendered from.
struct DesignOutcome {
  bool feasible = false;     ///< False: `error` is the row's error object.
  nlohmann::json error;      ///< {"code", "message", "field"} when not feasible.
  core::SceneResult result;  ///< The scene outputs, mass_properties and length_m (feasible).
  std::optional<double> collision_efficiency;  ///< q at the sweet spot, when asked for.
};

/// True when `scene` (a design's, its outputs set) is a valid scene; a row of properties only
/// is checked as if it named max_exit_speed. Otherwise false with the error in *error.
bool ValidateDesignScene(const core::Scene& scene, ApiError* error);

/// Runs the models of a valid design scene (`scene.outputs` = outputs.scene; its
/// mass_properties may be preset when they are known to be the bat's) into *out (a fresh
/// outcome, or one a previous design filled: every field is set again); the time and calls
/// per model in *timings when non-null. Never throws.
void ComputeDesign(const core::Scene& scene, const RowOutputs& outputs,
                   const core::SceneOptions& options, DesignOutcome* out,
                   std::vector<core::ModelTiming>* timings = nullptr);
/// ComputeDesign with `evaluator`'s options, its scene results written over *out's (a sweep's
/// worker: the options validated once, the result's buffers reused design after design).
void ComputeDesign(const core::Scene& scene, const RowOutputs& outputs,
                   core::SceneEvaluator* evaluator, DesignOutcome* out,
                   std::vector<core::ModelTiming>* timings = nullptr);

/// The row of an outcome: {"feasible": false, "error"} or {"feasible": true, outputs...}.
nlohmann::json RenderDesignRow(const DesignOutcome& outcome, const RowOutputs& outputs);

/// "report_units": "imperial" on a row: each output block (not "parameters", the swept values
/// as written, nor "error") gets its trade-unit fields as AddImperial gives them in a single
/// request's answer, the positions also from the tip of a bat of `length_m`.
void AddImperialToRow(nlohmann::json* row, double length_m);

/// Evaluates `design` (a bat and scene fields, as a request writes them): the mass properties
/// are computed once per design, whatever the outputs. Never throws.
DesignRow EvaluateDesign(const nlohmann::json& design, const RowOutputs& outputs,
                         const core::SceneOptions& options, const ApiLimits& limits);

}  // namespace sweetspot::api
