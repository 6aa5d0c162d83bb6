// The scene outputs of the barrel model (core/collision/barrel.hpp): `barrel` (the hoop mode,
// the barrel's stiffness and the effective COR along the barrel for the scene's ball and swing)
// and `bbcor` (the NCAA protocol, independent of the scene's ball and swing).
#pragma once

#include <string>

#include "core/collision/barrel.hpp"
#include "core/collision/bbcor_scan.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/scene/scene.hpp"

namespace sweetspot::core {

/// The `barrel` output of `scene` (its bat required) resolved as `resolved` (COR resolved). The
/// ball's COR at each point: the ball's COR law at the normal impact speed
/// ball.speed_mps + omega (x - pivot) when the ball has one, else the resolved COR. False with
/// *error when the model fails.
bool SceneBarrel(const Scene& scene, const ResolvedScene& resolved, const BarrelOptions& options,
                 BarrelOutput* out, std::string* error);

/// THE BBCOR of `bat` (issue 35; bbcor_scan.hpp): the flexible scan's maximum over the barrel
/// by the NCAA protocol with `flexible`'s impact options and modes (`modes`: the bat's impact
/// modes when the caller has them, else computed here with flexible.ImpactModes() and its
/// cache), `barrel`'s wall, the fixed-point estimate beside it. `rigid_body_properties` as
/// ComputeBbcorScan's. `scan` (optional): the whole scan. Never throws; ok = false with the
/// message on a failure (the modes' included).
BbcorResult ComputeCertifiedBbcor(const Bat& bat, const FlexibleOptions& flexible = {},
                                  const BarrelOptions& barrel = {},
                                  const MassProperties* rigid_body_properties = nullptr,
                                  const BatModes* modes = nullptr, BbcorScan* scan = nullptr);

}  // namespace sweetspot::core
