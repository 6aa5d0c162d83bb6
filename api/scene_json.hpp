// The scene as JSON (ball, swing, COR, outputs, options) for /v1/sweet-spot,
// /v1/collision and /v1/compare, and the renderers of their results.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

#include "api/bat_json.hpp"
#include "api/json_reader.hpp"
#include "api/json_writer.hpp"
#include "core/scene/collide.hpp"
#include "core/scene/evaluate_scene.hpp"

namespace sweetspot::api {

/// Reads the scene fields shared by every scene endpoint from `reader` (the
/// request body): "ball", "swing", "cor", "inertia_model". Fields not given
/// keep the defaults of the contract (Table 3 kinematics, a regulation ball,
/// COR from the bat's material, pivot at the knob).
bool ReadSceneCommon(ObjectReader& reader, core::Scene* scene);

/// The resolved swing a scene answer echoes: {angular_speed_rad_s, pivot_from_knob_m,
/// hands_from_knob_m} plus {bat_speed_mps, bat_speed_from_tip_m} when the bat speed set it.
nlohmann::json SwingToJson(const core::Swing& swing);
/// The same members written to `out` (api/json_writer.hpp's Out: TreeObject or TextObject).
template <class Out>
void WriteSwing(const core::Swing& swing, Out& out);

/// Reads "outputs" (an array of output names; default ["max_exit_speed"]).
bool ReadOutputs(ObjectReader& reader, core::Scene* scene);

/// Reads "options" of /v1/sweet-spot into `options`.
bool ReadSceneOptions(ObjectReader& reader, const ApiLimits& limits, core::SceneOptions* options);

/// Reads a "flexible" options object at `path` (the flexible beam: theory, tolerances, modes,
/// the impact's integrator and the sting settings; see docs/models.md) and checks it with
/// core's rules. `path` ends in "flexible" ("options.flexible" or "flexible").
bool ReadFlexibleOptions(const nlohmann::json& value, const std::string& path,
                         const ApiLimits& limits, core::FlexibleOptions* options, ApiError* error);

/// Reads options.distance at `path` (distance_sweet_spot and carry_map: the region, the
/// searches' grids, tolerances and budget, the normal-law table); the ranges are core's
/// (DistanceOptions::Validate, checked with the scene's options).
bool ReadDistanceOptions(const nlohmann::json& value, const std::string& path,
                         core::DistanceOptions* options, ApiError* error);

/// Reads a "hertz" options object at `path`.
bool ReadHertzOptions(const nlohmann::json& value, const std::string& path, const ApiLimits& limits,
                      core::HertzOptions* options, ApiError* error);

/// Lowers the defaults of `options` (solver time, evaluations, integration steps)
/// to the configured limits, so a default never exceeds what a request may ask for.
void ClampToLimits(const ApiLimits& limits, core::SceneOptions* options);
/// The same for the contact model's integrator.
void ClampToLimits(const ApiLimits& limits, core::HertzOptions* options);
/// The same for the flexible impact's integrator.
void ClampToLimits(const ApiLimits& limits, core::FlexibleOptions* options);

/// The error response for a core result that was refused or failed: 501 for
/// a missing model, 400 for invalid input (field from the core message when it
/// names one), 422 ModelFailed for a model that could not finish. With
/// `options_object`, a field the core names that is not a scene field (bat,
/// ball, swing, cor, outputs, inertia_model) is one of the request's
/// "options" and is reported as "options.<field>".
Response CoreFailure(const core::Summary& summary, const std::string& missing_model,
                     const std::string& field, bool options_object = false);

/// CoreFailure for a scene whose bat was parsed with ParseBatGeometry: a failure
/// on mass properties that are not usable (`properties`, as core computed them
/// once) is the bat's, a 400 on `bat_path` as ParseBat answers.
Response SceneFailure(const core::Summary& summary, const std::string& missing_model,
                      const core::MassProperties& properties, const std::string& bat_path,
                      const std::string& field, bool options_object = false);

/// The summary block {termination, message, backend, raw_status, iterations,
/// evaluations, error_estimate, solve_time_s, models_used, warnings}.
nlohmann::json SummaryToJson(const core::Summary& summary);
/// The same members written to `out` (TreeObject or TextObject).
template <class Out>
void WriteSummary(const core::Summary& summary, Out& out);

/// The `barrel` output (hoop mode, stiffness, effective COR along the barrel); null hoop fields
/// for a solid bat.
nlohmann::json BarrelOutputToJson(const core::BarrelOutput& barrel);
/// The `bbcor` output: value and the protocol's ball, speed, impact point, pivot and method.
nlohmann::json BbcorToJson(const core::BbcorResult& bbcor);
/// The `bbcor_scan` output: every point (position, e_A, BBCOR, the rigid free bat's BBCOR), the
/// maximum and its location, the fixed-point value beside it.
nlohmann::json BbcorScanToJson(const core::BbcorScan& scan);

/// One collision result: exit speed, model and what the model knows.
nlohmann::json CollisionResultToJson(const core::CollisionResult& result);

/// The vibration_node block: {position_from_knob_m, frequency_hz, other_node_from_knob_m,
/// second_mode: {frequency_hz, nodes_from_knob_m}, theory, elements, ...}.
nlohmann::json VibrationNodeToJson(const core::VibrationNodeResult& node);

/// The least_sting_zone block: the zone, the least-sting impact and the sweep's curve (flexible
/// and rigid exit speeds side by side, vibration and hands' energy, peak loads at the hands).
nlohmann::json LeastStingZoneToJson(const core::LeastStingZoneResult& zone);

/// The "flexible" block of a collision: exit speed, vibration energy, the sting at the hands,
/// contact time, peak force, the modes used, energies, error estimates and the solve summary.
nlohmann::json FlexibleImpactToJson(const core::FlexibleImpactResult& impact);

}  // namespace sweetspot::api
