// The COR an optimisation uses (issue 18), decided once per request from the scene and the
// base design: a typed policy, which the api only renders.
#pragma once

#include <optional>
#include <string>

#include "core/bat/mass_properties.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/scene/scene.hpp"

namespace sweetspot::core {

/// Where an optimisation's COR comes from.
enum class DesignCorPolicyKind {
  kScene,            ///< The request's `cor`, held fixed.
  kBarrelPerDesign,  ///< Each design's own barrel (DesignProblem::cor_from_barrel).
  kBaseDesign,       ///< The ball's law at the base design's impact speed, held fixed.
  kMaterial,         ///< The material's COR (of each design: the material may be chosen).
};

/// The policy ResolveDesignCor chose, with what its description needs.
struct DesignCorPolicy {
  DesignCorPolicyKind kind = DesignCorPolicyKind::kMaterial;
  /// kBarrelPerDesign: the ball's preset ("custom" without one).
  std::string ball;
  /// kBaseDesign: the base design's resolved source ("ball:<preset>" or "barrel:<preset>",
  /// ResolvedScene::cor_source) and the normal impact speed it was evaluated at, m/s.
  std::string base_source;
  double base_impact_speed_mps = 0.0;

  /// The answer's "cor_source" text; for kMaterial "material:<material_name>" (the chosen
  /// design's material).
  std::string Describe(const std::string& material_name) const;
};

/// True when a design of `problem` may be hollow: its base bat is, or a variable sets the wall.
bool MayBeHollowDesign(const DesignProblem& problem);

/// Chooses the COR of `problem` (objective, bat, variables set) in `scene` (its ball, swing,
/// cor and inertia model): the scene's `cor` held fixed; without one, a ball with a COR law
///   - on a hollow design with an exit-speed objective: each design's own barrel's COR
///     (sets problem->cor_from_barrel: the trampoline at kCorReferenceFromTipM from the tip);
///   - otherwise the law's value at the base design's impact speed (through the barrel for a
///     hollow base), held fixed while the design changes (sets problem->cor);
/// otherwise the material's (a scene the base cannot resolve is left to the problem's
/// validation). `base_properties` are the base bat's mass properties under
/// scene.inertia_model, computed once by the caller (not computed again here).
DesignCorPolicy ResolveDesignCor(const Scene& scene, const MassProperties& base_properties,
                                 DesignProblem* problem);

}  // namespace sweetspot::core
