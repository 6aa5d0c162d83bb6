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
#include "api/json_reader.hpp"
#include "api/memory_reserve.hpp"
#include "api/scene_json.hpp"
#include "api/trade_units.hpp"
#include "core/numerics/timing_book.hpp"

namespace sweetspot::api {

using Json = nlohmann::json;

enum class DesignBinder::Target {
  kBallMass,
  kBallRadius,
  kBallSpeed,
  kBallStiffness,
  kBallExponent,
  kSwingOmega,
  kSwingPivot,
  kSwingHands,
  kCor,
  kShapeLength,
  kShapeHandle,
  kShapeBarrel,
  kShapeTaperStart,
  kShapeTaperEnd,
  kKnotX,
  kKnotRadius,
  kDensity,
  kYoungs,
  kShear,
  kPoisson,
  kMaterialCor,
  kWall,
  kFillDiameter,
  kFillDepth,
};

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
  using T = Target;
  static const std::map<std::string_view, T> kScene = {
      {"ball.mass_kg", T::kBallMass},
      {"ball.radius_m", T::kBallRadius},
      {"ball.speed_mps", T::kBallSpeed},
      {"ball.stiffness_n_m_p", T::kBallStiffness},
      {"ball.stiffness_exponent", T::kBallExponent},
      {"swing.angular_speed_rad_s", T::kSwingOmega},
      {"swing.pivot_from_knob_m", T::kSwingPivot},
      {"swing.hands_from_knob_m", T::kSwingHands},
      {"cor", T::kCor},
      {"bat.wall_thickness_m", T::kWall}};
  static const std::map<std::string_view, T> kShape = {
      {"bat.three_segment.length_m", T::kShapeLength},
      {"bat.three_segment.handle_radius_m", T::kShapeHandle},
      {"bat.three_segment.barrel_radius_m", T::kShapeBarrel},
      {"bat.three_segment.taper_start_m", T::kShapeTaperStart},
      {"bat.three_segment.taper_end_m", T::kShapeTaperEnd}};
  static const std::map<std::string_view, T> kKnot = {
      {"bat.profile.knots[].x_m", T::kKnotX}, {"bat.profile.knots[].radius_m", T::kKnotRadius}};
  static const std::map<std::string_view, T> kMaterial = {
      {"bat.material.density_kg_m3", T::kDensity},
      {"bat.material.youngs_modulus_pa", T::kYoungs},
      {"bat.material.shear_modulus_pa", T::kShear},
      {"bat.material.poissons_ratio", T::kPoisson},
      {"bat.material.cor", T::kMaterialCor}};
  static const std::map<std::string_view, T> kFill = {{"bat.fill.diameter_m", T::kFillDiameter},
                                                      {"bat.fill.depth_m", T::kFillDepth}};
  binder.parameters_ = parameters;
  for (std::size_t k = 0; k < parameters.size(); ++k) {
    for (std::size_t t = 0; t < parameters[k].targets.size(); ++t) {
      std::vector<std::size_t> indices;
      const std::string pattern = StepPattern(parameters[k].targets[t], &indices);
      Binding binding{};
      binding.parameter = k;
      binding.target_index = t;
      if (const auto it = kScene.find(pattern); it != kScene.end()) {
        binding.target = it->second;
      } else if (const auto shape = kShape.find(pattern);
                 shape != kShape.end() && spec->three_segment) {
        binding.target = shape->second;
        binder.shape_ = spec->three_segment;
      } else if (const auto knot = kKnot.find(pattern);
                 knot != kKnot.end() && spec->shape_form == "profile" && indices.size() == 1 &&
                 indices[0] < spec->bat.knots.size()) {
        binding.target = knot->second;
        binding.index = indices[0];
      } else if (const auto material = kMaterial.find(pattern);
                 material != kMaterial.end() && IsObjectAt(bat, {"material"})) {
        binding.target = material->second;
      } else if (const auto fill = kFill.find(pattern);
                 fill != kFill.end() && IsObjectAt(bat, {"fill"}) && spec->bat.fill) {
        binding.target = fill->second;
      } else {
        return std::nullopt;  // not bound here: the JSON path
      }
      switch (binding.target) {
        case T::kBallMass:
        case T::kBallRadius:
        case T::kBallSpeed:
        case T::kBallStiffness:
        case T::kBallExponent:
          binder.changes_.ball = true;
          break;
        case T::kSwingOmega:
        case T::kSwingPivot:
        case T::kSwingHands:
          binder.changes_.swing = true;
          break;
        case T::kCor:
          binder.changes_.cor = true;
          break;
        case T::kDensity:
        case T::kYoungs:
        case T::kShear:
        case T::kPoisson:
        case T::kMaterialCor:
          binder.changes_.bat_materials = true;
          break;
        case T::kShapeLength:
        case T::kShapeHandle:
        case T::kShapeBarrel:
        case T::kShapeTaperStart:
        case T::kShapeTaperEnd:
        case T::kKnotX:
        case T::kKnotRadius:
        case T::kWall:
        case T::kFillDiameter:
        case T::kFillDepth:
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
      std::none_of(binder.bindings_.begin(), binder.bindings_.end(), [](const Binding& b) {
        switch (b.target) {
          case T::kKnotX:
          case T::kKnotRadius:
          case T::kDensity:
          case T::kYoungs:
          case T::kShear:
          case T::kPoisson:
          case T::kMaterialCor:
          case T::kWall:
          case T::kFillDiameter:
          case T::kFillDepth:
            return true;
          default:
            return false;
        }
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
  for (std::size_t k = 0; k < bindings_.size(); ++k) {
    const Binding& b = bindings_[k];
    const double v = parameters_[b.parameter].TargetValue(b.target_index, values[b.parameter]);
    switch (bindings_[k].target) {
      case Target::kBallMass:
        scene->ball.mass_kg = v;
        break;
      case Target::kBallRadius:
        scene->ball.radius_m = v;
        break;
      case Target::kBallSpeed:
        scene->ball.speed_mps = v;
        break;
      case Target::kBallStiffness:
        scene->ball.stiffness = v;
        break;
      case Target::kBallExponent:
        scene->ball.stiffness_exponent = v;
        break;
      case Target::kSwingOmega:
        scene->swing.angular_speed_rad_s = v;
        break;
      case Target::kSwingPivot:
        scene->swing.pivot_from_knob_m = v;
        break;
      case Target::kSwingHands:
        scene->swing.hands_from_knob_m = v;
        break;
      case Target::kCor:
        scene->cor = v;
        break;
      case Target::kShapeLength:
        shape->length_m = v;
        break;
      case Target::kShapeHandle:
        shape->handle_radius_m = v;
        break;
      case Target::kShapeBarrel:
        shape->barrel_radius_m = v;
        break;
      case Target::kShapeTaperStart:
        shape->taper_start_m = v;
        break;
      case Target::kShapeTaperEnd:
        shape->taper_end_m = v;
        break;
      case Target::kKnotX:
        bat.knots[bindings_[k].index].x_m = v;
        break;
      case Target::kKnotRadius:
        bat.knots[bindings_[k].index].radius_m = v;
        break;
      case Target::kDensity:
        bat.material.density_kg_m3 = v;
        break;
      case Target::kYoungs:
        bat.material.youngs_modulus_pa = v;
        break;
      case Target::kShear:
        bat.material.shear_modulus_pa = v;
        bat.material.poissons_ratio_assumed = false;  // given now: no "nu assumed" warning
        break;
      case Target::kPoisson:
        bat.material.poissons_ratio = v;
        bat.material.poissons_ratio_assumed = false;
        break;
      case Target::kMaterialCor:
        bat.material.cor = v;
        break;
      case Target::kWall:
        bat.wall_thickness_m = v;
        break;
      case Target::kFillDiameter:
        bat.fill->diameter_m = v;
        break;
      case Target::kFillDepth:
        bat.fill->depth_m = v;
        break;
    }
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
