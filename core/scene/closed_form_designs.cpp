#include "core/scene/closed_form_designs.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/scene/resolved_scene.hpp"

namespace sweetspot::core {

bool ClosedFormDesigns::Applies(const SceneOptions& options, const Scene& scene) {
  if (!scene.bat.has_value() || scene.outputs.empty()) return false;
  for (const SceneOutput o : scene.outputs) {
    if (o != SceneOutput::kMaxExitSpeed) return false;
  }
  if (options.method != SweetSpotMethod::kClosedForm || !options.Validate(nullptr)) return false;
  std::string reason;
  const CollisionModel model = ResolveExitModel(options.model, scene, &reason);
  if (model != CollisionModel::kRigidPivot && model != CollisionModel::kFreeBat) return false;
  if (scene.swing.bat_speed_mps.has_value()) return false;
  // ResolveScene's COR: the scene's, else the ball's law (not here), else the material's.
  return scene.cor.has_value() || !scene.ball.cor_law.has_value();
}

ClosedFormDesigns::ClosedFormDesigns(const SceneOptions& options, const Scene& scene,
                                     SceneChanges changes)
    : options_(options), changes_(changes) {
  std::string reason;
  model_ = ResolveExitModel(options.model, scene, &reason);
}

bool ClosedFormDesigns::Evaluate(const Scene& scene, ClosedFormDesign* out) {
  // What EvaluateScene checks and computes for such a scene (ResolveScene, then the closed
  // form), in its order; anything else is left to it.
  if (!scene.bat.has_value() || scene.swing.bat_speed_mps.has_value()) return false;
  const Bat& bat = *scene.bat;
  if (!validated_) {
    if (!scene.Validate(nullptr)) return false;
    validated_ = true;  // what no design changes is valid from now on
  } else {
    if (changes_.bat_materials) {
      if (!bat.Validate(nullptr)) return false;
    } else if (changes_.bat_geometry) {
      // A valid shape's knots pass their own checks: the same verdict without them.
      if (!(changes_.knots_of_valid_shape ? bat.ValidateGeometryOfShapeKnots(nullptr)
                                          : bat.ValidateGeometry(nullptr))) {
        return false;
      }
    }
    if (changes_.ball && !scene.ball.Validate(nullptr)) return false;
    if (changes_.swing && !scene.swing.Validate(nullptr)) return false;
    if (changes_.cor && !scene.ValidateCor(nullptr)) return false;
  }
  double cor = 0.0;
  if (scene.cor.has_value()) {
    cor = *scene.cor;
  } else if (!scene.ball.cor_law.has_value() && bat.material.cor.has_value()) {
    cor = *bat.material.cor;
  } else {
    return false;  // the ball's law, or no COR: EvaluateScene says which
  }
  MassProperties& mp = out->mass_properties;
  mp = scene.mass_properties.has_value()
           ? *scene.mass_properties
           : ComputeMassPropertiesOfValidBat(bat, scene.inertia_model);
  if (!(std::isfinite(mp.mass_kg) && mp.mass_kg > 0.0 && std::isfinite(mp.balance_point_m) &&
        std::isfinite(mp.moi_centroid_kg_m2) && mp.moi_centroid_kg_m2 > 0.0)) {
    return false;
  }
  const double length = bat.LengthM();
  out->length_m = length;
  const double h = scene.swing.hands_from_knob_m;
  if (!(h >= 0.0 && h <= length)) return false;
  for (const double x : options_.curve_positions_from_knob_m) {
    if (!(x >= 0.0 && x <= length)) return false;
  }
  // No bat speed: the resolved swing is the scene's (ResolveSwing).
  out->max_exit_speed = ClosedFormMaximumOnBat(
      ClosedFormProfileFor(model_, mp, scene.ball, scene.swing, cor), length);
  return true;
}

}  // namespace sweetspot::core
