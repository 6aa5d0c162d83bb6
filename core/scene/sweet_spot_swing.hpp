// A swing given at its "sweet_spot" with an exit model that has no closed form (hertz,
// flexible): the bat-speed point moved from free_bat's closed-form maximum (where ResolveScene
// put it) to the exit model's own maximum, by a fixed-point iteration with a stated tolerance.
#pragma once

#include <memory>
#include <optional>

#include "core/scene/resolved_scene.hpp"
#include "core/scene/scene_models.hpp"

namespace sweetspot::core {

/// Most iterations of SolveSweetSpotSwing.
inline constexpr int kMaxSweetSpotIterations = 20;
/// SolveSweetSpotSwing's tolerance on the speed at the model's maximum, relative to the given
/// speed (dimensionless); looser when the maximum's own error estimate (m) times omega is larger.
inline constexpr double kSweetSpotSpeedRelTolerance = 1e-6;

/// For `scene` whose swing has bat_speed_point kSweetSpot and a bat speed, and `model` kHertz
/// or kFlexible (else nothing happens, true): iterates omega_{k+1} = v / (x*(omega_k) - pivot),
/// x* the exit model's maximum (SearchMaxExitSpeed, or BracketMaxExitSpeed for flexible with
/// method closed_form, as max_exit_speed finds it), starting from free_bat's closed-form point,
/// until |omega_k (x*_k - pivot) - v| <= max(kSweetSpotSpeedRelTolerance v, omega_k * x*'s error
/// estimate), re-resolving *resolved (the swing, and a ball-law COR at the new speed) and
/// rebuilding *exit_model at each step. resolved->swing.resolution then names `model` as the
/// point's model, with its iterations; a run that stops without meeting the tolerance (a failed
/// search, kMaxSweetSpotIterations) warns in *summary with the speed error left. False (the
/// refusal in *summary) when a re-resolution is refused.
bool SolveSweetSpotSwing(const Scene& scene, const SceneOptions& options, CollisionModel model,
                         bool needs_cor, TimingBook* book,
                         const std::shared_ptr<const BatModes>& modes, ResolvedScene* resolved,
                         std::optional<ExitSpeedModel>* exit_model, Summary* summary);

}  // namespace sweetspot::core
