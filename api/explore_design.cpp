#include "api/explore_design.hpp"

#include <chrono>
#include <optional>
#include <string>
#include <utility>

#include "api/bat_json.hpp"
#include "api/json_reader.hpp"
#include "api/scene_json.hpp"
#include "core/collision/collide.hpp"

namespace sweetspot::api {
namespace {
using Json = nlohmann::json;
}  // namespace

DesignRow EvaluateDesign(const Json& design_json, const RowOutputs& outputs,
                         const core::SceneOptions& options, const ApiLimits& limits) {
  DesignRow out;
  const auto refused = [&out](Json error) {
    out.row = {{"feasible", false}, {"error", std::move(error)}};
    return out;
  };
  ApiError error;
  ObjectReader reader(design_json, "", &error);
  core::Scene scene;
  std::optional<BatSpec> spec;
  // The bat's mass properties are left to the single computation below.
  if (const Json* bat = reader.Get("bat")) spec = ParseBatGeometry(*bat, "bat", limits, &error);
  if (spec) {
    scene.bat = spec->bat;
    ReadSceneCommon(reader, &scene);
  }
  scene.outputs = outputs.scene;
  if (!error.code) {
    // A row of properties only names no scene output; the scene (bat, ball,
    // swing, cor) must still be valid, so it is checked as if it named one.
    core::Scene check = scene;
    if (check.outputs.empty()) check.outputs = {core::SceneOutput::kMaxExitSpeed};
    if (core::Refusal refusal; !check.Validate(&refusal)) CoreRefusal(refusal, "", &error);
  }
  const auto error_json = [](const ApiError& e) {
    return Json{{"code", ErrorCodeName(e.code.value_or(ErrorCode::kInternalError))},
                {"message", e.message},
                {"field", e.field}};
  };
  if (error.code) return refused(error_json(error));
  Json row{{"feasible", true}};
  core::TimingBook book;
  core::SceneResult result;
  if (!scene.outputs.empty()) {
    result = core::EvaluateScene(scene, options);
    for (const auto& t : result.timings) book.Add(t.model, t.time_s, t.calls);
    out.timings = book.timings();
    if (!result.summary.IsSolutionUsable()) {
      // The same code and field /v1/sweet-spot would answer for this design.
      const Response failure =
          SceneFailure(result.summary, result.missing_model, result.mass_properties, "bat",
                       result.refused_field.empty() ? "outputs" : result.refused_field,
                       /*options_object=*/true);
      return refused(failure.body);
    }
    Json rendered = SceneResultToJson(result);
    for (const core::SceneOutput output : scene.outputs) {
      const char* name = core::SceneOutputName(output);
      if (rendered.contains(name)) row[name] = std::move(rendered[name]);
    }
  } else {
    const auto start = std::chrono::steady_clock::now();
    result.mass_properties = core::ComputeMassProperties(spec->bat, scene.inertia_model);
    book.Add("mass_properties", core::SecondsSince(start), 1);
    out.timings = book.timings();
    if (!CheckComputable(result.mass_properties, "bat", &error)) return refused(error_json(error));
    result.length_m = spec->bat.LengthM();
  }
  if (outputs.properties) {
    row["properties"] = PropertiesToJson(result.mass_properties, result.length_m);
  }
  if (outputs.collision_efficiency && result.max_exit_speed) {
    // The impact at the sweet spot, with the mass properties the scene already computed.
    core::Scene resolved = scene;
    resolved.mass_properties = result.mass_properties;
    const core::CollisionResult hit = core::Collide(
        resolved, result.max_exit_speed->position_from_knob_m, core::CollisionModel::kRigidPivot);
    for (const auto& t : hit.timings) book.Add(t.model, t.time_s, t.calls);
    out.timings = book.timings();
    if (hit.rigid_pivot) row["collision_efficiency"] = hit.rigid_pivot->collision_efficiency;
  }
  out.row = std::move(row);
  return out;
}

}  // namespace sweetspot::api
