// DesignBinder: sets a sweep design's swept values on the template's scene without JSON.
#include "api/explore/binder.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <map>
#include <mutex>
#include <new>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>
#include "api/bat_json.hpp"
#include "api/fields.hpp"
#include "api/json_reader.hpp"
#include "api/memory_reserve.hpp"
#include "api/scene_json.hpp"
#include "api/trade_units.hpp"
#include "core/numerics/timing_book.hpp"

namespace sweetspot::api {

using Json = nlohmann::json;

namespace {

// The steps of a path as "bat.profile.knots[].x_m" (indices left out) and its indices.
std::string StepPattern(const std::vector<PathStep>& steps, std::vector<std::size_t>* indices) {
  std::string pattern;
  for (const PathStep& step : steps) {
    if (const auto* key = std::get_if<std::string>(&step)) {
      if (!pattern.empty()) pattern += '.';
      pattern += *key;
    } else {
      pattern += "[]";
      indices->push_back(std::get<std::size_t>(step));
    }
  }
  return pattern;
}

bool IsObjectAt(const Json& root, std::initializer_list<const char*> keys) {
  const Json* node = &root;
  for (const char* key : keys) {
    if (!node->is_object()) return false;
    const auto it = node->find(key);
    if (it == node->end()) return false;
    node = &*it;
  }
  return node->is_object();
}

// True when the template has the part `group`'s field sits in: a three-segment shape, a
// profile with that knot, a material or fill given as an object.
bool HasPart(FieldGroup group, const Json& bat, const BatSpec& spec,
             const std::vector<std::size_t>& indices) {
  switch (group) {
    case FieldGroup::kShape:
      return spec.three_segment.has_value();
    case FieldGroup::kKnot:
      return spec.shape_form == "profile" && indices.size() == 1 &&
             indices[0] < spec.bat.knots.size();
    case FieldGroup::kMaterial:
      return IsObjectAt(bat, {"material"});
    case FieldGroup::kFill:
    case FieldGroup::kFillMaterial:
      return IsObjectAt(bat, {"fill"}) && spec.bat.fill.has_value();
    default:
      return true;
  }
}

}  // namespace

std::optional<DesignBinder> DesignBinder::Compile(
    const Json& base, const std::vector<SweepParameter>& parameters, const RowOutputs& outputs,
    const ApiLimits& limits, const core::MassPropertiesOfBothModels* template_properties) {
  DesignBinder binder;
  ApiError error;
  if (!base.is_object() || !base.contains("bat")) return std::nullopt;
  const auto spec = ParseBatGeometry(base["bat"], "bat", limits, &error);
  if (!spec) return std::nullopt;
  ObjectReader reader(base, "", &error);
  binder.scene_.bat = spec->bat;
  binder.scene_.paper_bat = spec->paper;
  if (!ReadSceneCommon(reader, &binder.scene_)) return std::nullopt;
  binder.scene_.outputs = outputs.scene;
  const Json& bat = base["bat"];
  binder.parameters_ = parameters;
  for (std::size_t k = 0; k < parameters.size(); ++k) {
    for (std::size_t t = 0; t < parameters[k].targets.size(); ++t) {
      std::vector<std::size_t> indices;
      const std::string pattern = StepPattern(parameters[k].targets[t], &indices);
      Binding binding{};
      binding.parameter = k;
      binding.target_index = t;
      binding.field = FindField(pattern);
      // Bound here when the template has the field's part; otherwise the JSON path.
      if (binding.field == nullptr || !binding.field->swept ||
          !HasPart(binding.field->group, bat, *spec, indices)) {
        return std::nullopt;
      }
      switch (binding.field->group) {
        case FieldGroup::kBall:
          binder.changes_.ball = true;
          break;
        case FieldGroup::kSwing:
          binder.changes_.swing = true;
          break;
        case FieldGroup::kCor:
          binder.changes_.cor = true;
          break;
        case FieldGroup::kContact:  // read by batted_ball only: nothing resolved changes
          break;
        case FieldGroup::kMaterial:
        case FieldGroup::kFillMaterial:
          binder.changes_.bat_materials = true;
          break;
        case FieldGroup::kShape:
          binder.shape_ = spec->three_segment;
          binder.changes_.bat_geometry = true;
          break;
        case FieldGroup::kKnot:
          binding.index = indices[0];
          binder.changes_.bat_geometry = true;
          break;
        case FieldGroup::kWall:
        case FieldGroup::kFill:
        case FieldGroup::kEndCap:  // not swept (fields.cpp): never reached
        case FieldGroup::kKnob:
        case FieldGroup::kHandle:
          binder.changes_.bat_geometry = true;
          break;
      }
      if (pattern.rfind("bat.", 0) == 0) binder.bat_swept_ = true;
      if (pattern.rfind("bat.material.", 0) == 0 || pattern.rfind("bat.fill.", 0) == 0) {
        binder.materials_swept_ = true;
      }
      binder.bindings_.push_back(binding);
    }
  }
  // The bat changes through its three-segment shape only: no knot, material, wall or fill.
  binder.only_shape_swept_ =
      binder.bat_swept_ &&
      std::all_of(binder.bindings_.begin(), binder.bindings_.end(), [](const Binding& b) {
        const FieldGroup g = b.field->group;
        return g == FieldGroup::kBall || g == FieldGroup::kSwing || g == FieldGroup::kCor ||
               g == FieldGroup::kShape;
      });
  // Bind gives such a bat the knots of a shape that passed ThreeSegmentShape::ValidateSize.
  binder.changes_.knots_of_valid_shape = binder.only_shape_swept_;
  if (!binder.bat_swept_) {
    // The bat is the template's in every design: its mass properties are computed once, by
    // the request's ParseBat when given (a bat the JSON path would refuse as too small leaves
    // them to each design).
    const core::MassProperties p =
        template_properties != nullptr
            ? template_properties->Of(binder.scene_.inertia_model)
            : core::ComputeMassProperties(*binder.scene_.bat, binder.scene_.inertia_model);
    if (ApiError e; CheckComputable(p, "bat", &e)) binder.scene_.mass_properties = p;
  }
  return binder;
}

bool DesignBinder::Bind(const std::vector<double>& values, core::Scene* scene) const {
  core::Bat& bat = *scene->bat;
  std::optional<core::ThreeSegmentShape> shape = shape_;
  FieldHost host = FieldHost::Of(scene, shape ? &*shape : nullptr);
  for (const Binding& b : bindings_) {
    host.knot = b.index;
    b.field->set(host, parameters_[b.parameter].TargetValue(b.target_index, values[b.parameter]));
  }
  // The JSON path's checks, in its order (ParseBatGeometry, then the scene's).
  if (shape) {
    if (!shape->ValidateSize(nullptr)) return false;
    shape->KnotsInto(&bat.knots);
  }
  // A scene output validates the scene itself (EvaluateScene, Bat::Validate among it); a
  // design it refuses is not feasible, and the engine gives it the JSON path's row.
  // The caps of the template's materials and fill hold unless one of their numbers is swept.
  // The knots of a shape within its caps are within theirs (ThreeSegmentShape::KnotsInto: x in
  // [0, L], radii r1 and r2).
  if (!scene->outputs.empty()) {
    return !bat_swept_ || only_shape_swept_ ||
           (materials_swept_ ? bat.ValidateCaps(nullptr) : bat.ValidateKnotCaps(nullptr));
  }
  if (bat_swept_ && !bat.ValidateSize(nullptr)) return false;
  core::Scene check = *scene;
  check.outputs = {core::SceneOutput::kMaxExitSpeed};
  return check.Validate(nullptr);
}

}  // namespace sweetspot::api
