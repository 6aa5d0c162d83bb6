// A sweep's lean path through the closed-form rigid models: for designs whose only scene output
// is max_exit_speed under rigid_pivot or free_bat (closed form), the numbers EvaluateScene
// gives (the mass properties, the length, the closed-form sweet spot) without its result's
// strings, vectors, summary and timings, and with the scene validated in full only once: after
// that, only the parts a sweep changes are checked again. A design it cannot vouch for is left
// to EvaluateScene (Evaluate returns false), so its answer, an error among them, is the one a
// single request gets.
#pragma once

#include "core/bat/mass_properties.hpp"
#include "core/scene/scene.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {

/// Which parts of a scene a sweep's designs change (the checks Evaluate runs again per design).
struct SceneChanges {
  bool bat_geometry = false;  ///< Knots, shape, wall or fill size: Bat::ValidateGeometry.
  /// With bat_geometry: the bat changes only through its knots, in every design those of a
  /// ThreeSegmentShape that passes Validate (KnotsInto): Bat::ValidateGeometryOfShapeKnots.
  bool knots_of_valid_shape = false;
  bool bat_materials = false;  ///< A number of the bat's or the fill's material: Bat::Validate.
  bool ball = false;           ///< A ball field: Ball::Validate.
  bool swing = false;          ///< A swing field: Swing::Validate.
  bool cor = false;            ///< The scene's cor: its range.
};

/// The numbers of EvaluateScene's result that a design's row reads.
struct ClosedFormDesign {
  MassProperties mass_properties;    ///< As SceneResult::mass_properties.
  double length_m = 0.0;             ///< As SceneResult::length_m.
  ClosedFormMaximum max_exit_speed;  ///< The numbers of SceneResult::max_exit_speed.
};

/// Evaluates a sweep's designs on the lean path. Not thread-safe: one per thread (it remembers
/// whether it has validated a whole scene).
class ClosedFormDesigns {
 public:
  /// True when designs like `scene` (its bat and outputs; `options` valid) go the lean path:
  /// a bat, outputs max_exit_speed only (duplicates allowed), method closed_form with an
  /// exit-speed model resolving to rigid_pivot or free_bat, no swing.bat_speed_mps, and the COR
  /// from the scene or the bat's material (not a ball's COR law).
  static bool Applies(const SceneOptions& options, const Scene& scene);
  /// For designs of `scene`'s kind (Applies) under `options` that differ from one another only
  /// in the parts `changes` names. `options` must outlive this object.
  ClosedFormDesigns(const SceneOptions& options, const Scene& scene, SceneChanges changes);
  /// The exit-speed model the designs use (rigid_pivot or free_bat).
  CollisionModel model() const { return model_; }
  /// True, with *out set, when EvaluateScene(scene, options) gives a usable result whose numbers
  /// are *out's, bit for bit; false when it may not (then evaluate the design in full). The
  /// first scene that passes is validated in full; later ones only in their changing parts.
  bool Evaluate(const Scene& scene, ClosedFormDesign* out);

 private:
  const SceneOptions& options_;
  SceneChanges changes_;
  CollisionModel model_ = CollisionModel::kRigidPivot;
  bool validated_ = false;  // a scene of this sweep passed Scene::Validate
};

}  // namespace sweetspot::core
