// The sweep's binder: a swept parameter (SweepParameter) and DesignBinder, which sets a design's
// swept values on the template's resolved scene without JSON (ball, swing, cor, the
// three-segment shape, profile knots, material, wall and fill numbers).
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "api/explore/columns.hpp"
#include "api/json_path.hpp"
#include "api/limits.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/scene/closed_form_designs.hpp"
#include "core/scene/scene.hpp"

namespace sweetspot::api {

struct Field;

/// A swept parameter: its path as written, its steps from the template root.
struct SweepParameter {
  /// Its name in rows ("parameters.<name>"): "path" as written ("three_segment.taper_start_m"),
  /// or for linked fields "name" (default: the paths joined with "+").
  std::string path;
  std::vector<PathStep> steps;  ///< The first field, from the template root ("bat", ...).
  /// Every field the value sets ("paths": all set to the value; "scale_paths": each the
  /// template's value times the swept value), in order; one for "path".
  std::vector<std::vector<PathStep>> targets;
  /// For "scale_paths": the template's value of each target (the value multiplies them).
  std::vector<double> scale_bases;
  /// Per target, the factor from the swept value to the target's SI field: 1, or for a path
  /// written in a trade unit ("ball.speed_mph", whose target is "ball.speed_mps") its TradeForm's
  /// (0.44704). Not used by "scale_paths" (the value is a ratio).
  std::vector<double> to_si;
  bool scale = false;  ///< True for "scale_paths".

  /// The value of target `t` in a design whose swept value is `value`.
  double TargetValue(std::size_t t, double value) const {
    if (scale) return scale_bases[t] * value;
    return t < to_si.size() ? value * to_si[t] : value;
  }
};

/// Sets a design's swept values on the template's scene without JSON. Made once per sweep.
class DesignBinder {
 public:
  /// The binder of `parameters` on `base` (the template: bat and scene fields), or nullopt
  /// when a path is not one it binds (the sweep then runs on the JSON path).
  /// `template_properties`: the template bat's mass properties as the request's ParseBat
  /// computed them (BatSpec::properties), used when no parameter changes the bat; null:
  /// computed here.
  static std::optional<DesignBinder> Compile(
      const nlohmann::json& base, const std::vector<SweepParameter>& parameters,
      const RowOutputs& outputs, const ApiLimits& limits,
      const core::MassPropertiesOfBothModels* template_properties = nullptr);
  /// The template's scene (outputs set; mass properties preset when no parameter changes the
  /// bat): a worker's starting scene, which Bind then changes in place.
  const core::Scene& base_scene() const { return scene_; }
  /// Sets `values` (one per parameter) on *scene (base_scene() or a scene Bind has bound
  /// before). True when the design passes every check the JSON path makes; false when it
  /// does not (its row is then the JSON path's).
  bool Bind(const std::vector<double>& values, core::Scene* scene) const;
  /// The parts of the scene Bind changes (the checks the lean path runs again per design).
  const core::SceneChanges& changes() const { return changes_; }

 private:
  struct Binding {
    const Field* field = nullptr;  // its row of the table of fields (api/fields.hpp)
    std::size_t index = 0;         // a knot's
    std::size_t parameter = 0;     // whose value it takes
    std::size_t target_index = 0;  // which of that parameter's targets (SweepParameter)
  };
  std::vector<SweepParameter> parameters_;  // the values' meaning (linked and scaled paths)
  std::vector<Binding> bindings_;
  core::Scene scene_;
  std::optional<core::ThreeSegmentShape> shape_;  // the template's, when one is swept
  bool bat_swept_ = false;                        // some parameter changes the bat
  bool materials_swept_ = false;   // some parameter is a number of the material or the fill
  bool only_shape_swept_ = false;  // the bat is swept only through its three-segment shape
  core::SceneChanges changes_;     // which parts of the scene the bindings change
};

}  // namespace sweetspot::api
