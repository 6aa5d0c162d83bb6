// ClassifyWorkload: which of the server's worker pools a request belongs in.
#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "api/handlers/handlers.hpp"
#include "api/router.hpp"
#include "core/scene/output_registry.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

// The collision model named by `object[key]`, or `fallback` when it is absent
// or not a known name (the handler refuses such a body at once).
core::CollisionModel ModelAt(const Json& object, const char* key, core::CollisionModel fallback) {
  const auto it = object.find(key);
  if (it == object.end() || !it->is_string()) return fallback;
  return core::ParseCollisionModel(it->get_ref<const std::string&>()).value_or(fallback);
}

// The names that can make a scene body need an iterative model: the outputs whose declaration
// says compute (core/scene/output_registry.hpp), and the exit-speed models that are not
// closed forms (an output of class kAsExitModel is then compute).
const std::vector<std::string>& IterativeNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const core::SceneOutputDecl* output : core::SceneOutputTable()) {
      if (output->workload == core::OutputWorkload::kCompute) out.emplace_back(output->name);
    }
    for (const core::CollisionModel model :
         {core::CollisionModel::kRigidPivot, core::CollisionModel::kFreeBat,
          core::CollisionModel::kHertz, core::CollisionModel::kFlexible}) {
      if (!core::IsClosedFormModel(model)) out.emplace_back(core::CollisionModelName(model));
    }
    return out;
  }();
  return names;
}

// Curve points a scene body may ask for over all its bats (a compare's baseline and
// variants) and still be answered in the light pool: a closed-form curve of 10,000 points
// is a few ms and under 1 MB of JSON, but 65 bats of them are 57 MB of JSON and, while it
// is built, about six times that in memory: such bodies go to the bounded compute pool
// (whose requests also have a time budget and stop when their client leaves).
constexpr double kLightCurvePoints = 10000;

// True when `body` cannot name an iterative output or model, nor a long curve: none of
// their names appears in it, and it has no escape (a name could hide behind \u).
// Saves the JSON parse for the closed-form scenes that make most of the traffic.
bool CannotNeedIterativeModel(std::string_view body) {
  if (body.find('\\') != std::string_view::npos) return false;
  for (const std::string& name : IterativeNames()) {
    if (body.find(name) != std::string_view::npos) return false;
  }
  return body.find("exit_speed_curve") == std::string_view::npos;
}

// The curve points `body` asks for over all its bats (0 without exit_speed_curve).
double CurvePoints(const Json& body, const std::vector<core::SceneOutput>& outputs) {
  if (std::find(outputs.begin(), outputs.end(), core::SceneOutput::kExitSpeedCurve) ==
      outputs.end()) {
    return 0;
  }
  double points = 41;  // the default curve_samples
  if (const auto options = body.find("options"); options != body.end() && options->is_object()) {
    if (const auto n = options->find("curve_samples"); n != options->end() && n->is_number()) {
      points = n->get<double>();
    }
    const auto at = options->find("curve_positions_from_knob_m");
    if (at != options->end() && at->is_array()) points = static_cast<double>(at->size());
  }
  double bats = 1;
  if (const auto variants = body.find("variants"); variants != body.end() && variants->is_array()) {
    bats += static_cast<double>(variants->size());
  }
  return points * bats;
}

// A scene body (sweet-spot, compare, collision) needs the compute pool when an
// output it asks for needs an iterative model.
Workload SceneWorkload(const Request& request, const Json& body) {
  if (request.path == "/v1/collision") {
    const core::CollisionModel model = ModelAt(body, "model", core::CollisionModel::kAuto);
    return core::WorkloadOf(core::SceneOutput::kMaxExitSpeed, model) ==
                   core::OutputWorkload::kCompute
               ? Workload::kCompute
               : Workload::kLight;
  }
  core::CollisionModel model = core::CollisionModel::kRigidPivot;
  if (const auto options = body.find("options"); options != body.end() && options->is_object()) {
    model = ModelAt(*options, "model", model);
  }
  std::vector<core::SceneOutput> outputs = {core::SceneOutput::kMaxExitSpeed};
  if (const auto named = body.find("outputs"); named != body.end() && named->is_array()) {
    outputs.clear();
    for (const Json& name : *named) {
      if (!name.is_string()) continue;
      if (const auto output = core::ParseSceneOutput(name.get_ref<const std::string&>())) {
        outputs.push_back(*output);
      }
    }
  }
  for (const core::SceneOutput output : outputs) {
    if (core::WorkloadOf(output, model) == core::OutputWorkload::kCompute) {
      return Workload::kCompute;
    }
  }
  return CurvePoints(body, outputs) > kLightCurvePoints ? Workload::kCompute : Workload::kLight;
}

}  // namespace

Workload ClassifyWorkload(std::string_view method, std::string_view path, std::string_view body,
                          const Context& context, std::shared_ptr<Json>* parsed) {
  try {
    const Route* route = FindRoute(method, path);
    if (route == nullptr) return Workload::kLight;
    switch (route->workload) {
      case RouteWorkload::kLight:
        return Workload::kLight;
      case RouteWorkload::kCompute:
        return Workload::kCompute;
      case RouteWorkload::kScene: {
        if (CannotNeedIterativeModel(body)) return Workload::kLight;
        const Request request{std::string(method), std::string(path), std::string(body)};
        Response refused;
        std::optional<Json> object = ParseObjectBody(request, context, &refused);
        if (!object) return Workload::kLight;  // the handler refuses it (and parses it again)
        const Workload workload = SceneWorkload(request, *object);
        if (parsed != nullptr) *parsed = std::make_shared<Json>(std::move(*object));
        return workload;
      }
    }
  } catch (...) {
    // Out of memory while parsing: the handler will answer; the light pool is fine.
  }
  return Workload::kLight;
}

}  // namespace sweetspot::api
