#include "api/explore_engine.hpp"

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
#include "core/scene/timing_book.hpp"

namespace sweetspot::api {

using Json = nlohmann::json;

// ---- DesignBinder ---------------------------------------------------------------------------

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

// ---- Direct columns -------------------------------------------------------------------------

namespace {

// A value a column reads from a design's outcome without a JSON row.
struct DirectValue {
  enum Kind { kMissing, kNumber, kUnsigned, kBool, kString } kind = kMissing;
  double number = 0.0;
  std::uint64_t count = 0;
  bool flag = false;
  std::string_view text;
};

// Where a direct column's value comes from.
enum class Source {
  kIndex,
  kFeasible,
  kParameter,
  kMissing,
  kCollisionEfficiency,
  kMaxPosition,
  kMaxSpeed,
  kMaxUnconstrained,
  kMaxPlacement,
  kMaxModel,
  kMaxMethod,
  kCopPosition,
  kCopHands,
  kCopMoiHands,
  kCopPlacement,
  kMass,
  kBalance,
  kMoiKnob,
  kMoiSixInch,
  kMoiCentroid,
  kVolume,
  kLength,
  kInertiaModel,
  kLengthIn,
  kWeightOz,
  kDrop,
  kBalanceIn,
  kMoiKnobOzIn2,
  kMoiSixInchOzIn2,
  kMoiCentroidOzIn2,
};

// How a direct value is turned into the trade-unit field a column names (ImperialSources).
enum class DirectConvert {
  kNone,     // the value as it is
  kDivide,   // value / factor ("exit_speed_mph")
  kFromTip,  // (bat length - value) / inch ("position_from_tip_in")
};

struct DirectAccessor {
  Source source = Source::kMissing;
  std::size_t parameter = 0;
  DirectConvert convert = DirectConvert::kNone;
  double factor = 1.0;  // kDivide's divisor
};

std::optional<DirectAccessor> CompileSiAccessor(const std::vector<std::string>& tokens,
                                                const std::vector<SweepParameter>& parameters,
                                                const RowOutputs& outputs);

bool IsNumberSource(Source s) {
  switch (s) {
    case Source::kIndex:
    case Source::kFeasible:
    case Source::kParameter:
    case Source::kMissing:
    case Source::kMaxPlacement:
    case Source::kMaxModel:
    case Source::kMaxMethod:
    case Source::kCopPlacement:
    case Source::kInertiaModel:
      return false;
    default:
      return true;
  }
}

// The accessor of `tokens` in a feasible row of this sweep, or nullopt when the engine does
// not read it directly (the row is then rendered as JSON). A field of an output block may be
// named in a trade unit, as "report_units": "imperial" adds it (AddImperialToRow): its SI
// field's accessor with the conversion AddImperial makes, so the number is the same bits.
std::optional<DirectAccessor> CompileAccessor(const std::vector<std::string>& tokens,
                                              const std::vector<SweepParameter>& parameters,
                                              const RowOutputs& outputs) {
  if (auto native = CompileSiAccessor(tokens, parameters, outputs)) return native;
  if (tokens.size() < 2 || tokens[0] == "parameters" || tokens[0] == "error") return std::nullopt;
  for (const ImperialSource& source : ImperialSources(tokens.back())) {
    std::vector<std::string> si = tokens;
    si.back() = source.si_key;
    auto accessor = CompileSiAccessor(si, parameters, outputs);
    if (!accessor || !IsNumberSource(accessor->source)) continue;
    accessor->convert = source.from_tip ? DirectConvert::kFromTip : DirectConvert::kDivide;
    accessor->factor = source.to_si;
    return accessor;
  }
  return std::nullopt;
}

// The accessor of SI (or native) field `tokens` in a feasible row of this sweep, or nullopt.
// The names are those RenderDesignRow renders (SceneResultToJson, PropertiesToJson):
// explore_engine_test checks every one of them against the JSON row.
std::optional<DirectAccessor> CompileSiAccessor(const std::vector<std::string>& tokens,
                                                const std::vector<SweepParameter>& parameters,
                                                const RowOutputs& outputs) {
  using S = Source;
  const auto has = [&outputs](core::SceneOutput o) {
    return std::find(outputs.scene.begin(), outputs.scene.end(), o) != outputs.scene.end();
  };
  const auto field = [&tokens](const std::map<std::string_view, S>& table) -> std::optional<S> {
    if (tokens.size() != 2) return std::nullopt;
    const auto it = table.find(tokens[1]);
    if (it == table.end()) return std::nullopt;
    return it->second;
  };
  if (tokens.empty()) return std::nullopt;
  const std::string& head = tokens[0];
  std::optional<S> source;
  if (tokens.size() == 1 && head == "index") {
    source = S::kIndex;
  } else if (tokens.size() == 1 && head == "feasible") {
    source = S::kFeasible;
  } else if (tokens.size() == 2 && head == "parameters") {
    for (std::size_t k = 0; k < parameters.size(); ++k) {
      if (parameters[k].path == tokens[1]) return DirectAccessor{S::kParameter, k};
    }
  } else if (head == "error") {
    source = S::kMissing;  // a feasible row has no error
  } else if (tokens.size() == 1 && head == "collision_efficiency" && outputs.collision_efficiency) {
    source = S::kCollisionEfficiency;
  } else if (head == "max_exit_speed" && has(core::SceneOutput::kMaxExitSpeed)) {
    source = field({{"position_from_knob_m", S::kMaxPosition},
                    {"exit_speed_mps", S::kMaxSpeed},
                    {"unconstrained_position_from_knob_m", S::kMaxUnconstrained},
                    {"placement", S::kMaxPlacement},
                    {"model", S::kMaxModel},
                    {"method", S::kMaxMethod}});
  } else if (head == "center_of_percussion" && has(core::SceneOutput::kCenterOfPercussion)) {
    source = field({{"position_from_knob_m", S::kCopPosition},
                    {"hands_from_knob_m", S::kCopHands},
                    {"moi_hands_kg_m2", S::kCopMoiHands},
                    {"placement", S::kCopPlacement}});
  } else if (head == "properties" && outputs.properties) {
    if (tokens.size() == 3 && tokens[1] == "imperial") {
      static const std::map<std::string_view, S> kImperial = {
          {"length_in", S::kLengthIn},
          {"weight_oz", S::kWeightOz},
          {"drop", S::kDrop},
          {"balance_point_in", S::kBalanceIn},
          {"moi_knob_oz_in2", S::kMoiKnobOzIn2},
          {"moi_six_inch_oz_in2", S::kMoiSixInchOzIn2},
          {"moi_centroid_oz_in2", S::kMoiCentroidOzIn2}};
      if (const auto it = kImperial.find(tokens[2]); it != kImperial.end()) source = it->second;
    } else {
      source = field({{"mass_kg", S::kMass},
                      {"balance_point_m", S::kBalance},
                      {"moi_knob_kg_m2", S::kMoiKnob},
                      {"moi_six_inch_kg_m2", S::kMoiSixInch},
                      {"moi_centroid_kg_m2", S::kMoiCentroid},
                      {"volume_m3", S::kVolume},
                      {"length_m", S::kLength},
                      {"inertia_model", S::kInertiaModel}});
    }
  }
  if (!source) return std::nullopt;
  return DirectAccessor{*source, 0};
}

DirectValue Number(double v) {
  DirectValue d;
  d.kind = DirectValue::kNumber;
  d.number = v;
  return d;
}

DirectValue Text(std::string_view v) {
  DirectValue d;
  d.kind = DirectValue::kString;
  d.text = v;
  return d;
}

// What a direct column reads of a feasible design: a DesignOutcome's result, or the lean
// path's numbers (core::ClosedFormDesign), the same fields under the same names.
struct DirectView {
  const core::MassProperties* properties = nullptr;
  double length_m = 0.0;
  const std::optional<double>* collision_efficiency = nullptr;  // null: none
  bool has_max = false;                                         // max_exit_speed was computed
  double max_position = 0.0, max_speed = 0.0, max_unconstrained = 0.0;
  core::Placement max_placement = core::Placement::kOnBat;
  std::string_view max_model, max_method;
  const core::CenterOfPercussionResult* cop = nullptr;  // null: none
};

DirectView ViewOf(const DesignOutcome& o) {
  const core::SceneResult& r = o.result;
  DirectView v;
  v.properties = &r.mass_properties;
  v.length_m = r.length_m;
  v.collision_efficiency = &o.collision_efficiency;
  if (r.max_exit_speed) {
    const core::MaxExitSpeedResult& m = *r.max_exit_speed;
    v.has_max = true;
    v.max_position = m.position_from_knob_m;
    v.max_speed = m.exit_speed_mps;
    v.max_unconstrained = m.unconstrained_position_from_knob_m;
    v.max_placement = m.placement;
    v.max_model = m.model;
    v.max_method = m.method;
  }
  if (r.center_of_percussion) v.cop = &*r.center_of_percussion;
  return v;
}

// The lean path's design: max_exit_speed by the closed form of the model named `model_name`.
DirectView ViewOf(const core::ClosedFormDesign& d, std::string_view model_name) {
  DirectView v;
  v.properties = &d.mass_properties;
  v.length_m = d.length_m;
  v.has_max = true;
  v.max_position = d.max_exit_speed.position_from_knob_m;
  v.max_speed = d.max_exit_speed.exit_speed_mps;
  v.max_unconstrained = d.max_exit_speed.unconstrained_position_from_knob_m;
  v.max_placement = d.max_exit_speed.placement;
  v.max_model = model_name;
  v.max_method = "closed_form";  // ClosedFormMaxExitSpeed's
  return v;
}

DirectValue ReadSiDirect(const DirectAccessor& a, std::uint64_t index,
                         const std::vector<double>& values, const DirectView& o,
                         const core::ImperialProperties& imperial);

// The value of `a` in the feasible row of design `index`.
DirectValue ReadDirect(const DirectAccessor& a, std::uint64_t index,
                       const std::vector<double>& values, const DirectView& o,
                       const core::ImperialProperties& imperial) {
  DirectValue d = ReadSiDirect(a, index, values, o, imperial);
  if (a.convert == DirectConvert::kNone || d.kind != DirectValue::kNumber) return d;
  // As AddImperial computes it (api/trade_units.cpp), operation for operation.
  d.number = a.convert == DirectConvert::kDivide ? d.number / a.factor
                                                 : (o.length_m - d.number) / a.factor;
  return d;
}

// The value of `a`'s SI field in the feasible row of design `index`.
DirectValue ReadSiDirect(const DirectAccessor& a, std::uint64_t index,
                         const std::vector<double>& values, const DirectView& o,
                         const core::ImperialProperties& imperial) {
  using S = Source;
  const core::MassProperties& p = *o.properties;
  const bool m = o.has_max;
  const core::CenterOfPercussionResult* c = o.cop;
  switch (a.source) {
    case S::kIndex: {
      DirectValue d;
      d.kind = DirectValue::kUnsigned;
      d.count = index;
      return d;
    }
    case S::kFeasible: {
      DirectValue d;
      d.kind = DirectValue::kBool;
      d.flag = true;
      return d;
    }
    case S::kParameter:
      return Number(values[a.parameter]);
    case S::kMissing:
      return {};
    case S::kCollisionEfficiency:
      return o.collision_efficiency != nullptr && o.collision_efficiency->has_value()
                 ? Number(**o.collision_efficiency)
                 : DirectValue{};
    case S::kMaxPosition:
      return m ? Number(o.max_position) : DirectValue{};
    case S::kMaxSpeed:
      return m ? Number(o.max_speed) : DirectValue{};
    case S::kMaxUnconstrained:
      return m ? Number(o.max_unconstrained) : DirectValue{};
    case S::kMaxPlacement:
      return m ? Text(core::PlacementName(o.max_placement)) : DirectValue{};
    case S::kMaxModel:
      return m ? Text(o.max_model) : DirectValue{};
    case S::kMaxMethod:
      return m ? Text(o.max_method) : DirectValue{};
    case S::kCopPosition:
      return c ? Number(c->position_from_knob_m) : DirectValue{};
    case S::kCopHands:
      return c ? Number(c->hands_from_knob_m) : DirectValue{};
    case S::kCopMoiHands:
      return c ? Number(c->moi_hands_kg_m2) : DirectValue{};
    case S::kCopPlacement:
      return c ? Text(core::PlacementName(c->placement)) : DirectValue{};
    case S::kMass:
      return Number(p.mass_kg);
    case S::kBalance:
      return Number(p.balance_point_m);
    case S::kMoiKnob:
      return Number(p.moi_knob_kg_m2);
    case S::kMoiSixInch:
      return Number(p.MoiSixInchKgM2());
    case S::kMoiCentroid:
      return Number(p.moi_centroid_kg_m2);
    case S::kVolume:
      return Number(p.volume_m3);
    case S::kLength:
      return Number(o.length_m);
    case S::kInertiaModel:
      return Text(InertiaModelName(p.inertia_model));
    case S::kLengthIn:
      return Number(imperial.length_in);
    case S::kWeightOz:
      return Number(imperial.weight_oz);
    case S::kDrop:
      return Number(imperial.drop);
    case S::kBalanceIn:
      return Number(imperial.balance_point_in);
    case S::kMoiKnobOzIn2:
      return Number(imperial.moi_knob_oz_in2);
    case S::kMoiSixInchOzIn2:
      return Number(imperial.moi_six_inch_oz_in2);
    case S::kMoiCentroidOzIn2:
      return Number(imperial.moi_centroid_oz_in2);
  }
  return {};
}

bool NeedsImperial(const std::vector<DirectAccessor>& accessors) {
  return std::any_of(accessors.begin(), accessors.end(), [](const DirectAccessor& a) {
    return a.source >= Source::kLengthIn && a.source <= Source::kMoiCentroidOzIn2;
  });
}

Json ToJson(const DirectValue& v) {
  switch (v.kind) {
    case DirectValue::kMissing:
      return nullptr;
    case DirectValue::kNumber:
      return v.number;
    case DirectValue::kUnsigned:
      return v.count;
    case DirectValue::kBool:
      return v.flag;
    case DirectValue::kString:
      return std::string(v.text);
  }
  return nullptr;
}

double ToObjective(const DirectValue& v) {
  if (v.kind == DirectValue::kNumber) return v.number;
  if (v.kind == DirectValue::kUnsigned) return static_cast<double>(v.count);
  return std::nan("");
}

void WriteCsv(const DirectValue& v, CsvRowWriter* writer) {
  switch (v.kind) {
    case DirectValue::kMissing:
      writer->Empty();
      break;
    case DirectValue::kNumber:
      writer->Number(v.number);
      break;
    case DirectValue::kUnsigned:
      writer->Unsigned(v.count);
      break;
    case DirectValue::kBool:
      writer->Bool(v.flag);
      break;
    case DirectValue::kString:
      writer->String(v.text);
      break;
  }
}

std::string DumpRow(const Json& value) {
  return value.dump(-1, ' ', false, Json::error_handler_t::replace);
}

// The JSON text of the last number or string one column wrote, reused while the value stays
// the same: a grid's slower parameters keep their value for many rows.
struct JsonValueMemo {
  DirectValue::Kind kind = DirectValue::kMissing;  // kMissing: nothing remembered
  std::uint64_t bits = 0;                          // kNumber: the number's bits
  std::string source;                              // kString: the string
  std::string text;                                // kString: its JSON text
  std::array<char, 64> number;                     // kNumber: its JSON text, number_size long
  std::size_t number_size = 0;
};

// Appends `v` as the serializer of DumpRow writes it (nlohmann's: its shortest round-trip text
// of a double, null for a missing value or a non-finite number, the string escaped).
void AppendJsonValue(const DirectValue& v, JsonValueMemo* memo, std::string* out) {
  switch (v.kind) {
    case DirectValue::kMissing:
      out->append("null");
      return;
    case DirectValue::kUnsigned: {
      char buffer[24];
      out->append(buffer, std::to_chars(buffer, buffer + sizeof(buffer), v.count).ptr);
      return;
    }
    case DirectValue::kBool:
      out->append(v.flag ? "true" : "false");
      return;
    case DirectValue::kNumber: {
      std::uint64_t bits = 0;
      std::memcpy(&bits, &v.number, sizeof bits);
      if (memo->kind != DirectValue::kNumber || memo->bits != bits) {
        memo->kind = DirectValue::kNumber;
        memo->bits = bits;
        char* const begin = memo->number.data();
        if (!std::isfinite(v.number)) {
          std::memcpy(begin, "null", 4);
          memo->number_size = 4;
        } else {
          // What basic_json's serializer calls for a double (dump_float), in its buffer size.
          const char* end =
              nlohmann::detail::to_chars(begin, begin + memo->number.size(), v.number);
          memo->number_size = static_cast<std::size_t>(end - begin);
        }
      }
      out->append(memo->number.data(), memo->number_size);
      return;
    }
    case DirectValue::kString:
      if (memo->kind != DirectValue::kString || memo->source != v.text) {
        memo->kind = DirectValue::kString;
        memo->source.assign(v.text);
        memo->text = DumpRow(Json(memo->source));
      }
      out->append(memo->text);
      return;
  }
}

// What one run of a sweep shares between its threads: the format, the compiled columns and
// objectives, the designs.
struct RunPlan {
  const Sweep* sweep = nullptr;
  std::uint64_t memory_failures = 0;  // MemoryFailures() when the run started
  RowFormat format = RowFormat::kJson;
  const std::vector<ExploreColumn>* columns = nullptr;
  std::vector<DirectAccessor> column_accessors;     // when `direct`
  std::vector<DirectAccessor> objective_accessors;  // when `direct`
  bool direct = false;  // feasible bound rows are written without a JSON row
  // Direct rows, and full rows filled in a worker's template, whose designs go the lean path
  // first (core::ClosedFormDesigns): the scene outputs only max_exit_speed by a closed form,
  // and no collision efficiency.
  bool lean = false;
  // kNdjson direct rows: the columns in the order of the JSON object's keys (sorted, each path
  // once), each with its key's text ("\"path\":").
  std::vector<std::pair<std::size_t, std::string>> ndjson_keys;
  bool imperial = false;    // some direct column reads the imperial properties
  bool row_twins = false;   // full rows carry the trade-unit fields (report_units imperial)
  bool json_twins = false;  // JSON rows get them before columns and objectives read them
  std::uint64_t in_shard = 0;

  // The design index of the shard's k-th design.
  std::uint64_t DesignIndex(std::uint64_t k) const {
    return sweep->shard.index + k * sweep->shard.count;
  }
};

// One block's rows and what the summary needs from them.
struct BlockResult {
  BlockRows rows;
  std::uint64_t failed = 0;
  // Feasible designs whose max_exit_speed lies beyond the tip / before the knob (clamped).
  std::uint64_t beyond_tip = 0, before_knob = 0;
  std::vector<std::vector<double>> objective_values;
  std::vector<std::uint64_t> indices;
  bool cancelled = false;  // stopped early: Progress::Cancel()
};

// A worker's reusable state.
struct Worker {
  std::optional<core::Scene> scene;             // the binder's scene, bound design after design
  std::optional<core::DesignSequence> designs;  // the sweep's, with this worker's position
  DesignOutcome outcome;  // the last bound design's, refilled design after design
  std::optional<core::SceneEvaluator> evaluator;  // the sweep's options, validated once
  // Full rows of bound designs: the first feasible row, kept as a template whose leaves are
  // overwritten design after design (no JSON tree built per row), when every leaf is a value
  // the engine reads directly.
  bool template_tried = false;
  std::optional<Json> row_template;
  std::vector<std::pair<Json*, DirectAccessor>> leaves;
  // The lean path (plan.lean): its evaluator and the last design's numbers.
  std::optional<core::ClosedFormDesigns> lean;
  core::ClosedFormDesign lean_design;
  std::string_view lean_model_name;       // core::CollisionModelName of lean's model
  std::vector<CsvNumberMemo> csv_memos;   // per CSV column: the text of its last number
  std::vector<JsonValueMemo> json_memos;  // per NDJSON column: the text of its last value
  // The template's NDJSON text cut at its leaves (CompileTemplateText): the text before each
  // leaf with the leaf's index in `leaves`, in the order DumpRow writes them, then the tail.
  std::vector<std::pair<std::string, std::size_t>> template_pieces;
  std::string template_tail;
  std::vector<JsonValueMemo> template_memos;  // per leaf: the text of its last value
};

// The text DumpRow gives `node` (part of a row template: objects and leaves), cut at each
// leaf: the text before the leaf and its index in `leaves` into *pieces; what follows the last
// leaf so far in *pending. False when a leaf is not one of `leaves`.
bool CompileTemplateText(const Json& node,
                         const std::vector<std::pair<Json*, DirectAccessor>>& leaves,
                         std::vector<std::pair<std::string, std::size_t>>* pieces,
                         std::string* pending) {
  if (node.is_object()) {
    pending->push_back('{');
    bool first = true;
    for (auto it = node.begin(); it != node.end(); ++it) {
      if (!first) pending->push_back(',');
      first = false;
      pending->append(DumpRow(Json(it.key())));
      pending->push_back(':');
      if (!CompileTemplateText(it.value(), leaves, pieces, pending)) return false;
    }
    pending->push_back('}');
    return true;
  }
  for (std::size_t k = 0; k < leaves.size(); ++k) {
    if (leaves[k].first == &node) {
      pieces->emplace_back(std::move(*pending), k);
      pending->clear();
      return true;
    }
  }
  return false;
}

// The leaves of `node` (at `tokens`) with their accessors into *leaves; false when one is not
// read directly (or is an array).
bool CollectLeaves(Json* node, std::vector<std::string>* tokens, const Sweep& sweep,
                   std::vector<std::pair<Json*, DirectAccessor>>* leaves) {
  if (node->is_array()) return false;
  if (node->is_object()) {
    for (auto it = node->begin(); it != node->end(); ++it) {
      tokens->push_back(it.key());
      const bool ok = CollectLeaves(&it.value(), tokens, sweep, leaves);
      tokens->pop_back();
      if (!ok) return false;
    }
    return true;
  }
  const auto accessor = CompileAccessor(*tokens, sweep.parameters, sweep.outputs);
  if (!accessor || accessor->source == Source::kMissing) return false;
  leaves->emplace_back(node, *accessor);
  return true;
}

// True when `value` is of the kind of the template's leaf `node` (so the leaf set to it dumps
// as a freshly rendered row would).
bool LeafTakes(const DirectValue& value, const Json& node) {
  switch (value.kind) {
    case DirectValue::kNumber:
      return node.is_number_float();
    case DirectValue::kUnsigned:
      return node.is_number_unsigned();
    case DirectValue::kBool:
      return node.is_boolean();
    case DirectValue::kString:
      return node.is_string();
    case DirectValue::kMissing:
      return false;
  }
  return false;
}

// Sets `value` on the template's leaf `node` when it is of the leaf's own kind (so the dump is
// the one of a freshly rendered row); false otherwise.
bool SetLeaf(const DirectValue& value, Json* node) {
  if (!LeafTakes(value, *node)) return false;
  switch (value.kind) {
    case DirectValue::kNumber:
      *node->get_ptr<double*>() = value.number;
      return true;
    case DirectValue::kUnsigned:
      *node->get_ptr<std::uint64_t*>() = value.count;
      return true;
    case DirectValue::kBool:
      *node->get_ptr<bool*>() = value.flag;
      return true;
    case DirectValue::kString:
      node->get_ptr<std::string*>()->assign(value.text);
      return true;
    case DirectValue::kMissing:
      return false;
  }
  return false;
}

// The row of design `i` from its JSON row (the JSON path, or a bound design whose columns are
// not all direct): the trade-unit fields added when the plan wants them (for a feasible row,
// `length_m` its bat's length; nullopt when they are there already), index and parameters
// added, objectives read, then written in the format.
void AddJsonRow(const RunPlan& plan, std::uint64_t i, const std::vector<double>& point, Json row,
                std::optional<double> length_m, BlockResult* out) {
  const Sweep& sweep = *plan.sweep;
  if (plan.json_twins && length_m) AddImperialToRow(&row, *length_m);
  Json values = Json::object();
  for (std::size_t k = 0; k < sweep.parameters.size(); ++k)
    values[sweep.parameters[k].path] = point[k];
  row["index"] = i;
  row["parameters"] = std::move(values);
  if (!row["feasible"].get<bool>()) ++out->failed;
  if (!sweep.objectives.empty()) {
    std::vector<double> v;
    for (const auto& objective : sweep.objectives) {
      const Json* value = FindAt(row, objective.tokens);
      v.push_back(value != nullptr && value->is_number() ? value->get<double>() : std::nan(""));
    }
    out->objective_values.push_back(std::move(v));
    out->indices.push_back(i);
  }
  const std::vector<ExploreColumn>& columns = *plan.columns;
  switch (plan.format) {
    case RowFormat::kCsv:
      AppendCsvRow(row, columns, &out->rows.text);
      break;
    case RowFormat::kNdjson:
      out->rows.text += DumpRow(columns.empty() ? row : ProjectRow(row, columns));
      out->rows.text += '\n';
      break;
    case RowFormat::kJson:
      out->rows.rows.push_back(columns.empty() ? std::move(row) : ProjectRow(row, columns));
      break;
  }
}

// The full row of feasible bound design `i` from the worker's template, its leaves set from
// `outcome`: the bytes of RenderDesignRow's row (explore_engine_test checks it). False, with
// nothing written, when a leaf's value is not of the template's kind (render it instead).
bool FillTemplate(const RunPlan& plan, std::uint64_t i, const std::vector<double>& point,
                  const DirectView& view, Worker* worker, BlockResult* out) {
  const Sweep& sweep = *plan.sweep;
  const core::ImperialProperties imperial = core::ToImperial(*view.properties, view.length_m);
  if (plan.format == RowFormat::kNdjson && sweep.objectives.empty() &&
      !worker->template_pieces.empty()) {
    // DumpRow's text of the template with its leaves set, written leaf by leaf.
    std::string& text = out->rows.text;
    const std::size_t start = text.size();
    worker->template_memos.resize(worker->leaves.size());
    for (const auto& [before, k] : worker->template_pieces) {
      text.append(before);
      const DirectValue value = ReadDirect(worker->leaves[k].second, i, point, view, imperial);
      if (!LeafTakes(value, *worker->leaves[k].first)) {
        text.resize(start);
        return false;
      }
      AppendJsonValue(value, &worker->template_memos[k], &text);
    }
    text.append(worker->template_tail);
    text.push_back('\n');
    return true;
  }
  for (auto& [node, accessor] : worker->leaves) {
    if (!SetLeaf(ReadDirect(accessor, i, point, view, imperial), node)) {
      // The template is left part-filled: the next design overwrites every leaf again.
      return false;
    }
  }
  const Json& row = *worker->row_template;
  if (!sweep.objectives.empty()) {
    std::vector<double> v;
    for (const auto& objective : sweep.objectives) {
      const Json* value = FindAt(row, objective.tokens);
      v.push_back(value != nullptr && value->is_number() ? value->get<double>() : std::nan(""));
    }
    out->objective_values.push_back(std::move(v));
    out->indices.push_back(i);
  }
  if (plan.format == RowFormat::kNdjson) {
    out->rows.text += DumpRow(row);
    out->rows.text += '\n';
  } else {
    out->rows.rows.push_back(row);
  }
  return true;
}

// The most characters of a direct CSV row written in a local buffer (WriteDirectRow), where a
// field has room for 32 characters and its separator.
constexpr std::size_t kCsvRowBytes = 512;
static_assert(sizeof(CsvNumberMemo::text) <= 32, "a number's text copied whole into its room");

// The CSV row of WriteDirectRow. Flattened: ReadDirect's switch and the value it returns,
// inlined, cost a row's two columns about as much as the calls did.
[[gnu::flatten]] void WriteDirectCsvRow(const RunPlan& plan, std::uint64_t i,
                                        const std::vector<double>& point, const DirectView& view,
                                        const core::ImperialProperties& imperial, Worker* worker,
                                        BlockResult* out) {
  const std::size_t n = plan.column_accessors.size();
  worker->csv_memos.resize(n);
  // The row in a local buffer, appended at once, when it fits: a field takes at most 32
  // characters and a separator unless it is a string (CsvRowWriter then writes the row).
  char row[kCsvRowBytes];
  std::size_t size = 0;
  bool local = n * 33 <= sizeof(row);
  for (std::size_t c = 0; local && c < n; ++c) {
    const DirectValue value = ReadDirect(plan.column_accessors[c], i, point, view, imperial);
    if (c > 0) row[size++] = ',';
    switch (value.kind) {
      case DirectValue::kMissing:
        break;
      case DirectValue::kNumber: {
        // The memo's whole buffer (a fixed-size copy; the field's room is 32 characters),
        // of which its text's characters count.
        CsvNumberMemo& memo = worker->csv_memos[c];
        const std::size_t length = CsvNumberText(value.number, &memo).size();
        std::memcpy(row + size, memo.text, sizeof(memo.text));
        size += length;
        break;
      }
      case DirectValue::kUnsigned:
        size = static_cast<std::size_t>(
            std::to_chars(row + size, row + size + 32, value.count).ptr - row);
        break;
      case DirectValue::kBool:
        std::memcpy(row + size, value.flag ? "true" : "false", value.flag ? 4 : 5);
        size += value.flag ? 4 : 5;
        break;
      case DirectValue::kString:
        local = false;
        break;
    }
  }
  if (local) {
    row[size++] = '\n';
    out->rows.text.append(row, size);
    return;
  }
  CsvRowWriter writer(&out->rows.text);
  for (std::size_t c = 0; c < n; ++c) {
    const DirectValue value = ReadDirect(plan.column_accessors[c], i, point, view, imperial);
    if (value.kind == DirectValue::kNumber) {
      writer.Number(value.number, &worker->csv_memos[c]);
    } else {
      WriteCsv(value, &writer);
    }
  }
  writer.EndRow();
}

// The row of feasible bound design `i` from its direct columns (plan.direct).
void WriteDirectRow(const RunPlan& plan, std::uint64_t i, const std::vector<double>& point,
                    const DirectView& view, Worker* worker, BlockResult* out) {
  const Sweep& sweep = *plan.sweep;
  const core::ImperialProperties imperial = plan.imperial
                                                ? core::ToImperial(*view.properties, view.length_m)
                                                : core::ImperialProperties{};
  if (!sweep.objectives.empty()) {
    std::vector<double> v;
    for (const DirectAccessor& a : plan.objective_accessors) {
      v.push_back(ToObjective(ReadDirect(a, i, point, view, imperial)));
    }
    out->objective_values.push_back(std::move(v));
    out->indices.push_back(i);
  }
  const std::vector<ExploreColumn>& columns = *plan.columns;
  if (plan.format == RowFormat::kCsv) {
    WriteDirectCsvRow(plan, i, point, view, imperial, worker, out);
    return;
  }
  if (plan.format == RowFormat::kNdjson) {
    // The text DumpRow gives the flat object below, written value by value.
    std::string& text = out->rows.text;
    worker->json_memos.resize(columns.size());
    text.push_back('{');
    bool first = true;
    for (const auto& [c, key] : plan.ndjson_keys) {
      if (!first) text.push_back(',');
      first = false;
      text.append(key);
      AppendJsonValue(ReadDirect(plan.column_accessors[c], i, point, view, imperial),
                      &worker->json_memos[c], &text);
    }
    text.append("}\n");
    return;
  }
  Json flat = Json::object();
  for (std::size_t c = 0; c < columns.size(); ++c) {
    flat[columns[c].path] = ToJson(ReadDirect(plan.column_accessors[c], i, point, view, imperial));
  }
  out->rows.rows.push_back(std::move(flat));
}

// Design `i` (the JSON path, or bound) into *out.
void EvaluateOne(const RunPlan& plan, std::uint64_t i, Worker* worker, BlockResult* out) {
  const Sweep& sweep = *plan.sweep;
  if (!worker->designs) worker->designs.emplace(*sweep.designs);
  const std::vector<double>& point = worker->designs->Design(i);
  if (sweep.binder) {
    if (!worker->scene) worker->scene = sweep.binder->base_scene();
    if (sweep.binder->Bind(point, &*worker->scene)) {
      // Full rows go the lean path once a full evaluation has made the worker's template.
      if (plan.lean && (plan.direct || worker->row_template)) {
        if (!worker->lean) {
          worker->lean.emplace(sweep.options, *worker->scene, sweep.binder->changes());
          worker->lean_model_name = core::CollisionModelName(worker->lean->model());
        }
        core::ClosedFormDesign& design = worker->lean_design;
        if (worker->lean->Evaluate(*worker->scene, &design)) {
          const DirectView view = ViewOf(design, worker->lean_model_name);
          bool written = true;
          if (plan.direct) {
            WriteDirectRow(plan, i, point, view, worker, out);
          } else {
            written = FillTemplate(plan, i, point, view, worker, out);
          }
          if (written) {
            const core::Placement at = design.max_exit_speed.placement;
            out->beyond_tip += at == core::Placement::kBeyondTip;
            out->before_knob += at == core::Placement::kBeforeKnob;
            return;
          }
        }
        // Not vouched for by the lean path (or not a row of the template): evaluated in full.
      }
      DesignOutcome& outcome = worker->outcome;
      if (!worker->evaluator) worker->evaluator.emplace(sweep.options);
      ComputeDesign(*worker->scene, sweep.outputs, &*worker->evaluator, &outcome);
      if (outcome.feasible && outcome.result.max_exit_speed) {
        const core::Placement at = outcome.result.max_exit_speed->placement;
        out->beyond_tip += at == core::Placement::kBeyondTip;
        out->before_knob += at == core::Placement::kBeforeKnob;
      }
      if (outcome.feasible && !plan.direct && plan.columns->empty() &&
          plan.format != RowFormat::kCsv) {
        if (worker->row_template && FillTemplate(plan, i, point, ViewOf(outcome), worker, out)) {
          return;
        }
        if (!worker->template_tried) {
          // The first feasible row: rendered, and kept as the template when it can be.
          worker->template_tried = true;
          Json row = RenderDesignRow(outcome, sweep.outputs);
          if (plan.json_twins) AddImperialToRow(&row, outcome.result.length_m);
          Json values = Json::object();
          for (std::size_t k = 0; k < sweep.parameters.size(); ++k) {
            values[sweep.parameters[k].path] = point[k];
          }
          row["index"] = i;
          row["parameters"] = std::move(values);
          std::vector<std::string> tokens;
          worker->row_template = row;
          if (!CollectLeaves(&*worker->row_template, &tokens, sweep, &worker->leaves)) {
            worker->row_template.reset();
            worker->leaves.clear();
          } else if (std::string tail; CompileTemplateText(*worker->row_template, worker->leaves,
                                                           &worker->template_pieces, &tail)) {
            worker->template_tail = std::move(tail);
          } else {
            worker->template_pieces.clear();
          }
          AddJsonRow(plan, i, point, std::move(row), std::nullopt, out);
          return;
        }
      }
      if (outcome.feasible && !plan.direct) {
        AddJsonRow(plan, i, point, RenderDesignRow(outcome, sweep.outputs), outcome.result.length_m,
                   out);
        return;
      }
      if (outcome.feasible) {
        WriteDirectRow(plan, i, point, ViewOf(outcome), worker, out);
        return;
      }
    }
    // A bound design that fails a check or a model: the JSON path says why, as a single
    // request would.
  }
  Json design = sweep.base;
  for (std::size_t k = 0; k < sweep.parameters.size(); ++k) {
    const SweepParameter& parameter = sweep.parameters[k];
    for (std::size_t t = 0; t < parameter.targets.size(); ++t) {
      SetNumberAtPath(&design, parameter.targets[t], parameter.TargetValue(t, point[k]), nullptr);
    }
  }
  DesignRow evaluated = EvaluateDesign(design, sweep.outputs, sweep.options, sweep.limits);
  const Json& row = evaluated.row;
  if (const Json* at = FindAt(row, {"max_exit_speed", "placement"}); at != nullptr) {
    out->beyond_tip += *at == core::PlacementName(core::Placement::kBeyondTip);
    out->before_knob += *at == core::PlacementName(core::Placement::kBeforeKnob);
  }
  AddJsonRow(plan, i, point, std::move(evaluated.row), evaluated.length_m, out);
}

// The most designs in a block, and the time a block aims at: blocks of fast designs are
// large (few hand-overs), those of slow ones short, so a streamed answer gets its first rows
// within about kBlockTargetS whatever a design costs.
constexpr std::uint64_t kMaxBlockDesigns = 256;
constexpr double kBlockTargetS = 0.01;
// A block's text stays under malloc's mmap threshold (128 KiB), so that its buffer is reused
// from the heap rather than mapped and faulted in anew each time.
constexpr double kBlockTargetBytes = 64 * 1024;

// What the last block measured per design (negative: nothing measured yet).
struct BlockCost {
  double seconds = -1.0;
  double bytes = -1.0;
};

// How many designs the next block takes (one before anything is measured).
std::uint64_t BlockDesigns(const BlockCost& cost) {
  if (!(cost.seconds >= 0.0)) return 1;
  double n = static_cast<double>(kMaxBlockDesigns);
  if (cost.seconds > 0.0) n = std::min(n, kBlockTargetS / cost.seconds);
  if (cost.bytes > 0.0) n = std::min(n, kBlockTargetBytes / cost.bytes);
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(n));
}

// The shard's designs [first, first + count) into *out; what a design cost in *cost.
void EvaluateBlock(const RunPlan& plan, std::uint64_t first, std::uint64_t count,
                   core::Progress* progress, Worker* worker, BlockResult* out, BlockCost* cost) {
  const auto start = std::chrono::steady_clock::now();
  if (plan.format != RowFormat::kJson && cost->bytes > 0.0) {
    out->rows.text.reserve(
        static_cast<std::size_t>(cost->bytes * static_cast<double>(count) * 1.25));
  }
  for (std::uint64_t k = first; k < first + count; ++k) {
    if (core::IsCancelled(progress)) {
      out->cancelled = true;
      return;
    }
    // An allocation failed since the run started and the memory reserve was spent on it
    // (api/memory_reserve.hpp): stop here, where unwinding has the reserve's memory, rather
    // than at an allocation inside the json code.
    if (MemoryFailures() != plan.memory_failures) throw std::bad_alloc();
    EvaluateOne(plan, plan.DesignIndex(k), worker, out);
    ++out->rows.count;
  }
  cost->seconds = core::SecondsSince(start) / static_cast<double>(count);
  cost->bytes = static_cast<double>(out->rows.text.size()) / static_cast<double>(count);
}

}  // namespace

// ---- RunSweep --------------------------------------------------------------------------------

SweepOutcome RunSweep(const Sweep& sweep, RowFormat format,
                      const std::vector<ExploreColumn>& columns, core::Progress* progress,
                      const std::function<bool(BlockRows&)>& emit) {
  SweepOutcome outcome;
  if (!RestoreMemoryReserve()) {
    // An earlier allocation failed and its reserve cannot be taken back yet: a sweep now could
    // fail where nothing is left to unwind with (api/memory_reserve.hpp).
    outcome.failed = true;
    outcome.message =
        "the server is low on memory (an allocation failed earlier and the memory "
        "it kept back cannot be taken again yet)";
    return outcome;
  }
  RunPlan plan;
  plan.memory_failures = MemoryFailures();
  plan.sweep = &sweep;
  plan.format = format;
  plan.columns = &columns;
  const core::Shard& shard = sweep.shard;
  const std::uint64_t total = sweep.total;
  plan.in_shard = total / shard.count + (shard.index < total % shard.count ? 1 : 0);
  // The trade-unit fields: in full rows with report_units imperial; in the JSON rows that
  // columns and objectives read when one of them names such a field (not in the SI row).
  plan.row_twins = sweep.imperial && columns.empty();
  plan.json_twins = plan.row_twins;
  if (!columns.empty()) {
    std::vector<std::string> parameter_paths;
    for (const SweepParameter& parameter : sweep.parameters)
      parameter_paths.push_back(parameter.path);
    const Json si_shape = RowShape(parameter_paths, sweep.outputs);
    for (const ExploreColumn& column : columns) {
      plan.json_twins = plan.json_twins || FindAt(si_shape, column.tokens) == nullptr;
    }
    for (const ParetoObjective& objective : sweep.objectives) {
      plan.json_twins = plan.json_twins || FindAt(si_shape, objective.tokens) == nullptr;
    }
  }
  // Direct rows: every column and objective is read from the outcome (a full row is JSON).
  if (sweep.binder && !columns.empty()) {
    plan.direct = true;
    for (const ExploreColumn& column : columns) {
      const auto a = CompileAccessor(column.tokens, sweep.parameters, sweep.outputs);
      if (!a) plan.direct = false;
      if (a) plan.column_accessors.push_back(*a);
    }
    for (const ParetoObjective& objective : sweep.objectives) {
      const auto a = CompileAccessor(objective.tokens, sweep.parameters, sweep.outputs);
      if (!a) plan.direct = false;
      if (a) plan.objective_accessors.push_back(*a);
    }
    plan.imperial = NeedsImperial(plan.column_accessors) || NeedsImperial(plan.objective_accessors);
  }
  if (plan.direct && format == RowFormat::kNdjson) {
    // A JSON object's keys are in std::map order, each once (the last value set wins; a path's
    // values are the same).
    std::vector<std::size_t> order(columns.size());
    for (std::size_t c = 0; c < order.size(); ++c) order[c] = c;
    std::stable_sort(order.begin(), order.end(), [&columns](std::size_t a, std::size_t b) {
      return columns[a].path < columns[b].path;
    });
    for (const std::size_t c : order) {
      if (!plan.ndjson_keys.empty() &&
          columns[plan.ndjson_keys.back().first].path == columns[c].path) {
        continue;
      }
      plan.ndjson_keys.emplace_back(c, DumpRow(Json(columns[c].path)) + ":");
    }
  }
  // The lean path reads no collision efficiency (the outputs do not ask for it) and no centre
  // of percussion (an output it does not take).
  plan.lean = (plan.direct || (sweep.binder && columns.empty() && format != RowFormat::kCsv)) &&
              !sweep.outputs.collision_efficiency &&
              core::ClosedFormDesigns::Applies(sweep.options, sweep.binder->base_scene());

  std::vector<std::vector<double>> objective_values;
  std::vector<std::uint64_t> indices;
  std::vector<core::Sense> senses;
  for (const auto& o : sweep.objectives) senses.push_back(o.sense);
  // The Pareto front kept as it grows: a design dominated by the designs so far is dominated
  // in the whole sweep, and a design on the whole front is on the front of any set holding it,
  // so the values are cut to their front whenever they have grown 8-fold since the last cut
  // (memory of the order of the front, not of the sweep; the same front, in design order). A
  // cut costs O(values x front), so cutting more often would cost more time than one cut at
  // the end.
  std::size_t cut_at = std::max<std::size_t>(1, sweep.pareto_cut_min);
  const auto cut_to_front = [&] {
    std::vector<std::vector<double>> kept_values;
    std::vector<std::uint64_t> kept_indices;
    for (const std::size_t k : core::ParetoFront(objective_values, senses)) {
      kept_values.push_back(std::move(objective_values[k]));
      kept_indices.push_back(indices[k]);
    }
    objective_values = std::move(kept_values);
    indices = std::move(kept_indices);
  };
  std::uint64_t evaluated = 0, failed = 0, beyond_tip = 0, before_knob = 0;
  // Takes a finished block: false when the sweep ends here (cancelled or stopped).
  const auto take = [&](BlockResult& block) {
    if (block.cancelled || core::IsCancelled(progress)) {
      outcome.cancelled = true;
      outcome.message = "the sweep was cancelled after " + std::to_string(evaluated) + " designs";
      return false;
    }
    failed += block.failed;
    beyond_tip += block.beyond_tip;
    before_knob += block.before_knob;
    for (auto& v : block.objective_values) objective_values.push_back(std::move(v));
    indices.insert(indices.end(), block.indices.begin(), block.indices.end());
    if (!senses.empty() && objective_values.size() >= cut_at) {
      cut_to_front();
      cut_at = std::max(sweep.pareto_cut_min, 8 * objective_values.size());
    }
    if (!emit(block.rows)) {
      outcome.stopped = true;
      return false;
    }
    evaluated += block.rows.count;
    if (progress != nullptr && plan.in_shard > 0) {
      progress->Report(static_cast<double>(evaluated) / static_cast<double>(plan.in_shard));
    }
    return true;
  };

  // Threads beyond this one come from the budget, without waiting for it.
  const std::uint64_t n = plan.in_shard;
  int helpers = static_cast<int>(std::min<std::uint64_t>(
      static_cast<std::uint64_t>(std::max(1, sweep.threads) - 1), n > 0 ? n - 1 : 0));
  if (helpers > 0 && sweep.budget != nullptr) helpers = sweep.budget->TryTake(helpers);
  // An exception (std::bad_alloc) in any thread of the sweep ends it as a failure: in a
  // helper std::thread it would otherwise reach std::terminate and end the process.
  const auto fail = [&](const std::exception_ptr& caught) {
    outcome = SweepOutcome{};
    outcome.failed = true;
    std::string what = "an unknown exception";
    try {
      std::rethrow_exception(caught);
    } catch (const std::bad_alloc&) {
      what = "out of memory (std::bad_alloc)";
    } catch (const std::system_error& e) {
      what = std::string("a system error (") + e.code().message() + ")";
    } catch (...) {
    }
    outcome.message = "the sweep failed after " + std::to_string(evaluated) + " designs: " + what;
    return outcome;
  };
  if (helpers <= 0) {
    try {
      Worker worker;
      BlockCost cost;
      for (std::uint64_t k = 0; k < n;) {
        BlockResult block;
        const std::uint64_t count = std::min(n - k, BlockDesigns(cost));
        EvaluateBlock(plan, k, count, progress, &worker, &block, &cost);
        k += count;
        if (!take(block)) return outcome;
      }
    } catch (...) {
      return fail(std::current_exception());
    }
  } else {
    // Workers (this thread among them) take the next designs as a block; this thread hands
    // the blocks on in design order. At most `window` blocks are finished or being evaluated
    // beyond the one handed on next.
    std::mutex mutex;
    std::condition_variable ready, room;
    std::map<std::uint64_t, BlockResult> done;  // by first design
    std::uint64_t next = 0;                     // the first design not taken yet
    std::uint64_t in_flight = 0;                // blocks being evaluated
    BlockCost cost;                             // what a design of the last block cost
    bool stop = false;
    std::exception_ptr failure;  // the first exception of any thread (then stop)
    const std::uint64_t window = 4 * static_cast<std::uint64_t>(helpers + 1);
    const auto has_room = [&] { return next < n && done.size() + in_flight < window; };
    // Takes the next block under the lock: [*first, *first + *count).
    const auto claim = [&](std::uint64_t* first, std::uint64_t* count) {
      *first = next;
      *count = std::min(n - next, BlockDesigns(cost));
      next += *count;
      ++in_flight;
    };
    // Evaluates a claimed block outside the lock, then files it under the lock.
    const auto evaluate = [&](std::unique_lock<std::mutex>& lock, std::uint64_t first,
                              std::uint64_t count, Worker* worker) {
      BlockResult block;
      BlockCost measured = cost;
      lock.unlock();
      EvaluateBlock(plan, first, count, progress, worker, &block, &measured);
      lock.lock();
      cost = measured;
      done.emplace(first, std::move(block));
      --in_flight;
    };
    // Records the first exception of any thread and stops every thread (`lock` may or may not
    // hold the mutex: an exception inside `evaluate` leaves it released).
    const auto record_failure = [&](std::unique_lock<std::mutex>& lock) {
      if (!lock.owns_lock()) lock.lock();
      if (!failure) failure = std::current_exception();
      stop = true;
      lock.unlock();
      ready.notify_all();
      room.notify_all();
    };
    const auto work = [&]() {
      std::unique_lock<std::mutex> lock(mutex, std::defer_lock);
      try {
        Worker worker;
        lock.lock();
        for (;;) {
          room.wait(lock, [&] { return stop || next >= n || has_room(); });
          if (stop || next >= n) return;
          std::uint64_t first = 0, count = 0;
          claim(&first, &count);
          evaluate(lock, first, count, &worker);
          ready.notify_all();
        }
      } catch (...) {
        record_failure(lock);
      }
    };
    std::vector<std::thread> threads;
    bool ok = true;
    try {
      threads.reserve(static_cast<std::size_t>(helpers));
      for (int t = 0; t < helpers; ++t) threads.emplace_back(work);
    } catch (...) {
      // A thread that could not start (std::system_error: no memory for its stack): the
      // threads that did start, and this one, do the work; the rest go back to the budget.
    }
    if (sweep.budget != nullptr) sweep.budget->Give(helpers - static_cast<int>(threads.size()));
    std::uint64_t handed = 0;  // the first design not handed on yet
    {
      std::unique_lock<std::mutex> lock(mutex, std::defer_lock);
      try {
        Worker own_worker;
        while (ok && handed < n) {
          BlockResult block;
          lock.lock();
          ready.wait(lock, [&] { return failure || done.count(handed) > 0 || has_room(); });
          if (failure) {
            lock.unlock();
            break;
          }
          if (done.count(handed) == 0) {
            // The next block is not finished and there is room: this thread evaluates one too.
            std::uint64_t first = 0, count = 0;
            claim(&first, &count);
            evaluate(lock, first, count, &own_worker);
            lock.unlock();
            continue;
          }
          block = std::move(done[handed]);
          done.erase(handed);
          // A cancelled block is short: what follows it is never handed on.
          handed += block.cancelled ? n : block.rows.count;
          lock.unlock();
          room.notify_all();
          ok = take(block);
        }
      } catch (...) {
        record_failure(lock);
      }
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      stop = true;
    }
    room.notify_all();
    for (std::thread& t : threads) t.join();
    if (sweep.budget != nullptr) sweep.budget->Give(static_cast<int>(threads.size()));
    if (failure) return fail(failure);
    if (!ok) return outcome;
  }

  Json summary{{"designs_total", total},
               {"designs_in_shard", evaluated},
               {"failed", failed},
               {"sampling", core::SamplingMethodName(sweep.plan.method)},
               {"seed", sweep.plan.seed},
               {"shard", {{"index", shard.index}, {"count", shard.count}}},
               {"timing_s", core::SecondsSince(sweep.start)}};
  if (!sweep.objectives.empty()) {
    cut_to_front();
    Json front = indices;
    summary["pareto_front"] = std::move(front);
    summary["pareto_objectives"] = ObjectivesToJson(sweep.objectives);  // for explore-merge
    summary["pareto_scope"] = "the rows of this response (this shard)";
  }
  if (std::any_of(sweep.outputs.scene.begin(), sweep.outputs.scene.end(), [](auto o) {
        return o == core::SceneOutput::kMaxExitSpeed || o == core::SceneOutput::kSweetZone ||
               o == core::SceneOutput::kExitSpeedCurve;
      })) {
    summary["exit_speed_model"] = sweep.exit_speed_model;
    summary["model_reason"] = sweep.model_reason;
  }
  AddEndPlacements(beyond_tip, before_knob, &summary);
  if (sweep.imperial) summary["report_units"] = "imperial";  // explore-merge keeps it
  summary["provenance"] = sweep.provenance;
  outcome.summary = std::move(summary);
  return outcome;
}

}  // namespace sweetspot::api
