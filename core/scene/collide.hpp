// Collide: one impact of a scene's ball on its bat under one collision model (or the cheapest
// adequate one). Value-in/value-out, never throws; the scene is resolved once
// (core/scene/resolved_scene.hpp) and handed to the model through its adapter.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/collision/flexible_impact.hpp"
#include "core/collision/free_bat.hpp"
#include "core/collision/hertz_contact.hpp"
#include "core/collision/rigid_pivot.hpp"
#include "core/numerics/timing_book.hpp"
#include "core/scene/batted_ball.hpp"
#include "core/scene/scene.hpp"
#include "core/summary.hpp"

namespace sweetspot::core {

/// Options of Collide.
struct CollisionOptions {
  bool want_contact_details = false;  ///< kAuto: contact time / peak force wanted (selects hertz).
  HertzOptions hertz;                 ///< Contact-model settings (the flexible model uses its
                                      ///< bat_surface_compliance too).
  FlexibleOptions flexible;           ///< Flexible-beam settings (model = kFlexible).
  /// Also the batted ball at the impact point (CollisionResult::batted_ball): the oblique impact
  /// with the scene's contact.undercut_m, its normal part by the model that ran, then the flight
  /// with the scene's environment and aero (core/scene/batted_ball.hpp).
  bool want_batted_ball = false;

  /// True when every field is in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// The answer of Collide.
struct CollisionResult {
  Summary summary;            ///< termination, message, backend, models_used, time.
  std::string missing_model;  ///< Set when refused for a missing model.
  CollisionModel model = CollisionModel::kRigidPivot;  ///< The model that ran.
  std::string model_reason;                            ///< Why (auto) or "requested".
  double impact_from_knob_m = 0.0;                     ///< m from the knob.
  double approach_speed_mps = 0.0;                     ///< u + bat speed at the impact point, m/s.
  double exit_speed_mps = 0.0;                         ///< m/s, positive away from the bat.
  double error_estimate_mps = 0.0;                     ///< Estimated error of the exit speed, m/s.
  double cor = 0.0;                                    ///< The COR used.
  std::string cor_source;  ///< "scene", "ball:<preset>" or "material:<name>" (ResolvedScene).
  /// With cor_source "ball:...": this impact's normal speed the ball's law was evaluated at, m/s.
  std::optional<double> cor_impact_speed_mps;
  MassProperties mass_properties;  ///< The properties used (when refused: as computed, or zero).
  /// The swing used, its angular speed resolved (from bat_speed_mps when given).
  Swing swing;
  std::optional<RigidPivotImpact> rigid_pivot;   ///< Details when model = rigid_pivot.
  std::optional<FreeBatImpact> free_bat;         ///< Details when model = free_bat.
  std::optional<HertzImpact> hertz;              ///< Details when model = hertz.
  std::optional<FlexibleImpactResult> flexible;  ///< Details when model = flexible.
  /// With CollisionOptions::want_batted_ball, when the impact ran: the batted ball.
  std::optional<BattedBallResult> batted_ball;
  bool modes_cache_hit = false;      ///< model = flexible: the modes came from the cache.
  std::vector<ModelTiming> timings;  ///< Time per model.
};

/// One impact at `impact_from_knob_m` with `model`. Never throws.
CollisionResult Collide(const Scene& scene, double impact_from_knob_m, CollisionModel model,
                        const CollisionOptions& options = {});

}  // namespace sweetspot::core
