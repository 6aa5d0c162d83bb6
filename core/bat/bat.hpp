// The bat: a solid of revolution along x, from the knob (x = 0) to the barrel
// tip (x = L), with a piecewise-linear outer radius, a material, an optional
// hollow shell and an optional fill bored from the barrel end.
//
// Geometry conventions (everything SI, positions from the knob):
// - Outer radius: linear between knots; knots strictly increasing in x from 0
//   to L. A step in the radius is two knots a tiny distance apart (1e-12 m
//   works: the mass properties integrate each segment without dividing by its
//   length, so a short segment costs no accuracy).
// - Hollow shell (wall_thickness_m = t > 0): the inner radius is r(x) - t(x)
//   at every x (the wall is measured radially, not normal to the surface).
//   t(x) is the bat's wall_thickness_m, or, where knots give their own
//   wall_thickness_m (issue 35), linear between the knots' walls (a knot
//   without one takes the bat's): r - t stays linear per segment, so the mass
//   properties stay exact. The shell is an open tube unless an end cap and a
//   knob (BatPart, below) close it. The cavity holds nothing unless a fill is
//   given. t = 0 is a solid bat; t must be less than the smallest outer
//   radius, and a knot's own wall less than its radius.
// - Fill: a coaxial cylinder of radius diameter_m / 2 occupying
//   [L - depth_m, L]. In a solid bat it is bored out of the bat's material and
//   holds the fill material (density 0 = left empty, e.g. a cupped end); in a
//   hollow bat it sits inside the cavity, so it must fit inside the inner
//   radius. Either way it must lie strictly inside the material around it
//   over its whole depth, and depth_m <= L.
// - End cap and knob (BatPart, issue 35): parts the profile's material does not give, each a
//   uniform solid cylinder on the axis from its end of the bat inwards over its length_m, of
//   the bat's inner radius at that end (a solid bat's outer radius). Its mass adds to the
//   profile's there (the shell, or a solid bat's wood, is kept), exactly in the mass
//   properties (mass, balance point, moments with the part's own m (l^2/12 + r^2/4)) and in the
//   beam (its mass and rotary inertia per length over its range, no stiffness). It adds no
//   volume to MassProperties::volume_m3.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/bat/material.hpp"

namespace sweetspot::core {

// The sizes a bat given from outside (a request) is held to, by ValidateSize. Core's numerics
// work far beyond them (tests/hard_cases: a megametre bat); these say what is plausible.
/// Largest length of a bat and largest position along one (knots, taper, fill depth), m: a
/// 100 m bat is already absurd.
inline constexpr double kMaxBatLengthM = 100.0;
/// Largest radius of a bat (knots, handle, barrel; so also of its wall thickness), m.
inline constexpr double kMaxBatRadiusM = 10.0;
/// Largest diameter of a fill's bore, m.
inline constexpr double kMaxFillDiameterM = 10.0;
/// Largest mass of an end cap or a knob, kg (a 100 kg end cap is already absurd).
inline constexpr double kMaxBatPartMassKg = 100.0;

/// One knot of the outer radius profile.
struct ProfileKnot {
  double x_m = 0.0;       ///< Position from the knob, m.
  double radius_m = 0.0;  ///< Outer radius at x_m, m (> 0).
  /// The shell's wall at x_m, m: 0 = the bat's wall_thickness_m; > 0 (a hollow bat only, below
  /// radius_m) this knot's own. Linear between knots.
  double wall_thickness_m = 0.0;
};

/// The paper's three-segment shape: handle cylinder r1 on [0, x1], linear
/// taper to r2 on [x1, x2], barrel cylinder r2 on [x2, L].
struct ThreeSegmentShape {
  double length_m = 0.0;         ///< L, m (> 0).
  double handle_radius_m = 0.0;  ///< r1, m (> 0).
  double barrel_radius_m = 0.0;  ///< r2, m (> 0).
  double taper_start_m = 0.0;    ///< x1 from the knob, m (0 <= x1 <= x2).
  double taper_end_m = 0.0;      ///< x2 from the knob, m (x2 <= L).

  /// Width of the step that stands for a zero-length taper (0 < x1 = x2 < L,
  /// r1 != r2), relative to L: the two knots sit at x1 -+ L * kStepWidth / 2.
  /// The mass properties then differ from the ideal step's by less than
  /// kStepWidth / 6 relative (the exact integrals of the short taper).
  static constexpr double kStepWidth = 1e-12;

  /// True when the shape is well formed (finite; L, r1, r2 > 0;
  /// 0 <= x1 <= x2 <= L); otherwise the refusal in *refusal (if non-null): field, value and
  /// rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
  /// Validate, then the plausible sizes: L in (0, kMaxBatLengthM], r1, r2 in
  /// (0, kMaxBatRadiusM] ("length_m = 200: must be in (0, 100]"); for a shape given from
  /// outside.
  bool ValidateSize(Refusal* refusal) const;
  /// The knots of this shape, x strictly increasing: (0, r1), (x1, r1),
  /// (x2, r2), (L, r2) with coincident knots merged (x1 = 0: no handle knot;
  /// x2 = L: no barrel knot; x1 = x2 with r1 = r2: one knot; x1 = x2 = 0 or
  /// x1 = x2 = L: the bat is all barrel or all handle; 0 < x1 = x2 < L with
  /// r1 != r2: a step of width L * kStepWidth). 2 to 4 knots.
  std::vector<ProfileKnot> Knots() const;
  /// Knots() into *knots (its buffer reused: a sweep's designs).
  void KnotsInto(std::vector<ProfileKnot>* knots) const;
};

/// A cylinder bored from the barrel end along the axis and filled.
struct Fill {
  /// What fills the bore (density 0 = left empty; see EmptyFillMaterial()).
  Material material;
  double diameter_m = 0.0;  ///< Bore diameter, m (>= 0).
  /// Bore depth from the barrel tip towards the knob, m (0 <= depth_m <= L).
  double depth_m = 0.0;

  /// Bore radius, m.
  double RadiusM() const { return 0.5 * diameter_m; }
  /// True when the bore holds nothing (material density 0).
  bool IsEmpty() const { return material.density_kg_m3 == 0.0; }
};

/// An end cap or a knob: a part the profile's material does not give (see the file comment).
struct BatPart {
  double mass_kg = 0.0;   ///< The mass it adds, kg (> 0).
  double length_m = 0.0;  ///< Its length along the axis from its end of the bat, m (0 < l <= L).
  /// What it is made of: a catalogue material's name ("rubber", "aluminium-7050") or "" when
  /// not given. Informational (reported back); its mass is mass_kg.
  std::string material;
};

/// The handle of a two-piece bat (issue 35): its own material, and optionally its own wall,
/// from the knob to the joint; the bat's profile is unchanged, the bat's own material and wall
/// run from the joint to the tip. Exact in the mass properties (the integrals split at the
/// joint) and in the beam (the sections' material and wall per side).
struct Handle {
  Material material;  ///< The handle's material.
  /// The handle's wall, m: absent = the bat's walls (its wall_thickness_m and knots' walls);
  /// 0 = a solid handle; > 0 a hollow handle of this uniform wall (below the handle's radii).
  std::optional<double> wall_thickness_m;
  /// Where the handle ends and the barrel begins, from the knob, m (0 < joint < L).
  double joint_from_knob_m = 0.0;

  /// The handle's wall at a point whose bat's wall is `bat_wall_m`, m.
  double WallM(double bat_wall_m) const {
    return wall_thickness_m.has_value() ? *wall_thickness_m : bat_wall_m;
  }
};

/// A complete bat.
struct Bat {
  /// Outer radius; x strictly increasing from 0 to L (a step is two knots at
  /// nearly the same x).
  std::vector<ProfileKnot> knots;
  Material material;               ///< The bat's material.
  double wall_thickness_m = 0.0;   ///< Hollow shell wall, m; 0 = solid (see the file comment).
  std::optional<Fill> fill;        ///< Optional fill.
  std::optional<BatPart> end_cap;  ///< Optional end cap at the barrel tip (x in [L - l, L]).
  std::optional<BatPart> knob;     ///< Optional knob at the handle end (x in [0, l]).
  std::optional<Handle> handle;    ///< A two-piece bat's handle (x in [0, joint]).

  /// True when the bat is physically valid; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule", e.g.
  /// "knots[3].x_m = 0.2: must be greater than
  /// knots[2].x_m = 0.3". Refuses: fewer than 2 knots, non-finite numbers,
  /// first knot not at 0, x not strictly increasing, radius <= 0, an invalid
  /// material, wall < 0 or >= the smallest outer radius, a fill deeper than
  /// the bat, negative fill dimensions, a bore not strictly inside the
  /// material around it (outer radius, or inner radius of a hollow bat) over
  /// the fill's depth, an invalid non-empty fill material, an end cap or knob whose mass is not
  /// positive or whose length is not in (0, L] ("end_cap.length_m = 0.9: must be in (0, 0.84]").
  /// Does not allocate when refusal is null and the bat is valid.
  /// Core's field names: "wall_thickness_m", "knots[2].x_m", "fill.material.density_kg_m3".
  bool Validate(Refusal* refusal) const;
  /// Validate, then the plausible sizes: knots' x in [0, kMaxBatLengthM], radii in
  /// (0, kMaxBatRadiusM] (so the wall, below the smallest radius, and the fill's depth, within
  /// the length, are capped too), fill diameter in [0, kMaxFillDiameterM], an end cap's and a
  /// knob's mass in (0, kMaxBatPartMassKg], the materials' (the bat's, a fill's, a handle's)
  /// Material::ValidateSize ("knots[1].x_m = 150: must be in [0, 100]"); for a bat given from
  /// outside.
  bool ValidateSize(Refusal* refusal) const;
  /// Validate without the materials' own checks (the bat's material and a non-empty fill's):
  /// for a bat whose materials are known to pass them, as a sweep's designs that change only
  /// the geometry, the wall or the fill's size. Does not allocate when the bat is valid and
  /// refusal is null.
  bool ValidateGeometry(Refusal* refusal) const;
  /// The caps of ValidateSize alone (ValidateSize = Validate, then this): for a bat that
  /// Validate checks elsewhere.
  bool ValidateCaps(Refusal* refusal) const;
  /// The caps on the knots alone (x and radius), the first check of ValidateCaps: for a bat
  /// whose material, wall and fill are known to pass theirs.
  bool ValidateKnotCaps(Refusal* refusal) const;
  /// ValidateGeometry, the same verdict, for a bat whose knots are a valid shape's
  /// (ThreeSegmentShape::KnotsInto of a shape that passes Validate): 2 to 4 knots, finite, the
  /// first at 0, radii positive by the shape's own checks, so only their order is checked (a
  /// step on a bat too short for a double to resolve it puts two knots at one x), then the
  /// wall and the fill as ValidateGeometry checks them. For a sweep of a shape's fields.
  bool ValidateGeometryOfShapeKnots(Refusal* refusal) const;
  /// L, m (the last knot's x; 0 without knots).
  double LengthM() const;
  /// Outer radius at x (from the knob), m; 0 outside [0, L].
  double RadiusAtM(double x_m) const;
  /// True for a hollow shell (wall_thickness_m > 0).
  bool IsHollow() const { return wall_thickness_m > 0.0; }
  /// True when a knot gives its own wall (the wall varies along the bat).
  bool HasKnotWalls() const;
  /// The wall at knot i, m: its own wall_thickness_m when > 0, else the bat's.
  double KnotWallM(std::size_t i) const {
    return knots[i].wall_thickness_m > 0.0 ? knots[i].wall_thickness_m : wall_thickness_m;
  }
  /// The wall at x (from the knob), m: linear between the knots' walls (KnotWallM); 0 for a
  /// solid bat or outside [0, L].
  double WallAtM(double x_m) const;
  /// Inner radius of the shell at x, m: RadiusAtM(x) - WallAtM(x) for a hollow bat,
  /// 0 for a solid bat or outside [0, L].
  double InnerRadiusAtM(double x_m) const;
  /// Smallest outer radius over the bat, m (0 without knots).
  double MinRadiusM() const;
  /// The radius of a part's cylinder, m: the inner radius at the bat's tip (end_cap = true) or
  /// knob end (false; a two-piece bat's handle wall there), the outer radius there for a solid
  /// bat; 0 without knots.
  double PartRadiusM(bool end_cap) const;
  /// One side of a two-piece bat as a bat of its own over [0, joint] (knots cut at the joint,
  /// walls as there, no fill or parts): with the handle's material and wall (`handle_side`) or
  /// with the bat's. Needs a valid bat with a handle.
  Bat HandleRegion(bool handle_side) const;

 private:
  // Validate's checks in its order; the materials' own only when `materials`.
  bool ValidateChecks(Refusal* refusal, bool materials) const;
  // The knots' checks of ValidateChecks, in order: their count, finite numbers, the first at 0,
  // x strictly increasing, radii positive.
  bool ValidateKnotOrder(Refusal* refusal) const;
  // An end cap's or knob's checks (its fields prefixed by `prefix`, "end_cap."); true without one.
  bool ValidatePart(const std::optional<BatPart>& part, std::string_view prefix,
                    Refusal* refusal) const;
  // A handle's checks ("handle.joint_from_knob_m", ...); true without one.
  bool ValidateHandle(Refusal* refusal, bool materials) const;
  // The rest of ValidateChecks, for valid knots whose smallest radius is `min_radius`: the
  // materials (when `materials`), the wall and the fill.
  bool ValidateBody(Refusal* refusal, bool materials, double min_radius) const;
};

/// A bat of the paper's three-segment shape (knots from shape.Knots()),
/// solid, without fill.
Bat MakeThreeSegmentBat(const ThreeSegmentShape& shape, const Material& material);

}  // namespace sweetspot::core
