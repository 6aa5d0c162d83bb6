// Design problems shared by the hollow-bat optimiser tests (optimize_bbcor_test.cpp,
// optimize_barrel_cor_test.cpp): variables that reach every input of the barrel model (the
// wall, the impact point's segment, the length, the density) for the gradient checks.
#pragma once

#include <vector>

#include "core/bat/material.hpp"
#include "core/optimize/design_problem.hpp"

namespace sweetspot::core::hollow_design_problems {

/// Variables of the `bbcor-33-aluminium` preset's profile: the wall (m), the radii (m) and
/// positions (m) of knots 10 and 11 (the segment 6 in from the tip falls in), the last knot's
/// position (the length, m) and the alloy's density (kg/m^3).
inline std::vector<DesignVariable> PresetBarrelVariables() {
  return {
      {"wall_thickness_m", 0.0020, 0.0035},          {"profile.knots[10].radius_m", 0.030, 0.0334},
      {"profile.knots[11].radius_m", 0.030, 0.0334}, {"profile.knots[10].x_m", 0.50, 0.54},
      {"profile.knots[11].x_m", 0.80, 0.83},         {"profile.knots[12].x_m", 0.835, 0.845},
      {"material.density_kg_m3", 2500.0, 3000.0}};
}

/// A scale variable ("barrel", 0.97 to 1.03, dimensionless) on knot 9's radius and knot 4's
/// position of the same preset.
inline DesignVariable PresetScaleVariable() {
  return {"barrel", 0.97, 1.03, {}, {"profile.knots[9].radius_m", "profile.knots[4].x_m"}};
}

/// A three-segment aluminium-7050 bat (0.84 m long, radii 0.0125 / 0.032 m, tapers at 0.25 and
/// 0.60 m, a 2.5 mm wall) whose length, barrel and handle radii, taper end (in
/// [taper_end_min_m, taper_end_max_m], so the impact point can fall in the taper) and wall are
/// the variables.
inline DesignProblem ThreeSegmentAluminium(double taper_end_min_m, double taper_end_max_m) {
  DesignProblem p;
  p.three_segment = ThreeSegmentShape{0.84, 0.0125, 0.032, 0.25, 0.60};
  p.bat.material = *FindMaterial("aluminium-7050");
  p.bat.wall_thickness_m = 0.0025;
  p.variables = {{"three_segment.length_m", 0.80, 0.86},
                 {"three_segment.barrel_radius_m", 0.030, 0.0333},
                 {"three_segment.handle_radius_m", 0.011, 0.014},
                 {"three_segment.taper_end_m", taper_end_min_m, taper_end_max_m},
                 {"wall_thickness_m", 0.0018, 0.0035}};
  return p;
}

}  // namespace sweetspot::core::hollow_design_problems
