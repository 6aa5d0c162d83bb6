// The batted_ball output: at max_exit_speed's point, the oblique bat-ball impact
// (core/collision/oblique_impact.hpp: the normal part from the scene's closed-form exit-speed
// model, free_bat or rigid_pivot, the tangential part by the law's defaults), then the ball's
// flight (core/flight/flight.hpp: default environment and aero, nathan-2016).
#include <cmath>
#include <limits>
#include <string>

#include "core/collision/oblique_impact.hpp"
#include "core/flight/flight.hpp"
#include "core/geometry_format.hpp"
#include "core/scene/output_registry.hpp"

namespace sweetspot::core {
namespace outputs_batted_ball {
namespace {

// The scene's name of an oblique-impact input the impact refused ("undercut_m" ->
// "contact.undercut_m"); others as they are.
std::string SceneFieldOf(const std::string& field) {
  if (field == "undercut_m") return "contact.undercut_m";
  if (field == "attack_angle_deg") return "swing.attack_angle_deg";
  if (field == "descent_angle_deg") return "ball.descent_angle_deg";
  if (field == "ball_backspin_rad_s") return "ball.spin_rpm";
  return field;
}

// Reads max_exit_speed's result (its declaration's needs_output).
void ComputeBattedBall(OutputContext& c) {
  const MaxExitSpeedResult& mx = *c.out.max_exit_speed;
  if (!mx.summary.IsSolutionUsable()) {
    c.Note(Termination::kFailure, "batted_ball: needs max_exit_speed, which failed");
    return;
  }
  if (c.model != CollisionModel::kFreeBat && c.model != CollisionModel::kRigidPivot) {
    c.Refuse(TextRefusal("model", "batted_ball takes the normal impact from a closed-form "
                                  "exit-speed model: give options.model free_bat or "
                                  "rigid_pivot (hertz and flexible are not fed in yet)"));
    return;
  }
  const Scene& s = c.scene;
  const ResolvedScene& r = c.resolved;
  const Swing& swing = r.swing;
  const MassProperties& mp = r.mass_properties;
  const double x = mx.position_from_knob_m;
  // The bat's inverse effective mass along the line of centres at x: free_bat 1/M + b^2/I_cm,
  // rigid_pivot z^2/J (the models' own recoil factors divided by the ball's mass).
  double inverse_mass = 0.0;
  if (c.model == CollisionModel::kFreeBat) {
    const double b = x - mp.balance_point_m;
    inverse_mass = 1.0 / mp.mass_kg + b * b / mp.moi_centroid_kg_m2;
  } else {
    const RigidPivotInputs pivot = RigidPivotInputsFor(s, r);
    const double z = x - pivot.pivot_from_knob_m;
    inverse_mass = z * z / pivot.moi_pivot_kg_m2;
  }
  BattedBallResult out;
  out.impact_from_knob_m = x;
  out.undercut_m = s.contact.undercut_m;
  out.bat_effective_mass_kg =
      inverse_mass > 0.0 ? 1.0 / inverse_mass : std::numeric_limits<double>::infinity();
  out.normal_cor = *r.cor;

  ObliqueImpactInputs in;
  in.ball_speed_mps = s.ball.speed_mps;
  in.descent_angle_deg = s.ball.descent_angle_deg;
  in.ball_backspin_rad_s = RpmToRadPerSecond(s.ball.spin_rpm);
  in.bat_speed_mps = swing.angular_speed_rad_s * (x - swing.pivot_from_knob_m);
  in.attack_angle_deg = swing.attack_angle_deg;
  in.undercut_m = s.contact.undercut_m;
  in.ball_mass_kg = s.ball.mass_kg;
  in.ball_radius_m = s.ball.radius_m;
  if (s.bat.has_value()) {
    in.bat_radius_m = s.bat->RadiusAtM(x);
    in.bat_roll_moi_kg_m2 = BatRollMoiKgM2(*s.bat);
  } else {
    c.Warn(SceneOutput::kBattedBall,
           "no bat geometry (mass_properties only): the bat's radius and roll inertia are "
           "the oblique impact's defaults");
  }
  in.normal.bat_effective_mass_kg = out.bat_effective_mass_kg;
  in.normal.cor = out.normal_cor;
  out.bat_speed_at_impact_mps = in.bat_speed_mps;
  out.bat_radius_m = in.bat_radius_m;

  const auto ti = c.book.Now();
  out.impact = SolveObliqueImpact(in);
  c.book.Add("oblique_impact", c.book.Since(ti), 1);
  if (out.impact.summary.refusal.has_value()) {
    Refusal why = *out.impact.summary.refusal;
    why.field = SceneFieldOf(why.field);
    c.Refuse(std::move(why));
    return;
  }
  if (!out.impact.summary.IsSolutionUsable()) {
    c.Note(Termination::kFailure, "batted_ball: " + out.impact.summary.message);
    return;
  }
  flight::Launch launch;
  launch.exit_speed_mps = out.impact.exit_speed_mps;
  launch.launch_angle_deg = out.impact.launch_angle_deg;
  launch.backspin_rpm = out.impact.backspin_rpm;
  launch.sidespin_rpm = 0.0;  // a 2-D impact: no sidespin
  const auto tf = c.book.Now();
  out.flight = flight::Fly(launch);
  c.book.Add("flight", c.book.Since(tf), 1);
  if (!out.flight.Landed()) {
    const std::string why = out.flight.refusal.has_value()
                                ? out.flight.refusal->Message()
                                : flight::FlightTerminationName(out.flight.termination);
    c.Note(Termination::kFailure,
           "batted_ball: the ball's launch cannot be flown (exit speed " +
               FormatNumber(out.impact.exit_speed_mps) + " m/s, launch angle " +
               FormatNumber(out.impact.launch_angle_deg) + " deg): " + why);
    return;
  }
  c.out.batted_ball = std::move(out);
}

}  // namespace
}  // namespace outputs_batted_ball

extern const SceneOutputDecl kBattedBallOutput{
    SceneOutput::kBattedBall,
    "batted_ball",
    /*uses_exit_model=*/true,
    /*models=*/{"oblique_impact", "flight"},
    /*needs_geometry=*/false,
    /*needs_cor=*/true,
    OutputModes::kNone,
    "",
    /*needs_output=*/SceneOutput::kMaxExitSpeed,
    OutputWorkload::kAsExitModel,
    outputs_batted_ball::ComputeBattedBall,
    SlotPresent<&SceneOutputResults::batted_ball>,
    ResetSlot<&SceneOutputResults::batted_ball>,
    nullptr,
};

}  // namespace sweetspot::core
