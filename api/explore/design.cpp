#include "api/explore/design.hpp"

#include <optional>
#include <string>
#include <utility>

#include "api/bat_json.hpp"
#include "api/json_reader.hpp"
#include "api/outputs/scene_outputs.hpp"
#include "api/scene_json.hpp"
#include "api/trade_units.hpp"
#include "core/scene/collide.hpp"

namespace sweetspot::api {
namespace {
using Json = nlohmann::json;

Json DesignErrorJson(const ApiError& e) {
  return Json{{"code", ErrorCodeName(e.code.value_or(ErrorCode::kInternalError))},
              {"message", e.message},
              {"field", e.field}};
}
}  // namespace

bool ValidateDesignScene(const core::Scene& scene, ApiError* error) {
  // A row of properties only names no scene output; the scene (bat, ball,
  // swing, cor) must still be valid, so it is checked as if it named one.
  core::Refusal refusal;
  if (scene.outputs.empty()) {
    core::Scene check = scene;
    check.outputs = {core::SceneOutput::kMaxExitSpeed};
    if (check.Validate(&refusal)) return true;
  } else if (scene.Validate(&refusal)) {
    return true;
  }
  CoreRefusal(refusal, "", error);
  return false;
}

void ComputeDesign(const core::Scene& scene, const RowOutputs& outputs,
                   const core::SceneOptions& options, DesignOutcome* out,
                   std::vector<core::ModelTiming>* timings) {
  core::SceneEvaluator evaluator(options);
  ComputeDesign(scene, outputs, &evaluator, out, timings);
}

void ComputeDesign(const core::Scene& scene, const RowOutputs& outputs,
                   core::SceneEvaluator* evaluator, DesignOutcome* out_ptr,
                   std::vector<core::ModelTiming>* timings) {
  const core::SceneOptions& options = evaluator->options();
  DesignOutcome& out = *out_ptr;
  out.feasible = false;
  out.error = nullptr;
  out.collision_efficiency.reset();
  core::SceneResult& result = out.result;
  core::TimingBook book(options.time_models);
  const auto done = [&] {
    if (timings != nullptr) *timings = book.TakeTimings();
  };
  if (!scene.outputs.empty()) {
    evaluator->Evaluate(scene, &result);
    if (timings != nullptr) {
      for (const auto& t : result.timings) book.Add(t.model, t.time_s, t.calls);
    }
    if (!result.summary.IsSolutionUsable()) {
      // The same code and field /v1/sweet-spot would answer for this design.
      const Response failure =
          SceneFailure(result.summary, result.missing_model, result.mass_properties, "bat",
                       result.refused_field.empty() ? "outputs" : result.refused_field,
                       /*options_object=*/true);
      out.error = failure.body;
      done();
      return;
    }
  } else {
    result.Reset();
    if (scene.mass_properties) {
      result.mass_properties = *scene.mass_properties;
    } else {
      const auto start = book.Now();
      result.mass_properties = core::ComputeMassProperties(*scene.bat, scene.inertia_model);
      book.Add("mass_properties", book.Since(start), 1);
    }
    if (ApiError error; !CheckComputable(result.mass_properties, "bat", &error)) {
      out.error = DesignErrorJson(error);
      done();
      return;
    }
    result.length_m = scene.bat->LengthM();
  }
  if (outputs.collision_efficiency && result.max_exit_speed) {
    // The impact at the sweet spot, with the mass properties the scene already computed.
    core::Scene resolved = scene;
    resolved.mass_properties = result.mass_properties;
    const core::CollisionResult hit = core::Collide(
        resolved, result.max_exit_speed->position_from_knob_m, core::CollisionModel::kRigidPivot);
    if (timings != nullptr) {
      for (const auto& t : hit.timings) book.Add(t.model, t.time_s, t.calls);
    }
    if (hit.rigid_pivot) out.collision_efficiency = hit.rigid_pivot->collision_efficiency;
  }
  out.feasible = true;
  done();
}

Json RenderDesignRow(const DesignOutcome& outcome, const RowOutputs& outputs) {
  if (!outcome.feasible) return {{"feasible", false}, {"error", outcome.error}};
  Json row{{"feasible", true}};
  if (!outputs.scene.empty()) {
    Json rendered = SceneResultToJson(outcome.result);
    for (const core::SceneOutput output : outputs.scene) {
      const char* name = core::SceneOutputName(output);
      if (rendered.contains(name)) row[name] = std::move(rendered[name]);
    }
  }
  if (outputs.properties) {
    row["properties"] = PropertiesToJson(outcome.result.mass_properties, outcome.result.length_m);
  }
  if (outcome.collision_efficiency) row["collision_efficiency"] = *outcome.collision_efficiency;
  // A bat speed gives each design its own omega (its own length): the row says which. Without
  // one every row's swing is the request's, so rows stay as they were.
  if (outcome.result.swing.bat_speed_mps) row["swing"] = SwingToJson(outcome.result.swing);
  return row;
}

void AddImperialToRow(Json* row, double length_m) {
  for (auto& [key, block] : row->items()) {
    if (key == "parameters" || key == "error" || !block.is_structured()) continue;
    AddImperial(&block, length_m);
  }
}

DesignRow EvaluateDesign(const Json& design_json, const RowOutputs& outputs,
                         const core::SceneOptions& options, const ApiLimits& limits) {
  DesignRow out;
  ApiError error;
  ObjectReader reader(design_json, "", &error);
  core::Scene scene;
  // The bat's mass properties are left to the single computation in ComputeDesign.
  if (const Json* bat = reader.Get("bat")) {
    if (auto spec = ParseBatGeometry(*bat, "bat", limits, &error)) {
      scene.bat = std::move(spec->bat);
      scene.paper_bat = spec->paper;
      ReadSceneCommon(reader, &scene);
    }
  }
  scene.outputs = outputs.scene;
  if (!error.code) ValidateDesignScene(scene, &error);
  if (error.code) {
    out.row = {{"feasible", false}, {"error", DesignErrorJson(error)}};
    return out;
  }
  DesignOutcome outcome;
  ComputeDesign(scene, outputs, options, &outcome, &out.timings);
  out.row = RenderDesignRow(outcome, outputs);
  if (outcome.feasible) out.length_m = outcome.result.length_m;
  return out;
}

}  // namespace sweetspot::api
