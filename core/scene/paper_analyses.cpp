#include "core/scene/paper_analyses.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <utility>

#include "core/bat/bat.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"
#include "core/collision/rigid_pivot.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/sweet_spot/sweet_spot.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
namespace {

constexpr double kTable5Moi[] = {0.163, 0.173, 0.183, 0.193, 0.203, 0.213};
constexpr double kTable5Position[] = {0.596, 0.617, 0.638, 0.660, 0.682, 0.702};
constexpr double kTable5Speed[] = {31.517, 32.085, 32.645, 33.198, 33.744, 34.283};

// The unconstrained rigid-pivot maximum (x from the pivot, speed) for J about the pivot. The
// paper's Table 5 gives J itself (no bat), so these inputs are not built from mass properties.
ProfileMaximum MaxFor(double moi_pivot, double cor, double omega, double u, double m) {
  RigidPivotInputs in;
  in.moi_pivot_kg_m2 = moi_pivot;
  in.cor = cor;
  in.angular_speed_rad_s = omega;
  in.ball_speed_mps = u;
  in.ball_mass_kg = m;
  return RigidPivotProfile(in).Maximum();
}

double Table5Speed(double moi_pivot) {
  const PaperTable5Conventions c;
  return MaxFor(moi_pivot, c.cor, c.angular_speed_rad_s, c.ball_speed_mps, c.ball_mass_kg)
      .exit_speed_mps;
}

double Table3Speed(double moi_pivot) {
  const PaperTable3Kinematics k;
  return MaxFor(moi_pivot, k.cor, k.angular_speed_rad_s, k.ball_speed_mps, k.ball_mass_kg)
      .exit_speed_mps;
}

Bat PaperWood() {
  if (auto p = FindPreset("paper-wood")) return p->bat;
  Material wood;
  wood.name = "paper-wood";
  wood.density_kg_m3 = 649.0;
  wood.youngs_modulus_pa = 1.814e10;
  wood.cor = 0.5;
  return MakeThreeSegmentBat(PaperThreeSegmentShape(), wood);
}

}  // namespace

std::vector<PaperTable5Row> PaperTable5() {
  const PaperTable5Conventions c;
  std::vector<PaperTable5Row> rows;
  for (int i = 0; i < 6; ++i) {
    PaperTable5Row r;
    r.moi_pivot_kg_m2 = kTable5Moi[i];
    r.printed_position_m = kTable5Position[i];
    r.printed_speed_mps = kTable5Speed[i];
    const ProfileMaximum a =
        MaxFor(r.moi_pivot_kg_m2, c.cor, c.angular_speed_rad_s, c.ball_speed_mps, c.ball_mass_kg);
    r.position_from_knob_m = c.pivot_from_knob_m + a.x_m;
    r.speed_mps = a.exit_speed_mps;
    const PaperTable3Kinematics k;
    const ProfileMaximum b =
        MaxFor(r.moi_pivot_kg_m2, k.cor, k.angular_speed_rad_s, k.ball_speed_mps, k.ball_mass_kg);
    r.consistent_position_from_pivot_m = b.x_m;
    r.consistent_speed_mps = b.exit_speed_mps;
    rows.push_back(r);
  }
  return rows;
}

std::vector<PaperTable4Row> PaperTable4() {
  const Bat bat = PaperWood();
  const double rho = bat.material.density_kg_m3;
  const double length = bat.LengthM();
  const double diameter = 0.0254;
  const double depth = 0.254;
  const double rs = diameter / 2.0;
  const double area = kPi * rs * rs;
  const MassProperties base = ComputeMassProperties(bat, InertiaModel::kSlenderRod);
  const double pivot = PaperTable5Conventions{}.pivot_from_knob_m;
  struct Printed {
    double density, dm_g, dc_cm, dj, dv;
  };
  const Printed printed[] = {{320.0, 40.0, 0.01, 0.02, 1.1}, {260.0, 46.0, 0.01, 0.03, 1.6}};
  std::vector<PaperTable4Row> rows;
  for (const Printed& p : printed) {
    PaperTable4Row r;
    r.cork_density_kg_m3 = p.density;
    r.printed_delta_mass_g = p.dm_g;
    r.printed_delta_balance_cm = p.dc_cm;
    r.printed_delta_moi_kg_m2 = p.dj;
    r.printed_delta_speed_mps = p.dv;
    // The bore [L - d, L] loses (rho - rho_s) per unit volume: closed forms.
    const double drho = rho - p.density;
    const double x0 = length - depth;
    r.delta_mass_kg = drho * area * depth;
    const double first_moment = r.delta_mass_kg * (length - depth / 2.0);
    const double mass_after = base.mass_kg - r.delta_mass_kg;
    const double c_after = (base.mass_kg * base.balance_point_m - first_moment) / mass_after;
    r.delta_balance_m = base.balance_point_m - c_after;
    r.delta_moi_knob_kg_m2 = drho * area * (length * length * length - x0 * x0 * x0) / 3.0;
    // Cross-check with the general mass-properties code on the filled bat.
    Bat corked = bat;
    Fill fill;
    fill.material = FindMaterial("cork").value_or(Material{});
    fill.material.density_kg_m3 = p.density;
    fill.diameter_m = diameter;
    fill.depth_m = depth;
    corked.fill = fill;
    const MassProperties after = ComputeMassProperties(corked, InertiaModel::kSlenderRod);
    r.delta_moi_knob_check_kg_m2 = base.moi_knob_kg_m2 - after.moi_knob_kg_m2;
    // Paper convention: Table 5's kinematics at J0 = 0.213 and J0 - dJ rounded to 0.01.
    const double dj_rounded = std::round(r.delta_moi_knob_kg_m2 * 100.0) / 100.0;
    r.delta_speed_paper_mps = Table5Speed(0.213) - Table5Speed(0.213 - dj_rounded);
    // Consistent: one pivot for both bats, Table 3 kinematics, J about that pivot.
    r.delta_speed_consistent_mps =
        Table3Speed(base.MoiAboutKgM2(pivot)) - Table3Speed(after.MoiAboutKgM2(pivot));
    rows.push_back(r);
  }
  return rows;
}

std::vector<PaperSweetSpotClaim> PaperSweetSpotClaims() {
  std::vector<PaperSweetSpotClaim> out;
  const PaperTable3Kinematics k;
  for (auto [name, printed] : {std::pair<const char*, double>{"paper-wood-m885", 0.66},
                               std::pair<const char*, double>{"paper-wood", 0.70}}) {
    PaperSweetSpotClaim c;
    c.preset = name;
    c.printed_position_m = printed;
    const auto preset = FindPreset(name);
    if (!preset) continue;
    const MassProperties rod = ComputeMassProperties(preset->bat, InertiaModel::kSlenderRod);
    const MassProperties full = ComputeMassProperties(preset->bat, InertiaModel::kRigidBody);
    c.mass_kg = rod.mass_kg;
    c.moi_knob_kg_m2 = rod.moi_knob_kg_m2;
    const ProfileMaximum a =
        MaxFor(rod.moi_knob_kg_m2, k.cor, k.angular_speed_rad_s, k.ball_speed_mps, k.ball_mass_kg);
    c.position_from_knob_m = a.x_m;
    c.exit_speed_mps = a.exit_speed_mps;
    c.rigid_body_position_from_knob_m =
        MaxFor(full.moi_knob_kg_m2, k.cor, k.angular_speed_rad_s, k.ball_speed_mps, k.ball_mass_kg)
            .x_m;
    out.push_back(c);
  }
  return out;
}

std::vector<PaperMaterialRow> PaperWoodVsAluminium() {
  std::vector<PaperMaterialRow> out;
  const PaperTable3Kinematics k;
  const Bat wood = PaperWood();
  Bat alu = wood;
  alu.material = FindMaterial("aluminium-7050").value_or(Material{});
  alu.wall_thickness_m = 0.003;
  for (const Bat* b : std::initializer_list<const Bat*>{&wood, &alu}) {
    PaperMaterialRow r;
    r.material = b->material.name;
    r.wall_thickness_m = b->wall_thickness_m;
    const MassProperties mp = ComputeMassProperties(*b, InertiaModel::kSlenderRod);
    r.mass_kg = mp.mass_kg;
    r.moi_knob_kg_m2 = mp.moi_knob_kg_m2;
    r.cor = b->material.cor.value_or(0.5);
    const ProfileMaximum a =
        MaxFor(mp.moi_knob_kg_m2, r.cor, k.angular_speed_rad_s, k.ball_speed_mps, k.ball_mass_kg);
    const double length = b->LengthM();
    r.position_from_knob_m = std::min(a.x_m, length);
    Ball ball;
    ball.mass_kg = k.ball_mass_kg;
    ball.speed_mps = k.ball_speed_mps;
    Swing swing;  // the paper's pivot: the knob
    swing.pivot_from_knob_m = 0.0;
    swing.angular_speed_rad_s = k.angular_speed_rad_s;
    r.exit_speed_mps = RigidPivotProfile(RigidPivotInputsFor(mp, ball, swing, r.cor))
                           .ExitSpeedMps(r.position_from_knob_m);
    out.push_back(r);
  }
  return out;
}

}  // namespace sweetspot::core
