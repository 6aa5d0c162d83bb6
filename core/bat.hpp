// The bat: a solid of revolution along x, from the knob (x = 0) to the barrel
// tip (x = L), with a piecewise-linear outer radius, a material, an optional
// hollow shell and an optional fill bored from the barrel end.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/material.hpp"

namespace sweetspot::core {

/// One knot of the outer radius profile.
struct ProfileKnot {
  double x_m = 0.0;       ///< Position from the knob, m.
  double radius_m = 0.0;  ///< Outer radius at x_m, m (> 0).
};

/// The paper's three-segment shape: handle cylinder r1 on [0, x1], linear
/// taper to r2 on [x1, x2], barrel cylinder r2 on [x2, L].
struct ThreeSegmentShape {
  double length_m = 0.0;         ///< L, m.
  double handle_radius_m = 0.0;  ///< r1, m.
  double barrel_radius_m = 0.0;  ///< r2, m.
  double taper_start_m = 0.0;    ///< x1 from the knob, m (0 <= x1 <= x2).
  double taper_end_m = 0.0;      ///< x2 from the knob, m (x2 <= L).

  /// True when the shape is well formed; otherwise "field = value: rule" in *why.
  bool IsValid(std::string* why) const;
  /// The knots of this shape (3 or 4 knots; coincident knots are merged).
  std::vector<ProfileKnot> Knots() const;
};

/// A cylinder bored from the barrel end along the axis and filled.
struct Fill {
  Material material;        ///< What fills the bore (density 0 = left empty).
  double diameter_m = 0.0;  ///< Bore diameter, m.
  double depth_m = 0.0;     ///< Bore depth from the barrel tip towards the knob, m.
};

/// A complete bat.
struct Bat {
  std::vector<ProfileKnot> knots;  ///< Outer radius; x strictly increasing from 0 to L (a step is two knots at nearly the same x).
  Material material;               ///< The bat's material.
  double wall_thickness_m = 0.0;   ///< Hollow shell wall, m; 0 = solid.
  std::optional<Fill> fill;        ///< Optional fill.

  /// True when the bat is physically valid; otherwise "field = value: rule" in *why.
  bool IsValid(std::string* why) const;
  /// L, m.
  double LengthM() const;
  /// Outer radius at x (from the knob), m; 0 outside [0, L].
  double RadiusAtM(double x_m) const;
};

/// A bat of the paper's three-segment shape.
Bat MakeThreeSegmentBat(const ThreeSegmentShape& shape, const Material& material);

}  // namespace sweetspot::core
