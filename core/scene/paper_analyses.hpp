// The seed paper's analyses regenerated from first principles, with the conventions of
// shared/docs/paper-notes.md that reproduce its printed numbers, beside the numbers of a
// consistent model. Every row says which inertia model (rigid body or the paper's slender
// rod) and which kinematics it uses. See docs/paper-analyses.md.
#pragma once

#include <string>
#include <vector>

namespace sweetspot::core {

/// The kinematics that reproduce Table 5 (paper-notes.md section 2): not the paper's Table 3.
struct PaperTable5Conventions {
  double cor = 0.5;                     ///< e.
  double angular_speed_rad_s = 34.576;  ///< omega = 2 x 17.288, rad/s.
  double ball_speed_mps = 41.69;        ///< |v1|, m/s.
  double ball_mass_kg = 0.1403;         ///< m, kg.
  double pivot_from_knob_m =
      0.1838;  ///< Pivot, m from the knob; positions are reported from the knob.
};

/// The paper's Table 3 kinematics with a regulation ball (the consistent model).
struct PaperTable3Kinematics {
  double cor = 0.5;                     ///< e.
  double angular_speed_rad_s = 17.288;  ///< omega, rad/s.
  double ball_speed_mps = 27.7;         ///< |v1|, m/s.
  double ball_mass_kg = 0.145;          ///< m, kg.
};

/// One row of Table 5 (J sweep; J about the pivot, as the paper gives it).
struct PaperTable5Row {
  double moi_pivot_kg_m2 = 0.0;       ///< J, kg m^2 (the paper's column).
  double printed_position_m = 0.0;    ///< The paper's sweet spot, m.
  double printed_speed_mps = 0.0;     ///< The paper's maximum speed, m/s.
  double position_from_knob_m = 0.0;  ///< Reproduced (PaperTable5Conventions), m from the knob.
  double speed_mps = 0.0;             ///< Reproduced maximum exit speed, m/s.
  double consistent_position_from_pivot_m = 0.0;  ///< Table 3 kinematics, same J: m from the pivot.
  double consistent_speed_mps = 0.0;              ///< Table 3 kinematics, same J: m/s.
};

/// Table 5 reproduced, and beside it the same J with the paper's own Table 3 kinematics.
std::vector<PaperTable5Row> PaperTable5();

/// One row of Table 4 (cork: a 0.0254 m x 0.254 m bore at the barrel end of "paper-wood").
struct PaperTable4Row {
  double cork_density_kg_m3 = 0.0;        ///< rho_s, kg/m^3.
  double printed_delta_mass_g = 0.0;      ///< The paper's dM, g.
  double printed_delta_balance_cm = 0.0;  ///< The paper's dC, "cm" (consistent only as metres).
  double printed_delta_moi_kg_m2 = 0.0;   ///< The paper's dJ, kg m^2.
  double printed_delta_speed_mps = 0.0;   ///< The paper's dv, m/s.
  double delta_mass_kg = 0.0;             ///< (rho - rho_s) V_s, kg (closed form for the bore).
  double delta_balance_m =
      0.0;  ///< C - C', m (slender-rod and rigid-body agree: same first moments).
  double delta_moi_knob_kg_m2 =
      0.0;  ///< J - J' about the knob, slender rod (closed form for the bore), kg m^2.
  double delta_moi_knob_check_kg_m2 =
      0.0;  ///< The same from ComputeMassProperties of the filled bat, kg m^2.
  double delta_speed_paper_mps =
      0.0;  ///< Paper convention: Table 5 at J0 = 0.213 minus at J0 - round(dJ, 2), m/s.
  double delta_speed_consistent_mps =
      0.0;  ///< One pivot (0.1838 m) for everything, Table 3 kinematics, slender rod, m/s.
};

/// Table 4 computed from first principles ("paper-wood" bat, slender-rod inertia).
std::vector<PaperTable4Row> PaperTable4();

/// The abstract's 66 cm and the body's 70 cm sweet-spot claims.
struct PaperSweetSpotClaim {
  std::string preset;               ///< "paper-wood-m885" or "paper-wood".
  double printed_position_m = 0.0;  ///< 0.66 or 0.70.
  double mass_kg = 0.0;             ///< M, kg.
  double moi_knob_kg_m2 = 0.0;  ///< Slender-rod J about the knob (the paper's integral), kg m^2.
  double position_from_knob_m = 0.0;             ///< Pivot at the knob, Table 3 kinematics, m.
  double exit_speed_mps = 0.0;                   ///< m/s.
  double rigid_body_position_from_knob_m = 0.0;  ///< The same with the full rigid-body J, m.
};

/// Both claims (pivot at the knob, |v1| = 27.7, omega = 17.288, m = 0.145, e = 0.5).
std::vector<PaperSweetSpotClaim> PaperSweetSpotClaims();

/// Wood against hollow aluminium, same outer shape (the paper's Figure 5).
struct PaperMaterialRow {
  std::string material;               ///< Catalogue name.
  double wall_thickness_m = 0.0;      ///< 0 = solid.
  double mass_kg = 0.0;               ///< M, kg.
  double moi_knob_kg_m2 = 0.0;        ///< Slender-rod J about the knob, kg m^2.
  double cor = 0.0;                   ///< e used (the material's default).
  double position_from_knob_m = 0.0;  ///< Sweet spot, pivot at the knob, Table 3 kinematics, m.
  double exit_speed_mps = 0.0;        ///< m/s.
};

/// The paper's shape in its wood and as a hollow aluminium-7050 shell (3 mm wall).
std::vector<PaperMaterialRow> PaperWoodVsAluminium();

}  // namespace sweetspot::core
