// What every output of one request shares (the mass properties, the length, the COR): resolved
// once per request and passed down; and the only adapters from a resolved scene to each
// model's inputs.
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
#include "core/scene/scene.hpp"
#include "core/summary.hpp"

namespace sweetspot::core {

/// Where a resolved scene's COR came from (ResolvedScene::cor_source says the same as text).
enum class CorOrigin {
  kNone,      ///< No COR resolved (nothing wanted needs one).
  kScene,     ///< The request's `cor`.
  kBall,      ///< The ball's COR law at the impact speed.
  kBarrel,    ///< A hollow bat: the trampoline's effective COR from the ball's law.
  kMaterial,  ///< The bat material's COR.
};

/// A scene's shared quantities, computed once per request.
struct ResolvedScene {
  MassProperties mass_properties;  ///< The bat's (computed from `bat`, or the scene's own).
  double length_m = 0.0;           ///< The bat length, m.
  /// The scene's swing with its angular speed resolved (from bat_speed_mps when given): what
  /// every model adapter below uses.
  Swing swing;
  std::optional<double> cor;  ///< The COR; unset when nothing wanted needs one.
  /// "scene" (the request's `cor`), "ball:<preset>" (the ball's COR law), "barrel:<preset>" (a
  /// hollow bat: the trampoline's effective COR from the ball's law) or "material:<name>";
  /// "" when `cor` is unset.
  std::string cor_source;
  CorOrigin cor_origin = CorOrigin::kNone;  ///< cor_source as a value, to branch on.
  /// With cor_source "ball:...": the normal impact speed the ball's law was evaluated at, m/s.
  std::optional<double> cor_impact_speed_mps;
};

/// True when a scene without `cor` takes its COR from the ball's law (the ball has one, and the
/// bat is solid, absent, or has no material COR); false: the bat material's COR, as before.
bool BallCorApplies(const Scene& scene);

/// Validates `scene`, resolves its COR when `needs_cor`, computes (or takes) its mass properties
/// once (timed as "mass_properties" in *book when computed), checks the hands are on the bat and
/// resolves the swing (ResolveSwing: omega from a bat speed, now that the length is known).
/// The COR: the scene's `cor`; else, when BallCorApplies, the ball's law at the normal impact
/// speed ball.speed_mps + omega (x - pivot) at x = `cor_impact_from_knob_m` (clamped to the bat)
/// or, without it, kCorReferenceFromTipM from the tip; for a hollow bat that ball COR goes through
/// the barrel model (EffectiveCorAt, default BarrelOptions) at the same point and speed
/// ("barrel:<ball>"); else the bat material's. False with the
/// termination and message in *summary otherwise. Never throws.
/// `exit_model` is the model the answer's exit speeds come from (kAuto: ResolveExitModel's
/// choice): a swing given at its "sweet_spot" is solved at that model's closed-form maximum
/// (free_bat's for hertz and flexible, with a warning).
bool ResolveScene(const Scene& scene, bool needs_cor, TimingBook* book, ResolvedScene* resolved,
                  Summary* summary, std::optional<double> cor_impact_from_knob_m = std::nullopt,
                  CollisionModel exit_model = CollisionModel::kAuto);

/// `swing` resolved for a bat with `mass_properties`, `length_m` long, hit by `ball`, into
/// *resolved (`swing` must be valid). Without a bat speed: ResolveSwing. With one, v = the given
/// speed times SwingWeightSpeedFactor(MOI about the hands, reference, n) when speed_model is
/// kSwingWeight (else 1); then at bat_speed_point kFromTip ResolveSwing at v, and at kSweetSpot
/// the angular speed at which the max-exit-speed point of `point_model`'s closed form
/// (kRigidPivot or kFreeBat) moves at v: solved exactly (the quadratic in docs/models.md, "Bat
/// speed"; the COR does not move that point), or, when the maximum on the bat is an end of it,
/// v at that end. resolved->resolution says how; bat_speed_mps and bat_speed_from_tip_m become
/// this bat's speed and point. False with the refusal (ResolveSwing's, or the sweet spot's)
/// otherwise.
bool ResolveSceneSwing(const Ball& ball, const Swing& swing, const MassProperties& mass_properties,
                       double length_m, CollisionModel point_model, Swing* resolved,
                       Refusal* refusal);

/// The rigid-pivot inputs of a bat with `mass_properties` hit by `ball` in `swing` with `cor`.
RigidPivotInputs RigidPivotInputsFor(const MassProperties& mass_properties, const Ball& ball,
                                     const Swing& swing, double cor);
/// The exit-speed profile of a closed-form model (kFreeBat; anything else: kRigidPivot) for a
/// bat with `mass_properties` hit by `ball` in `swing` with `cor`.
ExitSpeedProfile ClosedFormProfileFor(CollisionModel model, const MassProperties& mass_properties,
                                      const Ball& ball, const Swing& swing, double cor);
/// The rigid-pivot inputs of a resolved scene (its COR must be resolved).
RigidPivotInputs RigidPivotInputsFor(const Scene& scene, const ResolvedScene& resolved);

/// The free-bat inputs of a bat with `mass_properties` hit by `ball` in `swing` with `cor`.
FreeBatInputs FreeBatInputsFor(const MassProperties& mass_properties, const Ball& ball,
                               const Swing& swing, double cor);
/// The free-bat inputs of a resolved scene (its COR must be resolved).
FreeBatInputs FreeBatInputsFor(const Scene& scene, const ResolvedScene& resolved);

/// The contact model's problem for an impact `impact_from_knob_m` m from the knob (the COR must
/// be resolved); notes on the bat surface are appended to *warnings (may be null).
HertzProblem HertzProblemFor(const Scene& scene, const ResolvedScene& resolved,
                             double impact_from_knob_m, const HertzOptions& options,
                             std::vector<std::string>* warnings);

/// The flexible impact's inputs for an impact `impact_from_knob_m` m from the knob (the COR must
/// be resolved); the bat surface's stiffness when hertz.bat_surface_compliance.
FlexibleImpactInputs FlexibleImpactInputsFor(const Scene& scene, const ResolvedScene& resolved,
                                             double impact_from_knob_m, const HertzOptions& hertz);

}  // namespace sweetspot::core
