#include "core/optimize/design_cor.hpp"

#include <algorithm>
#include <vector>

#include "core/geometry_format.hpp"
#include "core/numerics/timing_book.hpp"
#include "core/scene/resolved_scene.hpp"

namespace sweetspot::core {

std::string DesignCorPolicy::Describe(const std::string& material_name) const {
  switch (kind) {
    case DesignCorPolicyKind::kScene:
      return "scene";
    case DesignCorPolicyKind::kBarrelPerDesign:
      return "barrel:" + ball + " recomputed for every design at " +
             FormatNumber(kCorReferenceFromTipM) +
             " m from its tip, at its normal impact speed there (cor_impact_from_knob_m, "
             "cor_impact_speed_mps: the answer's); treated as constant along the bat";
    case DesignCorPolicyKind::kBaseDesign:
      return base_source + " at the base design's impact speed (" +
             FormatNumber(base_impact_speed_mps) + " m/s), held fixed while the design changes";
    case DesignCorPolicyKind::kMaterial:
      break;
  }
  return "material:" + material_name;
}

bool MayBeHollowDesign(const DesignProblem& problem) {
  if (problem.bat.IsHollow()) return true;
  for (const DesignVariable& v : problem.variables) {
    std::vector<std::string> paths = {v.path};
    paths.insert(paths.end(), v.linked_paths.begin(), v.linked_paths.end());
    paths.insert(paths.end(), v.scale_paths.begin(), v.scale_paths.end());
    if (std::find(paths.begin(), paths.end(), "wall_thickness_m") != paths.end()) return true;
  }
  return false;
}

DesignCorPolicy ResolveDesignCor(const Scene& scene, const MassProperties& base_properties,
                                 DesignProblem* problem) {
  DesignCorPolicy policy;
  if (scene.cor.has_value()) {
    policy.kind = DesignCorPolicyKind::kScene;
    return policy;
  }
  const bool exit_speed = problem->objective == DesignObjective::kMaxExitSpeed ||
                          problem->objective == DesignObjective::kMaxExitSpeedSwingWeight ||
                          problem->objective == DesignObjective::kWidestSweetZone;
  if (exit_speed && scene.ball.cor_law.has_value() && MayBeHollowDesign(*problem)) {
    problem->cor_from_barrel = true;
    policy.kind = DesignCorPolicyKind::kBarrelPerDesign;
    policy.ball = scene.ball.preset.empty() ? "custom" : scene.ball.preset;
    return policy;
  }
  Scene base = scene;
  base.bat = problem->bat;
  base.mass_properties = base_properties;  // computed once, by the caller
  TimingBook book(false);
  ResolvedScene resolved;
  Summary summary;
  if (ResolveScene(base, true, &book, &resolved, &summary) &&
      (resolved.cor_origin == CorOrigin::kBall || resolved.cor_origin == CorOrigin::kBarrel)) {
    problem->cor = resolved.cor;
    policy.kind = DesignCorPolicyKind::kBaseDesign;
    policy.base_source = resolved.cor_source;
    policy.base_impact_speed_mps = resolved.cor_impact_speed_mps.value_or(0.0);
  }
  return policy;
}

}  // namespace sweetspot::core
